"""Fixed ends: x_{N+1} = 0 (with the plate drive also x_0 = 0), a spring K to a wall at x = 0."""

from __future__ import annotations

from stickslip.models.piece import Piece, njit


@njit(cache=True, inline="always")
def ghost(edge, other, wall):
    """The wall's position (theta: the edge value, no flux)."""
    return wall


PIECE = Piece(
    "ends",
    "fixed",
    "x_{N+1} = 0 (a drive on every block: also x_0 = 0)",
    steady_sliding=False,
    wall=True,
    module=__name__,
)
