"""A force F_start + r t on every block, slowly increased: the self-organised criticality protocol
of a random medium (Sakaguchi and Kadowaki, arXiv:1705.06410).

f_i = K (x_{i+1} - 2 x_i + x_{i-1}) + (F_start + r t_n). Nothing pulls block 1: x_0 is the ends'
ghost cell (free ends: x_0 = x_1).

How the drive reads t: the kernels compute one time-dependent number per step, the pull point
p = V * (n dt) (:func:`stickslip.kernels.laws._pull`), from the integer step n. This drive has
the kernels' V set to r (:attr:`~stickslip.models.piece.Piece.pull_velocity`), so p = r * (n dt)
is r t_n, rounded once, exactly as every integrator computes it, and the force adds it to
F_start: F_start + p. No division by V, no second clock, so dense, exact and a resumed run agree
bit for bit. ChainParams' V is not read.

On the fast path: the force on a stopped block, F_start + r (n dt) plus its springs, is
non-decreasing in n for r >= 0 (each rounding is monotone), so the plate's start search
(:func:`stickslip.kernels.triggers._plate_trigger`, a bisection on the step's own expression,
which ``leaf_spring`` selects) is exact for it. ``exact`` runs on the plate's paths (the sparse
lists for a friction without theta). Not on the located integrator (its frame u = x - V t holds
the drive at u = 0). No steady sliding: the force never stops growing.
"""

from __future__ import annotations

from stickslip.models.piece import Param, Piece, kernel_params, njit

READS = ("F_start", "r")
Params = kernel_params(__name__, READS)


@njit(cache=True, inline="always")
def force(xl, xc, xr, K, p, dp):
    """K (x_{i+1} - 2 x_i + x_{i-1}) + (F_start + r t_n), with the pull point p = r t_n."""
    return K * ((xl - xc) - (xc - xr)) + (dp.F_start + p)


@njit(cache=True, inline="always")
def force_rate(vl, vc, vr, K, q, dp):
    """d/dt of :func:`force`: K (v_{i+1} - 2 v_i + v_{i-1}) + r, with q = r the pull point's
    velocity."""
    return K * ((vl - vc) - (vc - vr)) + q


@njit(cache=True, inline="always")
def force_lap(lap, xc, K, p, dp):
    """K times the Laplacian of x plus F_start + r t_n, the pull point p = r t_n.
    ``lap`` is the lattice's Laplacian of x at the block (:mod:`stickslip.models.lattice`);
    :func:`force` in the same order of operations, so the chain's bits stay."""
    return K * lap + (dp.F_start + p)


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
    "force-ramp",
    "a force F_start + r t on every block: f_i gains F_start + r t; no pulling point (x_0 the ends' ghost cell)",
    READS,
    params=(
        Param("F_start", 0.0, "force F_start on every block at t = 0 (drive force-ramp)", low=0.0, symbol="F_{start}"),
        Param("r", 1e-4, "rate r of the force F_start + r t on every block (drive force-ramp)", low=0.0, symbol="r"),
    ),
    leaf_spring=True,
    pull_velocity=lambda p: p.r,
    steady_sliding=False,
    located=False,
    module=__name__,
    lanes=True,
)
