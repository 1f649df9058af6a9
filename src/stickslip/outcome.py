"""An experiment's result as the analysis, the figures and the report read it, and the settings of
one chain run of Figs. 5-8 (``stickslip reproduce``).

Below :mod:`stickslip.experiments`, :mod:`stickslip.plotting` and :mod:`stickslip.report`, so that
each reads an experiment's result without importing the code that computes it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from stickslip.models.params import ChainParams

__all__ = ["Outcome", "point_settings", "chain_common"]


@dataclass
class Outcome:
    """An experiment's loaded result: its spec (``experiment``, an
    :class:`~stickslip.experiments.specs.Experiment`), its run directory, ``data`` (what its runner
    loads), ``summary``, whether it was reused and how long it took."""

    experiment: Any
    run_dir: Path
    data: dict[str, Any]
    summary: dict[str, Any]
    reused: bool
    wall_seconds: float


_CHAIN_FIELDS = ("N", "K", "D", "V", "beta", "alpha", "Fs", "dt")


def point_settings(cfg: dict[str, Any]) -> tuple[ChainParams, float, dict[str, Any]]:
    """The chain of eq. (4), run length and run options of one chain run of Figs. 5-8.

    Parameters
    ----------
    cfg : dict
        The point's N and beta merged with its experiment's shared settings
        (:func:`chain_common`).

    Returns
    -------
    tuple
        ``(params, t_end, options)``: the options of :func:`stickslip.run.driver.run_chain`
        (sample interval, start of the average, the stop at steady sliding above
        ``until_steady_above``, Fig. 6's profile window at ``profile_N`` and ``profile_betas``).
    """
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


def chain_common(exp: Any) -> dict[str, Any]:
    """The settings every chain run of Figs. 5-8 shares.

    Parameters
    ----------
    exp : Experiment
        The ``chain_runs`` experiment of a reproduction.

    Returns
    -------
    dict
        Its parameters and options, less the point lists.
    """
    common = dict(exp.params)
    common.update({k: v for k, v in exp.options.items() if k not in ("points", "sweep_N", "figure_N")})
    return common
