"""An experiment's result as the analysis, the figures and the report read it, and the settings of
one chain run of Figs. 5-8 (``stickslip reproduce``).

Below :mod:`stickslip.experiments`, :mod:`stickslip.plotting` and :mod:`stickslip.report`, so that
each reads an experiment's result without importing the code that computes it. The experiments are
the points of the paper's studies (:data:`stickslip.experiments.studies.PAPER`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from stickslip.models.params import ChainParams

__all__ = ["Outcome", "Results", "point_settings", "chain_params"]


@dataclass
class Outcome:
    """An experiment's loaded result: the ``settings`` its task received (the point merged with
    the study's shared settings), its folder (``run_dir``), ``data`` (what its loader reads),
    ``summary``, whether it was reused and how long it took."""

    settings: dict[str, Any]
    run_dir: Path
    data: dict[str, Any]
    summary: dict[str, Any]
    reused: bool
    wall_seconds: float


@dataclass
class Results:
    """What the findings and figures of one of the paper's studies read: the ``outcomes`` of its
    experiments by name, the ``analysis`` of the chain runs of Figs. 5-8
    (:func:`stickslip.analysis.stats.chain_runs.chain_analysis`; None for the other studies) and the
    ``mode``."""

    outcomes: dict[str, Outcome]
    analysis: dict[str, Any] | None
    mode: str


_CHAIN_FIELDS = ("N", "K", "D", "V", "beta", "alpha", "Fs", "dt")


def point_settings(cfg: dict[str, Any]) -> tuple[ChainParams, float, dict[str, Any]]:
    """The chain of eq. (4), run length and run options of one chain run of Figs. 5-8.

    Parameters
    ----------
    cfg : dict
        The point's N and beta merged with the shared settings of the chain runs
        (:mod:`stickslip.experiments.studies.figs5_8`).

    Returns
    -------
    tuple
        ``(params, t_end, options)``: the options of :func:`stickslip.run.driver.run_chain`
        (sample interval, start of the average, the stop at steady sliding above
        ``until_steady_above``, Fig. 6's profile window at ``profile_N`` and ``profile_betas``).
    """
    params = chain_params(cfg)
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


def chain_params(cfg: dict[str, Any], **changes: Any) -> ChainParams:
    """The chain of eq. (4) that the settings ``cfg`` of the chain runs of Figs. 5-8 name, with
    ``changes`` (e.g. ``N``) applied."""
    return ChainParams(**{**{k: cfg[k] for k in _CHAIN_FIELDS if k in cfg}, **changes})
