"""The state threshold: a stuck block starts when f_i > theta_i (the paper's reading of
Batista-Carlson, docs/model.md)."""

from __future__ import annotations

from stickslip.models.piece import Piece, kernel_params, njit

READS: tuple[str, ...] = ()
Params = kernel_params(__name__, READS)


@njit(cache=True, inline="always")
def value(th, tp):
    """theta_i: the threshold moves with the state variable."""
    return th


PIECE = Piece(
    "threshold",
    "state",
    "a stuck block starts when f_i > theta_i (the paper's reading of Batista-Carlson)",
    READS,
    has_state=True,
    module=__name__,
)
