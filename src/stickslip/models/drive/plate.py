"""The plate drive of Burridge-Knopoff and Carlson-Langer: every block joined to a plate at V t
by a leaf spring Kp."""

from __future__ import annotations

from stickslip.models.piece import Param, Piece, kernel_params, njit

READS = ("Kp",)
Params = kernel_params(__name__, READS)


@njit(cache=True, inline="always")
def force(xl, xc, xr, K, p, dp):
    """K (x_{i+1} - 2 x_i + x_{i-1}) + Kp (V t - x_i), the plate at p = V t."""
    return K * ((xl - xc) - (xc - xr)) + dp.Kp * (p - xc)


@njit(cache=True, inline="always")
def force_rate(vl, vc, vr, K, q, dp):
    """d/dt of :func:`force`: K (v_{i+1} - 2 v_i + v_{i-1}) + Kp (q - v_i), q = V the plate's
    velocity."""
    return K * ((vl - vc) - (vc - vr)) + dp.Kp * (q - vc)


@njit(cache=True, inline="always")
def force_lap(lap, xc, K, p, dp):
    """K times the Laplacian of x plus Kp (V t - x_i), the plate at p = V t.
    ``lap`` is the lattice's Laplacian of x at the block (:mod:`stickslip.models.lattice`);
    :func:`force` in the same order of operations, so the chain's bits stay."""
    return K * lap + dp.Kp * (p - xc)


@njit(cache=True, inline="always")
def leaf(dp):
    """Kp."""
    return dp.Kp


@njit(cache=True, inline="always")
def left(p, ghost):
    """x_0 is the ends' ghost cell (the plate pulls every block, not block 1)."""
    return ghost


PIECE = Piece(
    "drive",
    "plate",
    "every block joined to a plate at V t by a leaf spring Kp: f_i gains Kp (V t - x_i)",
    READS,
    params=(
        Param(
            "Kp",
            1.0,
            "leaf spring Kp joining each block to the plate (plate drive)",
            low=0.0,
            low_open=True,
            symbol="K_p",
        ),
    ),
    leaf_spring=True,
    module=__name__,
    lanes=True,
)
