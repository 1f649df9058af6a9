"""Free ends: x_{N+1} = x_N (with the plate drive also x_0 = x_1), no spring beyond the chain."""

from __future__ import annotations

from stickslip.models.piece import Piece, njit


@njit(cache=True, inline="always")
def ghost(edge, other, wall):
    """The end block's own value: the spring beyond it carries no force."""
    return edge


PIECE = Piece("ends", "free", "x_{N+1} = x_N (a drive on every block: also x_0 = x_1)", module=__name__)
