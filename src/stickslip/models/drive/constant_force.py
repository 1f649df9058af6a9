"""A constant external force F on every block, no pulling point: the depinning protocol of a
random medium (Sakaguchi and Kadowaki, arXiv:1705.06410).

f_i = K (x_{i+1} - 2 x_i + x_{i-1}) + F. Nothing pulls block 1: x_0 is the ends' ghost cell (free
ends: x_0 = x_1). The force does not read t, so the kernels' pull point p = V t_n goes unread
and V means nothing here.

On the fast path: the force on a stopped block changes only when a neighbour moves, so the plate's
start search (:func:`stickslip.kernels.triggers._plate_trigger`, which ``leaf_spring`` selects)
is exact for it: the step's own expression is constant in n, so a stopped block starts at once or
never. ``exact`` therefore runs on the plate's paths: the sparse lists for a friction without
theta (:mod:`stickslip.kernels.plate`), the interval with the plate's start steps otherwise.
Not on the located integrator (its frame u = x - V t holds the drive at u = 0).

Steady sliding: every block at the v where the frictions balance the forces,
sum_i c_i(v) = sum_i F (:func:`stickslip.models.physics.steady_velocity`); for the strengthening
law F0 + beta v, v = (F - F0) / beta. Below the static threshold (F < Fs) a chain at rest stays
at rest.
"""

from __future__ import annotations

from stickslip.models.piece import Param, Piece, kernel_params, njit

READS = ("F",)
Params = kernel_params(__name__, READS)


@njit(cache=True, inline="always")
def force(xl, xc, xr, K, p, dp):
    """K (x_{i+1} - 2 x_i + x_{i-1}) + F: the springs and the constant force."""
    return K * ((xl - xc) - (xc - xr)) + dp.F


@njit(cache=True, inline="always")
def force_rate(vl, vc, vr, K, q, dp):
    """d/dt of :func:`force`: K (v_{i+1} - 2 v_i + v_{i-1}) (F is constant)."""
    return K * ((vl - vc) - (vc - vr))


@njit(cache=True, inline="always")
def force_lap(lap, xc, K, p, dp):
    """K times the Laplacian of x plus the constant force F.
    ``lap`` is the lattice's Laplacian of x at the block (:mod:`stickslip.models.lattice`);
    :func:`force` in the same order of operations, so the chain's bits stay."""
    return K * lap + dp.F


@njit(cache=True, inline="always")
def leaf(dp):
    """No spring to the drive."""
    return 0.0


@njit(cache=True, inline="always")
def left(p, ghost):
    """x_0 is the ends' ghost cell (nothing pulls block 1)."""
    return ghost


PIECE = Piece(
    "drive",
    "constant-force",
    "a constant force F on every block: f_i gains F; no pulling point (x_0 the ends' ghost cell)",
    READS,
    params=(Param("F", 2.0, "constant external force F on every block (drive constant-force)", low=0.0, symbol="F"),),
    leaf_spring=True,
    applied=lambda p: p.F,
    located=False,
    module=__name__,
    lanes=True,
)
