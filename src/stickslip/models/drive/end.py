"""The end drive of eq. (4): a pulling point x_0 = V t joined to block 1 by the spring K."""

from __future__ import annotations

from stickslip.models.piece import Piece, kernel_params, njit

READS: tuple[str, ...] = ()
Params = kernel_params(__name__, READS)


@njit(cache=True, inline="always")
def force(xl, xc, xr, K, p, dp):
    """K (x_{i+1} - 2 x_i + x_{i-1}) (eq. 4); block 1 reads the pulling point as its x_0."""
    return K * ((xl - xc) - (xc - xr))


@njit(cache=True, inline="always")
def force_rate(vl, vc, vr, K, q, dp):
    """d/dt of :func:`force`: K (v_{i+1} - 2 v_i + v_{i-1}), block 1 reading the pulling point's
    velocity q in its ghost cell (the stress rate a law with ``PIECE.context`` reads,
    :mod:`stickslip.kernels.laws`)."""
    return K * ((vl - vc) - (vc - vr))


@njit(cache=True, inline="always")
def force_lap(lap, xc, K, p, dp):
    """K times the Laplacian of x (eq. 4); an edge block reads the pulling point in its ghost cell.
    ``lap`` is the lattice's Laplacian of x at the block (:mod:`stickslip.models.lattice`);
    :func:`force` in the same order of operations, so the chain's bits stay."""
    return K * lap


@njit(cache=True, inline="always")
def leaf(dp):
    """No spring to the drive but block 1's."""
    return 0.0


@njit(cache=True, inline="always")
def left(p, ghost):
    """x_0 is the pulling point."""
    return p


PIECE = Piece(
    "drive",
    "end",
    "pulling point x_0 = V t joined to block 1 by the spring K (eq. 4)",
    READS,
    module=__name__,
    lanes=True,
)
