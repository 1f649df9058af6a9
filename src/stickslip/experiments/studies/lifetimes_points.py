"""The points of ``stickslip study lifetimes`` (:mod:`stickslip.experiments.studies.lifetimes`):
one start run until its slips repeat (``measure`` ``lifetime``, the default), or the flow's
exponent and the decorrelation threshold of one model at one N and beta (``measure``
``exponent``), for the paper's chain (eq. 4) and its relatives (two blocks, Carlson-Langer, the
train model).

Starts (:func:`start_state`):

- ``paper``: the paper's start (x = 0, v = 0.1, theta = 0.1), every x_i moved by a uniform draw
  in [-A, A] (``perturbation`` A, ``seed``); the lifetime counts from t = 0;
- ``rest``: every block stuck at x_i = -A u_i, u_i uniform in [0, 1) drawn with ``seed``
  (Carlson-Langer's start, :meth:`stickslip.run.state.ChainState.rest`); from t = 0;
- ``loaded``: the model's own start (its preset's: the paper's, or at rest with the preset's
  draw) run to ``load_t`` (default twice the loading time L_ss / V,
  :func:`stickslip.models.physics.loading_time`; the plate drive loads every block at once and
  needs ``load_t``), then every x_i moved as for ``paper``; the lifetime counts from there.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any

import numpy as np

from stickslip.experiments.sweep_points import point_params

__all__ = ["STARTS", "MEASURES", "check_point", "start_state", "lifetime_point", "exponent_point", "task"]

STARTS = ("paper", "rest", "loaded")
MEASURES = ("lifetime", "exponent")


def load_time(params, cfg: dict[str, Any]) -> float:
    """The time a ``loaded`` start runs before it is perturbed: ``load_t`` of the point, else twice
    L_ss / V (:func:`stickslip.models.physics.loading_time`); NaN where neither is given."""
    from stickslip.models import physics

    if cfg.get("load_t") is not None:
        return float(cfg["load_t"])
    return 2.0 * physics.loading_time(params)


def check_point(cfg: dict[str, Any], params=None) -> None:
    """Raise ParameterError (one line) unless a point's merged settings are valid."""
    from stickslip.analysis.dynamics.benettin import check_run
    from stickslip.models.params import ParameterError, check_number

    params = point_params("chain", cfg) if params is None else params
    if params.ends_piece.wall:
        raise ParameterError("the lifetimes study restarts no clock: fixed ends (which read t) are refused")
    measure = cfg.get("measure", "lifetime")
    if measure not in MEASURES:
        raise ParameterError(f"measure must be one of {', '.join(MEASURES)} (got {measure!r})")
    if measure == "exponent":
        check_number("transient", cfg.get("transient"), low=0.0, low_open=True)
        check_number("events", cfg.get("events"), low=1, integer=True)
        check_number("windows", cfg.get("windows"), low=1, integer=True)
        for d in cfg.get("deltas") or []:
            check_number("delta", d, low=0.0, low_open=True, high=1.0)
        if not cfg.get("deltas"):
            raise ParameterError("an exponent point needs deltas (the decorrelation's perturbations)")
        interval, d0 = float(cfg.get("interval", 10.0)), float(cfg.get("d0", 1e-8))
        check_run(params, float(cfg.get("flow_t", 0.0)), interval, d0, 0.0, None, 10)
        return
    if cfg.get("start") not in STARTS:
        raise ParameterError(f"start must be one of {', '.join(STARTS)} (got {cfg.get('start')!r})")
    check_number("budget", cfg.get("budget"), low=0.0, low_open=True)
    check_number("perturbation", cfg.get("perturbation", 0.0), low=0.0, high=1.0)
    check_number("seed", cfg.get("seed", 0), low=0, integer=True)
    if cfg["start"] == "loaded" and not math.isfinite(load_time(params, cfg)):
        raise ParameterError("a loaded start of this model needs load_t > 0 (it has no loading time L_ss / V)")
    if cfg.get("load_t") is not None:
        check_number("load_t", cfg["load_t"], low=0.0, low_open=True)


def start_state(params, start: str, amplitude: float, seed: int, stop_requested=None, *, load_t: float | None = None):
    """The state a point starts from (module docstring): the paper's start with every x_i moved by
    a uniform draw in [-amplitude, amplitude] (numpy's Generator seeded with ``seed``), the rest
    start drawn with ``amplitude`` and ``seed``, or the model's own start run to ``load_t``
    (default twice L_ss / V) and then moved as the paper's."""
    from stickslip.models.presets import PRESETS
    from stickslip.run.driver import run_chain
    from stickslip.run.errors import short_runs_expected
    from stickslip.run.state import ChainState

    if start == "rest":
        return ChainState.rest(params, amplitude, seed)
    state = ChainState.paper(params)
    if start == "loaded":
        t_load = load_time(params, {"load_t": load_t})
        own = PRESETS[params.model]
        first: str | ChainState = "paper"
        if own.start == "rest":
            first = ChainState.rest(params, own.start_options.get("amplitude", 0.01), own.start_options.get("seed", 0))
        with short_runs_expected():
            state = run_chain(
                params, t_load, start=first, sample_interval=t_load, progress=False, stop_requested=stop_requested
            ).state
    state = state.copy()
    rng = np.random.default_rng(seed)
    state.x[:] += rng.uniform(-amplitude, amplitude, params.N)
    return state


def lifetime_point(cfg: dict[str, Any], params, point_dir: Path | None = None) -> dict[str, Any]:
    """One start (module docstring): its lifetime, whether it ended (on a periodic orbit or in
    steady sliding) or was censored, and the orbit's period."""
    from stickslip.analysis.stats.periodicity import PeriodicStop
    from stickslip.experiments.sweep import stop_requested
    from stickslip.run.driver import run_chain

    wall0, cpu0 = time.perf_counter(), time.process_time()
    check_point(cfg, params)
    stop = stop_requested(point_dir) if point_dir is not None else None
    amplitude = float(cfg["perturbation"])
    state = start_state(params, cfg["start"], amplitude, int(cfg["seed"]), stop, load_t=cfg.get("load_t"))
    t0 = state.step * params.dt
    hook = PeriodicStop(rtol=float(cfg["rtol"]), max_period=int(cfg["max_period"]), repeats=int(cfg["repeats"]))
    budget = float(cfg["budget"])
    run = run_chain(
        params,
        t0 + budget,
        start=state,
        hooks=[hook],
        until_steady=float(cfg["until_steady"]),
        sample_interval=max(params.dt, budget / 1000),
        progress=False,
        stop_requested=stop,
    )
    found = hook.result
    if found is not None:
        end, t_end = "periodic", found.settled_from_t
    elif run.summary.get("stopped_early"):
        end, t_end = "steady", run.summary["t_steady"]
    else:
        end, t_end = "censored", run.summary["t_reached"]
    return {
        "lifetime": float(t_end) - t0,
        "ended": end != "censored",
        "end": end,
        "period_slips": found.period_slips if found else None,
        "period_t": found.period_t if found else None,
        "settled_from_slip": found.settled_from_slip if found else None,
        "slips": int(len(run.events)),
        "t_start": t0,
        "t_reached": float(run.summary["t_reached"]) - t0,
        "budget": budget,
        "point_wall_seconds": time.perf_counter() - wall0,
        # the worker's own time: the point's cost on a machine shared with other work
        "point_cpu_seconds": time.process_time() - cpu0,
    }


def exponent_point(cfg: dict[str, Any], params, point_dir: Path | None = None) -> dict[str, Any]:
    """The flow's largest exponent and the decorrelation threshold of one model at one N and beta,
    from the engine's state at ``transient`` after the model's own start
    (:func:`stickslip.run.loaded.loaded_state`, unperturbed: the paper's start, or at rest with the
    preset's draw):

    - the exponent at the step dt by two trajectories with located switches over ``flow_t``
      (:func:`stickslip.analysis.dynamics.lyapunov_flow.flow_lyapunov`, ``interval``, d0 = ``d0``);
    - whether the engine's slips from the same state repeat within ``flow_t``
      (:class:`~stickslip.analysis.stats.periodicity.PeriodicStop`, the lifetimes' rule): an exponent of
      a periodic orbit;
    - n(delta) for perturbations of the state on the engine's map over ``windows`` windows of
      ``events`` slips (:func:`stickslip.analysis.dynamics.decorrelation.sequence_decorrelation`) and the
      bracket of delta* (:func:`stickslip.analysis.dynamics.threshold.delta_star`).
    """
    from stickslip.analysis.dynamics.decorrelation import GridSequences, sequence_decorrelation
    from stickslip.analysis.dynamics.lyapunov_flow import flow_lyapunov
    from stickslip.analysis.dynamics.threshold import delta_star
    from stickslip.analysis.stats.periodicity import PeriodicStop
    from stickslip.experiments.sweep import stop_requested
    from stickslip.experiments.sweep_points import preset_start
    from stickslip.run.driver import run_chain
    from stickslip.run.errors import short_runs_expected
    from stickslip.run.loaded import loaded_state

    wall0, cpu0 = time.perf_counter(), time.process_time()
    check_point(cfg, params)
    stop = stop_requested(point_dir) if point_dir is not None else None
    cache = Path(point_dir) / "state" if point_dir is not None else None
    own = preset_start(params, {})
    loaded = loaded_state(params, float(cfg["transient"]), **own, cache=cache, stop_requested=stop)
    flow_t = float(cfg["flow_t"])
    flow = flow_lyapunov(
        params,
        flow_t,
        start=loaded.located(params),
        interval=float(cfg.get("interval", 10.0)),
        d0=float(cfg.get("d0", 1e-8)),
        segments=10,
        stop_requested=stop,
    )
    hook = PeriodicStop(rtol=float(cfg["rtol"]), max_period=int(cfg["max_period"]), repeats=int(cfg["repeats"]))
    t0 = loaded.state.step * params.dt
    with short_runs_expected():
        run_chain(params, t0 + flow_t, start=loaded.state, hooks=[hook], progress=False, stop_requested=stop)
    rows = sequence_decorrelation(
        GridSequences(params),
        loaded.state,
        [float(d) for d in cfg["deltas"]],
        perturbation="state",
        events=int(cfg["events"]),
        seeds=int(cfg["windows"]),
    ).to_dict()["decorrelation"]
    ds = delta_star(rows)
    found = hook.result
    return {
        "lyapunov": float(flow.lyapunov),
        "lyapunov_err": float(flow.lyapunov_err),
        "flow_dt": float(params.dt),
        "flow_slips": int(flow.events),
        "orbit_period": found.period_slips if found else None,
        "orbit_from_t": float(found.settled_from_t) - t0 if found else None,
        "threshold_below": ds["below"],
        "threshold_low": ds["low"],
        "windows_decorrelated": len(ds["seeds"]) - int(ds["censored"]),
        "point_wall_seconds": time.perf_counter() - wall0,
        # the worker's own time: the point's cost on a machine shared with other work
        "point_cpu_seconds": time.process_time() - cpu0,
    }


def task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """One point on a worker: :func:`exponent_point` or :func:`lifetime_point` by its ``measure``."""
    measure = exponent_point if point.get("measure") == "exponent" else lifetime_point
    return measure(point, point_params("chain", point), Path(point_dir))
