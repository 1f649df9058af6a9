"""What a point of a parameter sweep holds (:mod:`stickslip.experiments.sweep`): a chain point
:class:`~stickslip.models.params.ChainParams` fields (with ``model``, a preset) and the options of
:data:`CHAIN_RUN_OPTIONS`, a block point :class:`~stickslip.models.params.BlockParams` fields and
:data:`BLOCK_RUN_OPTIONS`; both need ``t_end``.
"""

from __future__ import annotations

import dataclasses
import warnings
from typing import Any

from stickslip.models.params import BlockParams, ChainParams
from stickslip.run.errors import ShortRunWarning

__all__ = ["CHAIN_RUN_OPTIONS", "BLOCK_RUN_OPTIONS", "point_params", "split_point", "chain_run_args", "preset_start"]

CHAIN_RUN_OPTIONS = (
    "t_end",
    "integrator",
    "start",
    "sample_interval",
    "average_from",
    "profile_window",
    "profile_min_blocks",
)
BLOCK_RUN_OPTIONS = ("t_end", "every")


def point_params(kind: str, point: dict[str, Any]):
    """The parameters of one sweep point: BlockParams, or ChainParams of the point's ``model``
    preset (default the paper's chain) with the point's other fields as overrides."""
    params_cls = ChainParams if kind == "chain" else BlockParams
    values = {k: v for k, v in point.items() if k in {f.name for f in dataclasses.fields(params_cls)}}
    if params_cls is BlockParams:
        return BlockParams(**values)
    from stickslip.models.presets import chain_params

    return chain_params(values.pop("model", "sakaguchi"), **values)


def preset_start(params: ChainParams, cfg: dict[str, Any]) -> dict[str, Any]:
    """A chain point's ``start``, ``perturbation`` and ``seed`` (:func:`stickslip.run.driver.run_chain`):
    the point's own, else those of its model's preset (:mod:`stickslip.models.presets`); the paper's
    start (x_i = 0, section 3) is never perturbed."""
    from stickslip.models.presets import PRESETS

    preset = PRESETS[params.model]
    start = cfg.get("start", preset.start)
    amplitude = float(cfg.get("perturbation", preset.start_options.get("amplitude", 0.0)))
    seed = int(cfg.get("seed", preset.start_options.get("seed", 0)))
    return {"start": start, "perturbation": 0.0 if start == "paper" else amplitude, "seed": seed}


def split_point(point: dict[str, Any], params_cls: type, options: tuple[str, ...]) -> tuple[Any, dict[str, Any]]:
    unknown = sorted(set(point) - {f.name for f in dataclasses.fields(params_cls)} - set(options))
    if unknown:
        raise ValueError(f"unknown keys for {params_cls.__name__}: {', '.join(unknown)}")
    params = point_params("chain" if params_cls is ChainParams else "block", point)
    run_options = {k: v for k, v in point.items() if k in options}
    if "t_end" not in run_options:
        raise ValueError("a sweep point needs t_end")
    return params, run_options


def chain_run_args(point: dict[str, Any]) -> tuple[ChainParams, float, dict[str, Any]]:
    """The parameters, run length and run options of a chain point (the model's start by default)."""
    params, options = split_point(point, ChainParams, CHAIN_RUN_OPTIONS)
    t_end = options.pop("t_end")
    if "start" not in options:  # the model's own start (Carlson-Langer: every block stuck, seeded)
        options.update(preset_start(params, {}))
    return params, t_end, options


def warn_short_chain_runs(points: list[dict[str, Any]], common: dict[str, Any], names: list[str]) -> None:
    """One :class:`ShortRunWarning` per chain point too short to leave the loading (run.state.loading_warnings)."""
    from stickslip.run.state import loading_warnings

    for point, name in zip(points, names, strict=False):
        try:
            params, t_end, options = chain_run_args({**common, **point})
        except (ValueError, TypeError):
            continue  # the point itself reports its error when it runs
        for message in loading_warnings(params, t_end, options.get("average_from"), options["start"]):
            warnings.warn(f"{name}: {message}", ShortRunWarning, stacklevel=3)
