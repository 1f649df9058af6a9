"""One point of a study that is one chain run of eq. (4) (or of a relative,
:mod:`stickslip.models.presets`) and its analysis, a task of
:func:`stickslip.experiments.sweep.run_sweep`: :func:`order_task` gives the order parameter and
the final state (the phase diagram), :func:`sizes_task` the slip-size exponent (the exponents).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

__all__ = ["order_task", "sizes_task", "check_point", "loading_time", "t_end_of"]


def loading_time(N: int, K: float = 10.0, V: float = 0.001) -> float:
    """L_ss / V at c = 1: the time the pulling point takes to stretch the chain to its steady
    length, ``N (N - 1) / (2 K V)`` (docs/model.md, "Steady sliding")."""
    return N * (N - 1) / (2.0 * K * V)


def t_end_of(N: int, loads: float) -> float:
    """Run length: ``loads`` loading times of a chain of ``N`` blocks (the paper's K and V),
    rounded up to 3 significant digits."""
    t = loads * loading_time(N)
    scale = 10.0 ** (math.floor(math.log10(t)) - 2)
    return math.ceil(t / scale) * scale


def point_run_options(cfg: dict[str, Any], params) -> tuple[float, dict[str, Any]]:
    """Run length and :func:`~stickslip.run.driver.run_chain` options of a point."""
    from stickslip.experiments.sweep_points import preset_start

    t_end = float(cfg["t_end"])
    options: dict[str, Any] = {
        **preset_start(params, cfg),
        "sample_interval": max(t_end / float(cfg.get("n_samples", 2000)), params.dt),
        "average_from": float(cfg.get("average_fraction", 0.5)) * t_end,
        "sample_moving": cfg.get("analysis") == "order",
    }
    if cfg.get("until_steady"):
        options["until_steady"] = float(cfg["until_steady"])
    return t_end, options


def check_point(cfg: dict[str, Any]) -> None:
    """Raise ParameterError (one line) unless a point's merged settings make a valid run."""
    from stickslip.experiments.sweep_points import point_params

    point_run_options(cfg, point_params("chain", cfg))


def _run(point: dict[str, Any], point_dir: Path, analyse) -> dict[str, Any]:
    """The point's chain run (continued from its checkpoint): the summary fields every point
    stores and ``analyse(run, params, options)``, the summary of its ``done.json``."""
    from stickslip.experiments.sweep import run_chain_point
    from stickslip.experiments.sweep_points import point_params

    params = point_params("chain", point)
    t_end, options = point_run_options(point, params)
    run = run_chain_point(params, t_end, Path(point_dir), **options)
    return {
        "model": params.model,
        "t_end": t_end,
        "t_reached": float(run.summary["t_reached"]),
        "n_events_total": int(run.summary["n_events"]),
        "run_wall_seconds": float(run.summary["wall_seconds"]),
        "block_updates": int(run.summary["block_updates"]),
        **analyse(run, params, options),
    }


def order_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """One chain run and its order parameter and final state, a task of ``run_sweep``."""
    from stickslip.analysis.stats.order import order_summary

    return _run(point, point_dir, lambda run, params, options: order_summary(run, params, options["average_from"]))


def sizes_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """One chain run and its slip-size exponent over the events after its transient, a task of
    ``run_sweep``."""
    from stickslip.analysis.stats.chain_runs import sizes_summary

    def sizes(run, params, options) -> dict[str, Any]:
        t_from = float(point.get("transient", point.get("average_fraction", 0.5))) * float(run.options.t_end)
        spanning, seed = point.get("spanning", "max_block"), int(point.get("seed", 0))
        return sizes_summary(run, t_from, spanning=spanning, seed=seed, bootstrap=int(point.get("bootstrap", 200)))

    return _run(point, point_dir, sizes)
