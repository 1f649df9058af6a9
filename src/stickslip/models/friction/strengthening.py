"""The train model's friction: F0 + beta v, no state variable.

Kernel expressions: ``FRICTION_STRENGTHENING`` in :mod:`stickslip.kernels.laws`.
"""

from __future__ import annotations

from typing import Any

from stickslip.models.piece import Piece


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
    ("beta", "F0"),
    steady=_steady,
    slope=_slope,
    label=r"$F_0 + \beta v$",
)
