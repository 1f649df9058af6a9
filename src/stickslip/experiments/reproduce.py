"""Reproduce the paper: run every experiment, draw every figure, compare every stated number.

:func:`reproduce` takes the spec set of a mode (:func:`stickslip.experiments.specs.experiments`),
runs each experiment as a point of :func:`stickslip.experiments.sweep.run_sweep` (the runner of the
studies too: its cache, resume and Dask), loads the results, draws the figures and writes the
report (:mod:`stickslip.report.writer`). Layout of the output directory::

    DIR/
      runs/<name>-<key>/      one directory per experiment (key: hash of its spec and the
                              package version); the sweep's ``done.json`` is written last
      runs/chain-runs-<key>/points/beta=1_N=199/ ...
                              one chain run per point (run.json, state.nc, events.parquet,
                              first_move.parquet, checkpoint/)
      runs/summary.parquet    the sweep of the experiments of sections 2 and Fig. 4
      figures/<stem>.png|.pdf one image per figure of the paper, and the data drawn beside it
      report.json, report.html

A second call with the same mode finds every ``done.json`` and only redraws. A chain run that
was interrupted continues from its last checkpoint (:func:`stickslip.run.driver.resume_chain`);
adding a value of beta to a spec only runs the new point.

This module holds the runners (one per kind of experiment) and the driver; they use the model
code (:mod:`stickslip.run`, :mod:`stickslip.analysis`). The analysis of the chain runs is
:mod:`stickslip.analysis.chain_runs`, the figures :mod:`stickslip.plotting.figures`, the rows
of stated numbers :mod:`stickslip.report.rows`.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from stickslip import heartbeat, io
from stickslip.analysis.chain_runs import chain_analysis
from stickslip.experiments.specs import Experiment, experiments
from stickslip.jsonable import table_records
from stickslip.models.params import BlockParams, ChainParams
from stickslip.models.physics import UNTIL_STEADY
from stickslip.outcome import Outcome
from stickslip.outcome import chain_common as _chain_common
from stickslip.outcome import point_settings as _point_settings
from stickslip.plotting.figures import draw_figures
from stickslip.report.rows import report_rows
from stickslip.report.writer import write_report

__all__ = [
    "reproduce",
    "run_experiment",
    "run_experiments",
    "experiment_task",
    "chain_point_task",
    "report_rows",
    "ReproduceError",
]


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
        heartbeat.note(text)
        if self.enabled:
            sys.stderr.write(f"[reproduce {time.perf_counter() - self.t0:6.1f} s] {text}\n")
            sys.stderr.flush()


# ---------------------------------------------------------------------------------------------
# Running experiments (with reuse): every one a point of a sweep (run_sweep)


def run_experiments(
    exps: list[Experiment],
    runs_dir: str | Path,
    *,
    scheduler: str | None = None,
    n_workers: int | None = None,
    log: Callable[[str], None] | None = None,
) -> dict[str, Outcome]:
    """Compute the experiments into ``runs_dir``, or load those already there: each one a point of
    :func:`stickslip.experiments.sweep.run_sweep` (its cache, resume and Dask).

    The experiments of sections 2 and Fig. 4 are the points of one sweep over ``runs_dir``, each
    in ``<name>-<key>/``; the chain runs of Figs. 5-8 are the points of a sweep of their own in
    ``chain-runs-<key>/points/``. A point is reused only if its ``done.json`` holds the same spec
    (kind, parameters, run length, options, package version), is as written and every file it
    recorded matches its checksum (:func:`stickslip.experiments.cache.damage`).

    Parameters
    ----------
    exps : list of Experiment
        The experiments (:func:`stickslip.experiments.specs.experiments`).
    runs_dir : str or Path
        The runs folder of the reproduction.
    scheduler : str, optional
        Address of an existing Dask scheduler; else a local cluster of ``n_workers`` processes.
    n_workers : int, optional
        Worker processes of the local cluster (default one per core).
    log : callable, optional
        Takes the progress lines.

    Returns
    -------
    dict
        The :class:`~stickslip.outcome.Outcome` of each experiment by its name, in the order given.
    """
    from stickslip.experiments.sweep import DONE_FILE

    log = log or (lambda text: None)
    runs = Path(runs_dir)
    kw = {"scheduler": scheduler, "n_workers": n_workers, "log": log}
    single = [e for e in exps if e.kind != "chain_runs"]
    outcomes: dict[str, Outcome] = {}
    if single:
        points = [{k: v for k, v in e.spec().items() if k != "version"} for e in single]
        table = _sweep(experiment_task, points, runs, names=[e.dirname for e in single], **kw)
        for exp, row in zip(single, table.itertuples(), strict=True):
            summary = io.read_json(runs / exp.dirname / DONE_FILE)["summary"]
            data = _RUNNERS[exp.kind].load(exp, runs / exp.dirname, summary)
            outcomes[exp.name] = Outcome(exp, runs / exp.dirname, data, summary, bool(row.reused), row.wall_seconds)
    for exp in exps:
        if exp.kind == "chain_runs":
            outcomes[exp.name] = _chain_runs(exp, runs / exp.dirname, **kw)
    return {e.name: outcomes[e.name] for e in exps}


def run_experiment(exp: Experiment, runs_dir: str | Path, **options: Any) -> Outcome:
    """Compute one experiment into ``runs_dir/<name>-<key>/``, or load it if already there.

    Parameters
    ----------
    exp : Experiment
        The experiment.
    runs_dir : str or Path
        The runs folder.
    **options
        ``scheduler``, ``n_workers`` and ``log`` of :func:`run_experiments`.

    Returns
    -------
    Outcome
        Its result, loaded.
    """
    return run_experiments([exp], runs_dir, **options)[exp.name]


def experiment_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """One experiment of sections 2 and Fig. 4 (``point``: its spec less the package version), as
    a task of :func:`stickslip.experiments.sweep.run_sweep`: its runner computes it into
    ``point_dir`` and returns its summary."""
    exp = Experiment(point_dir.name, point["kind"], point["params"], point["t_end"], point["options"])
    return _RUNNERS[exp.kind].compute(exp, point_dir)


def _sweep(task: Callable[..., dict[str, Any]], points: list[dict[str, Any]], out: Path, *, log, **kw) -> pd.DataFrame:
    """``run_sweep`` of ``points``, the reused ones and those run again because damaged said on
    ``log``; a failed point raises ReproduceError."""
    from stickslip.experiments.sweep import STOP_WAIT_SECONDS, run_sweep

    show = bool(getattr(log, "enabled", False))
    result = run_sweep(task, points, out, stop_wait=STOP_WAIT_SECONDS, progress=show, **kw)
    table = result.table
    for r in table.itertuples():
        state = f"not reused, {r.note}" if isinstance(getattr(r, "note", None), str) else None
        state = state or ("reused" if r.reused else f"computed in {r.wall_seconds:.1f} s")
        log(f"{r.point_dir}: {state}")
    failed = table[table["status"] != "ok"]
    if len(failed):
        lines = "; ".join(f"{r.point_dir}: {r.error}" for r in failed.itertuples())
        raise ReproduceError(f"{len(failed)} run(s) failed ({lines}); run again to retry them")
    return table


@dataclass(frozen=True)
class _Runner:
    compute: Callable[..., dict[str, Any]]
    load: Callable[[Experiment, Path, dict[str, Any]], dict[str, Any]]


def _reads(key: str, file: str) -> Callable[[Experiment, Path, dict[str, Any]], dict[str, Any]]:
    """The loader of an experiment whose result is one file of its folder: ``{key: its data}``."""
    read = io.read_table if file.endswith(".parquet") else io.read_dataset
    return lambda exp, run_dir, summary: {key: read(run_dir / file)}


# --- block_run: eq. (1), Figs. 1 and 2 -------------------------------------------------------


def _compute_block_run(exp: Experiment, run_dir: Path) -> dict[str, Any]:
    """Eq. (1) at the paper's parameters with every step stored (Figs. 1, 2)."""
    from stickslip.run.block import simulate_block

    run = simulate_block(BlockParams(**exp.params), exp.t_end, every=1)
    io.write_dataset(run_dir / "series.nc", run.series)
    io.write_table_files(run_dir / "slips", run.slips)
    f = run.final
    return {**run.summary(), "final": {"x": f.x, "v": f.v, "theta": f.theta, "stopped": f.stopped}}


def _load_block_run(exp: Experiment, run_dir: Path, summary: dict[str, Any]) -> dict[str, Any]:
    from stickslip.run.block import BlockRun, BlockState

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


def _compute_slip_limit(exp: Experiment, run_dir: Path) -> dict[str, Any]:
    """Eq. (3) accurately (DOP853, event v = 0) and with the Heun step of the paper."""
    from stickslip.analysis.slip_limit import heun_slip_limit, solve_slip_limit

    p = BlockParams(**exp.params)
    law = solve_slip_limit(p, rtol=exp.options["rtol"], atol=exp.options["atol"])
    heun = heun_slip_limit(p)
    io.write_dataset(run_dir / "curve.nc", law.curve)
    return {**law.summary(), "heun_duration": heun.duration, "heun_force_at_stop": heun.force_at_stop, "heun_dt": p.dt}


def _load_slip_limit(exp: Experiment, run_dir: Path, summary: dict[str, Any]) -> dict[str, Any]:
    from stickslip.analysis.slip_limit import SlipLimit

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


def _compute_period_sweep(exp: Experiment, run_dir: Path) -> dict[str, Any]:
    """Simulated stick-slip period at log-spaced V (Fig. 3)."""
    from stickslip.analysis.slip_limit import paper_V_values, period_sweep

    o = exp.options
    table = period_sweep(
        BlockParams(**exp.params), paper_V_values(o["n"], o["V_min"], o["V_max"]), periods=o["periods"]
    )
    io.write_table_files(run_dir / "periods", table)
    return {
        "max_abs_rel_dev": float(np.nanmax(np.abs(table["rel_dev"]))),
        "n_V": int(len(table)),
        "V": table["V"].tolist(),
        "rel_dev": table["rel_dev"].tolist(),
    }


# --- block_stability: eq. (2) ----------------------------------------------------------------


def _compute_block_stability(exp: Experiment, run_dir: Path) -> dict[str, Any]:
    """Hopf point at the spec's beta, stability for all V at ``beta_stable``, the stability map."""
    from stickslip.analysis import stability as st

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


# --- hysteresis: section 2 -------------------------------------------------------------------


def _compute_hysteresis(exp: Experiment, run_dir: Path) -> dict[str, Any]:
    """V raised slowly and lowered again for the single block (the inverse transition, sec. 2)."""
    from stickslip.analysis import hysteresis as hy

    result = hy.hysteresis_sweep(BlockParams(**exp.params), hy.SweepSettings(**exp.options))
    io.write_dataset(run_dir / "hysteresis.nc", result.data)
    return result.summary()


# --- chain_modes: eq. (5), Fig. 4 ------------------------------------------------------------


def _compute_chain_modes(exp: Experiment, run_dir: Path) -> dict[str, Any]:
    """Fourier modes of the linearised chain at the betas of Fig. 4, and the critical beta."""
    from stickslip.analysis import stability as st

    p = ChainParams(**exp.params)
    betas = [float(b) for b in exp.options["betas"]]
    ds = st.fig4_data(p, betas=betas, k=np.linspace(0.0, np.pi, int(exp.options["n_k"])))
    io.write_dataset(run_dir / "fig4.nc", ds)
    per_beta = []
    for b in betas:
        s = st.chain_stability(p.replace(beta=b))
        per_beta.append(
            {
                "beta": b,
                "max_growth_rate": s.max_growth_rate,
                "k_at_max": s.k_at_max,
                "unstable": s.unstable,
                "marginal": s.marginal,
            }
        )
    return {
        "critical_beta": st.chain_critical_beta(p),
        "critical_beta_numeric": st.chain_critical_beta_numeric(p),
        "per_beta": per_beta,
    }


# --- chain_runs: eq. (4), Figs. 5-8, on Dask -------------------------------------------------


def chain_point_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """One chain run of eq. (4) for Figs. 5-8, as a task of :func:`stickslip.experiments.sweep.run_sweep`.

    ``point`` holds N and beta merged with the experiment's common settings (see
    :func:`stickslip.experiments.specs.experiments`). Runs at beta above ``until_steady_above`` stop
    once the chain slides steadily; the runs at N = ``profile_N`` and beta in ``profile_betas``
    also store the displacement over windows of ``profile_window`` for Fig. 6. The run
    checkpoints into ``point_dir``, continues from a checkpoint there, and checkpoints and stops
    when the reproduction is interrupted (:func:`stickslip.experiments.sweep.run_chain_point`).
    Returns the run's summary with <L> and its batch-means error (Fig. 5b) and the final state
    ("steady sliding" or "stick-slip", section 3).
    """
    from stickslip.analysis.chain_runs import run_summary
    from stickslip.experiments.sweep import run_chain_point

    params, t_end, options = _point_settings(point)
    run = run_chain_point(params, t_end, point_dir, **options)
    return {**run_summary(run, params, options["average_from"], UNTIL_STEADY), "t_end_requested": t_end}


def _chain_runs(exp: Experiment, run_dir: Path, *, log, **kw: Any) -> Outcome:
    """All chain runs of the experiment as one Dask sweep (Figs. 5-8), loaded."""
    points = [dict(p) for p in exp.options["points"]]
    common = _chain_common(exp)
    for p in points:  # validate every point before any work starts
        _point_settings({**common, **p})
    log(f"chain runs: {len(points)} points on Dask ({kw['scheduler'] or 'local cluster'}); finished points are reused")
    table = _sweep(chain_point_task, points, run_dir / "points", common=common, log=log, **kw)
    # as the table was read back from JSON when a record of the experiment held it; the final
    # state of each run is its task's (analysis.chain_runs.run_summary)
    summary = {"points": table_records(table)}
    table = pd.DataFrame(summary["points"])
    cache: dict[tuple[int, float], Any] = {}

    def get(N: int, beta: float):
        """The full run at (N, beta), read from its directory when first asked for."""
        from stickslip.experiments.sweep import point_name
        from stickslip.run.driver import load_run

        key = (int(N), float(beta))
        if key not in cache:
            cache[key] = load_run(run_dir / "points" / point_name({"N": int(N), "beta": float(beta)}))
        return cache[key]

    wall = float(np.nansum(table["wall_seconds"].to_numpy(dtype=float)))
    return Outcome(exp, run_dir, {"table": table, "run": get}, summary, bool(table["reused"].all()), wall)


_RUNNERS: dict[str, _Runner] = {
    "block_run": _Runner(_compute_block_run, _load_block_run),
    "slip_limit": _Runner(_compute_slip_limit, _load_slip_limit),
    "period_sweep": _Runner(_compute_period_sweep, _reads("table", "periods.parquet")),
    "block_stability": _Runner(_compute_block_stability, _reads("map", "stability_map.nc")),
    "hysteresis": _Runner(_compute_hysteresis, _reads("data", "hysteresis.nc")),
    "chain_modes": _Runner(_compute_chain_modes, _reads("modes", "fig4.nc")),
}


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

    Runs (or reuses) every experiment of ``mode`` (:func:`stickslip.experiments.specs.experiments`),
    draws every figure as PNG and PDF with its data, and writes ``report.json`` and
    ``report.html`` with one row per number of docs/model.md's last table. The experiments are
    points of :func:`stickslip.experiments.sweep.run_sweep` (:func:`run_experiments`) on a local
    Dask cluster (``n_workers`` processes, default one per core) or on the cluster at
    ``scheduler``. Progress goes to stderr when ``progress``. Returns what the command prints:
    mode, paths, the rows, the figures, and per experiment whether it was reused and how long it
    took.
    """
    start = time.perf_counter()
    specs = experiments(mode)
    out = Path(out_dir)
    runs = out / "runs"
    log = _Log(progress)
    log(f"{len(specs)} experiments in {runs}; finished ones are reused")
    outcomes = run_experiments(specs, runs, scheduler=scheduler, n_workers=n_workers, log=log)
    log("analysing the chain runs")
    analysis = chain_analysis(outcomes["chain-runs"]) if "chain-runs" in outcomes else None
    log("drawing figures")
    figures, not_drawn = draw_figures(outcomes, analysis, out, mode, log=log)
    rows = report_rows(outcomes, analysis, mode)
    wall = time.perf_counter() - start
    io.write_json(
        out / "experiments.json",
        [
            {
                **oc.experiment.to_dict(),
                "run_dir": f"runs/{oc.experiment.dirname}",
                "reused": oc.reused,
                "compute_seconds": oc.wall_seconds,
            }
            for oc in outcomes.values()
        ],
    )
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
        "experiments": [
            {
                "name": oc.experiment.name,
                "run_dir": str(oc.run_dir),
                "reused": oc.reused,
                "compute_seconds": oc.wall_seconds,
            }
            for oc in outcomes.values()
        ],
    }
