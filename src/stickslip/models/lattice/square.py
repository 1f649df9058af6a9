"""The square lattice: L_rows x L_cols blocks, each joined by springs K to its four neighbours
(docs/lattice.md), the fault plane of the two-dimensional Burridge-Knopoff and Carlson-Langer
models and of eq. (4) in two dimensions.

Layout: the state arrays are flat, of (rows + 2) x (cols + 2), row-major with the row stride
W = cols + 2; block (r, c), r = 1..rows from the top and c = 1..cols from the left, sits at
k = r W + c, and the ring of ghost cells around the blocks is set before each stage by
:func:`fill` from each side's kind (:mod:`stickslip.models.lattice.edges`). The corners are never
read. The Laplacian of the 5-point stencil is the chain's along the row plus the chain's along the
column, :func:`lap`, so on a single row with free top and bottom it gives the chain's bits.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stickslip.models.lattice.edges import (
    CODES,
    FIXED,
    FREE,
    PERIODIC,
    SIDES,
    LatticeError,
    check_pairs,
    eigenvalues_1d,
    parse_edges,
    parse_shape,
)
from stickslip.models.piece import njit


@njit(cache=True, inline="always")
def lap(a, k, W):
    """The 5-point Laplacian at flat index k, row stride W: (a_l - a) - (a - a_r) along the row
    (the chain's expression, eq. 4), plus the same along the column."""
    return ((a[k - 1] - a[k]) - (a[k] - a[k + 1])) + ((a[k - W] - a[k]) - (a[k] - a[k + W]))


@njit(cache=True, inline="always")
def ghost_x(code, edge, other, p):
    """x of a ghost cell beyond a side of kind ``code``: the edge block's (free), the wall at 0
    (fixed), the opposite side's (periodic), the load point p (driven)."""
    if code == FREE:
        return edge
    if code == FIXED:
        return 0.0
    if code == PERIODIC:
        return other
    return p


@njit(cache=True, inline="always")
def ghost_th(code, edge, other):
    """theta of a ghost cell: the opposite side's (periodic), else the edge block's (no flux)."""
    if code == PERIODIC:
        return other
    return edge


@njit(cache=True)
def fill(x, th, geo, p):
    """Set the ghost ring of x and theta from the sides' kinds, the load point at p."""
    R, C, W = geo[0], geo[1], geo[2]
    top, bottom, left, right = geo[4], geo[5], geo[6], geo[7]
    for r in range(1, R + 1):
        k1 = r * W + 1
        kc = r * W + C
        x[k1 - 1] = ghost_x(left, x[k1], x[kc], p)
        x[kc + 1] = ghost_x(right, x[kc], x[k1], p)
        th[k1 - 1] = ghost_th(left, th[k1], th[kc])
        th[kc + 1] = ghost_th(right, th[kc], th[k1])
    for c in range(1, C + 1):
        k1 = W + c
        kr = R * W + c
        x[c] = ghost_x(top, x[k1], x[kr], p)
        x[kr + W] = ghost_x(bottom, x[kr], x[k1], p)
        th[c] = ghost_th(top, th[k1], th[kr])
        th[kr + W] = ghost_th(bottom, th[kr], th[k1])


@njit(cache=True, inline="always")
def fill_at(x, th, geo, p, k):
    """Set the ghost cells next to block k (none inside the square) as :func:`fill` does: what
    the active-set path fills before computing block k, O(1) per block instead of the ring."""
    R, C, W = geo[0], geo[1], geo[2]
    r = k // W
    c = k - r * W
    if c == 1:
        x[k - 1] = ghost_x(geo[6], x[k], x[k + C - 1], p)
        th[k - 1] = ghost_th(geo[6], th[k], th[k + C - 1])
    if c == C:
        x[k + 1] = ghost_x(geo[7], x[k], x[k - C + 1], p)
        th[k + 1] = ghost_th(geo[7], th[k], th[k - C + 1])
    if r == 1:
        x[k - W] = ghost_x(geo[4], x[k], x[k + (R - 1) * W], p)
        th[k - W] = ghost_th(geo[4], th[k], th[k + (R - 1) * W])
    if r == R:
        x[k + W] = ghost_x(geo[5], x[k], x[k - (R - 1) * W], p)
        th[k + W] = ghost_th(geo[5], th[k], th[k - (R - 1) * W])


@njit(cache=True, inline="always")
def rim(k, geo):
    """Whether block k reads a ghost cell (it sits on a side): those :func:`fill_at` fills."""
    R, C, W = geo[0], geo[1], geo[2]
    r = k // W
    c = k - r * W
    return r == 1 or r == R or c == 1 or c == C


@njit(cache=True, inline="always")
def neighbours(k, geo, out):
    """The blocks whose force reads block k through the stencil (left, right, up, down; across
    a periodic side the opposite edge's block), written to ``out``; returns how many."""
    R, C, W = geo[0], geo[1], geo[2]
    r = k // W
    c = k - r * W
    m = 0
    if c > 1:
        out[m] = k - 1
        m += 1
    elif geo[6] == PERIODIC:
        out[m] = k + C - 1
        m += 1
    if c < C:
        out[m] = k + 1
        m += 1
    elif geo[7] == PERIODIC:
        out[m] = k - C + 1
        m += 1
    if r > 1:
        out[m] = k - W
        m += 1
    elif geo[4] == PERIODIC:
        out[m] = k + (R - 1) * W
        m += 1
    if r < R:
        out[m] = k + W
        m += 1
    elif geo[5] == PERIODIC:
        out[m] = k - (R - 1) * W
        m += 1
    return m


@njit(cache=True)
def extent(first_step, x, x0ev, geo):
    """The extent of the event whose blocks have ``first_step`` >= 0: (area, moment, row_min,
    row_max, col_min, col_max), area the number of blocks that slipped and moment their total
    slip sum (x - x at first move), summed row by row; resets ``first_step`` to -1."""
    R, C, W = geo[0], geo[1], geo[2]
    area = 0
    moment = 0.0
    r0, r1, c0, c1 = R + 1, 0, C + 1, 0
    for r in range(1, R + 1):
        for c in range(1, C + 1):
            k = r * W + c
            if first_step[k] >= 0:
                area += 1
                moment += x[k] - x0ev[k]
                first_step[k] = -1
                r0 = min(r0, r)
                r1 = max(r1, r)
                c0 = min(c0, c)
                c1 = max(c1, c)
    return area, moment, r0, r1, c0, c1


@dataclass(frozen=True)
class Square:
    """The square lattice of ``rows`` x ``cols`` blocks with an edge kind per side
    (``edges``: top, bottom, left, right; :mod:`stickslip.models.lattice.edges`)."""

    rows: int
    cols: int
    edges: tuple[str, str, str, str]
    name: str = "square"

    @property
    def shape(self) -> tuple[int, int]:
        """(rows, cols)."""
        return self.rows, self.cols

    @property
    def n_blocks(self) -> int:
        return self.rows * self.cols

    @property
    def width(self) -> int:
        """Row stride W of the padded layout."""
        return self.cols + 2

    @property
    def size(self) -> int:
        """Length of the padded flat arrays."""
        return (self.rows + 2) * (self.cols + 2)

    def edge(self, side: str) -> str:
        return self.edges[SIDES.index(side)]

    def geometry(self) -> np.ndarray:
        """The kernels' ``geo``: rows, cols, W, first block's index, edge codes (top, bottom, left,
        right)."""
        return np.array(
            [self.rows, self.cols, self.width, self.width + 1, *(CODES[e] for e in self.edges)], dtype=np.int64
        )

    def index(self, r, c):
        """Flat index of block (r, c), 1-based."""
        return np.asarray(r) * self.width + np.asarray(c)

    def blocks(self) -> np.ndarray:
        """Flat indices of the blocks in row-major order."""
        r, c = self.coordinates()
        return self.index(r, c)

    def coordinates(self) -> tuple[np.ndarray, np.ndarray]:
        """(row, col) of every block, 1-based, in row-major order."""
        r, c = np.meshgrid(np.arange(1, self.rows + 1), np.arange(1, self.cols + 1), indexing="ij")
        return r.ravel(), c.ravel()

    def padded(self, values) -> np.ndarray:
        """A flat padded array with ``values`` (rows x cols, or a scalar) at the blocks, 0 at the ghosts."""
        out = np.zeros((self.rows + 2, self.cols + 2))
        out[1:-1, 1:-1] = values
        return out.ravel()

    def grid(self, a: np.ndarray) -> np.ndarray:
        """The blocks of a flat padded array as a (rows, cols) copy."""
        return np.asarray(a).reshape(self.rows + 2, self.cols + 2)[1:-1, 1:-1].copy()

    def driven(self) -> np.ndarray:
        """Flat indices of the blocks next to a driven side (those an edge drive pulls)."""
        r, c = self.coordinates()
        near = {"top": r == 1, "bottom": r == self.rows, "left": c == 1, "right": c == self.cols}
        mask = np.zeros(self.n_blocks, dtype=bool)
        for side, kind in zip(SIDES, self.edges, strict=True):
            if kind == "driven":
                mask |= near[side]
        return self.index(r[mask], c[mask])

    def laplacian_matrix(self):
        """The 5-point Laplacian over the blocks as a scipy sparse matrix (row-major
        block order), a driven or fixed side's ghost taken as 0 (the frame of the load point or
        the wall), so that lap(x) = A x + (the ghosts' known values)."""
        from scipy import sparse

        R, C = self.rows, self.cols
        top, bottom, left, right = self.edges
        return sparse.kronsum(_line(C, left, right), _line(R, top, bottom), format="csr")

    def eigenvalues(self) -> np.ndarray:
        """Eigenvalues of minus the Laplacian, ascending: 4 sin^2(kx/2) + 4 sin^2(ky/2) over the
        modes of each direction (:func:`~stickslip.models.lattice.edges.eigenvalues_1d`)."""
        top, bottom, left, right = self.edges
        lx = eigenvalues_1d(self.cols, left, right)
        ly = eigenvalues_1d(self.rows, top, bottom)
        return np.sort((ly[:, None] + lx[None, :]).ravel())

    def _toward_driven(self, a: np.ndarray) -> np.ndarray:
        """The (rows, cols) field ``a`` turned so that the driven side (the left if none) is at
        the left of each row (a view; :meth:`_from_driven` turns it back)."""
        side = next((s for s, kind in zip(SIDES, self.edges, strict=True) if kind == "driven"), "left")
        return {"left": a, "right": a[:, ::-1], "top": a.T, "bottom": a[::-1].T}[side]

    def _from_driven(self, a: np.ndarray) -> np.ndarray:
        side = next((s for s, kind in zip(SIDES, self.edges, strict=True) if kind == "driven"), "left")
        return {"left": a, "right": a[:, ::-1], "top": a.T, "bottom": a.T[::-1]}[side]

    def strain(self, dx: np.ndarray) -> np.ndarray:
        """The extensions of the springs along each line from the driven side (the left if no
        side is driven) of a displacement dx of the blocks (flat, row-major): every such line is
        the chain's, e_i = dx_{i-1} - dx_i with dx_0 = 0 at the pulling point
        (:meth:`stickslip.models.lattice.chain.Chain.strain`), so a square of one row gives the
        chain's bits. The position part of the norm of :mod:`stickslip.models.lattice.norm`."""
        g = self._toward_driven(np.asarray(dx).reshape(self.shape))
        e = np.concatenate((np.zeros((g.shape[0], 1)), g[:, :-1]), axis=1) - g
        return np.ascontiguousarray(self._from_driven(e)).ravel()

    def unstrain(self, e: np.ndarray) -> np.ndarray:
        """The displacement (flat, row-major) whose :meth:`strain` is ``e``: along each line from
        the driven side, dx_i = -(e_1 + ... + e_i)."""
        g = self._toward_driven(np.asarray(e).reshape(self.shape))
        return np.ascontiguousarray(self._from_driven(-np.cumsum(g, axis=1))).ravel()

    def describe(self) -> str:
        sides = ", ".join(f"{s} {e}" for s, e in zip(SIDES, self.edges, strict=True))
        return f"square {self.rows}x{self.cols} ({sides})"


def _line(n: int, low: str, high: str):
    """The 1-d Laplacian of n blocks with the sides ``low`` and ``high`` (sparse, n x n)."""
    from scipy import sparse

    main = np.full(n, -2.0)
    off = np.ones(n - 1)
    A = sparse.diags([off, main, off], [-1, 0, 1], shape=(n, n), format="lil")
    if low == "periodic":
        A[0, n - 1] += 1.0
        A[n - 1, 0] += 1.0
    for end, kind in ((0, low), (n - 1, high)):
        if kind == "free":
            A[end, end] += 1.0
    return A.tocsr()


def build(shape, edges=None, *, edge_drive: bool = False, ends: str = "free") -> Square:
    """The square of ``shape`` ((rows, cols) or ``"RxC"``) with ``edges``; with an edge drive the
    left side is driven unless ``edges`` names another (docs/lattice.md)."""
    rows, cols = parse_shape(shape)
    kinds = parse_edges(edges, default=ends)
    if edge_drive and "driven" not in kinds.values():
        named = SIDES if isinstance(edges, str) and "=" not in edges else parse_edges(edges, default="-")
        if kinds["left"] == "periodic" or (named is not SIDES and named["left"] != "-"):
            raise LatticeError(
                f"edges: an edge drive pulls exactly one side, the left unless another is named driven "
                f"(got left {kinds['left']})"
            )
        kinds["left"] = "driven"
    check_pairs(kinds, edge_drive)
    return Square(rows, cols, tuple(kinds[s] for s in SIDES))
