"""Reproduce the paper: run every experiment, draw every figure, compare every stated number.

:func:`reproduce` takes the spec set of a mode (:func:`stickslip.experiments.specs.experiments`) and,
for each experiment, either loads its stored result or computes it, then draws the figures and
writes the report (:mod:`stickslip.report.writer`). Layout of the output directory::

    DIR/
      runs/<name>-<key>/      one directory per experiment (key: hash of its spec and the
                              package version); ``result.json`` is written last and marks it done
      runs/chain-runs-<key>/points/beta=1_N=199/ ...
                              one chain run per point (run.json, state.nc, events.parquet,
                              first_move.parquet, checkpoint/), run on Dask by
                              :func:`stickslip.experiments.sweep.run_sweep`
      figures/<stem>.png|.pdf one image per figure of the paper, and the data drawn beside it
      report.json, report.html

A second call with the same mode finds every ``result.json`` and only redraws. A chain run
that was interrupted continues from its last checkpoint (:func:`stickslip.run.driver.resume_chain`);
finished chain runs are kept by the sweep's own ``done.json`` records, so adding a value of
beta to a spec only runs the new point.

This module holds the runners (one per kind of experiment) and the driver; they use the model
code (:mod:`stickslip.run`, :mod:`stickslip.analysis`). The analysis of the chain runs is
:mod:`stickslip.analysis.chain_runs`, the figures :mod:`stickslip.plotting.figures`, the rows
of stated numbers :mod:`stickslip.report.rows`.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from stickslip import heartbeat, io
from stickslip.analysis.chain_runs import chain_analysis, final_state
from stickslip.experiments.cache import damage, file_digests, read_record, sealed
from stickslip.experiments.specs import Experiment, experiments
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
    "chain_point_task",
    "report_rows",
    "ReproduceError",
    "RESULT_FILE",
]

RESULT_FILE = "result.json"


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
# Running experiments (with reuse)


def _stored(run_dir: Path, exp: Experiment, log: Callable[[str], None] | None = None) -> dict[str, Any] | None:
    """The stored ``result.json`` of ``exp`` if it is there, made from the same spec, as written
    (sealed) and with every file it recorded present with its checksum; else None, and a line on
    ``log`` saying why a record of this spec is not reused."""
    record = read_record(run_dir / RESULT_FILE, exp.spec())
    if record is None:
        return None
    reason = damage(run_dir, record)
    if reason:
        if log is not None:
            log(f"{exp.name}: not reused, {reason}: running it again")
        return None
    return record


def run_experiment(
    exp: Experiment,
    runs_dir: str | Path,
    *,
    scheduler: str | None = None,
    n_workers: int | None = None,
    log: Callable[[str], None] | None = None,
) -> Outcome:
    """Compute one experiment into ``runs_dir/<name>-<key>/``, or load it if already there.

    The stored result is reused only if its ``result.json`` holds the same spec (kind,
    parameters, run length, options, package version), is as written and every file it recorded
    matches its checksum (:func:`stickslip.experiments.cache.damage`). Chain runs go to Dask
    (``scheduler`` address, or a local cluster of ``n_workers`` processes).
    """
    log = log or (lambda text: None)
    runner = _RUNNERS[exp.kind]
    run_dir = Path(runs_dir) / exp.dirname
    record = _stored(run_dir, exp, log)
    reused = record is not None
    if record is None:
        run_dir.mkdir(parents=True, exist_ok=True)
        (run_dir / RESULT_FILE).unlink(missing_ok=True)
        start = time.perf_counter()
        summary = runner.compute(exp, run_dir, scheduler=scheduler, n_workers=n_workers, log=log)
        record = {"spec": exp.spec(), "name": exp.name, "summary": summary, "wall_seconds": time.perf_counter() - start}
        record = sealed({**record, "files": file_digests(run_dir)})
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


def _compute_slip_limit(exp: Experiment, run_dir: Path, **_: Any) -> dict[str, Any]:
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


def _compute_period_sweep(exp: Experiment, run_dir: Path, **_: Any) -> dict[str, Any]:
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


def _load_period_sweep(exp: Experiment, run_dir: Path, summary: dict[str, Any]) -> dict[str, Any]:
    return {"table": io.read_table(run_dir / "periods.parquet")}


# --- block_stability: eq. (2) ----------------------------------------------------------------


def _compute_block_stability(exp: Experiment, run_dir: Path, **_: Any) -> dict[str, Any]:
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


def _load_block_stability(exp: Experiment, run_dir: Path, summary: dict[str, Any]) -> dict[str, Any]:
    return {"map": io.read_dataset(run_dir / "stability_map.nc")}


# --- hysteresis: section 2 -------------------------------------------------------------------


def _compute_hysteresis(exp: Experiment, run_dir: Path, **_: Any) -> dict[str, Any]:
    """V raised slowly and lowered again for the single block (the inverse transition, sec. 2)."""
    from stickslip.analysis import hysteresis as hy

    result = hy.hysteresis_sweep(BlockParams(**exp.params), hy.SweepSettings(**exp.options))
    io.write_dataset(run_dir / "hysteresis.nc", result.data)
    return result.summary()


def _load_hysteresis(exp: Experiment, run_dir: Path, summary: dict[str, Any]) -> dict[str, Any]:
    return {"data": io.read_dataset(run_dir / "hysteresis.nc")}


# --- chain_modes: eq. (5), Fig. 4 ------------------------------------------------------------


def _compute_chain_modes(exp: Experiment, run_dir: Path, **_: Any) -> dict[str, Any]:
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


def _load_chain_modes(exp: Experiment, run_dir: Path, summary: dict[str, Any]) -> dict[str, Any]:
    return {"modes": io.read_dataset(run_dir / "fig4.nc")}


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
    from stickslip.analysis.statistics import time_average
    from stickslip.experiments.sweep import run_chain_point

    params, t_end, options = _point_settings(point)
    run = run_chain_point(params, t_end, point_dir, **options)
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
    s["final_state"], s["steady_deviation_final"] = final_state(s, run.state, params, UNTIL_STEADY)
    s["t_end_requested"] = t_end
    return s


def _compute_chain_runs(exp: Experiment, run_dir: Path, *, scheduler=None, n_workers=None, log=None) -> dict[str, Any]:
    """All chain runs of the experiment as one Dask sweep (Figs. 5-8)."""
    from stickslip.experiments.sweep import STOP_WAIT_SECONDS, run_sweep

    points = [dict(p) for p in exp.options["points"]]
    common = _chain_common(exp)
    for p in points:  # validate every point before any work starts
        _point_settings({**common, **p})
    if log:
        log(
            f"chain runs: {len(points)} points on Dask "
            f"({'scheduler ' + scheduler if scheduler else 'local cluster'}); finished points are reused"
        )
    result = run_sweep(
        chain_point_task,
        points,
        run_dir / "points",
        common=common,
        scheduler=scheduler,
        n_workers=n_workers,
        stop_wait=STOP_WAIT_SECONDS,
        progress=bool(getattr(log, "enabled", False)),
    )
    failed = result.table[result.table["status"] != "ok"]
    if len(failed):
        lines = "; ".join(f"{r.point_dir}: {r.error}" for r in failed.itertuples())
        raise ReproduceError(f"{len(failed)} chain run(s) failed ({lines}); run again to retry them")
    return {"points": _records(result.table), "n_run": result.n_run, "n_reused": result.n_reused}


def _records(table: pd.DataFrame) -> list[dict[str, Any]]:
    return table.astype(object).where(table.notna(), None).to_dict(orient="records")


def _load_chain_runs(exp: Experiment, run_dir: Path, summary: dict[str, Any]) -> dict[str, Any]:
    from stickslip.experiments.sweep import point_name
    from stickslip.run import driver as chain

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
        state, deviation = final_state(r._asdict(), get(r.N, r.beta).state, p, UNTIL_STEADY)
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
    ``report.html`` with one row per number of docs/model.md's last table. Chain runs go through
    :func:`stickslip.experiments.sweep.run_sweep` on a local Dask cluster (``n_workers`` processes, default
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
            log(
                f"{head}: done in {time.perf_counter() - start:.1f} s since start "
                f"({outcome.wall_seconds:.1f} s for this experiment)"
            )
        outcomes[exp.name] = outcome
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
