"""``stickslip study disorder``: chains with quenched random thresholds Fs_i (Sakaguchi and
Kadowaki, arXiv:1705.06410; docs/studies/disorder.md).

Three parts, each point one run (:mod:`stickslip.experiments.studies.disorder_points`):

* ``a``: the paper's chain (eq. 4) with Fs_i uniform on [3 (1 - w), 3 (1 + w)]: the order
  parameter m against beta through 1 (as the phase diagram reads it) and tau at beta = 0.4;
* ``b``: the random medium under a slowly increased force F0 + r t (velocity-strengthening
  friction F0 + beta v, random Fs_i) from rest: the events until the chain depins and their
  sizes pooled over disorder seeds, tau against N and beta beside qEW's 1.11;
* ``c``: a constant force F from rest: the mean velocity against F through the depinning force
  F_c, velocity-strengthening against Carlson-Langer's velocity weakening.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from stickslip.experiments.studies import Design, Study, finite, short
from stickslip.experiments.studies.chain_point import t_end_of
from stickslip.experiments.studies.disorder_points import disorder_check, disorder_task
from stickslip.models.physics import UNTIL_STEADY
from stickslip.models.presets import paper_parameters

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["DESIGN", "QEW_ZETA", "QEW_ZETA_ERR", "qew_tau", "findings", "ramp_fits", "part_a", "part_c"]

#: The roughness exponent of the quenched Edwards-Wilkinson line in one dimension
#: (Ferrero, Bustingorry and Kolton, Phys. Rev. E 87, 032122 (2013)).
QEW_ZETA, QEW_ZETA_ERR = 1.250, 0.005
#: Relative widths w of the paper's chain's random thresholds (part a).
WIDTHS = (0.0, 0.05, 0.1, 0.2, 0.4)
#: The random medium of parts b and c: strengthening friction F0 + beta v with F0 = 2 and
#: thresholds Fs_i uniform on [2, 4] (mean 3, w = 1/3); a block slipping at F > F0 never stops
#: on its own, so F0 sits at the weakest threshold (explored in docs/studies/disorder.md).
MEDIUM = {"model": "train", "drive": "force-ramp", "friction": "strengthening", "F0": 2.0, "Fs": "uniform(2, 4)"}
#: Carlson-Langer's weakening law under a constant force, thresholds uniform on [2/3, 4/3].
CL_MEDIUM = {
    "model": "carlson-langer",
    "drive": "constant-force",
    "friction": "weakening",
    "Fs": "uniform(0.667, 1.333)",
}


#: The ramp F_start + r t runs from F0 = 2 (nothing slips below the weakest threshold) to
#: RAMP_END, above every depinning force seen in the exploration (2.2 to 2.52).
RAMP_START, RAMP_END = 2.0, 2.7


def ramp_rate(N: int) -> float:
    """The ramp's rate r = 0.064 / N (1e-3 at N = 64): the chain's total load grows at the same
    rate at every N, so slips elsewhere start as often during an avalanche at every N (at a fixed
    r a long chain's avalanches overlap and merge into one event)."""
    return 0.064 / N


def qew_tau(zeta: float = QEW_ZETA, zeta_err: float = QEW_ZETA_ERR) -> tuple[float, float]:
    """qEW's avalanche-size exponent tau = 2 - 2 / (1 + zeta) (Rosso, Le Doussal and Wiese 2009)
    and its error from zeta's: 1.111 +- 0.001 at zeta = 1.250 +- 0.005."""
    return 2.0 - 2.0 / (1.0 + zeta), 2.0 * zeta_err / (1.0 + zeta) ** 2


def _fs(w: float) -> Any:
    return 3.0 if w == 0 else f"uniform({3 * (1 - w):.6g}, {3 * (1 + w):.6g})"


def _grid(mode: str) -> dict[str, Any]:
    if mode == "tiny":
        return dict(
            aN=9, abetas=(0.8, 1.4), widths=(0.0, 0.2), sN=19, sloads=5.0, bNs=(16,), bbetas=(1.0,), bseeds=2,
            scanN=16, cN=16, cF=(2.1, 2.6), cseeds=1, clF=(0.95, 1.05), ct=60.0, clt=20.0,
        )  # fmt: skip
    if mode == "quick":
        return dict(
            aN=49, abetas=(0.8, 0.9, 1.0, 1.1, 1.2, 1.3, 1.4), widths=WIDTHS, sN=99, sloads=5.0,
            bNs=(64, 256, 1024), bbetas=(0.2, 1.0, 3.0, 10.0), bseeds=4, scanN=256,
            cN=256, cF=(2.05, 2.1, 2.15, 2.2, 2.3, 2.4, 2.6, 2.8), cseeds=2,
            clF=(0.9, 0.95, 0.98, 1.0, 1.02, 1.05, 1.1), ct=300.0, clt=30.0,
        )  # fmt: skip
    return dict(
        aN=99, abetas=(0.7, 0.8, 0.9, 0.95, 1.0, 1.05, 1.1, 1.2, 1.3, 1.4, 1.5, 1.7), widths=WIDTHS, sN=199, sloads=5.0,
        bNs=(64, 256, 1024, 3199), bbetas=(0.1, 0.2, 0.5, 1.0, 2.0, 3.0, 5.0, 10.0), bseeds=16, scanN=256,
        cN=1024, cF=(2.02, 2.05, 2.1, 2.15, 2.2, 2.25, 2.3, 2.35, 2.4, 2.5, 2.6, 2.8), cseeds=4,
        clF=(0.9, 0.95, 0.97, 0.98, 0.99, 1.0, 1.01, 1.02, 1.05, 1.1), ct=500.0, clt=50.0,
    )  # fmt: skip


def build(mode: str) -> Study:
    """The points of ``mode``: part a (order at N = aN over beta, tau at N = sN and beta =
    0.4, per w), part b (the ramp: every N at beta = 1 and every beta at the largest quick N, each
    over ``bseeds`` disorder seeds) and part c (F grids of both frictions); the longest first."""
    g = _grid(mode)
    paper = paper_parameters("N", "beta", "Fs")
    pts: list[dict[str, Any]] = []
    for w in g["widths"]:
        base = {"part": "a", "model": "sakaguchi", **paper, "w": w, "Fs": _fs(w), "start": "paper"}
        pts.append({**base, "N": g["sN"], "beta": 0.4, "analysis": "sizes", "t_end": t_end_of(g["sN"], g["sloads"])})
        for b in g["abetas"]:
            order = {"analysis": "order", "until_steady": UNTIL_STEADY, "t_end": t_end_of(g["aN"], 2.5)}
            pts.append({**base, "N": g["aN"], "beta": b, **order})
    scan_N = g["scanN"]
    cells = {(n, 1.0) for n in g["bNs"]} | {(scan_N, b) for b in g["bbetas"]}
    for n, b in sorted(cells, key=lambda c: (-c[0], c[1])):
        ramp = {"part": "b", **MEDIUM, "F_start": RAMP_START, "r": ramp_rate(n), "K": 10.0}
        ramp["t_end"] = round((RAMP_END - RAMP_START) / ramp["r"], 6)
        pts += [{**ramp, "N": n, "beta": b, "disorder_seed": s} for s in range(g["bseeds"])]
    force = {"part": "c", **MEDIUM, "drive": "constant-force", "beta": 1.0, "N": g["cN"], "t_end": g["ct"]}
    pts += [{**force, "F": F, "disorder_seed": s} for F in g["cF"] for s in range(g["cseeds"])]
    cl = {"part": "c", **CL_MEDIUM, "N": g["cN"], "t_end": g["clt"]}
    pts += [{**cl, "F": F, "disorder_seed": 0} for F in g["clF"]]
    common = {"n_samples": 2000, "average_fraction": 0.5, "spanning": "max_block", "bootstrap": 200, "seed": 0}
    note = (
        f"{mode}: (a) eq. (4) with Fs_i uniform on [3(1-w), 3(1+w)], w in {list(g['widths'])}, N = {g['aN']} at "
        f"beta in {list(g['abetas'])} (2.5 loading times from the paper's start, stopped at steady sliding) "
        f"and tau at N = {g['sN']}, beta = 0.4 ({g['sloads']:g} loading times); "
        f"(b) force ramp 2 + r t with r = 0.064 / N from rest to F = {RAMP_END:g}, F0 = 2 + beta v, Fs_i uniform "
        f"on [2, 4], N in {list(g['bNs'])} at beta = 1 and beta in {list(g['bbetas'])} at N = {scan_N}, "
        f"{g['bseeds']} disorder seeds each; (c) constant force from rest to t = {g['ct']:g} at N = {g['cN']}: "
        f"strengthening F in {list(g['cF'])} ({g['cseeds']} seeds), Carlson-Langer (periodic) F in {list(g['clF'])} "
        f"to t = {g['clt']:g}"
    )
    return Study("disorder", mode, common, tuple(pts), note=note)


# ---------------------------------------------------------------------------------------------
# Findings: one function per part, each on the study's table (synthetic tables in the tests)


def _rows(table: pd.DataFrame, part: str) -> pd.DataFrame:
    if "part" not in table:
        return table.iloc[:0]
    return table[table["part"] == part]


def part_a(table: pd.DataFrame) -> dict[str, Any]:
    """Per w: the bracket of the transition in beta (last stick-slip beta, first steady above it,
    :func:`~stickslip.analysis.stats.order.transition_bracket`), m at the last stick-slip beta (the
    step a continuous transition makes small), and tau at beta = 0.4 with its error; the change of
    the bracket's middle and of tau from w = 0."""
    from stickslip.analysis.stats.order import transition_bracket

    rows = _rows(table, "a")
    order = rows[rows["analysis"] == "order"] if "analysis" in rows else rows.iloc[:0]
    sizes = rows[rows["analysis"] == "sizes"] if "analysis" in rows else rows.iloc[:0]
    per_w = []
    for w in sorted(set(order["w"]) | set(sizes["w"])):
        rec: dict[str, Any] = {"w": float(w)}
        g = order[order["w"] == w].sort_values("beta")
        if len(g):
            br = transition_bracket(g["beta"].astype(float), g["final_state"])
            rec.update(beta_lo=br["lo"], beta_hi=br["hi"], beta_t=br["estimate"], beta_t_err=br["uncertainty"])
            at = g[g["beta"] == br["lo"]]
            rec["m_step"] = float(at["order_parameter"].iloc[0]) if len(at) else math.nan
            rec["m"] = [float(m) for m in g["order_parameter"]]
            rec["betas"] = [float(b) for b in g["beta"]]
        s = sizes[sizes["w"] == w]
        if len(s):
            rec["tau"] = float(s["tau"].iloc[0]) if finite(s["tau"].iloc[0]) else math.nan
            rec["tau_err"] = float(s["tau_err"].iloc[0]) if finite(s["tau_err"].iloc[0]) else math.nan
        per_w.append(rec)
    return {"per_w": per_w}


def ramp_fits(table: pd.DataFrame, bootstrap: int = 200) -> list[dict[str, Any]]:
    """Part b per (N, beta): the event sizes of every seed pooled and fitted with the truncated
    power law (:func:`~stickslip.analysis.stats.statistics.fit_power_law`, s_min by least KS distance),
    the depinning force F_c (mean and spread over seeds), the events per run and the seeds where
    the chain never depinned."""
    from stickslip.analysis.stats.statistics import fit_power_law

    rows = _rows(table, "b")
    out = []
    for (N, beta), g in rows.groupby(["N", "beta"]):
        S = np.concatenate([np.asarray(json.loads(t), dtype=float) for t in g["sizes"]]) if len(g) else np.array([])
        Fc = g["F_c"].astype(float).to_numpy()
        rec: dict[str, Any] = {
            "N": int(N),
            "beta": float(beta),
            "seeds": int(len(g)),
            "events": int(S.size),
            "events_per_run": float(S.size / max(len(g), 1)),
            "F_c": float(np.nanmean(Fc)) if np.isfinite(Fc).any() else math.nan,
            "F_c_sd": float(np.nanstd(Fc, ddof=1)) if np.isfinite(Fc).sum() > 1 else math.nan,
            "pinned_runs": int((~np.isfinite(Fc)).sum()),
            "tau": math.nan,
            "tau_err": math.nan,
        }
        if S.size >= 20:
            try:
                fit = fit_power_law(S, bootstrap=bootstrap, seed=0)
                rec.update(tau=fit.tau, tau_err=fit.tau_err, s_min=fit.s_min, s_max=fit.s_max, n_fit=fit.n)
            except (ValueError, TypeError) as exc:  # too few distinct sizes for a range
                rec["note"] = str(exc)
        out.append(rec)
    return out


def _distributions(table: pd.DataFrame, fits: list[dict[str, Any]]) -> dict[str, Any]:
    """The catalogue's comparison of the power law with the other candidates
    (:func:`~stickslip.analysis.stats.model_comparison.compare_distributions`) on the pooled sizes of the
    largest chain at beta = 1, on its fitted range."""
    from stickslip.analysis.stats.model_comparison import compare_distributions

    ok = [f for f in fits if f["beta"] == 1.0 and finite(f["tau"])]
    if not ok:
        return {"reason": "no power-law fit at beta = 1"}
    f = max(ok, key=lambda f: f["N"])
    rows = _rows(table, "b")
    g = rows[(rows["N"] == f["N"]) & (rows["beta"] == 1.0)]
    S = np.concatenate([np.asarray(json.loads(t), dtype=float) for t in g["sizes"]])
    try:
        c = compare_distributions(S, f["s_min"], f["s_max"])
    except ValueError as exc:
        return {"N": f["N"], "reason": str(exc)}
    c.pop("objects", None)
    verdicts = {x["alternative"]: x["verdict"] for x in c["comparisons"]}
    return {"N": f["N"], "best_aic": c.get("best_aic"), "verdicts": verdicts}


def part_c(table: pd.DataFrame) -> list[dict[str, Any]]:
    """Part c per friction: the bracket of the depinning force (largest F where the chain ends
    pinned in every seed, smallest F where it slides in every seed), the mean velocity just above
    it (a continuous depinning makes it small), and for the strengthening law the largest
    difference from its closed form (F - F0) / beta on the sliding side."""
    rows = _rows(table, "c")
    out = []
    for friction, g in rows.groupby("friction"):
        per_F = g.groupby("F").agg(v=("v_mean", "mean"), moving=("moving_fraction", "min"), v_end=("v_end", "mean"))
        per_F = per_F.reset_index().sort_values("F")
        pinned = per_F[per_F["v"].abs() < 1e-3]
        sliding = per_F[per_F["moving"] >= 1.0]
        lo = float(pinned["F"].max()) if len(pinned) else math.nan
        above = sliding[sliding["F"] > lo] if math.isfinite(lo) else sliding
        hi = float(above["F"].min()) if len(above) else math.nan
        rec: dict[str, Any] = {
            "friction": friction,
            "F_lo": lo,
            "F_hi": hi,
            "F_c": 0.5 * (lo + hi),
            "F_c_err": 0.5 * (hi - lo),
            "v_at_hi": float(above["v"].iloc[0]) if len(above) else math.nan,
            "v_end_at_hi": float(above["v_end"].iloc[0]) if len(above) else math.nan,
            "curve": table_of(per_F),
        }
        if friction == "strengthening" and len(above):
            F0, beta = float(g["F0"].iloc[0]), float(g["beta"].iloc[0])
            rec["closed_form_dev"] = float(np.max(np.abs(above["v_end"] - (above["F"] - F0) / beta)))
            rec["jump_closed_form"] = (hi - F0) / beta
        out.append(rec)
    return out


def table_of(frame: pd.DataFrame) -> list[dict[str, Any]]:
    """Records of a small frame with plain floats (for study.json)."""
    return [{k: float(v) for k, v in r.items()} for r in frame.to_dict(orient="records")]


def _a_summary(per_w: list[dict[str, Any]]) -> list[str]:
    """Part a in two lines: whether the bracket of the transition moves with w beyond its own
    width, and tau's least-squares change with w (weighted by its errors) with the error of
    that slope."""
    out = []
    ok = [r for r in per_w if finite(r.get("beta_t")) and finite(r.get("beta_t_err"))]
    ref = next((r for r in ok if r["w"] == 0.0), None)
    if ref is not None and len(ok) > 1:
        moved = [r for r in ok if abs(r["beta_t"] - ref["beta_t"]) > r["beta_t_err"] + ref["beta_t_err"]]
        out.append(
            f"(a) the transition's bracket at w = 0 is [{short(ref['beta_lo'])}, {short(ref['beta_hi'])}]; "
            + (
                "it moves beyond the brackets' widths at w = " + ", ".join(f"{r['w']:g}" for r in moved)
                if moved
                else "no width moves it beyond the brackets' widths (the grid's resolution)"
            )
        )
    taus = [r for r in per_w if finite(r.get("tau")) and finite(r.get("tau_err")) and r["tau_err"] > 0]
    if len(taus) > 2:
        w = np.array([r["w"] for r in taus])
        t = np.array([r["tau"] for r in taus])
        e = np.array([r["tau_err"] for r in taus])
        (slope, _), cov = np.polyfit(w, t, 1, w=1.0 / e, cov="unscaled")
        out.append(f"(a) tau at beta = 0.4 changes by {slope:+.2f} +- {math.sqrt(cov[0, 0]):.2f} per unit w")
    return out


def findings(spec: Study, table: pd.DataFrame) -> dict[str, Any]:
    """The statements of the three parts (module docstring) and their numbers."""
    tau_q, tau_q_err = qew_tau()
    a, fits, c = part_a(table), ramp_fits(table, int(spec.common.get("bootstrap", 200))), part_c(table)
    say: list[str] = []
    ref = next((r for r in a["per_w"] if r["w"] == 0.0), None)
    for r in a["per_w"]:
        moved = ""
        if ref is not None and r is not ref and finite(r.get("beta_t")) and finite(ref.get("beta_t")):
            moved = f"; moved by {r['beta_t'] - ref['beta_t']:+.3g} from w = 0"
        say.append(
            f"(a) w = {r['w']:g}: last stick-slip beta {short(r.get('beta_lo'))}, first steady above it "
            f"{short(r.get('beta_hi'))}{moved}; m at the last stick-slip beta {short(r.get('m_step'))}; "
            f"tau at beta = 0.4: {short(r.get('tau'))} +- {short(r.get('tau_err'), 2)}"
        )
    say.extend(_a_summary(a["per_w"]))
    for f in fits:
        dev = (f["tau"] - tau_q) / math.hypot(f["tau_err"], tau_q_err) if finite(f["tau_err"]) else math.nan
        say.append(
            f"(b) N = {f['N']}, beta = {f['beta']:g}: {f['events']} events over {f['seeds']} seeds "
            f"({f['events_per_run']:.3g} per run), depinned at F_c = {short(f['F_c'])} +- {short(f['F_c_sd'], 2)} "
            f"(sd; {f['pinned_runs']} runs never depinned); tau = {short(f['tau'])} +- {short(f['tau_err'], 2)}"
            + (f" ({dev:+.1f} sigma from qEW's {tau_q:.3f})" if finite(dev) else " (no fit)")
        )
    dist = _distributions(table, fits)
    if "verdicts" in dist:
        say.append(
            f"(b) distributions at N = {dist['N']}, beta = 1: least AIC {dist['best_aic']}; power law against "
            + ", ".join(f"{k}: {v}" for k, v in dist["verdicts"].items())
        )
    for r in c:
        line = (
            f"(c) {r['friction']}: pinned up to F = {short(r['F_lo'])}, sliding from F = {short(r['F_hi'])} "
            f"(F_c = {short(r['F_c'])} +- {short(r['F_c_err'], 2)}); mean velocity there {short(r['v_at_hi'])}, "
            f"final {short(r['v_end_at_hi'])}"
        )
        if "jump_closed_form" in r:
            line += (
                f"; the sliding branch is (F - F0) / beta to {short(r['closed_form_dev'], 2)}, so v jumps "
                f"from 0 to {short(r['jump_closed_form'])} at F_c: no power law (F - F_c)^theta"
            )
        say.append(line)
    return {
        "statements": say,
        "qew_tau": [tau_q, tau_q_err],
        "part_a": a,
        "ramp": fits,
        "distributions": dist,
        "force": c,
    }


def figures(spec: Study, table: pd.DataFrame, page_dir: Path) -> list[tuple[str, Any, str]]:
    """m against beta per w and tau against w (part a), tau against N and beta beside qEW's (part
    b), the mean velocity against F (part c) (:mod:`stickslip.plotting.disorder`)."""
    from stickslip.plotting.disorder import force_figure, order_figure, ramp_figure

    found = findings(spec, table)
    out: list[tuple[str, Any, str]] = []
    if found["part_a"]["per_w"]:
        caption = (
            "(a) Eq. (4) with Fs_i uniform on [3(1-w), 3(1+w)]: m = 1 - <L>/L_ss against beta (filled: ends in "
            "stick-slip, open: steady), and tau at beta = 0.4 against w (bootstrap errors)."
        )
        out.append(("order_beta", order_figure(_rows(table, "a")), caption))
    if found["ramp"]:
        caption = (
            "(b) Force ramp on the random medium: tau of the events before depinning, pooled over seeds, against "
            "N (beta = 1) and against beta (none where no event ended before the chain depinned); the band is "
            "qEW's 2 - 2/(1 + zeta) = 1.111."
        )
        out.append(("ramp_tau", ramp_figure(found["ramp"], qew_tau()), caption))
    if found["force"]:
        caption = (
            "(c) Constant force from rest: mean velocity x/t (and the final velocity) against F, velocity "
            "strengthening and Carlson-Langer's weakening; dashed: (F - F0)/beta."
        )
        out.append(("force_velocity", force_figure(_rows(table, "c")), caption))
    return out


def _tables(found: dict[str, Any]) -> list[tuple[str, list[str], list[dict[str, Any]]]]:
    per_w = [{k: v for k, v in r.items() if k not in ("m", "betas")} for r in found.get("part_a", {}).get("per_w", [])]
    force = [{k: v for k, v in r.items() if k != "curve"} for r in found.get("force", [])]
    return [
        ("(a) per w", "w beta_lo beta_hi beta_t beta_t_err m_step tau tau_err".split(), per_w),
        ("(b) per N and beta", "N beta seeds events events_per_run F_c F_c_sd pinned_runs tau tau_err".split(),
         found.get("ramp", [])),
        ("(c) per friction", "friction F_lo F_hi F_c F_c_err v_at_hi v_end_at_hi jump_closed_form".split(), force),
    ]  # fmt: skip


COST = {
    "quick": "about 90 s on two free cores with the kernels compiled (measured; 28 minutes before the ramp "
    "runs stopped at depinning, on a loaded machine)",
    "full": "about 11 minutes on two free cores with the kernels compiled (measured)",
}


def describe() -> str:
    """The text of ``stickslip study disorder --help``."""
    quick, full = build("quick"), build("full")
    return (
        "Chains with quenched random thresholds Fs_i: (a) does the paper's stick-slip transition at beta = 1 "
        "survive random Fs, does it move, how does tau change; (b) the random medium (strengthening friction, "
        "random Fs) under a slowly increased force: tau of its avalanches against N and beta beside qEW's 1.11; "
        "(c) the mean velocity against a constant force through depinning, strengthening against "
        f"Carlson-Langer's weakening. Grid: --quick {quick.note.split(': ', 1)[1]} ({len(quick.points)} runs, "
        f"{COST['quick']}); --full {full.note.split(': ', 1)[1]} ({len(full.points)} runs, {COST['full']}). "
        "Outputs in DIR/disorder/: table.parquet and table.csv (one row per run), "
        "order_beta, ramp_tau and force_velocity (PNG, PDF), study.json, index.html."
    )


DESIGN = Design(
    cost=COST,
    name="disorder",
    summary="random thresholds: the transition, avalanches under a force ramp (qEW), depinning",
    describe=describe,
    build=build,
    task=disorder_task,
    check=disorder_check,
    findings=findings,
    figures=figures,
    columns=tuple(
        "part model friction N beta w F disorder_seed final_state order_parameter tau tau_err F_c n_events "
        "v_mean v_end moving_fraction t_end run_wall_seconds".split()
    ),
    tables=_tables,
)
