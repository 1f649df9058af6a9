"""The state threshold: a stuck block starts when f_i > theta_i (the paper's reading of
Batista-Carlson, docs/model.md)."""

from __future__ import annotations

from stickslip.models.friction import state as law
from stickslip.models.piece import Piece, kernel_params, njit

READS: tuple[str, ...] = ()
#: ``sigma``: the single block's threshold sigma theta (eq. 1); None (the chain) reads theta_i.
Params = kernel_params(__name__, READS, optional=("sigma",))


@njit(cache=True, inline="always")
def value(th, tp):
    """theta_i (sigma theta for the single block): the threshold moves with the state variable."""
    return law.scaled(tp.sigma, th)


PIECE = Piece(
    "threshold",
    "state",
    "a stuck block starts when f_i > theta_i (the paper's reading of Batista-Carlson)",
    READS,
    has_state=True,
    module=__name__,
)
