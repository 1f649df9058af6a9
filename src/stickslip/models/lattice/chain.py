"""The chain of eq. (4) as a lattice: N blocks on a line, ghost cells at 0 and N + 1
(docs/model.md, "Chain"; docs/lattice.md).

Its layout is the chain kernels' (:mod:`stickslip.kernels.layout`): block i at index i of arrays
of N + 2. :func:`lap` is the chain kernels' expression (x_{i-1} - x_i) - (x_i - x_{i+1}) and
:func:`fill` sets the ghost cells as :func:`stickslip.kernels.laws._set_ghosts` does (the drive's
load point at x_0 for an edge drive, else the ends' ghost; theta without flux), so a lattice
kernel run on the chain gives the chain kernels' bits.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stickslip.models.lattice.edges import CODES, PERIODIC, LatticeError, eigenvalues_1d
from stickslip.models.lattice.square import ghost_th, ghost_x
from stickslip.models.params import MAX_BLOCKS
from stickslip.models.piece import njit


@njit(cache=True, inline="always")
def lap(a, k, W):
    """(a_{k-1} - a_k) - (a_k - a_{k+1}): the chain's Laplacian (eq. 4); W is not read."""
    return (a[k - 1] - a[k]) - (a[k] - a[k + 1])


@njit(cache=True)
def fill(x, th, geo, p):
    """Ghost cells 0 and N + 1 of x and theta from the ends' kinds (geo[6], geo[7]), the load
    point at p."""
    N = geo[1]
    x[0] = ghost_x(geo[6], x[1], x[N], p)
    x[N + 1] = ghost_x(geo[7], x[N], x[1], p)
    th[0] = ghost_th(geo[6], th[1], th[N])
    th[N + 1] = ghost_th(geo[7], th[N], th[1])


@njit(cache=True, inline="always")
def fill_at(x, th, geo, p, k):
    """Set the ghost cell next to block k (at an end) as :func:`fill` does (the active-set path)."""
    N = geo[1]
    if k == 1:
        x[0] = ghost_x(geo[6], x[1], x[N], p)
        th[0] = ghost_th(geo[6], th[1], th[N])
    if k == N:
        x[N + 1] = ghost_x(geo[7], x[N], x[1], p)
        th[N + 1] = ghost_th(geo[7], th[N], th[1])


@njit(cache=True, inline="always")
def rim(k, geo):
    """Whether block k reads a ghost cell (block 1 or N)."""
    return k == 1 or k == geo[1]


@njit(cache=True, inline="always")
def neighbours(k, geo, out):
    """The blocks whose force reads block k (k - 1, k + 1; across periodic ends the other end),
    written to ``out``; returns how many."""
    N = geo[1]
    m = 0
    if k > 1:
        out[m] = k - 1
        m += 1
    elif geo[6] == PERIODIC:
        out[m] = N
        m += 1
    if k < N:
        out[m] = k + 1
        m += 1
    elif geo[7] == PERIODIC:
        out[m] = 1
        m += 1
    return m


@njit(cache=True)
def extent(first_step, x, x0ev, geo):
    """(area, moment, 1, 1, first block, last block) of the event whose blocks have
    ``first_step`` >= 0, moment summed in block order as the chain's S; resets ``first_step``."""
    N = geo[1]
    area = 0
    moment = 0.0
    lo, hi = N + 1, 0
    for i in range(1, N + 1):
        if first_step[i] >= 0:
            area += 1
            moment += x[i] - x0ev[i]
            first_step[i] = -1
            lo = min(lo, i)
            hi = max(hi, i)
    return area, moment, 1, 1, lo, hi


@dataclass(frozen=True)
class Chain:
    """N blocks on a line; ``left`` and ``right`` the kinds of its ends (``driven`` at block 1
    for the end drive of eq. (4))."""

    N: int
    left: str
    right: str
    name: str = "chain"

    @property
    def shape(self) -> tuple[int, int]:
        return 1, self.N

    @property
    def n_blocks(self) -> int:
        return self.N

    @property
    def width(self) -> int:
        return self.N + 2

    @property
    def size(self) -> int:
        return self.N + 2

    def geometry(self) -> np.ndarray:
        """The kernels' ``geo``: 1 row of N, stride N + 2, block 1 at index 1, no top or bottom."""
        return np.array([1, self.N, self.N + 2, 1, -1, -1, CODES[self.left], CODES[self.right]], dtype=np.int64)

    def index(self, r, c):
        return np.asarray(c) + 0 * np.asarray(r)

    def blocks(self) -> np.ndarray:
        return np.arange(1, self.N + 1)

    def coordinates(self) -> tuple[np.ndarray, np.ndarray]:
        """(row, col) of every block: row 1, col i."""
        return np.ones(self.N, dtype=np.int64), np.arange(1, self.N + 1)

    def padded(self, values) -> np.ndarray:
        out = np.zeros(self.N + 2)
        out[1:-1] = np.ravel(values) if np.ndim(values) else values
        return out

    def grid(self, a: np.ndarray) -> np.ndarray:
        return np.asarray(a)[1:-1].reshape(1, self.N).copy()

    def driven(self) -> np.ndarray:
        """Block 1 for the end drive (index N for a driven right end); none otherwise."""
        out = [i for i, kind in ((1, self.left), (self.N, self.right)) if kind == "driven"]
        return np.array(out, dtype=np.int64)

    def laplacian_matrix(self):
        """The chain's Laplacian over the blocks (sparse N x N), driven and fixed ghosts 0."""
        from stickslip.models.lattice.square import _line

        return _line(self.N, self.left, self.right)

    def eigenvalues(self) -> np.ndarray:
        """4 sin^2(k/2) over the chain's modes (:func:`~stickslip.models.lattice.edges.eigenvalues_1d`)."""
        return eigenvalues_1d(self.N, self.left, self.right)

    def strain(self, dx: np.ndarray) -> np.ndarray:
        """The springs' extensions e_i = dx_{i-1} - dx_i of a displacement dx of the blocks
        (1..N), dx_0 = 0 at the pulling point (eq. (4)'s end drive): the position part of the
        norm of :mod:`stickslip.models.lattice.norm`."""
        return np.concatenate(([0.0], dx[:-1])) - dx

    def unstrain(self, e: np.ndarray) -> np.ndarray:
        """The displacement whose :meth:`strain` is ``e``: dx_i = -(e_1 + ... + e_i)."""
        return -np.cumsum(e)

    def describe(self) -> str:
        return f"chain of {self.N} (left {self.left}, right {self.right})"


def build(shape, edges=None, *, edge_drive: bool = False, ends: str = "free") -> Chain:
    """The chain of N = ``shape`` blocks: block 1 driven with an edge drive, else the ends'
    kind; the right end the ends' kind (docs/model.md)."""
    if edges is not None:
        raise LatticeError("edges go with lattice square (the chain's ends are the ends piece)")
    try:
        N = int(shape[-1] if isinstance(shape, tuple) else shape)
    except (TypeError, ValueError):
        raise LatticeError(f"shape of a chain must be N, an integer >= 1 (got {shape!r})") from None
    if N < 1 or N > MAX_BLOCKS:
        raise LatticeError(f"shape of a chain must be N with 1 <= N <= {MAX_BLOCKS} (got {N})")
    if ends not in CODES or ends == "driven":
        raise LatticeError(f"ends must be free, fixed or periodic (got {ends!r})")
    return Chain(N, "driven" if edge_drive else ends, ends)
