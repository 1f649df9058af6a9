"""Periodic ends: x_0 = x_N, x_{N+1} = x_1, the chain closed into a ring (plate drive only)."""

from __future__ import annotations

from stickslip.models.piece import Piece, njit


@njit(cache=True, inline="always")
def ghost(edge, other, wall):
    """The opposite end's value: blocks 1 and N are neighbours."""
    return other


PIECE = Piece("ends", "periodic", "x_0 = x_N, x_{N+1} = x_1 (a drive on every block only)", ring=True, module=__name__)
