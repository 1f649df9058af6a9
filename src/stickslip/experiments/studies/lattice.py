"""``stickslip study lattice``: the paper's model (eq. 4) on the L x L square pulled at its left
edge, beside the chain, and Carlson-Langer on the periodic square (docs/lattice.md;
docs/studies/lattice.md).

Three parts, each point one task (:mod:`stickslip.experiments.studies.lattice_points`):

* the transition against beta: an ``up`` and a ``down`` ladder per L, as the transition study
  runs them for the chain; per rung the order parameter m = 1 - <d>/d_ss (d the mean slip
  deficit) and the final state; the edges of each ladder beside the finite lattice's linear
  threshold (:func:`~stickslip.analysis.dynamics.lattice_stability.lattice_critical_beta`);
* the slip sizes (moments) and magnitudes M = (2/3) log10 S
  (:func:`~stickslip.analysis.stats.magnitudes.magnitude`) of eq. (4) on the square at one beta
  from perturbed steady sliding, beside the chain of N = L blocks: tau of the truncated power law
  below the smallest spanning event and the b-value of the magnitudes;
* Carlson-Langer's magnitudes on the periodic square from rest.

Every point's cost is estimated before it runs (:func:`estimate_seconds`, from per-block-step
costs measured on the 2-core machine), and the run lengths of ``--full`` are chosen so that the
total fits in two hours on two cores; eq. (4) on the square runs on the dense integrator (its
state variable changes at every block and step), so L = 256 does not fit (:func:`describe`).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from stickslip.experiments.studies import Design, Study, finite, short
from stickslip.experiments.studies.lattice_points import lattice_check, lattice_task, loading_time

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["DESIGN", "build", "estimate_seconds", "ladder_edges", "size_fits", "findings", "SECONDS_PER_BLOCK_STEP"]

#: Seconds per block and step, measured on the 2-core machine under load (stickslip 0.1.0): eq. (4)
#: on the square (dense: every block every step, 26e6 block-steps/s), Carlson-Langer on the
#: periodic square (the active-set path, about 30e6 block-steps/s at L = 32 to 128 while the
#: events are small) and the paper's chain (its event-driven path, per block-step of the run).
SECONDS_PER_BLOCK_STEP = {"ladder": 3.9e-8, "sizes": 3.9e-8, "cl": 3.5e-8, "chain": 1.0e-9}
#: The beta of the size distributions: inside stick-slip for every L and for the chain.
BETA_SIZES = 0.5
#: Fewest events of a run for its fits of tau and b.
MIN_EVENTS = 50
#: The two-hour budget of --full on two cores, in core-seconds.
FULL_BUDGET = 2 * 3600.0 * 2


def _grid(mode: str) -> dict[str, Any]:
    if mode == "tiny":
        return dict(
            ladders={4: ((0.6, 1.6), 1.0)}, sizes={4: 2.0}, chains=(4,), cl={8: 300.0}, chain_loads=4.0,
        )  # fmt: skip
    if mode == "quick":
        return dict(
            ladders={16: ((0.6, 0.8, 0.95, 1.05, 1.2, 1.4), 1.5)}, sizes={16: 3.0, 32: 0.6},
            chains=(16, 32, 64), cl={32: 1500.0, 64: 800.0}, chain_loads=4.0,
        )  # fmt: skip
    return dict(
        ladders={16: ((0.5, 0.7, 0.8, 0.9, 0.95, 1.0, 1.05, 1.1, 1.2, 1.4, 1.7, 2.0), 2.0),
                 32: ((0.8, 0.95, 1.0, 1.05, 1.2), 1.0)},
        sizes={16: 6.0, 32: 2.0, 64: 0.75}, chains=(16, 32, 64, 128, 256),
        cl={32: 3000.0, 64: 2000.0, 128: 800.0, 256: 250.0}, chain_loads=4.0,
    )  # fmt: skip


def build(mode: str) -> Study:
    """The points of ``mode``: per ladder L an up and a down ladder over its betas (each rung
    ``rung_loads`` loading times), eq. (4) on the square at beta = :data:`BETA_SIZES` for each
    size L (its ``loads`` loading times from perturbed steady sliding, events of the second
    half), the chain at every L in ``chains``, and Carlson-Langer at each L of ``cl``; the
    costliest first."""
    g = _grid(mode)
    pts: list[dict[str, Any]] = []
    for L, (betas, loads) in g["ladders"].items():
        for direction in ("up", "down"):
            bs = sorted(betas, reverse=direction == "down")
            pts.append({"part": "ladder", "L": L, "N": L * L, "direction": direction, "betas": bs, "rung_loads": loads})
    for L, loads in g["sizes"].items():
        t_end = round(loads * loading_time(L), 3)
        pts.append({"part": "sizes", "L": L, "N": L * L, "beta": BETA_SIZES, "t_end": t_end})
    for L in g["chains"]:
        pts.append({"part": "chain", "L": L, "N": L, "beta": BETA_SIZES, "t_end": g["chain_loads"] * loading_time(L)})
    for L, t_end in g["cl"].items():
        pts.append({"part": "cl", "model": "carlson-langer", "L": L, "N": L * L, "t_end": t_end, "transient": 0.2})
    pts.sort(key=lambda p: -estimate_seconds(p))
    common = {"model": "sakaguchi", "perturbation": 1e-3, "down_perturbation": 1e-5, "n_samples": 400, "bootstrap": 200}
    ladders = ", ".join(
        f"L = {L}: beta in {list(b)}, {lo:g} loading times a rung" for L, (b, lo) in g["ladders"].items()
    )
    sizes = ", ".join(f"L = {L} ({lo:g} loads)" for L, lo in g["sizes"].items())
    note = (
        f"{mode}: eq. (4) on the L x L square pulled at its left edge, up and down ladders ({ladders}); "
        f"sizes at beta = {BETA_SIZES:g} from perturbed steady sliding, {sizes}, beside the chain at N = "
        f"{', '.join(str(n) for n in g['chains'])} ({g['chain_loads']:g} loads); Carlson-Langer on the periodic "
        f"square, " + ", ".join(f"L = {L} to t = {t:g}" for L, t in g["cl"].items())
    )
    return Study("lattice", mode, common, tuple(pts), note=note)


def estimate_seconds(point: dict[str, Any]) -> float:
    """The point's cost in seconds: its block-steps (blocks times steps of dt = 0.005) times
    :data:`SECONDS_PER_BLOCK_STEP` of its part."""
    part, L = point["part"], int(point["L"])
    if part == "ladder":
        t = len(point["betas"]) * float(point["rung_loads"]) * loading_time(L)
    else:
        t = float(point["t_end"])
    blocks = L if part == "chain" else L * L
    return t / 0.005 * blocks * SECONDS_PER_BLOCK_STEP[part]


# ---------------------------------------------------------------------------------------------
# Findings


def _rows(table: pd.DataFrame, part: str) -> pd.DataFrame:
    return table[table["part"] == part] if "part" in table else table.iloc[:0]


def _rungs(table: pd.DataFrame) -> list[dict[str, Any]]:
    out = []
    for r in _rows(table, "ladder").itertuples():
        out += [{"L": int(r.L), "direction": r.direction, **g} for g in json.loads(r.rungs)]
    return out


def ladder_edges(rungs: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per L: where the up ladder leaves stick-slip (its last stick-slip beta and the first steady
    beta above it, :func:`~stickslip.analysis.stats.order.transition_bracket`), where the down
    ladder leaves steady sliding (the same bracket on its rungs), m at the up ladder's last
    stick-slip beta, and the finite lattice's linear threshold of steady sliding."""
    from stickslip.analysis.dynamics.lattice_stability import lattice_critical_beta
    from stickslip.analysis.stats.order import transition_bracket
    from stickslip.experiments.studies.lattice_points import lattice_params

    out = []
    for L in sorted({r["L"] for r in rungs}):
        rec: dict[str, Any] = {"L": L, "linear_threshold": lattice_critical_beta(lattice_params({"L": L, "beta": 1.0}))}
        for d in ("up", "down"):
            g = [r for r in rungs if r["L"] == L and r["direction"] == d]
            if not g:
                continue
            br = transition_bracket([r["beta"] for r in g], [r["final_state"] for r in g])
            rec[f"{d}_lo"], rec[f"{d}_hi"], rec[f"{d}_undecided"] = br["lo"], br["hi"], br["undecided"]
            at = [r for r in g if r["beta"] == br["lo"]]
            rec[f"{d}_m_at_lo"] = at[0]["order_parameter"] if at else math.nan
            rec[f"{d}_m_err_at_lo"] = at[0]["order_parameter_err"] if at else math.nan
        out.append(rec)
    return out


def size_fits(table: pd.DataFrame, bootstrap: int = 200) -> list[dict[str, Any]]:
    """Per part (sizes, chain, cl) and L: tau of the truncated power law of the sizes below the
    smallest spanning one (:func:`~stickslip.analysis.stats.statistics.fit_power_law`, s_min by
    least KS distance, bootstrap error) and the b-value of the magnitudes M = (2/3) log10 S at or
    above M(s_min) (:func:`~stickslip.analysis.stats.magnitudes.b_value`; its error the larger of
    Shi and Bolt's and the bootstrap's) beside b = (3/2)(tau - 1)."""
    from stickslip.analysis.stats.magnitudes import DM, b_from_tau, b_value, magnitude
    from stickslip.analysis.stats.statistics import fit_power_law

    out = []
    for part in ("sizes", "chain", "cl"):
        for r in _rows(table, part).sort_values("L").itertuples():
            S, spans = np.asarray(json.loads(r.sizes), dtype=float), np.asarray(json.loads(r.spans), dtype=bool)
            rec: dict[str, Any] = {"part": part, "L": int(r.L), "N": int(r.N), "events": int(S.size)}
            rec["spanning"] = int(spans.sum())
            if "n_all_rows" in r._fields and part != "chain" and finite(r.n_all_rows):
                rec["all_rows"] = int(r.n_all_rows)
            rec.update(tau=math.nan, tau_err=math.nan, b=math.nan, b_err=math.nan, b_from_tau=math.nan)
            cutoff = float(S[spans].min()) if spans.any() else None
            if S.size < MIN_EVENTS:
                rec["note"] = f"fewer than {MIN_EVENTS} events: no fit"
                out.append(rec)
                continue
            try:
                fit = fit_power_law(S[S > 0], cutoff=cutoff, bootstrap=bootstrap, seed=0)
                rec.update(tau=fit.tau, tau_err=fit.tau_err, s_min=fit.s_min, s_max=fit.s_max, n_fit=fit.n)
                rec["b_from_tau"] = b_from_tau(fit.tau)
                M = magnitude(S[(S > 0) & (S <= fit.s_max)])
                mc = math.ceil(float(magnitude(fit.s_min)) / DM - 1e-9) * DM
                bv = b_value(M, round(mc, 6), bootstrap=bootstrap, seed=0)
                errs = [e for e in (bv.b_err_shi_bolt, bv.b_err_bootstrap) if finite(e)]
                rec.update(b=bv.b, b_err=max(errs) if errs else math.nan, mc=mc)
            except (ValueError, TypeError) as exc:  # too few events or distinct sizes for a fit
                rec["note"] = str(exc)
            out.append(rec)
    return out


def _names(part: str, L: int) -> str:
    return {"sizes": f"square L = {L}", "chain": f"chain N = {L}", "cl": f"Carlson-Langer L = {L}"}[part]


def findings(spec: Study, table: pd.DataFrame) -> dict[str, Any]:
    """The statements of the three parts (module docstring) and their numbers."""
    rungs = _rungs(table)
    edges = ladder_edges(rungs)
    fits = size_fits(table, int(spec.common.get("bootstrap", 200)))
    say: list[str] = []
    for e in edges:
        say.append(
            f"L = {e['L']}: the up ladder stick-slips up to beta = {short(e.get('up_lo'))} (steady from "
            f"{short(e.get('up_hi'))}; m there {short(e.get('up_m_at_lo'))} +- {short(e.get('up_m_err_at_lo'), 2)}); "
            f"the down ladder stick-slips up to {short(e.get('down_lo'))} (steady from {short(e.get('down_hi'))}); "
            f"undecided rungs: up {e.get('up_undecided', [])}, down {e.get('down_undecided', [])}; the finite "
            f"lattice's linear threshold is beta = {e['linear_threshold']:.4f}"
        )
    for L in sorted({r["L"] for r in rungs}):
        for d in ("up", "down"):
            g = [r for r in rungs if r["L"] == L and r["direction"] == d]
            say.append(
                f"L = {L}, {d} ladder: "
                + "; ".join(
                    f"beta {r['beta']:g} {r['final_state']} (m = {short(r['order_parameter'])} +- "
                    f"{short(r['order_parameter_err'], 2)}, {r['n_events']} events, {r['n_all_rows']} across all rows)"
                    for r in g
                )
            )
    for f in fits:
        tail = f" ({f['note']})" if "note" in f else ""
        say.append(
            f"{_names(f['part'], f['L'])}: {f['events']} events ({f['spanning']} spanning"
            + (f", {f['all_rows']} across all rows" if "all_rows" in f else "")
            + f"); tau = {short(f['tau'])} "
            f"+- {short(f['tau_err'], 2)}, b = {short(f['b'])} +- {short(f['b_err'], 2)} (from tau: "
            f"{short(f['b_from_tau'])}){tail}"
        )
    pairs = {(f["part"], f["L"]): f for f in fits}
    for (part, L), f in sorted(pairs.items()):
        c = pairs.get(("chain", L))
        if part == "sizes" and c and finite(f["tau"]) and finite(c["tau"]):
            z = (f["tau"] - c["tau"]) / math.hypot(f["tau_err"], c["tau_err"])
            say.append(f"L = {L}: tau on the square minus the chain's = {f['tau'] - c['tau']:+.3f} ({z:+.1f} sigma)")
    square_L = [int(L) for L in _rows(table, "sizes")["L"]] + [e["L"] for e in edges]
    if square_L and max(square_L) < 256:
        say.append(
            f"eq. (4) on the square stops at L = {max(square_L)} here: it runs on the dense integrator, and one "
            f"loading time at L = 256 costs about {_load_hours(256):.0f} core-hours (L = 128: "
            f"{_load_hours(128):.0f}), beyond any run of this study; L = 256 is the chain's and Carlson-Langer's only"
        )
    return {"statements": say, "edges": edges, "rungs": rungs, "fits": fits}


def figures(spec: Study, table: pd.DataFrame, page_dir: Path) -> list[tuple[str, Any, str]]:
    """m and the stuck fraction against beta (both ladders per L), the size densities and the
    magnitude distributions of the square beside the chain's, and Carlson-Langer's
    (:mod:`stickslip.plotting.lattice_study`)."""
    from stickslip.plotting.lattice_study import ladders_figure, magnitudes_figure, sizes_figure

    found = findings(spec, table)
    out: list[tuple[str, Any, str]] = []
    if found["rungs"]:
        caption = (
            "Eq. (4) on the L x L square: m = 1 - <d>/d_ss (d the mean slip deficit) and the fraction of time with "
            "a block stuck against beta, up ladders (filled) and down ladders (open, dashed); markers ringed where "
            "the rung ended steady; dotted: the finite lattice's linear threshold."
        )
        out.append(("ladders", ladders_figure(found["rungs"], found["edges"]), caption))
    sizes = {p: _sizes(table, p) for p in ("sizes", "chain", "cl")}
    if sizes["sizes"] or sizes["chain"]:
        caption = (
            f"Slip sizes (moments) at beta = {BETA_SIZES:g}: densities on log bins of eq. (4) on the square (left) "
            "and of the chain of N = L blocks (right); events of each run's second half."
        )
        out.append(("sizes", sizes_figure(sizes["sizes"], sizes["chain"]), caption))
        caption = (
            "Magnitudes M = (2/3) log10 S: the number of events with magnitude at least M, per unit of run time after "
            "the transient, for the square, the chain and Carlson-Langer on the periodic square."
        )
        out.append(("magnitudes", magnitudes_figure(sizes), caption))
    return out


def _sizes(table: pd.DataFrame, part: str) -> list[dict[str, Any]]:
    rows = _rows(table, part).sort_values("L") if len(_rows(table, part)) else _rows(table, part)
    frac = {"cl": 0.8}.get(part, 0.5)
    return [
        {"L": int(r.L), "S": np.asarray(json.loads(r.sizes), dtype=float), "t": frac * float(r.t_end)}
        for r in rows.itertuples()
    ]


def _tables(found: dict[str, Any]) -> list[tuple[str, list[str], list[dict[str, Any]]]]:
    edges = [{k: v for k, v in e.items() if not k.endswith("undecided")} for e in found.get("edges", [])]
    return [
        ("transition per L", "L up_lo up_hi up_m_at_lo down_lo down_hi linear_threshold".split(), edges),
        ("rungs", "L direction beta order_parameter order_parameter_err stuck_fraction final_state n_events".split(),
         found.get("rungs", [])),
        ("sizes and magnitudes", "part L N events spanning all_rows tau tau_err s_min s_max b b_err b_from_tau".split(),
         found.get("fits", [])),
    ]  # fmt: skip


def _total(mode: str) -> float:
    return sum(estimate_seconds(p) for p in build(mode).points)


COST = {
    "quick": "about 8 minutes on two free cores (measured: 846 s of CPU; 52 minutes of wall time at load "
    "average 17 to 23)",
    "full": "about 100 minutes on two cores (measured: 107 minutes of wall time on two shared cores; the points' "
    "run times sum to 11,142 s)",
}


def describe() -> str:
    """The text of ``stickslip study lattice --help``."""
    quick, full = build("quick"), build("full")
    return (
        "Eq. (4) on the L x L square pulled at its left edge (docs/lattice.md): the stick-slip transition against "
        "beta (order parameter m = 1 - <d>/d_ss of the mean slip deficit, up and down ladders), the slip-size and "
        "magnitude distributions beside the chain's, and Carlson-Langer's on the periodic square. Grid: --quick "
        f"{quick.note.split(': ', 1)[1]} ({len(quick.points)} points, {COST['quick']}; estimated "
        f"{_total('quick') / 60:.0f} core-minutes); --full {full.note.split(': ', 1)[1]} ({len(full.points)} points, "
        f"{COST['full']}; {_total('full') / 3600:.1f} core-hours). Eq. (4) on the square runs dense (26e6 "
        f"block-steps/s): a loading time of L = 256 costs about {_load_hours(256):.0f} core-hours, so the square's "
        "sizes stop at L = 64 and L = 256 is the chain's and Carlson-Langer's only. Outputs in DIR/lattice/: "
        "table.parquet and table.csv (one row per point), ladders, sizes and magnitudes (PNG, PDF), study.json, "
        "index.html."
    )


def _load_hours(L: int) -> float:
    return loading_time(L) / 0.005 * L * L * SECONDS_PER_BLOCK_STEP["sizes"] / 3600.0


DESIGN = Design(
    cost=COST,
    name="lattice",
    summary="eq. (4) on the square: the transition against beta, slip sizes and magnitudes beside the chain",
    describe=describe,
    build=build,
    task=lattice_task,
    check=lattice_check,
    findings=findings,
    figures=figures,
    columns=tuple("part model L N direction beta n_events n_spanning S_max t_end run_wall_seconds".split()),
    tables=_tables,
)
