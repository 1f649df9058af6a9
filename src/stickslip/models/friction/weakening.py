"""Carlson-Langer's velocity weakening: phi(v) = (1 - sigma) / (1 + 2 alpha max(v, 0) / (1 - sigma)).

No state variable. Kernel expressions: ``FRICTION_WEAKENING`` in :mod:`stickslip.kernels.laws`.
"""

from __future__ import annotations

from typing import Any

from stickslip.models.piece import Piece


def weakening_g(p: Any) -> float:
    """g = (1 + 2 alpha V / (1 - sigma))^-2 of CL's velocity weakening; -phi'(V) = 2 alpha g."""
    return float((1.0 + 2.0 * p.alpha * p.V / (1.0 - p.sigma)) ** -2)


def _slope(p: Any) -> float:
    """phi'(V) of CL's weakening, phi(v) = (1 - sigma) / (1 + 2 alpha v / (1 - sigma)): -2 alpha g."""
    return -2.0 * p.alpha * weakening_g(p)


def _steady(p: Any) -> tuple[float, float]:
    """c = phi(V); no state variable (theta_0 = 0, the value runs carry)."""
    w = 1.0 - p.sigma
    return w / (1.0 + 2.0 * p.alpha * p.V / w), 0.0


def _extras(p: Any) -> dict[str, float]:
    """alpha g, the number CL's stability criterion compares with the springs (docs/model.md)."""
    return {"alpha_g": p.alpha * weakening_g(p)}


PIECE = Piece(
    "friction",
    "weakening",
    "phi(v) = (1 - sigma) / (1 + 2 alpha max(v, 0) / (1 - sigma)) (Carlson-Langer)",
    ("alpha", "sigma"),
    steady=_steady,
    slope=_slope,
    stability_extras=_extras,
    label=r"$\phi(v) = (1 - \sigma) / (1 + 2 \alpha v / (1 - \sigma))$",
)
