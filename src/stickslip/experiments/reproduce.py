"""Reproduce the paper: run every experiment, draw every figure, compare every stated number.

:func:`reproduce` takes the spec set of a mode (:func:`stickslip.experiments.experiments`) and,
for each experiment, either loads its stored result or computes it, then draws the figures and
writes the report (:mod:`stickslip.report`). Layout of the output directory::

    DIR/
      runs/<name>-<key>/      one directory per experiment (key: hash of its spec and the
                              package version); ``result.json`` is written last and marks it done
      runs/chain-runs-<key>/points/beta=1_N=199/ ...
                              one chain run per point (run.json, state.nc, events.parquet,
                              first_move.parquet, checkpoint/), run on Dask by
                              :func:`stickslip.sweep.run_sweep`
      figures/<stem>.png|.pdf one image per figure of the paper, and the data drawn beside it
      report.json, report.html

A second call with the same mode finds every ``result.json`` and only redraws. A chain run
that was interrupted continues from its last checkpoint (:func:`stickslip.chain.resume_chain`);
finished chain runs are kept by the sweep's own ``done.json`` records, so adding a value of
beta to a spec only runs the new point.

The runners (one per kind of experiment) use the existing model code; the analysis of the chain
runs uses :mod:`stickslip.statistics`; the figures :mod:`stickslip.plotting`.
"""

from __future__ import annotations

import math
import shutil
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pandas as pd
import xarray as xr

from stickslip import io
from stickslip.experiments import Experiment, experiments
from stickslip.params import BlockParams, ChainParams
from stickslip.report import ReportFigure, ReportRow, write_report

__all__ = [
    "reproduce",
    "run_experiment",
    "chain_point_task",
    "report_rows",
    "ReproduceError",
    "RESULT_FILE",
    "CHECKPOINT_INTERVAL",
]

RESULT_FILE = "result.json"
#: Wall-clock seconds between checkpoints of a chain run (an interrupted run loses at most this).
CHECKPOINT_INTERVAL = 120.0

#: The paper's stated numbers (MODEL.md, last table) that the report compares with.
PAPER = {
    "hopf_V": 0.106,
    "V_up": 0.345,
    "duration": 1.035,
    "force_at_stop": -0.432,
    "law_a": 1.035,
    "law_b": 3.432,
    "critical_beta": 1.0,
    "front_speed": 1.43,
    "tau_beta1": 1.5,
    "tau_beta02": 1.6,
}


class ReproduceError(RuntimeError):
    """An experiment could not be completed (e.g. a chain run failed); the message says which."""


# ---------------------------------------------------------------------------------------------
# Progress on stderr


@dataclass
class _Log:
    """Progress lines on stderr: which experiment, how long it took, what is reused."""

    enabled: bool = True
    t0: float = field(default_factory=time.perf_counter)

    def __call__(self, text: str) -> None:
        if self.enabled:
            sys.stderr.write(f"[reproduce {time.perf_counter() - self.t0:6.1f} s] {text}\n")
            sys.stderr.flush()


# ---------------------------------------------------------------------------------------------
# Running experiments (with reuse)


@dataclass
class Outcome:
    """An experiment's loaded result: ``data`` (runner-specific), ``summary``, whether reused."""

    experiment: Experiment
    run_dir: Path
    data: dict[str, Any]
    summary: dict[str, Any]
    reused: bool
    wall_seconds: float


def _stored(run_dir: Path, exp: Experiment) -> dict[str, Any] | None:
    """The stored ``result.json`` of ``exp`` if it is there and made from the same spec."""
    path = run_dir / RESULT_FILE
    if not path.is_file():
        return None
    try:
        record = io.read_json(path)
    except (OSError, ValueError):
        return None
    return record if record.get("spec") == exp.spec() else None


def run_experiment(exp: Experiment, runs_dir: str | Path, *, scheduler: str | None = None,
                   n_workers: int | None = None, log: Callable[[str], None] | None = None) -> Outcome:
    """Compute one experiment into ``runs_dir/<name>-<key>/``, or load it if already there.

    The stored result is reused only if its ``result.json`` holds the same spec (kind,
    parameters, run length, options, package version). Chain runs go to Dask
    (``scheduler`` address, or a local cluster of ``n_workers`` processes).
    """
    log = log or (lambda text: None)
    runner = _RUNNERS[exp.kind]
    run_dir = Path(runs_dir) / exp.dirname
    record = _stored(run_dir, exp)
    reused = record is not None
    if record is None:
        run_dir.mkdir(parents=True, exist_ok=True)
        (run_dir / RESULT_FILE).unlink(missing_ok=True)
        start = time.perf_counter()
        summary = runner.compute(exp, run_dir, scheduler=scheduler, n_workers=n_workers, log=log)
        record = {"spec": exp.spec(), "name": exp.name, "summary": summary,
                  "wall_seconds": time.perf_counter() - start}
        io.write_json(run_dir / RESULT_FILE, record)
    data = runner.load(exp, run_dir, record["summary"])
    return Outcome(exp, run_dir, data, record["summary"], reused, float(record.get("wall_seconds", math.nan)))


@dataclass(frozen=True)
class _Runner:
    compute: Callable[..., dict[str, Any]]
    load: Callable[[Experiment, Path, dict[str, Any]], dict[str, Any]]


# --- block_run: eq. (1), Figs. 1 and 2 -------------------------------------------------------


def _compute_block_run(exp: Experiment, run_dir: Path, **_: Any) -> dict[str, Any]:
    """Eq. (1) at the paper's parameters with every step stored (Figs. 1, 2)."""
    from stickslip.block import simulate_block

    run = simulate_block(BlockParams(**exp.params), exp.t_end, every=1)
    io.write_dataset(run_dir / "series.nc", run.series)
    io.write_table(run_dir / "slips.parquet", run.slips)
    f = run.final
    return {**run.summary(), "final": {"x": f.x, "v": f.v, "theta": f.theta, "stopped": f.stopped}}


def _load_block_run(exp: Experiment, run_dir: Path, summary: dict[str, Any]) -> dict[str, Any]:
    from stickslip.block import BlockRun, BlockState

    run = BlockRun(
        params=BlockParams(**exp.params),
        series=io.read_dataset(run_dir / "series.nc"),
        slips=io.read_table(run_dir / "slips.parquet"),
        final=BlockState(**summary["final"]),
        steps=int(summary["steps"]),
        every=int(summary["every"]),
        v_min=float(summary["v_min"]),
        v_max=float(summary["v_max"]),
        n_stops=int(summary["n_stops"]),
        n_starts=int(summary["n_starts"]),
    )
    return {"run": run}


# --- slip_limit: eq. (3) ---------------------------------------------------------------------


def _compute_slip_limit(exp: Experiment, run_dir: Path, **_: Any) -> dict[str, Any]:
    """Eq. (3) accurately (DOP853, event v = 0) and with the Heun step of the paper."""
    from stickslip.slip_limit import heun_slip_limit, solve_slip_limit

    p = BlockParams(**exp.params)
    law = solve_slip_limit(p, rtol=exp.options["rtol"], atol=exp.options["atol"])
    heun = heun_slip_limit(p)
    io.write_dataset(run_dir / "curve.nc", law.curve)
    return {**law.summary(), "heun_duration": heun.duration, "heun_force_at_stop": heun.force_at_stop,
            "heun_dt": p.dt}


def _load_slip_limit(exp: Experiment, run_dir: Path, summary: dict[str, Any]) -> dict[str, Any]:
    from stickslip.slip_limit import SlipLimit

    law = SlipLimit(
        params=BlockParams(**exp.params),
        duration=float(summary["duration"]),
        force_at_stop=float(summary["force_at_stop"]),
        slip=float(summary["slip"]),
        theta_at_stop=float(summary["theta_at_stop"]),
        method=str(summary["method"]),
        curve=io.read_dataset(run_dir / "curve.nc"),
    )
    return {"law": law}


# --- period_sweep: Fig. 3 --------------------------------------------------------------------


def _compute_period_sweep(exp: Experiment, run_dir: Path, **_: Any) -> dict[str, Any]:
    """Simulated stick-slip period at log-spaced V (Fig. 3)."""
    from stickslip.block import paper_V_values, period_sweep

    o = exp.options
    table = period_sweep(BlockParams(**exp.params), paper_V_values(o["n"], o["V_min"], o["V_max"]),
                         periods=o["periods"])
    io.write_table(run_dir / "periods.parquet", table)
    return {"max_abs_rel_dev": float(np.nanmax(np.abs(table["rel_dev"]))),
            "n_V": int(len(table)), "V": table["V"].tolist(), "rel_dev": table["rel_dev"].tolist()}


def _load_period_sweep(exp: Experiment, run_dir: Path, summary: dict[str, Any]) -> dict[str, Any]:
    return {"table": io.read_table(run_dir / "periods.parquet")}


# --- block_stability: eq. (2) ----------------------------------------------------------------


def _compute_block_stability(exp: Experiment, run_dir: Path, **_: Any) -> dict[str, Any]:
    """Hopf point at the spec's beta, stability for all V at ``beta_stable``, the stability map."""
    from stickslip import stability as st

    p = BlockParams(**exp.params)
    hopf = st.hopf_point(p)
    q = p.replace(beta=float(exp.options["beta_stable"]))
    hopf_q = st.hopf_point(q)
    V_scan = np.linspace(0.0, 1.0 / q.alpha, 2001)[1:-1]
    growth_q = st.block_growth_map(q, np.array([q.beta]), V_scan)
    betas = np.linspace(0.0, 1.5 * st.hopf_beta_limit(p), int(exp.options["map_betas"]))
    Vs = np.linspace(0.0, 1.0 / p.alpha, int(exp.options["map_Vs"]) + 1)[1:]
    curve = st.hopf_curve(p, betas)
    ds = curve.assign(growth_rate=st.block_growth_map(p, betas, Vs))
    io.write_dataset(run_dir / "stability_map.nc", ds)
    return {
        "beta": p.beta,
        "hopf_V": hopf.V,
        "hopf_V_closed_form": st.hopf_point_closed_form(p),
        "hopf_omega": hopf.omega,
        "regime": hopf.regime,
        "beta_stable": q.beta,
        "regime_stable": hopf_q.regime,
        "hopf_V_stable": hopf_q.V,
        "max_growth_stable": float(growth_q.max()),
        "V_scan": [float(V_scan[0]), float(V_scan[-1]), int(V_scan.size)],
    }


def _load_block_stability(exp: Experiment, run_dir: Path, summary: dict[str, Any]) -> dict[str, Any]:
    return {"map": io.read_dataset(run_dir / "stability_map.nc")}


# --- hysteresis: section 2 -------------------------------------------------------------------


def _compute_hysteresis(exp: Experiment, run_dir: Path, **_: Any) -> dict[str, Any]:
    """V raised slowly and lowered again for the single block (the inverse transition, sec. 2)."""
    from stickslip import hysteresis as hy

    result = hy.hysteresis_sweep(BlockParams(**exp.params), hy.SweepSettings(**exp.options))
    io.write_dataset(run_dir / "hysteresis.nc", result.data)
    return result.summary()


def _load_hysteresis(exp: Experiment, run_dir: Path, summary: dict[str, Any]) -> dict[str, Any]:
    return {"data": io.read_dataset(run_dir / "hysteresis.nc")}


# --- chain_modes: eq. (5), Fig. 4 ------------------------------------------------------------


def _compute_chain_modes(exp: Experiment, run_dir: Path, **_: Any) -> dict[str, Any]:
    """Fourier modes of the linearised chain at the betas of Fig. 4, and the critical beta."""
    from stickslip import stability as st

    p = ChainParams(**exp.params)
    betas = [float(b) for b in exp.options["betas"]]
    ds = st.fig4_data(p, betas=betas, k=np.linspace(0.0, np.pi, int(exp.options["n_k"])))
    io.write_dataset(run_dir / "fig4.nc", ds)
    per_beta = []
    for b in betas:
        s = st.chain_stability(p.replace(beta=b))
        per_beta.append({"beta": b, "max_growth_rate": s.max_growth_rate, "k_at_max": s.k_at_max,
                         "unstable": s.unstable, "marginal": s.marginal})
    return {
        "critical_beta": st.chain_critical_beta(p),
        "critical_beta_numeric": st.chain_critical_beta_numeric(p),
        "per_beta": per_beta,
    }


def _load_chain_modes(exp: Experiment, run_dir: Path, summary: dict[str, Any]) -> dict[str, Any]:
    return {"modes": io.read_dataset(run_dir / "fig4.nc")}


# --- chain_runs: eq. (4), Figs. 5-8, on Dask -------------------------------------------------

_CHAIN_FIELDS = ("N", "K", "D", "V", "beta", "alpha", "Fs", "dt")


def _point_settings(cfg: dict[str, Any]) -> tuple[ChainParams, float, dict[str, Any]]:
    """Parameters, t_end and run options of one chain point from its merged settings."""
    params = ChainParams(**{k: cfg[k] for k in _CHAIN_FIELDS if k in cfg})
    t_end = float(cfg["t_end_by_N"][str(params.N)])
    options: dict[str, Any] = {
        "sample_interval": float(cfg["sample_interval"]),
        "average_from": float(cfg["average_fraction"]) * t_end,
        "until_steady": float(cfg["until_steady"]) if params.beta > float(cfg["until_steady_above"]) else None,
    }
    if params.N == int(cfg["profile_N"]) and any(math.isclose(params.beta, float(b)) for b in cfg["profile_betas"]):
        options["profile_window"] = float(cfg["profile_window"])
        options["profile_min_blocks"] = int(float(cfg["profile_min_fraction"]) * params.N)
    return params, t_end, options


def chain_point_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """One chain run of eq. (4) for Figs. 5-8, as a task of :func:`stickslip.sweep.run_sweep`.

    ``point`` holds N and beta merged with the experiment's common settings (see
    :func:`stickslip.experiments.experiments`). Runs at beta above ``until_steady_above`` stop
    once the chain slides steadily; the runs at N = ``profile_N`` and beta in ``profile_betas``
    also store the displacement over windows of ``profile_window`` for Fig. 6. The run
    checkpoints into ``point_dir`` every :data:`CHECKPOINT_INTERVAL` seconds and, if a
    checkpoint is there, continues from it.
    Returns the run's summary with <L> and its batch-means error (Fig. 5b) and the final state
    ("steady sliding" or "stick-slip", section 3).
    """
    from stickslip import chain
    from stickslip.statistics import time_average

    params, t_end, options = _point_settings(point)
    point_dir = Path(point_dir)
    run = None
    if (point_dir / "checkpoint" / "state.npz").is_file():
        try:
            run = chain.resume_chain(point_dir, checkpoint_interval=CHECKPOINT_INTERVAL, expect_params=params)
        except chain.ChainRunError:
            shutil.rmtree(point_dir / "checkpoint", ignore_errors=True)
            run = None
    if run is None:
        run = chain.run_chain(params, t_end, out_dir=point_dir, checkpoint_interval=CHECKPOINT_INTERVAL,
                              **options)
    s = dict(run.summary)
    stopped_early = bool(s.get("stopped_early", False))
    avg_from = options["average_from"]
    late = run.events[run.events["t_start"] >= avg_from]
    s["n_events_late"] = int(len(late))
    s["t_last_event"] = float(run.events["t_end"].max()) if len(run.events) else None
    if stopped_early:
        s["L_err"] = 0.0
    else:
        try:
            s["L_err"] = time_average(run.samples["L"], avg_from).stderr
        except ValueError:
            s["L_err"] = math.nan
    s["final_state"], s["steady_deviation_final"] = final_state(s, run.state, params)
    s["t_end_requested"] = t_end
    return s


def final_state(summary: dict[str, Any], state, params: ChainParams) -> tuple[str, float]:
    """The final state of a chain run (sec. 3): 'steady sliding', 'stick-slip' or 'sliding, not yet steady'.

    Steady sliding: the run stopped there (``until_steady``), or its final state is within
    :data:`stickslip.experiments.UNTIL_STEADY` of it (:func:`stickslip.chain.steady_deviation`),
    which for beta > 1 it never leaves. Otherwise stick-slip if events happened in the averaged
    second half or some block is stopped at the end. Returns the state and the final deviation.
    """
    from stickslip import chain
    from stickslip.experiments import UNTIL_STEADY

    deviation = chain.steady_deviation(state, params)
    if summary.get("stopped_early") or deviation <= UNTIL_STEADY:
        return "steady sliding", deviation
    if summary.get("n_events_late", 0) > 0 or summary["n_moving"] < params.N:
        return "stick-slip", deviation
    return "sliding, not yet steady", deviation


def _chain_common(exp: Experiment) -> dict[str, Any]:
    common = dict(exp.params)
    common.update({k: v for k, v in exp.options.items() if k not in ("points", "sweep_N", "figure_N")})
    return common


def _compute_chain_runs(exp: Experiment, run_dir: Path, *, scheduler=None, n_workers=None,
                        log=None) -> dict[str, Any]:
    """All chain runs of the experiment as one Dask sweep (Figs. 5-8)."""
    from stickslip.sweep import run_sweep

    points = [dict(p) for p in exp.options["points"]]
    common = _chain_common(exp)
    for p in points:  # validate every point before any work starts
        _point_settings({**common, **p})
    if log:
        log(f"chain runs: {len(points)} points on Dask "
            f"({'scheduler ' + scheduler if scheduler else 'local cluster'}); finished points are reused")
    result = run_sweep(chain_point_task, points, run_dir / "points", common=common, scheduler=scheduler,
                       n_workers=n_workers, progress=bool(getattr(log, "enabled", False)))
    failed = result.table[result.table["status"] != "ok"]
    if len(failed):
        lines = "; ".join(f"{r.point_dir}: {r.error}" for r in failed.itertuples())
        raise ReproduceError(f"{len(failed)} chain run(s) failed ({lines}); run again to retry them")
    return {"points": _records(result.table), "n_run": result.n_run, "n_reused": result.n_reused}


def _records(table: pd.DataFrame) -> list[dict[str, Any]]:
    return table.astype(object).where(table.notna(), None).to_dict(orient="records")


def _load_chain_runs(exp: Experiment, run_dir: Path, summary: dict[str, Any]) -> dict[str, Any]:
    from stickslip import chain
    from stickslip.sweep import point_name

    table = pd.DataFrame(summary["points"])
    cache: dict[tuple[int, float], Any] = {}

    def get(N: int, beta: float):
        """The full run at (N, beta), read from its directory when first asked for."""
        key = (int(N), float(beta))
        if key not in cache:
            cache[key] = chain.load_run(run_dir / "points" / point_name({"N": int(N), "beta": float(beta)}))
        return cache[key]

    # Classify every run from its stored final state, so stored runs follow the current rule.
    params = {k: v for k, v in exp.params.items()}
    states, deviations = [], []
    for r in table.itertuples():
        p = ChainParams(**{**params, "N": int(r.N), "beta": float(r.beta)})
        state, deviation = final_state(r._asdict(), get(r.N, r.beta).state, p)
        states.append(state)
        deviations.append(deviation)
    table["final_state"] = states
    table["steady_deviation_final"] = deviations
    return {"table": table, "run": get}


_RUNNERS: dict[str, _Runner] = {
    "block_run": _Runner(_compute_block_run, _load_block_run),
    "slip_limit": _Runner(_compute_slip_limit, _load_slip_limit),
    "period_sweep": _Runner(_compute_period_sweep, _load_period_sweep),
    "block_stability": _Runner(_compute_block_stability, _load_block_stability),
    "hysteresis": _Runner(_compute_hysteresis, _load_hysteresis),
    "chain_modes": _Runner(_compute_chain_modes, _load_chain_modes),
    "chain_runs": _Runner(_compute_chain_runs, _load_chain_runs),
}


# ---------------------------------------------------------------------------------------------
# Analysis of the chain runs (Figs. 5-8)


def choose_s_min(S: np.ndarray, s_max: float, *, max_quantile: float = 0.9, n_candidates: int = 40) -> float:
    """Lower end of the power-law fit of Figs. 7, 8: the s_min with the least KS distance.

    The candidates are ``n_candidates`` log-spaced values from the smallest S to its
    ``max_quantile`` quantile (and below ``s_max``); each gets the truncated maximum-likelihood
    fit of :func:`stickslip.statistics.fit_power_law` on [s_min, s_max], and the one whose
    fitted CDF is closest to the data (Kolmogorov-Smirnov) wins (the recipe of Clauset, Shalizi
    and Newman, SIAM Review 51, 661 (2009), with the upper cut-off kept).
    """
    from stickslip.statistics import fit_power_law

    S = np.asarray(S, dtype=float)
    S = S[np.isfinite(S) & (S > 0)]
    hi = min(float(np.quantile(S, max_quantile)), s_max / 10.0)
    lo = float(S.min())
    if not hi > lo:
        return lo
    best, best_ks = lo, math.inf
    for s_min in np.geomspace(lo, hi, n_candidates):
        if np.count_nonzero((S >= s_min) & (S <= s_max)) < 50:
            break
        fit = fit_power_law(S, s_min=float(s_min), s_max=s_max, bootstrap=0)
        if math.isfinite(fit.ks_distance) and fit.ks_distance < best_ks:
            best, best_ks = float(s_min), fit.ks_distance
    return best


def size_statistics(events: pd.DataFrame, N: int, *, small_only: bool, seed: int = 0) -> dict[str, Any]:
    """Slip-size statistics of one chain run for Fig. 7 (beta = 1) or Fig. 8 (beta = 0.2).

    The events that reach block N ("system-spanning") set the largest sizes. With
    ``small_only`` (Fig. 8, "about 1.6 for small S") the power law is fitted below the smallest
    system-spanning event, s_span; otherwise (Fig. 7) up to the largest S, with the cut-off in
    the likelihood. s_min is chosen by :func:`choose_s_min`. ``excess`` is the number of events
    with S >= s_span over the number the fitted power law, continued without cut-off beyond
    s_span, predicts for them (the paper's "excess of large events" at beta = 0.2 is > 1).
    """
    from stickslip.statistics import fit_power_law

    S = events["S"].to_numpy(dtype=float)
    S = S[np.isfinite(S) & (S > 0)]
    spanning = events[events["max_block"] >= N]
    s_span = float(spanning["S"].min()) if len(spanning) else math.nan
    s_max = s_span if (small_only and math.isfinite(s_span)) else float(S.max())
    s_min = choose_s_min(S, s_max)
    fit = fit_power_law(S, s_min=s_min, s_max=s_max, bootstrap=200, seed=seed)
    excess = math.nan
    if math.isfinite(s_span) and fit.tau > 1.0:
        n_above_min = np.count_nonzero(S >= s_min)
        expected = n_above_min * (s_span / s_min) ** (1.0 - fit.tau)
        observed = np.count_nonzero(S >= s_span)
        excess = observed / expected if expected > 0 else math.nan
    largest = events.loc[events["S"].idxmax()] if len(events) else None
    return {
        "fit": fit,
        "n_events": int(len(events)),
        "n_spanning": int(len(spanning)),
        "s_span": s_span,
        "S_max": float(S.max()) if S.size else math.nan,
        "largest_reaches_N": bool(largest is not None and int(largest["max_block"]) >= N),
        "excess": excess,
    }


def front_statistics(run, N: int, t_from: float) -> dict[str, Any]:
    """Rupture fronts for Fig. 6: the picked large and intermediate events and all spanning ones.

    The picks (:func:`stickslip.statistics.pick_front_events`) are made among the events after
    ``t_from`` whose displacement profiles were stored. ``speeds`` are the front speeds
    (:func:`stickslip.statistics.front_speed`, far half of the chain) of every event after
    ``t_from`` that reached block N; their median is the number compared with the paper's c.
    """
    from stickslip.statistics import front_speed, pick_front_events

    events = run.events[run.events["t_start"] >= t_from]
    with_profiles = set(np.unique(run.profiles["event"].values).tolist()) if run.profiles.sizes.get("row") else set()
    candidates = events[events["event"].isin(with_profiles)]
    picks = pick_front_events(candidates, N) if len(candidates) else candidates.assign(kind=pd.Series(dtype=str))
    groups = {int(e): g for e, g in run.first_move.groupby("event")}
    fronts, labels = [], []
    for row in picks.itertuples():
        fm = groups.get(int(row.event))
        if fm is None:
            continue
        try:
            fronts.append(front_speed(fm, int(row.event)))
        except ValueError:
            continue
        labels.append(f"{row.kind} event (S = {row.S:.4g}, {row.n_blocks} blocks)")
    speeds = []
    for e in events.loc[events["max_block"] >= N, "event"]:
        fm = groups.get(int(e))
        if fm is None:
            continue
        try:
            speeds.append(front_speed(fm, int(e)).speed)
        except ValueError:
            continue
    speeds = np.asarray(speeds, dtype=float)
    return {
        "fronts": fronts,
        "labels": labels,
        "picks": picks,
        "speeds": speeds,
        "median_speed": float(np.median(speeds)) if speeds.size else math.nan,
        "quartiles": [float(q) for q in np.quantile(speeds, [0.25, 0.75])] if speeds.size else [math.nan] * 2,
    }


def chain_analysis(outcome: Outcome) -> dict[str, Any]:
    """Everything Figs. 5-8 and their rows need from the chain runs of one experiment."""
    opts = outcome.experiment.options
    table = outcome.data["table"]
    sweep_N, fig_N = int(opts["sweep_N"]), int(opts["figure_N"])
    t_fig = float(opts["t_end_by_N"][str(fig_N)])
    t_from = float(opts["average_fraction"]) * t_fig
    out: dict[str, Any] = {"table": table, "sweep_N": sweep_N, "figure_N": fig_N, "t_fig": t_fig,
                           "t_from": t_from}
    run1 = outcome.data["run"](fig_N, 1.0)
    run02 = outcome.data["run"](fig_N, 0.2)
    out["run1"], out["run02"] = run1, run02
    ev1 = run1.events[run1.events["t_start"] >= t_from]
    ev02 = run02.events[run02.events["t_start"] >= t_from]
    out["events1"], out["events02"] = ev1, ev02
    out["sizes1"] = size_statistics(ev1, fig_N, small_only=False) if len(ev1) >= 10 else None
    out["sizes02"] = size_statistics(ev02, fig_N, small_only=True) if len(ev02) >= 10 else None
    out["fronts"] = front_statistics(run1, fig_N, t_from)
    return out


# ---------------------------------------------------------------------------------------------
# Figures


FORMATS = ("png", "pdf")


def _save(fig, figures_dir: Path, stem: str) -> tuple[str, str]:
    """Save a figure as figures/<stem>.png and .pdf; return both paths relative to the report."""
    from stickslip.plotting.style import save_figure

    save_figure(fig, figures_dir / stem, formats=FORMATS)
    return f"figures/{stem}.png", f"figures/{stem}.pdf"


def _write_csv(path: Path, table: pd.DataFrame) -> Path:
    with io.atomic_path(path) as tmp:
        table.to_csv(tmp, index=False)
    return path


def _figure(stem: str, label: str, caption: str, figures_dir: Path, fig, data: list[Path],
            command: str = "") -> ReportFigure:
    png, pdf = _save(fig, figures_dir, stem)
    return ReportFigure(figure=label, image=png, caption=caption, pdf=pdf,
                        data=tuple(f"figures/{p.name}" for p in data), command=command)


def _fig1_2(o: dict[str, Outcome], d: Path) -> list[ReportFigure]:
    """Figs. 1 and 2 from the block run and eq. (3)."""
    from stickslip.plotting.block import fig1_position, fig2_slip, slip_window

    run = o["block"].data["run"]
    law = o["slip-limit"].data["law"]
    s = run.series
    f1 = io.write_dataset(d / "fig1.nc", s[["x"]])
    figs = [_figure("fig1", "Fig. 1", "Time evolution of x of the single block, eq. (1), at M = alpha = beta = "
                    "sigma = 1, K = 10, V = 0.001, Fs = 3 (Heun, dt = 0.005, from x = v = 0, theta = 0.1): "
                    "stick-slip with period 344.", d, fig1_position(run), [f1], _block_command(o["block"]))]
    w = slip_window(run)
    f2 = io.write_dataset(d / "fig2.nc", xr.Dataset(
        {"eq1_v": ("t_eq1", w["v"].values), "eq1_theta": ("t_eq1", w["theta"].values),
         "eq3_v": ("t_eq3", law.curve["v"].values), "eq3_theta": ("t_eq3", law.curve["theta"].values)},
        coords={"t_eq1": w["t"].values, "t_eq3": law.curve["t"].values},
        attrs={"description": "Fig. 2: v and theta against t - t_c, eq. (1) (Heun) and eq. (3) (DOP853)"}))
    figs.append(_figure("fig2", "Fig. 2", "(a) v(t - t_c) during the second slip of the run of Fig. 1 (solid) "
                        "and of eq. (3) (dashed); (b) the phase portrait (v, theta). The paper: the curves "
                        "overlap.", d, fig2_slip(run, law), [f2], "stickslip slip-limit --json"))
    return figs


def _fig3(o: dict[str, Outcome], d: Path) -> list[ReportFigure]:
    """Fig. 3: period against V with the law T = a + b / (K V) of eq. (3)."""
    from stickslip.plotting.block import fig3_period

    table = o["period-sweep"].data["table"]
    law = o["slip-limit"].data["law"]
    f = _write_csv(d / "fig3.csv", table)
    return [_figure("fig3", "Fig. 3", f"Period of stick-slip against V: simulated (marks) and "
                    f"T = {law.law_a:.4f} + {law.law_b:.4f} / (K V) from eq. (3) (dashed; the paper: "
                    "T = 1.035 + 3.432 / (K V)).", d, fig3_period(table, law), [f],
                    "stickslip block --fig3 --out DIR")]


def _stability_map(o: dict[str, Outcome], d: Path) -> list[ReportFigure]:
    """Section 2: the Hopf curve V_c(beta) of the single block at K = 10 (eq. 2)."""
    from stickslip.plotting.stability import plot_stability_map

    ds = o["stability-block"].data["map"]
    f = io.write_dataset(d / "stability_map.nc", ds)
    fig = plot_stability_map(ds[["V_c", "V_c_closed_form"]].assign_attrs(ds.attrs), ds["growth_rate"])
    return [_figure("stability_map", "Section 2, eq. (2)", "Linear stability of steady sliding of the single "
                    "block at K = 10: largest Re(lambda) of eq. (2) over (beta, V) and the Hopf curve V_c(beta). "
                    "The paper: V_c = 0.106 at beta = 0.08; stable for all V at beta = 1.", d, fig, [f],
                    "stickslip stability block --K 10 --beta 0.08 --out DIR")]


def _hysteresis(o: dict[str, Outcome], d: Path) -> list[ReportFigure]:
    """Section 2: V raised slowly and lowered again; the inverse transition at V_up."""
    from stickslip.plotting.stability import plot_hysteresis

    data = o["hysteresis"].data["data"]
    f = io.write_dataset(d / "hysteresis.nc", data)
    return [_figure("hysteresis", "Section 2, inverse transition", "Single block, beta = 1, Fs = 3, K = 10: "
                    "largest and least v at each V as V is raised slowly and lowered again. Stick-slip "
                    "(min v = 0) ends at V_up (the paper: 0.345).", d, plot_hysteresis(data), [f],
                    _hysteresis_command(o["hysteresis"]))]


def _fig4(o: dict[str, Outcome], d: Path) -> list[ReportFigure]:
    """Fig. 4: real parts of the two largest eigenvalues of the Fourier modes of eq. (5)."""
    from stickslip.plotting.stability import plot_fig4

    ds = o["chain-modes"].data["modes"]
    f = io.write_dataset(d / "fig4.nc", ds)
    return [_figure("fig4", "Fig. 4", "Real parts of the two largest eigenvalues of the Fourier modes of the "
                    "linearised chain, eq. (5), against k at beta = 0.5, 1, 1.5 (K = 10, D = 5). Right: long "
                    "waves, unstable for beta < 1.", d, plot_fig4(ds), [f],
                    "stickslip stability chain --K 10 --D 5 --beta 1 --out DIR")]


def _fig5(o: dict[str, Outcome], a: dict[str, Any], d: Path, mode: str) -> list[ReportFigure]:
    """Fig. 5: (a) snapshot at the end of the beta = 1 run; (b) <L> against beta."""
    from stickslip.physics import chain_steady_profile_paper, chain_steady_state
    from stickslip.plotting.chain import fig5a_snapshot, fig5b_length

    run = a["run1"]
    snap = run.snapshots.isel(time=-1)
    t = float(snap["time"])
    p = run.params
    fa = _write_csv(d / "fig5a.csv", pd.DataFrame({
        "block": np.arange(1, p.N + 1), "x": snap.values, "x_steady_exact": chain_steady_state(p, t)["x"],
        "x_steady_paper": chain_steady_profile_paper(p, t)}))
    figs = [_figure("fig5a", "Fig. 5(a)", f"Snapshot of x_i at t = {t:.3g} at beta = 1 (N = {p.N}), in the frame "
                    "of the pulling point, against the exact discrete steady sliding profile (dashed) and the "
                    "paper's continuum form (dotted).", d, fig5a_snapshot(snap, p, t), [fa],
                    _chain_command(o["chain-runs"], p.N, 1.0))]
    sweep = _sweep_table(a)
    fb = _write_csv(d / "fig5b.csv", sweep)
    q = ChainParams(**{k: v for k, v in o["chain-runs"].experiment.params.items()}, N=a["sweep_N"])
    steady_note = ", ".join(f"{b:g}" for b in sweep.loc[sweep["final_state"] == "steady sliding", "beta"])
    figs.append(_figure("fig5b", "Fig. 5(b)", f"Time-averaged length <L> = <x_1 - x_N> against beta (N = "
                        f"{a['sweep_N']}, second half of each run; error bars: batch means) and the steady "
                        "sliding length (dashed). Runs that reached steady sliding (beta = "
                        f"{steady_note or 'none'}) were stopped there and count L_ss from then on.", d,
                        fig5b_length(sweep, q), [fb], _sweep_command(o["chain-runs"], mode)))
    return figs


def _sweep_table(a: dict[str, Any]) -> pd.DataFrame:
    t = a["table"]
    t = t[t["N"] == a["sweep_N"]].sort_values("beta")
    cols = ["beta", "N", "L_mean", "L_err", "L_steady", "final_state", "n_events", "n_events_late",
            "t_steady", "stopped_early", "t_end", "wall_seconds"]
    return t[[c for c in cols if c in t.columns]].reset_index(drop=True)


def _fig6(o: dict[str, Outcome], a: dict[str, Any], d: Path) -> list[ReportFigure]:
    """Fig. 6: rupture fronts of a large and an intermediate event at beta = 1."""
    from stickslip.plotting.chain import fig6_fronts

    fr = a["fronts"]
    run = a["run1"]
    if not fr["fronts"]:
        raise ValueError("no event with stored profiles to draw")
    ids = [f.event for f in fr["fronts"]]
    rows = np.flatnonzero(np.isin(run.profiles["event"].values, ids))
    prof = run.profiles.isel(row=rows)
    f1 = io.write_dataset(d / "fig6.nc", prof)
    fm = run.first_move[run.first_move["event"].isin(ids)]
    f2 = _write_csv(d / "fig6_first_move.csv", fm)
    f3 = _write_csv(d / "fig6_fronts.csv", pd.DataFrame([f.to_dict() for f in fr["fronts"]]).assign(
        label=fr["labels"]))
    caption = (f"Displacement over windows of 20 time units in a large and an intermediate slip event at beta = 1 "
               f"(N = {run.params.N}), and the time each block first moved with the fitted front speed. Median "
               f"front speed over the {fr['speeds'].size} events that reached block N: "
               f"{fr['median_speed']:.3g} (the paper: 1.43; sound speed 3.16).")
    return [_figure("fig6", "Fig. 6", caption, d,
                    fig6_fronts(prof, fm, fr["fronts"], run.params, labels=fr["labels"], window=20.0),
                    [f1, f2, f3], _chain_command(o["chain-runs"], run.params.N, 1.0))]


def _fig7_8(o: dict[str, Outcome], a: dict[str, Any], d: Path, which: str) -> list[ReportFigure]:
    """Figs. 7 (beta = 1) and 8 (beta = 0.2): slip-size distribution and S against time."""
    from stickslip.plotting.chain import fig7_8_sizes
    from stickslip.statistics import size_distribution

    beta, stem, label, paper_tau = (1.0, "fig7", "Fig. 7", 1.5) if which == "7" else (0.2, "fig8", "Fig. 8", 1.6)
    events = a["events1"] if which == "7" else a["events02"]
    stats = a["sizes1"] if which == "7" else a["sizes02"]
    if stats is None:
        raise ValueError("too few events in the second half of the run")
    fit = stats["fit"]
    f1 = _write_csv(d / f"{stem}_events.csv", events[["event", "t_start", "S", "max_block", "n_blocks"]])
    hist = size_distribution(events["S"].to_numpy(dtype=float), 30)
    f2 = io.write_dataset(d / f"{stem}_histogram.nc", hist)
    N = a["figure_N"]
    fit_range = (f"fitted on [{fit.s_min:.3g}, {fit.s_max:.3g}]" + (" (below the smallest event that reached "
                 "block N)" if which == "8" else " with the cut-off in the likelihood"))
    caption = (f"(a) Density of slip sizes S = sum_i dx_i at beta = {beta:g} (N = {N}, events of the second half "
               f"of the run), truncated power law {fit_range}: tau = {fit.tau:.2f} ± {fit.tau_err:.2f} (the paper: "
               f"{'nearly 1.5' if which == '7' else 'about 1.6 for small S, with an excess of large events'}). "
               f"(b) S against the event's start time.")
    return [_figure(stem, label, caption, d, fig7_8_sizes(events, fit, beta, paper_tau=paper_tau), [f1, f2],
                    _chain_command(o["chain-runs"], N, beta))]


def draw_figures(outcomes: dict[str, Outcome], analysis: dict[str, Any] | None, out_dir: Path,
                 mode: str, log: Callable[[str], None] | None = None) -> tuple[list[ReportFigure], dict[str, str]]:
    """Draw every figure of the paper (Figs. 1-8 and the two of section 2) into ``out_dir/figures``.

    Returns the report entries and, for a figure that cannot be drawn from these results (e.g.
    no event reached block N in a tiny run), the reason, by figure stem.
    """
    d = Path(out_dir) / "figures"
    d.mkdir(parents=True, exist_ok=True)
    figures: list[ReportFigure] = []
    not_drawn: dict[str, str] = {}
    steps: list[tuple[str, Callable[[], list[ReportFigure]]]] = [
        ("fig1, fig2", lambda: _fig1_2(outcomes, d)),
        ("fig3", lambda: _fig3(outcomes, d)),
        ("stability_map", lambda: _stability_map(outcomes, d)),
        ("hysteresis", lambda: _hysteresis(outcomes, d)),
        ("fig4", lambda: _fig4(outcomes, d)),
    ]
    if analysis is not None:
        steps += [
            ("fig5a, fig5b", lambda: _fig5(outcomes, analysis, d, mode)),
            ("fig6", lambda: _fig6(outcomes, analysis, d)),
            ("fig7", lambda: _fig7_8(outcomes, analysis, d, "7")),
            ("fig8", lambda: _fig7_8(outcomes, analysis, d, "8")),
        ]
    for name, draw in steps:
        try:
            figures += draw()
        except (ValueError, KeyError, IndexError) as exc:
            not_drawn[name] = f"{type(exc).__name__}: {exc}"
            if log:
                log(f"{name} not drawn: {exc}")
    return figures, not_drawn


# ---------------------------------------------------------------------------------------------
# Commands that reproduce a row or a figure


def _g(x: float) -> str:
    return f"{x:g}"


def _block_command(o: Outcome) -> str:
    return f"stickslip block --t-end {_g(o.experiment.t_end)} --out DIR"


def _hysteresis_command(o: Outcome) -> str:
    s = o.experiment.options
    return (f"stickslip hysteresis --K 10 --beta 1 --Fs 3 --V-min {_g(s['V_min'])} --V-max {_g(s['V_max'])} "
            f"--dV {_g(s['dV'])} --time-per-step {_g(s['time_per_step'])} --transient {_g(s['transient'])} --json")


def _chain_command(o: Outcome, N: int, beta: float) -> str:
    """The ``stickslip chain`` command of one chain run of the experiment."""
    cfg = {**_chain_common(o.experiment), "N": N, "beta": beta}
    params, t_end, opts = _point_settings(cfg)
    parts = [f"stickslip chain --N {N} --beta {_g(beta)} --t-end {_g(t_end)}",
             f"--sample-interval {_g(opts['sample_interval'])} --average-from {_g(opts['average_from'])}"]
    if opts.get("profile_window"):
        parts.append(f"--profile-window {_g(opts['profile_window'])} --profile-min-blocks {opts['profile_min_blocks']}")
    if opts.get("until_steady"):
        parts.append(f"--until-steady {_g(opts['until_steady'])}")
    parts.append("--out DIR")
    return " ".join(parts)


def _sweep_command(o: Outcome, mode: str) -> str:
    """The reproduce command whose Dask sweep gives the chain runs of Fig. 5(b)."""
    return f"stickslip reproduce --{mode} --out DIR  (chain runs on Dask: runs/{o.experiment.dirname}/points)"


# ---------------------------------------------------------------------------------------------
# The table of stated numbers (MODEL.md, last table)


def _f(x: Any, digits: int = 4) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "n/a"
    return f"{x:.{digits}g}"


def _section2_rows(o: dict[str, Outcome]) -> list[ReportRow]:
    """Rows of section 2, eq. (3) and Figs. 3 and 4: the same computation in every mode."""
    rows = []
    st = o["stability-block"].summary
    Vc = st["hopf_V"]
    rows.append(ReportRow(
        "sec. 2", "Hopf point of steady sliding, K = 10, beta = 0.08", "V_c = 0.106",
        f"V_c = {_f(Vc, 5)}", None if Vc is None else abs(Vc - PAPER["hopf_V"]) <= 1e-3,
        "|V_c - 0.106| <= 0.001", "stickslip stability block --K 10 --beta 0.08 --json",
        na_reason="no Hopf point found" if Vc is None else "",
        note=f"Routh-Hurwitz closed form {_f(st['hopf_V_closed_form'], 5)}; truncated to three "
             "digits it is the paper's 0.106"))
    stable = st["hopf_V_stable"] is None and st["max_growth_stable"] < 0.0
    lo, hi, n = st["V_scan"]
    rows.append(ReportRow(
        "sec. 2", "steady sliding linearly stable for all V > 0, K = 10, beta = 1", "stable for all V",
        f"{st['regime_stable']}; largest Re(lambda) over {n} V in [{_g(lo)}, {_g(hi)}]: "
        f"{_f(st['max_growth_stable'], 3)}", stable,
        "no Hopf point and Re(lambda) < 0 at every V of the grid",
        "stickslip stability block --K 10 --beta 1 --json"))
    hy = o["hysteresis"].summary
    V_up = hy["V_up"]
    dV = hy["sweep"]["dV"]
    rows.append(ReportRow(
        "sec. 2", "inverse transition stick-slip -> sliding as V is raised slowly, beta = 1, Fs = 3",
        "V = 0.345", f"V_up = {_f(V_up)}", None if V_up is None else abs(V_up - PAPER["V_up"]) <= dV + 1e-12,
        f"|V_up - 0.345| <= dV = {_g(dV)}", _hysteresis_command(o["hysteresis"]),
        na_reason="stick-slip did not end in the swept range" if V_up is None else "",
        note=f"V raised in steps of {_g(dV)}, {_g(hy['sweep']['time_per_step'])} time units per value; going "
             + ("down, the block keeps sliding steadily down to V = " + _g(hy["sweep"]["V_min"])
                if hy["V_down"] is None else f"down, stick-slip returns at V_down = {_f(hy['V_down'])}")))
    sl = o["slip-limit"].summary
    rows.append(ReportRow(
        "eq. 3", "slip duration t_e - t_c in the limit V -> 0", "1.035", f"{sl['duration']:.4f}",
        abs(sl["duration"] - PAPER["duration"]) <= sl["heun_dt"] + 1e-12,
        f"|t_e - t_c - 1.035| <= dt = {_g(sl['heun_dt'])} (the paper's number is from a Heun run with that step)",
        "stickslip slip-limit --json",
        note=f"DOP853 with event location; Heun with dt = {_g(sl['heun_dt'])} and the stop rule gives "
             f"{sl['heun_duration']:.4f}"))
    rows.append(ReportRow(
        "eq. 3", "spring force Fs - K x' when the block stops", "-0.432", f"{sl['force_at_stop']:.5f}",
        abs(sl["force_at_stop"] - PAPER["force_at_stop"]) <= 5e-4, "|f - (-0.432)| <= 0.0005 (rounding)",
        "stickslip slip-limit --json", note=f"Heun, dt = {_g(sl['heun_dt'])}: {sl['heun_force_at_stop']:.5f}"))
    law = o["slip-limit"].data["law"]
    ps = o["period-sweep"].summary
    ok = (abs(law.law_a - PAPER["law_a"]) <= sl["heun_dt"] + 1e-12 and abs(law.law_b - PAPER["law_b"]) <= 5e-4
          and ps["max_abs_rel_dev"] <= 0.03)
    rows.append(ReportRow(
        "Fig. 3", "period law T(V) = a + b / (K V), and the simulated periods", "T = 1.035 + 3.432 / (K V)",
        f"T = {law.law_a:.4f} + {law.law_b:.4f} / (K V); simulated periods within "
        f"{100 * ps['max_abs_rel_dev']:.1f}% of it for V in [1e-3, 1e-1]", ok,
        "|a - 1.035| <= dt, |b - 3.432| <= 0.0005, simulated periods within 3% of the law",
        "stickslip slip-limit --json; stickslip block --fig3 --out DIR"))
    cm = o["chain-modes"].summary
    per = {round(r["beta"], 6): r for r in cm["per_beta"]}

    def state(r):
        return "unstable" if r["unstable"] else ("marginal" if r["marginal"] else "stable")

    ok4 = (abs(cm["critical_beta_numeric"] - PAPER["critical_beta"]) <= 1e-3
           and all(r["unstable"] == (r["beta"] < 1.0) for r in cm["per_beta"]))
    rows.append(ReportRow(
        "Fig. 4", "long-wave instability of steady sliding of the chain, K = 10, D = 5", "for beta <= 1 "
        "(beta = 1 critical)",
        f"critical beta {cm['critical_beta']:g} (closed form), {cm['critical_beta_numeric']:.6f} (Fourier modes); "
        + ", ".join(f"beta = {b:g}: {state(r)}" for b, r in sorted(per.items())), ok4,
        "|beta_c - 1| <= 0.001; unstable exactly for the betas below 1",
        "stickslip stability chain --K 10 --D 5 --beta 1 --json",
        note="at beta = 1 the long-wave growth rate tends to 0 from below as k -> 0 (marginal); the paper "
             "counts beta = 1 with the unstable side"))
    return rows


def _final_state_row(o: Outcome, a: dict[str, Any], mode: str) -> ReportRow:
    t = a["table"].sort_values(["N", "beta"])
    parts, contradicts, unsettled = [], [], []
    for r in t.itertuples():
        state = r.final_state
        tag = f"beta = {r.beta:g} (N = {r.N}): {state}"
        if state == "steady sliding" and isinstance(r.t_steady, (int, float)) and math.isfinite(r.t_steady):
            tag += f" from t = {r.t_steady:.3g}"
        elif state == "steady sliding" and isinstance(r.t_last_event, (int, float)):
            tag += f" at the end (last event ended at t = {r.t_last_event:.3g})"
        parts.append(tag)
        if r.beta <= 1.0 and state != "stick-slip":
            contradicts.append(r.beta)
        if r.beta > 1.0 and state != "steady sliding":
            t_run = float(o.experiment.options["t_end_by_N"][str(int(r.N))])
            unsettled.append(f"{r.beta:g} (N = {r.N}, t = {_g(t_run)})")
    if mode == "smoke":
        agrees, reason = None, "smoke run: tiny chains"
    elif contradicts:
        agrees, reason = False, ""
    elif unsettled:
        agrees = None
        reason = (f"beta = {', '.join(unsettled)} has not settled into steady sliding by the end of its run; "
                  "the paper reaches steady sliding 'after a long run'")
    else:
        agrees, reason = True, ""
    return ReportRow(
        "sec. 3", "final state of the chain from the paper's initial state",
        "steady sliding for beta > 1, stick-slip for beta <= 1", "; ".join(parts), agrees,
        "every run at beta <= 1 stick-slips in its second half; every run at beta > 1 slides steadily at the end",
        _sweep_command(o, mode), na_reason=reason,
        note=f"runs at beta > {_g(o.experiment.options['until_steady_above'])} stop once every block slides within "
             f"{_g(o.experiment.options['until_steady'])} of steady sliding (v, theta and spring extensions); "
             "from there on nothing changes")


def _chain_rows(o: Outcome, a: dict[str, Any], mode: str) -> list[ReportRow]:
    """Rows of section 3 and Figs. 5-8 from the chain runs."""
    from stickslip.physics import chain_steady_state

    rows = [_final_state_row(o, a, mode)]
    smoke = mode == "smoke"
    def quick_reason(events: pd.DataFrame) -> str:
        return (f"quick run: N = {a['figure_N']} to t = {_g(a['t_fig'])} ({len(events)} events in the second half), "
                "the paper: N = 399 to t = 2e7")

    # Fig. 5(a)
    run = a["run1"]
    snap = run.snapshots.isel(time=-1)
    t = float(snap["time"])
    ss = chain_steady_state(run.params, t)["x"]
    L_ss = float(run.summary["L_steady"])
    dev = float(np.max(np.abs(snap.values - ss))) / L_ss
    rows.append(ReportRow(
        "Fig. 5(a)", f"snapshot of x_i at beta = 1 against steady sliding (t = {t:.3g}, N = {run.params.N})",
        "close to the steady sliding profile", f"max_i |x_i - x_i^ss| = {100 * dev:.2f}% of L_ss = {L_ss:.5g}",
        None if smoke else dev <= 0.05, "max_i |x_i - x_i^ss| <= 5% of L_ss",
        _chain_command(o, run.params.N, 1.0), na_reason="smoke run: tiny chain" if smoke else ""))
    # Fig. 5(b)
    sw = _sweep_table(a)
    below = sw[sw["beta"] <= 1.0]
    ratio = below["L_mean"] / below["L_steady"]
    err = below["L_err"].fillna(0.0).to_numpy()
    L = below["L_mean"].to_numpy()
    increasing = bool(np.all(np.diff(L) > -2.0 * np.hypot(err[1:], err[:-1]))) if len(L) > 1 else False
    under = bool(np.all((below["L_mean"] < below["L_steady"] + 2 * below["L_err"].fillna(0.0))
                        .to_numpy()[below["beta"].to_numpy() < 1.0]))
    at1 = below[np.isclose(below["beta"], 1.0)]
    meets = bool(len(at1) and abs(float(at1["L_mean"].iloc[0] / at1["L_steady"].iloc[0]) - 1.0) <= 0.03)
    above = sw[sw["beta"] > 1.0]
    rows.append(ReportRow(
        "Fig. 5(b)", f"<L> against beta (N = {a['sweep_N']})", "continuous decrease below beta = 1",
        "<L>/L_ss = " + ", ".join(f"{r:.3f} (beta = {b:g})" for b, r in zip(below["beta"], ratio)),
        None if smoke else (increasing and under and meets),
        "<L> increases with beta up to 1 (within 2 sigma), stays below L_ss, and is within 3% of L_ss at beta = 1",
        _sweep_command(o, mode), na_reason="smoke run: tiny chains" if smoke else "",
        note="above beta = 1: " + (", ".join(f"<L>/L_ss = {r.L_mean / r.L_steady:.3f} at beta = {r.beta:g} "
                                             f"({r.final_state})" for r in above.itertuples()) or "no runs")))
    # Fig. 6
    fr = a["fronts"]
    c = fr["median_speed"]
    big = next((f for f, lab in zip(fr["fronts"], fr["labels"]) if lab.startswith("large")), None)
    value = (f"c = {_f(c, 3)} (median over {fr['speeds'].size} events reaching block N; quartiles "
             f"{_f(fr['quartiles'][0], 3)}-{_f(fr['quartiles'][1], 3)})")
    if big is not None:
        value += f"; the large event of the figure: {big.speed:.3g} ± {big.speed_err:.2g}"
    settled = mode == "full" and math.isfinite(c)
    rows.append(ReportRow(
        "Fig. 6", "rupture front speed in large events, beta = 1", "c = 1.43 (sound speed sqrt(K) = 3.16)",
        value, (abs(c - PAPER["front_speed"]) <= 0.15 and c < math.sqrt(10.0)) if settled else None,
        "|c - 1.43| <= 0.15 and c < sqrt(K)", _chain_command(o, a["figure_N"], 1.0),
        na_reason="" if settled else ("no event reached block N" if not math.isfinite(c) else
                                      ("smoke run: tiny chain" if smoke else quick_reason(a["events1"]))),
        note="speed of the leading edge fitted over the far half of the blocks an event reached"))
    # Fig. 7
    s1 = a["sizes1"]
    if s1 is None:
        rows.append(ReportRow("Fig. 7", "slip-size distribution, beta = 1",
                              "power law, exponent about 1.5, cut off by N", None, None, "|tau - 1.5| <= 0.1",
                              _chain_command(o, a["figure_N"], 1.0), na_reason="too few events"))
    else:
        fit = s1["fit"]
        rows.append(ReportRow(
            "Fig. 7", "slip-size distribution, beta = 1", "power law, exponent about 1.5, cut off by N",
            f"tau = {fit.tau:.2f} ± {fit.tau_err:.2f} on S in [{fit.s_min:.3g}, {fit.s_max:.3g}] ({fit.n} events); "
            f"largest S = {s1['S_max']:.3g}, {'reached' if s1['largest_reaches_N'] else 'did not reach'} block N "
            f"({s1['n_spanning']} events reached it)",
            (abs(fit.tau - PAPER["tau_beta1"]) <= 0.1 and s1["largest_reaches_N"]) if mode == "full" else None,
            "|tau - 1.5| <= 0.1 and the largest events span the chain", _chain_command(o, a["figure_N"], 1.0),
            na_reason="" if mode == "full" else ("smoke run: tiny chain" if smoke else quick_reason(a["events1"])),
            note="maximum likelihood for a power law truncated to the fit range; s_min by least KS distance; "
                 "error: bootstrap"))
    # Fig. 8
    s2 = a["sizes02"]
    if s2 is None:
        rows.append(ReportRow("Fig. 8", "slip-size distribution, beta = 0.2", "about 1.6 for small S, excess of "
                              "large events", None, None, "|tau - 1.6| <= 0.15 and excess >= 2",
                              _chain_command(o, a["figure_N"], 0.2), na_reason="too few events"))
    else:
        fit = s2["fit"]
        ex = s2["excess"]
        ex1 = a["sizes1"]["excess"] if a["sizes1"] else math.nan
        rows.append(ReportRow(
            "Fig. 8", "slip-size distribution, beta = 0.2", "about 1.6 for small S, excess of large events",
            f"tau = {fit.tau:.2f} ± {fit.tau_err:.2f} on S in [{fit.s_min:.3g}, {fit.s_max:.3g}] ({fit.n} events); "
            f"events with S >= {_f(s2['s_span'], 3)}: {_f(ex, 3)} times the power law's count",
            (abs(fit.tau - PAPER["tau_beta02"]) <= 0.15 and ex >= 2.0) if mode == "full" else None,
            "|tau - 1.6| <= 0.15 and at least twice the power law's count of large events",
            _chain_command(o, a["figure_N"], 0.2),
            na_reason="" if mode == "full" else ("smoke run: tiny chain" if smoke else quick_reason(a["events02"])),
            note=f"large: S at least that of the smallest event that reached block N; the same ratio at beta = 1 is "
                 f"{_f(ex1, 3)}"))
    return rows


def report_rows(outcomes: dict[str, Outcome], analysis: dict[str, Any] | None, mode: str) -> list[ReportRow]:
    """One :class:`~stickslip.report.ReportRow` per number of MODEL.md's last table (eq. 3 gives two)."""
    rows = _section2_rows(outcomes)
    if analysis is not None:
        chain_rows = _chain_rows(outcomes["chain-runs"], analysis, mode)
        # report order of MODEL.md: sec. 2 rows, eq. 3, Fig. 3, Fig. 4, sec. 3, Figs. 5-8
        rows += chain_rows
    return rows


# ---------------------------------------------------------------------------------------------
# The driver


def reproduce(
    out_dir: str | Path,
    mode: str = "quick",
    *,
    scheduler: str | None = None,
    n_workers: int | None = None,
    progress: bool = True,
) -> dict[str, Any]:
    """Reproduce the paper's Figs. 1-8 and stated numbers into ``out_dir`` (``stickslip reproduce``).

    Runs (or reuses) every experiment of ``mode`` (:func:`stickslip.experiments.experiments`),
    draws every figure as PNG and PDF with its data, and writes ``report.json`` and
    ``report.html`` with one row per number of MODEL.md's last table. Chain runs go through
    :func:`stickslip.sweep.run_sweep` on a local Dask cluster (``n_workers`` processes, default
    one per core) or on the cluster at ``scheduler``. Progress goes to stderr when ``progress``.
    Returns what the command prints: mode, paths, the rows, the figures, and per experiment
    whether it was reused and how long it took.
    """
    start = time.perf_counter()
    specs = experiments(mode)
    out = Path(out_dir)
    runs = out / "runs"
    log = _Log(progress)
    outcomes: dict[str, Outcome] = {}
    for i, exp in enumerate(specs, 1):
        head = f"({i}/{len(specs)}) {exp.name} [{', '.join(exp.figures) or 'numbers'}]"
        stored = _stored(runs / exp.dirname, exp) is not None
        log(f"{head}: {'stored result, reusing' if stored else 'computing'} in runs/{exp.dirname}")
        outcome = run_experiment(exp, runs, scheduler=scheduler, n_workers=n_workers, log=log)
        if not outcome.reused:
            log(f"{head}: done in {time.perf_counter() - start:.1f} s since start "
                f"({outcome.wall_seconds:.1f} s for this experiment)")
        outcomes[exp.name] = outcome
    log("analysing the chain runs")
    analysis = chain_analysis(outcomes["chain-runs"]) if "chain-runs" in outcomes else None
    log("drawing figures")
    figures, not_drawn = draw_figures(outcomes, analysis, out, mode, log=log)
    rows = report_rows(outcomes, analysis, mode)
    wall = time.perf_counter() - start
    io.write_json(out / "experiments.json", [
        {**oc.experiment.to_dict(), "run_dir": f"runs/{oc.experiment.dirname}", "reused": oc.reused,
         "compute_seconds": oc.wall_seconds}
        for oc in outcomes.values()
    ])
    meta = {
        "mode": mode,
        "command": f"stickslip reproduce --{mode} --out {out}",
        "wall_seconds": round(wall, 1),
        "compute_seconds": round(sum(oc.wall_seconds for oc in outcomes.values()), 1),
        "experiments": [
            f"{oc.experiment.name}: runs/{oc.experiment.dirname}, "
            + (f"reused (computed in {oc.wall_seconds:.1f} s)" if oc.reused else f"computed in {oc.wall_seconds:.1f} s")
            for oc in outcomes.values()
        ],
        "specs": "experiments.json",
        "notes": [oc.experiment.note for oc in outcomes.values() if oc.experiment.note],
    }
    if not_drawn:
        meta["figures_not_drawn"] = not_drawn
    paths = write_report(out, rows, figures, meta)
    log(f"report: {paths['html']} ({wall:.1f} s)")
    return {
        "mode": mode,
        "out": str(out),
        "report_json": str(paths["json"]),
        "report_html": str(paths["html"]),
        "wall_seconds": wall,
        "rows": [r.to_dict() for r in rows],
        "figures": [f.to_dict() for f in figures],
        "figures_not_drawn": not_drawn,
        "experiments": [{"name": oc.experiment.name, "run_dir": str(oc.run_dir), "reused": oc.reused,
                         "compute_seconds": oc.wall_seconds} for oc in outcomes.values()],
    }
