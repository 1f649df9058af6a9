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
