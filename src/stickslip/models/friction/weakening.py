"""Carlson-Langer's velocity weakening: phi(v) = (1 - sigma) / (1 + 2 alpha max(v, 0) / (1 - sigma)).

No state variable. Its compiled functions :func:`accel` and :func:`rate` are what every
integrator evaluates (contract in :mod:`stickslip.kernels.laws`).
"""

from __future__ import annotations

from typing import Any

from stickslip.models.piece import Param, Piece, kernel_params, njit

READS = ("alpha", "sigma")
Params = kernel_params(__name__, READS)


@njit(cache=True, inline="always")
def accel(f, v, th, lp):
    """f - phi(v) with phi(v) = (1 - sigma) / (1 + 2 alpha max(v, 0) / (1 - sigma)) (Carlson-Langer).

    The divisor 1 - sigma is positive (ChainParams holds sigma in [0, 1)), so a kernel may compile
    this without a division-by-zero check (the plate kernel's numpy error model)."""
    w = 1.0 - lp.sigma
    return f - w / (1.0 + 2.0 * lp.alpha * max(v, 0.0) / w)


@njit(cache=True, inline="always")
def rate(thl, th, thr, v, lp):
    """No state variable: 0."""
    return 0.0


@njit(cache=True, inline="always")
def rate_lap(lap, th, v, lp):
    """:func:`rate`, which reads no neighbour: the law has no diffusion of theta (``lap`` unread;
    :mod:`stickslip.models.lattice`)."""
    return rate(th, th, th, v, lp)


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
    READS,
    params=(
        Param(
            "sigma",
            0.01,
            "friction drop sigma of velocity weakening (CL)",
            low=0.0,
            high=1.0,
            high_open=True,
            symbol=r"\sigma",
        ),
    ),
    steady=_steady,
    slope=_slope,
    stability_extras=_extras,
    module=__name__,
    label=r"$\phi(v) = (1 - \sigma) / (1 + 2 \alpha v / (1 - \sigma))$",
)
