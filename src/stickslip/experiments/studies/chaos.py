"""``stickslip study chaos``: is the chain of eq. (4) chaotic at the onset (section 3, "chaotic
motion")? Its points, the measurement of one point, its findings and figures
(docs/studies/chaos.md).

A point (:func:`chaos_point`: the paper's chain at several N and beta = 0.5, 0.9, 1, or two blocks
or Carlson-Langer as known answers) measures from the engine's state at the end of its transient
(:func:`stickslip.run.loaded.loaded_state`, kept in the point's folder with its loading check):

- the flow's largest exponent by two trajectories with located switches
  (:func:`stickslip.analysis.dynamics.lyapunov_flow.flow_lyapunov`) at dt, dt/2, dt/4 over ``flow_t``
  (some :data:`MIN_FLOW_SLIPS` slips or more per rung in the chain's points), extrapolated to
  dt -> 0 (:func:`stickslip.analysis.dynamics.lyapunov_flow.extrapolate`);
- n(delta) on the engine's map (:func:`stickslip.analysis.dynamics.decorrelation.sequence_decorrelation`,
  as ``stickslip lyapunov --decorrelation``) for each kind of perturbation (state, Fs, V) and each
  delta over ``seeds`` consecutive windows of ``events`` slips, and delta* per kind
  (:func:`stickslip.analysis.dynamics.threshold.delta_star`);
- the verdict (:func:`stickslip.analysis.dynamics.decorrelation.verdict`) from the exponent and the
  state's n(delta).

Each part (rung, kind) is written to ``parts/`` as it finishes and read back, not run again, when
the point runs again with the same settings, as are the transient's finished chunks: an
interrupted point loses at most the part it was in. Asked to stop
(:func:`stickslip.experiments.sweep.stop_requested`), a point stops within a chunk of the
transient, 64 renormalisations of a rung or one twin.

The findings (:func:`conclusions`, from the table): each point's verdict with its window, the
flow's exponent and the slips its rungs counted, the loading check; delta* per point and kind
(geometric mean over the windows, its error in decades, the range) and, for each beta and kind,
the least-squares slope of log10 delta* (one point per window) on log10 N
(:func:`stickslip.analysis.dynamics.threshold.threshold_fit`). The figures (:mod:`stickslip.plotting.chaos`)
read each point's ``flow.json``.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from stickslip.experiments.studies import Design, Study, finite, short
from stickslip.experiments.studies.chaos_lifetimes import lifetime_figures, lifetime_findings, load
from stickslip.models.presets import PRESETS, is_paper

if TYPE_CHECKING:  # loaded where used, so that listing the studies loads no heavy module
    import pandas as pd

__all__ = ["DESIGN", "chaos_point", "conclusions", "MIN_FLOW_SLIPS"]

KINDS = ("state", "Fs", "V")
#: The deltas of ``--full`` (and of docs/studies/decorrelation-grid.json): 1e-12, 1e-11, ..., 1e-1.
DELTAS_FULL = tuple(float(f"1e{k}") for k in range(-12, 0))
DELTAS_QUICK = (1e-10, 1e-8, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1)
#: Transients of the paper's chain from its start: at least twice the start of the first slip that
#: moves block N at beta = 0.5, 0.9, 1 (measured, docs/studies/chaos.md, "Loaded before comparing");
#: 2.5 loading times N (N - 1) / (2 K V) at N = 399 and 799.
TRANSIENTS = {49: 5e5, 99: 1.5e6, 199: 5e6, 399: 2e7, 799: 8e7}
#: Slips each rung of a chain point's ladder should count (the page reports what they did).
MIN_FLOW_SLIPS = 300


def build(mode: str) -> Study:
    """The study of ``mode``: the paper's chain (eq. 4) at several N and beta = 0.5, 0.9, 1, and two
    blocks and Carlson-Langer at their standard parameters (the verdict's known answers: chaotic),
    dearest first, and the settings they share. A point's own keys override the shared ones (the
    relatives' interval, kinds and ladder length)."""
    # a rung of 1.2e5 time units counts 0.9 of it: some 360 slips of the chain at every N (1000 slips
    # take 2.9e5 to 3.0e5, docs/studies/chaos.md); --full counts five times as many (at N = 799 the
    # growth of a separation comes in rare large slips, and 360 slips hold only a few of them)
    betas = (0.5, 0.9, 1.0)
    if mode == "tiny":
        Ns, deltas, seeds, events, flow_t, levels = (5, 9), (1e-8, 1e-4, 1e-1), 2, 40, 2000.0, 2
        transients = {5: 1e4, 9: 2e4}
        family = [{"model": "two-blocks", "transient": 100.0, "flow_t": 200.0, "events": 30, "seeds": 1}]
    else:  # --quick: three N, fewer deltas and windows, one window of the relatives
        quick = mode == "quick"
        Ns, deltas, seeds = ((49, 99, 199), DELTAS_QUICK, 2) if quick else ((49, 99, 199, 399, 799), DELTAS_FULL, 3)
        events, flow_t, levels, transients = 1000, 1.2e5 if quick else 6e5, 3, TRANSIENTS
        once = {"seeds": 1} if quick else {}
        family = [
            {"model": "two-blocks", "transient": 2e3, "flow_t": 1.2e4, **once},
            {"model": "carlson-langer", "transient": 2e3, "flow_t": 1e3, **once},
        ]
    shared = {
        "kinds": list(KINDS),
        "deltas": list(deltas),
        "seeds": seeds,
        "events": events,
        "flow_t": flow_t,
        "levels": levels,
        "interval": 10.0,
        # above the rounding floor of positions of order L_ss ~ N^2 / (2 K): at N = 799 the
        # exponent is the same for d0 = 1e-8 .. 1e-6 and grows spuriously below 1e-9
        # (docs/studies/chaos.md, "d0 and the rounding floor")
        "d0": 1e-8,
    }
    points: list[dict[str, Any]] = [
        {"model": "sakaguchi", "start": "paper", "N": N, "beta": b, "transient": transients[N]}
        for N in Ns
        for b in betas
    ]
    points += [
        {**f, "start": "rest", "perturbation": 0.01, "seed": 0, "kinds": "state", "interval": 1.0} for f in family
    ]
    points.sort(key=lambda p: -(p.get("N", 100) ** 2) * p["transient"] ** 0.5)
    common = {"analysis": "chaos", "segments": 10, "direction_seed": 0, **shared}
    note = (
        f"{mode}: eq. (4) at N = {', '.join(map(str, Ns))}, beta = {', '.join(f'{b:g}' for b in betas)}, "
        f"from loaded states (transients {', '.join(f'{transients[N]:g}' for N in Ns)}); "
        f"flow ladders of {flow_t:g} time units; n(delta) for {len(deltas)} deltas "
        f"({deltas[0]:g} .. {deltas[-1]:g}), perturbations of the state, Fs and V, {seeds} windows of "
        f"{events} slips; {' and '.join(PRESETS[f['model']].label or f['model'] for f in family)} at standard "
        "parameters"
    )
    return Study("chaos", mode, common, tuple(points), note=note)


# ---------------------------------------------------------------------------------------------
# One point, on a worker


def kinds_of(cfg: dict[str, Any]) -> list[str]:
    """A point's kinds of perturbation: a list, or one text with commas."""
    kinds = cfg["kinds"]
    return [k.strip() for k in kinds.split(",")] if isinstance(kinds, str) else [str(k) for k in kinds]


def threshold_columns(kind: str) -> tuple[str, ...]:
    """Table columns of delta* of one kind: geometric mean, its error in decades, range, censored."""
    base = f"delta_star_{kind}"
    return (base, f"{base}_err_log10", f"{base}_low", f"{base}_high", f"{base}_censored")


def check_point(cfg: dict[str, Any], params=None) -> None:
    """Raise ParameterError (one line) unless a chaos point's merged settings and its model
    ``params`` (by default :func:`~stickslip.experiments.sweep_points.point_params` of them) make
    a valid measurement."""
    from stickslip.analysis.dynamics.benettin import check_run
    from stickslip.analysis.dynamics.decorrelation import PERTURBATIONS
    from stickslip.experiments.sweep_points import point_params
    from stickslip.models.params import ParameterError, check_number

    params = point_params("chain", cfg) if params is None else params
    missing = [k for k in ("transient", "kinds", "deltas", "seeds", "events", "flow_t") if k not in cfg]
    if missing:
        raise ParameterError(f"a chaos point needs {', '.join(missing)}")
    check_number("transient", cfg["transient"], low=0.0, low_open=True)
    check_number("events", cfg["events"], low=1, integer=True)
    check_number("seeds", cfg["seeds"], low=1, integer=True)
    for kind in kinds_of(cfg):
        if kind not in PERTURBATIONS:
            raise ParameterError(f"kinds must be among {', '.join(PERTURBATIONS)} (got {kind!r})")
    if "state" not in kinds_of(cfg):
        raise ParameterError("a chaos point's verdict needs the kind 'state'")
    for d in cfg["deltas"]:
        check_number("delta", d, low=0.0, low_open=True, high=1.0)
    if params.ends_piece.wall:
        raise ParameterError("the chaos study restarts the clock: fixed ends (which read t) are refused")
    check_run(
        params, float(cfg["flow_t"]), float(cfg.get("interval", 10.0)), float(cfg.get("d0", 1e-10)), 0.0, None, 10
    )


def _part(folder: Path, spec: dict[str, Any], name: str, compute) -> dict[str, Any]:
    """The finished part ``folder/NAME.json`` of a point if it was made with ``spec`` and its own
    checksum (:func:`stickslip.experiments.cache.sealed`) holds, else ``compute()``, written so: an
    edited or foreign part is computed again."""
    from stickslip import io
    from stickslip.experiments.cache import canonical, read_done, sealed
    from stickslip.jsonable import to_jsonable

    path = folder / f"{name}.json"
    want = canonical({**spec, "part": name})
    kept, _ = read_done(path, want, "result")
    if kept is not None:
        return kept["result"]
    record = to_jsonable({"spec": want, "result": compute(), "files": {}})  # as a reused part reads it
    io.write_json(path, sealed(record))
    return record["result"]


def chaos_point(cfg: dict[str, Any], params, point_dir: Path) -> dict[str, Any]:
    """One point (module docstring) of the model ``params``
    (:func:`stickslip.experiments.sweep_points.point_params` of ``cfg``): writes
    ``flow.json`` (loading check, ladder, n(delta) of every kind, delta*, verdict) into
    ``point_dir`` and returns the table's columns."""
    from stickslip import __version__, io
    from stickslip.analysis.dynamics.decorrelation import GridSequences, sequence_decorrelation, verdict
    from stickslip.analysis.dynamics.lyapunov_flow import LADDER_COLUMNS, extrapolate, flow_lyapunov
    from stickslip.analysis.dynamics.threshold import delta_star
    from stickslip.experiments.sweep import stop_requested
    from stickslip.experiments.sweep_points import preset_start
    from stickslip.run.errors import Interrupted
    from stickslip.run.loaded import loaded_state

    wall0 = time.perf_counter()
    check_point(cfg, params)
    point_dir = Path(point_dir)
    stop = stop_requested(point_dir)
    start = preset_start(params, cfg)
    loaded = loaded_state(params, float(cfg["transient"]), **start, cache=point_dir / "state", stop_requested=stop)
    spec, parts = {**cfg, "version": __version__}, point_dir / "parts"
    direction_seed = int(cfg.get("direction_seed", 0))
    interval, d0 = float(cfg.get("interval", 10.0)), float(cfg.get("d0", 1e-10))
    flow_t, levels = float(cfg["flow_t"]), int(cfg.get("levels", 3))
    located = loaded.located(params)

    def rung(k: int) -> dict[str, Any]:
        return flow_lyapunov(
            params.replace(dt=params.dt / 2**k),
            flow_t,
            start=located,
            interval=interval,
            d0=d0,
            direction_seed=direction_seed,
            segments=int(cfg.get("segments", 10)),
            stop_requested=stop,
        ).to_dict()

    def stop_now(_line: str) -> None:  # n(delta)'s progress, after each twin: stop if the study asks
        if stop():
            raise Interrupted(None, math.nan)

    rungs = [_part(parts, spec, f"flow-rung-{k}", lambda k=k: rung(k)) for k in range(levels)]
    lam0, err0, slope = extrapolate(
        [r["dt"] for r in rungs], [_num(r["lyapunov"]) for r in rungs], [_num(r["lyapunov_err"]) for r in rungs]
    )
    decorrelation, thresholds = {}, {}
    for kind in kinds_of(cfg):

        def measure(kind=kind):
            return sequence_decorrelation(
                GridSequences(params),
                loaded.state,
                [float(d) for d in cfg["deltas"]],
                perturbation=kind,
                events=int(cfg["events"]),
                seeds=int(cfg["seeds"]),
                direction_seed=direction_seed,
                progress=stop_now,
            ).to_dict()

        decorrelation[kind] = _part(parts, spec, f"decorrelation-{kind}", measure)
        thresholds[kind] = delta_star(decorrelation[kind]["decorrelation"])
    window = min(int(w["reference_events"]) for w in decorrelation["state"]["decorrelation_windows"])
    v = verdict(lam0, err0, decorrelation["state"]["decorrelation"], window=window)
    flow_slips = min(int(r["events"]) for r in rungs)
    info = {
        "loading": loaded.info,
        "ladder": [{k: r[k] for k in LADDER_COLUMNS} for r in rungs],
        "lyapunov_dt0": lam0,
        "lyapunov_dt0_err": err0,
        "dt2_slope": slope,
        "flow_t": flow_t,
        "flow_slips": flow_slips,
        "interval": interval,
        "d0": d0,
        "decorrelation": decorrelation,
        "thresholds": thresholds,
        **v.to_dict(),
    }
    io.write_json(point_dir / "flow.json", info)
    out: dict[str, Any] = {
        "loaded": bool(loaded.info["loaded"]),
        "first_slip_reaching_block_N": loaded.info["first_slip_reaching_block_N"],
        **{k: info[k] for k in ("lyapunov_dt0", "lyapunov_dt0_err", "flow_slips")},
        "window": window,
        "n_deltas": len(cfg["deltas"]),
        **v.to_dict(),
        "point_wall_seconds": time.perf_counter() - wall0,
    }
    for kind, th in thresholds.items():
        mean, err, low, high, censored = threshold_columns(kind)
        fields = {mean: "geometric_mean", err: "log10_err", low: "low", high: "high"}
        out.update({column: _num(th[field]) for column, field in fields.items()})
        out[censored] = int(th["censored"])
        out.update({f"{mean}_seed{s}": _num(value) for s, value in zip(th["seeds"], th["per_seed"], strict=True)})
    return out


def _num(x) -> float:
    return math.nan if x is None else float(x)


def task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """One point on a worker (:func:`chaos_point`)."""
    from stickslip.experiments.sweep_points import point_params

    return chaos_point(point, point_params("chain", point), Path(point_dir))


# ---------------------------------------------------------------------------------------------
# Findings and figures, from the table of finished points


def _value(x) -> float | None:
    """A number of the table, None where it is missing or not finite (a censored window)."""
    return float(x) if finite(x) else None


def thresholds(table: pd.DataFrame) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """delta* of every chain point and kind (``N``, ``beta``, ``kind``, ``per_seed``,
    ``geometric_mean``, ``log10_err``, ``low``, ``high``, ``censored``) and, for each beta and
    kind, :func:`~stickslip.analysis.dynamics.threshold.threshold_fit` of its points."""
    from stickslip.analysis.dynamics.threshold import threshold_fit

    out = []
    for _, row in table[table["model"].map(is_paper)].sort_values(["N", "beta"]).iterrows():
        for kind in KINDS:
            mean, err, low, high, censored = threshold_columns(kind)
            if mean not in row.index or not finite(row.get(censored)):
                continue
            out.append(
                {
                    "N": int(row["N"]),
                    "beta": float(row["beta"]),
                    "kind": kind,
                    "per_seed": [_value(row.get(f"{mean}_seed{k}")) for k in range(int(row["seeds"]))],
                    "geometric_mean": _value(row[mean]),
                    "log10_err": float(row[err]) if finite(row[err]) else math.nan,
                    "low": _value(row[low]),
                    "high": _value(row[high]),
                    "censored": int(row[censored]),
                }
            )
    fits = []
    for beta, kind in sorted({(p["beta"], p["kind"]) for p in out}, key=lambda k: (KINDS.index(k[1]), k[0])):
        mine = sorted((p for p in out if p["beta"] == beta and p["kind"] == kind), key=lambda p: p["N"])
        fit = threshold_fit([p["N"] for p in mine], [p["per_seed"] for p in mine])
        fits.append({"beta": beta, "kind": kind, **fit})
    return out, fits


def conclusions(spec: Study | None, table: pd.DataFrame) -> dict[str, Any]:
    """Statements, verdicts, delta* and its fits of a chaos study's rows (module docstring), and
    the lifetimes study's verdicts where it ran into the same folder (:func:`lifetime_findings`)."""
    out: dict[str, Any] = {"statements": [], "verdicts": {}, "points": []}
    out["lifetimes"], lines = lifetime_findings(table.attrs.get("lifetimes"), table)
    say = out["statements"].append
    rows = table.assign(_chain=table["model"].map(is_paper))
    rows = rows.sort_values(["_chain", "N", "beta"], ascending=[False, True, True])
    for _, r in rows.iterrows():
        name = PRESETS[r["model"]].point_label(r["beta"], r["N"])
        lam, err = r.get("lyapunov_dt0"), r.get("lyapunov_dt0_err")
        slips = int(r["flow_slips"]) if finite(r.get("flow_slips")) else None
        out["points"].append(
            {
                "point": name,
                "model": r["model"],
                "N": int(r["N"]),
                "beta": _value(r.get("beta")),
                "verdict": r.get("verdict"),
                "verdict_text": r.get("verdict_text"),
                "lyapunov_dt0": _value(lam),
                "lyapunov_dt0_err": _value(err),
                "flow_slips": slips,
                "loaded": bool(r.get("loaded")) if r.get("loaded") is not None else None,
            }
        )
        out["verdicts"].setdefault(r.get("verdict"), []).append(name)
        say(
            f"{name}: flow exponent {short(lam)} +- {short(err, 2)} (each rung counting at least {slips} slips); "
            f"{r.get('verdict_text')}."
        )
    say("Verdicts: " + "; ".join(f"{label} at {', '.join(names)}" for label, names in out["verdicts"].items()) + ".")
    chain = rows[rows["_chain"]]
    if "loaded" in chain.columns and len(chain):
        not_loaded = [PRESETS[r.model].point_label(r.beta, r.N) for r in chain.itertuples() if not bool(r.loaded)]
        say(
            "Loading: every chain point started from a loaded state (transient at least twice the start of the "
            "first slip that moved block N)."
            if not not_loaded
            else f"Loading: NOT loaded by that rule: {', '.join(not_loaded)}."
        )
    out["thresholds"], out["fits"] = thresholds(table)
    for kind in KINDS:
        mine = [f for f in out["fits"] if f["kind"] == kind and math.isfinite(f["slope"])]
        if not mine:
            continue
        parts = [
            f"beta = {f['beta']:g}: {f['slope']:+.2f} +- {f['slope_err']:.2f} "
            + ("(no trend)" if f["trend"] == "none" else f"({f['trend']} with N)")
            for f in mine
        ]
        Ns = sorted({n for f in mine for n in f["Ns"]})
        say(
            f"delta* ({kind}) against N = {', '.join(map(str, Ns))}, slope of log10 delta* on log10 N "
            f"with its standard error: {'; '.join(parts)}."
        )
    for line in lines:
        say(line)
    return out


def figures(spec: Study, table: pd.DataFrame, page_dir: Path) -> list[tuple[str, Any, str]]:
    """The study's figures (name, Figure, caption), from each point's ``flow.json`` in its runs
    folder beside ``page_dir`` (the curves of :mod:`stickslip.plotting.chaos`: chain points by N
    then beta, the relatives last), and ``decorrelation.csv``/``.parquet`` in ``page_dir``: every
    n(delta) row (point, N, beta, kind, delta, seed, events, decorrelated, t_decorrelated)."""
    import pandas as pd

    from stickslip import io
    from stickslip.plotting import chaos as pc

    lives = lifetime_figures(table.attrs.get("lifetimes"), page_dir)
    if "point_dir" not in table.columns:
        return lives
    points_dir = spec.runs_dir(Path(page_dir).parent) / "points"
    found = []
    for r in sorted(table.itertuples(), key=lambda r: (0, r.N, r.beta) if is_paper(r.model) else (1, 0, 0.0)):
        path = points_dir / str(r.point_dir) / "flow.json"
        if not path.is_file():
            continue
        chain = is_paper(r.model)
        label = f"eq. (4), N = {int(r.N)}, beta = {r.beta:g}" if chain else f"{r.model}, N = {int(r.N)}"
        found.append({**io.read_json(path), "label": label, "N": int(r.N), "beta": float(r.beta) if chain else None})
    if not found:
        return []
    keys = ("delta", "seed", "events", "decorrelated", "t_decorrelated")
    rows = [
        {"point": c["label"], "N": c["N"], "beta": c["beta"], "kind": kind, **{k: r.get(k) for k in keys}}
        for c in found
        for kind, d in (c.get("decorrelation") or {}).items()
        for r in d.get("decorrelation", [])
    ]
    io.write_table_files(Path(page_dir) / "decorrelation", pd.DataFrame(rows))
    out = [
        (
            "decorrelation",
            pc.decorrelation_figure(found),
            "n(delta): slips that agree between a reference and a twin started delta apart (rows: "
            "the state moved, Fs or V changed by delta relative), one colour per beta, one marker per "
            "window of slips; open markers: the window never disagreed (n = the slips compared).",
        ),
        (
            "flow_ladder",
            pc.flow_ladder_figure(found),
            "Largest exponent of the flow (located switches, the time shift removed) at dt, dt/2, "
            "dt/4, with the fit lambda_0 + c dt^2 and lambda_0 (square) at dt = 0.",
        ),
    ]
    points, fits = thresholds(table)
    if points:
        caption = (
            "delta*, the smallest delta that decorrelated within the window, against N: each "
            "window (dots), the geometric mean with its standard error, and the least-squares "
            "line of log10 delta* on log10 N for each beta (dashed, slope in the legend)."
        )
        out.append(("threshold", pc.threshold_figure(points, fits), caption))
    return out + lives


#: The wall time of each mode (``stickslip study --help``, the README).
COST = {"quick": "about 8 minutes on two cores", "full": "about an hour on two cores"}


def describe() -> str:
    """The text of ``stickslip study chaos --help``."""
    quick, full = build("quick"), build("full")
    return (
        "Is the chain of eq. (4) chaotic at the onset of stick-slip? For each point, from a loaded "
        "state: the flow's largest exponent (two trajectories with located switches at dt, dt/2, "
        "dt/4, extrapolated to dt -> 0), the number of slips n(delta) that agree between a run and a "
        "twin perturbed by delta (the state, Fs or V), the threshold delta* and the verdict "
        "(chaotic, stable chaos, regular or undetermined); two blocks and Carlson-Langer as known answers. "
        f"Grid: --quick {quick.note.split(': ', 1)[1]} ({len(quick.points)} points, {COST['quick']}"
        f"); --full {full.note.split(': ', 1)[1]} ({len(full.points)} points, {COST['full']})."
        " Outputs in DIR/chaos/: table.parquet and table.csv (one row per point: "
        "verdict, exponent, delta* per kind), decorrelation.csv, decorrelation, flow_ladder and "
        "threshold (PNG, PDF), study.json, index.html; where `stickslip study lifetimes` ran into the same "
        "DIR, its verdicts, the lower bounds of <T> at N = 399, the revised verdicts of this study's points "
        "and the lifetimes' figures (survival curves, <T> against N, exponent against N)."
    )


DESIGN = Design(
    cost=COST,
    name="chaos",
    summary="the flow's exponent, slip decorrelation and its threshold delta* against N; the verdict",
    describe=describe,
    build=build,
    task=task,
    check=check_point,
    findings=conclusions,
    figures=figures,
    load=load,
    columns=(
        *"model N beta verdict verdict_text lyapunov_dt0 lyapunov_dt0_err flow_slips window".split(),
        *(column for kind in KINDS for column in threshold_columns(kind)),
        *"threshold_below threshold_low windows_decorrelated windows transient loaded".split(),
        *"first_slip_reaching_block_N flow_t seeds n_deltas".split(),
    ),
)
