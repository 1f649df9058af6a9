"""The constant static threshold Fs of eq. (4): a stuck block starts when f_i > Fs."""

from __future__ import annotations

from stickslip.models.piece import Piece, kernel_params, njit

READS = ("Fs",)
Params = kernel_params(__name__, READS)


@njit(cache=True, inline="always")
def value(th, tp):
    """Fs, whatever the state variable."""
    return tp.Fs


PIECE = Piece("threshold", "constant", "a stuck block starts when f_i > Fs", READS, module=__name__)
