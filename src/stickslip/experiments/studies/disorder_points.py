"""The points of ``stickslip study disorder`` (docs/studies/disorder.md), tasks of
:func:`stickslip.experiments.sweep.run_sweep`.

A point is JSON (hashed for the cache), so its per-block parameters are distribution expressions
(``"Fs": "uniform(2.7, 3.3)"``, :func:`stickslip.models.disorder.parse`) drawn with the point's
``disorder_seed`` (:func:`seeded_point`). ``part`` says which task runs it:

* ``a``: the paper's chain with random Fs: :func:`~stickslip.experiments.studies.chain_point.order_task`
  (``analysis`` "order") or :func:`~stickslip.experiments.studies.chain_point.sizes_task` ("sizes");
* ``b``: the force ramp F_start + r t from rest (:func:`ramp_task`): the events until the chain
  depins, their sizes, and the force F_c where every block first moves;
* ``c``: a constant force F from rest (:func:`force_task`): the mean velocity at the end and the
  fraction of blocks moving.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from stickslip.experiments.sweep_points import point_params

__all__ = [
    "seeded_point",
    "disorder_task",
    "disorder_check",
    "ramp_task",
    "force_task",
    "depinning_force",
    "depinned_stop",
]

#: Keys of a point that are the study's own (not ChainParams fields nor run options).
_OWN = ("part", "disorder_seed", "w")


def seeded_point(point: dict[str, Any]) -> dict[str, Any]:
    """The point with each distribution expression that names no seed drawn with the point's
    ``disorder_seed`` (default 0), as ``--disorder-seed`` does on the command line."""
    from stickslip.models.disorder import Quenched, parse

    seed = int(point.get("disorder_seed", 0))
    out = dict(point)
    for key, value in point.items():
        if key in _OWN or not isinstance(value, str) or "(" not in value:
            continue
        q = parse(value)
        if isinstance(q, Quenched) and q.seed is None:
            out[key] = Quenched(q.dist, *q.args, p=q.p, seed=seed)
    return out


def _params(point: dict[str, Any]):
    return point_params("chain", seeded_point(point))


def disorder_check(cfg: dict[str, Any]) -> None:
    """Raise ParameterError (one line) unless a point's merged settings make a valid run."""
    from stickslip.experiments.studies.chain_point import check_point

    if cfg.get("part") == "a":
        check_point(seeded_point(cfg))
    else:
        _params(cfg)


def disorder_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """One point of the study, by its ``part`` (module docstring); a task of ``run_sweep``."""
    from stickslip.experiments.studies.chain_point import order_task, sizes_task

    part = point.get("part")
    if part == "a":
        task = order_task if point.get("analysis") == "order" else sizes_task
        return task(seeded_point(point), point_dir)
    if part == "b":
        return ramp_task(point, point_dir)
    if part == "c":
        return force_task(point, point_dir)
    raise ValueError(f"part must be a, b or c (got {part!r})")


def _run_from_rest(point: dict[str, Any], point_dir: Path, t_end: float, *, stop_at_depinning: bool = False):
    """The point's chain from rest at x_i = 0 (every block stuck, springs unstretched), sampled
    with the count of moving blocks (``n_samples`` samples to ``t_end``, default 400); with
    ``stop_at_depinning``, ended by :func:`depinned_stop` at the sampling steps."""
    from stickslip.experiments.sweep import run_chain_point

    params = _params(point)
    interval = _sample_interval(point, params, t_end)
    hooks = (depinned_stop(int(round(interval / params.dt))),) if stop_at_depinning else ()
    run = run_chain_point(
        params,
        t_end,
        Path(point_dir),
        start="rest",
        perturbation=0.0,
        seed=0,
        sample_interval=interval,
        sample_moving=True,
        hooks=hooks,
    )
    return params, run


def _sample_interval(point: dict[str, Any], params, t_end: float) -> float:
    return max(t_end / int(point.get("n_samples", 400)), params.dt)


def depinned_stop(every: int):
    """A run hook (:class:`stickslip.run.Hook`) that ends a ramp run of part b at the first
    multiple of ``every`` steps (the sampling steps) with every block moving: the chain has
    depinned, and with F above the strengthening law's F0 a sliding block never stops again, so
    no event ends after it and the rest of the ramp (every block sliding, the costliest steps)
    adds nothing to the sizes or to F_c."""
    from stickslip.run import Hook

    class DepinnedStop(Hook):
        def stop_at(self, n):
            return (n // every + 1) * every

        def at(self, loop, n):
            return n % every == 0 and bool(np.all(loop.state.mov[1:-1] != 0.0))

    return DepinnedStop()


def depinning_force(t: Any, n_moving: Any, N: int, F_start: float, r: float) -> float:
    """The ramp's force F_start + r t at the first sample where all N blocks move (the chain has
    depinned: with F above the strengthening law's F0 a sliding chain never stops again); NaN
    when it never does."""
    t, n = np.asarray(t, dtype=float), np.asarray(n_moving)
    hit = np.flatnonzero(n >= N)
    return float(F_start + r * t[hit[0]]) if hit.size else math.nan


def ramp_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """The force ramp F_start + r t on a chain at rest with random thresholds (part b): the
    sizes S of the events that ended (as JSON text, for the study to pool over seeds), the force
    F_c where every block first moves, and the run's costs. The run ends at F_c
    (:func:`depinned_stop`) or at ``t_end``; ``t_stop`` and ``F_end`` say where."""
    t_end = float(point["t_end"])
    params, run = _run_from_rest(point, point_dir, t_end, stop_at_depinning=True)
    samples = run.samples
    F_start, r = float(point["F_start"]), float(point["r"])
    F_c = depinning_force(samples["t"].values, samples["n_moving"].values, params.N, F_start, r)
    events = run.events
    S = events["S"].to_numpy(dtype=float)
    blocks = run.state.blocks()
    return {
        "t_end": t_end,
        "t_stop": float(run.state.step * params.dt),
        "n_events": int(len(events)),
        "n_events_total": int(run.summary["n_events"]),
        "F_c": F_c,
        "F_end": F_start + r * float(run.state.step * params.dt),
        "moving_end": int(np.count_nonzero(~blocks["stopped"])),
        "v_end": float(np.mean(blocks["v"])),
        "S_max": float(S.max()) if S.size else math.nan,
        "n_blocks_max": int(events["n_blocks"].max()) if len(events) else 0,
        "sizes": json.dumps([float(s) for s in S]),
        "run_wall_seconds": float(run.summary["wall_seconds"]),
        "block_updates": int(run.summary["block_updates"]),
    }


def force_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """A constant force F on a chain at rest with random thresholds (part c): the mean velocity
    of the blocks at the end, its mean over the run (the mean displacement over t_end),
    and the fraction of blocks moving at the end."""
    t_end = float(point["t_end"])
    params, run = _run_from_rest(point, point_dir, t_end)
    blocks = run.state.blocks()
    moving = int(np.count_nonzero(~blocks["stopped"]))
    return {
        "t_end": t_end,
        "v_end": float(np.mean(blocks["v"])),
        "v_mean": float(np.mean(blocks["x"])) / t_end,
        "moving_end": moving,
        "moving_fraction": moving / params.N,
        "n_events": int(run.summary["n_events"]),
        "run_wall_seconds": float(run.summary["wall_seconds"]),
        "block_updates": int(run.summary["block_updates"]),
    }
