"""The train model's friction: F0 + beta v, no state variable.

Its compiled functions :func:`accel` and :func:`rate` are what every integrator evaluates
(contract in :mod:`stickslip.kernels.laws`).
"""

from __future__ import annotations

from typing import Any

from stickslip.models.piece import Param, Piece, kernel_params, njit

READS = ("beta", "F0")
Params = kernel_params(__name__, READS)


@njit(cache=True, inline="always")
def accel(f, v, th, lp):
    """f - F0 - beta v: the force on a moving block less the train model's friction."""
    return f - lp.F0 - lp.beta * v


@njit(cache=True, inline="always")
def rate(thl, th, thr, v, lp):
    """No state variable: 0."""
    return 0.0


@njit(cache=True, inline="always")
def rate_lap(lap, th, v, lp):
    """:func:`rate`, which reads no neighbour: the law has no diffusion of theta (``lap`` unread;
    :mod:`stickslip.models.lattice`)."""
    return rate(th, th, th, v, lp)


def _slope(p: Any) -> float:
    """phi'(V) of the train model's F0 + beta v: beta."""
    return float(p.beta)


def _steady(p: Any) -> tuple[float, float]:
    """c = F0 + beta V; no state variable (theta_0 = 0)."""
    return p.F0 + p.beta * p.V, 0.0


PIECE = Piece(
    "friction",
    "strengthening",
    "F0 + beta v, no state variable (train model)",
    READS,
    params=(Param("F0", 1.0, "constant part F0 of strengthening friction (train model)", low=0.0, symbol="F_0"),),
    steady=_steady,
    slope=_slope,
    module=__name__,
    lanes=True,
    label=r"$F_0 + \beta v$",
)
