"""The lattice piece (docs/lattice.md): layout, ghost cells, Laplacians, driven sets, coordinates,
eigenvalues and shapes, against values computed here by other means."""

from __future__ import annotations

import numpy as np
import pytest

from stickslip.models.lattice import LatticeError, chain, lattice, square
from stickslip.models.lattice.edges import eigenvalues_1d, parse_edges, parse_shape

SIDES = ("top", "bottom", "left", "right")
#: edge kinds per side (top, bottom, left, right)
SQUARES = [
    ("free",) * 4,
    ("fixed",) * 4,
    ("periodic",) * 4,
    ("periodic", "periodic", "driven", "fixed"),
    ("fixed", "free", "free", "driven"),
]


def _lap_by_stencil(lat, a_grid, kinds, p=0.0):
    """The Laplacian of a (rows, cols) field with each side's ghost rule written out with np.pad."""
    top, bottom, left, right = kinds
    g = np.pad(a_grid, 1)
    rule = {"free": lambda edge, other: edge, "fixed": lambda e, o: 0.0 * e, "periodic": lambda e, o: o}
    rule["driven"] = lambda e, o: 0.0 * e + p
    g[1:-1, 0] = rule[left](a_grid[:, 0], a_grid[:, -1])
    g[1:-1, -1] = rule[right](a_grid[:, -1], a_grid[:, 0])
    g[0, 1:-1] = rule[top](a_grid[0, :], a_grid[-1, :])
    g[-1, 1:-1] = rule[bottom](a_grid[-1, :], a_grid[0, :])
    c = g[1:-1, 1:-1]
    return (g[1:-1, :-2] - c) + (g[1:-1, 2:] - c) + (g[:-2, 1:-1] - c) + (g[2:, 1:-1] - c)


def _compiled_lap(module, lat, grid, p=0.0):
    x = lat.padded(grid)
    th = lat.padded(grid)
    module.fill(x, th, lat.geometry(), p)
    W = lat.width
    return np.array([module.lap(x, k, W) for k in lat.blocks()]).reshape(lat.shape), x


@pytest.mark.parametrize("shape", [(3, 4), (5, 5), (1, 6), (4, 1), (2, 2)])
@pytest.mark.parametrize("kinds", SQUARES)
def test_square_laplacian_matches_the_stencil(shape, kinds):
    edge_drive = "driven" in kinds
    lat = lattice("square", shape, dict(zip(SIDES, kinds, strict=True)), edge_drive=edge_drive)
    grid = np.random.default_rng(1).normal(size=shape)
    got, _ = _compiled_lap(square, lat, grid, p=0.7)
    np.testing.assert_allclose(got, _lap_by_stencil(lat, grid, kinds, p=0.7), rtol=0, atol=1e-12)


@pytest.mark.parametrize("shape", [(3, 4), (5, 5), (1, 5), (3, 1), (2, 3)])
@pytest.mark.parametrize("kinds", SQUARES + [("free", "fixed", "driven", "free")])
def test_eigenvalues_are_those_of_the_stencil(shape, kinds):
    """The closed-form spectrum (4 sin^2(kx/2) + 4 sin^2(ky/2)) against the eigenvalues of the
    matrix whose columns are the compiled stencil applied to unit fields (the load point at 0)."""
    lat = lattice("square", shape, dict(zip(SIDES, kinds, strict=True)), edge_drive="driven" in kinds)
    n = lat.n_blocks
    cols = [_compiled_lap(square, lat, np.eye(n)[j].reshape(shape))[0].ravel() for j in range(n)]
    A = np.array(cols).T
    np.testing.assert_allclose(np.sort(-np.linalg.eigvals(A).real), lat.eigenvalues(), atol=1e-10)
    np.testing.assert_allclose(lat.laplacian_matrix().toarray(), A, atol=0)


def test_periodic_eigenvalues_closed_form():
    lat = lattice("square", (4, 6), "periodic", edge_drive=False)
    kx, ky = 2 * np.pi * np.arange(6) / 6, 2 * np.pi * np.arange(4) / 4
    want = (4 * np.sin(ky[:, None] / 2) ** 2 + 4 * np.sin(kx[None, :] / 2) ** 2).ravel()
    np.testing.assert_allclose(lat.eigenvalues(), np.sort(want), atol=1e-14)
    # the chain's end drive: (2m - 1) pi / (2N + 1), the modes of a pulled end and a free one
    np.testing.assert_allclose(eigenvalues_1d(3, "driven", "free"), 4 * np.sin(np.array([1, 3, 5]) * np.pi / 14) ** 2)


def test_chain_lattice_is_the_chain_kernels():
    """The chain's ghost cells and Laplacian are stickslip.kernels.laws's, bit for bit."""
    from numba import njit

    from stickslip.kernels.laws import _set_ghosts

    def ghosts(drive, ends):
        pieces = f"'stickslip.models.drive.{drive}', 'stickslip.models.ends.{ends}'"
        source = f"def g(x, th, p):\n    _set_ghosts(x, th, 7, p, {pieces})\n"
        scope = {"_set_ghosts": _set_ghosts}
        exec(source, scope)
        return njit(scope["g"])

    rng = np.random.default_rng(3)
    for drive, ends, edge in (("end", "free", True), ("plate", "periodic", False), ("plate", "fixed", False)):
        lat = lattice("chain", 7, edge_drive=edge, ends=ends)
        x0, th0 = rng.normal(size=9), rng.random(9)
        x, th = x0.copy(), th0.copy()
        chain.fill(x, th, lat.geometry(), 0.37)
        xr, thr = x0.copy(), th0.copy()
        ghosts(drive, ends)(xr, thr, 0.37)
        assert x.tobytes() == xr.tobytes() and th.tobytes() == thr.tobytes()
        for k in range(1, 8):
            assert chain.lap(x, k, 9) == (x[k - 1] - x[k]) - (x[k] - x[k + 1])


def test_driven_set_coordinates_and_layout():
    lat = lattice("square", (3, 4), edge_drive=True)
    assert lat.edges == ("free", "free", "driven", "free")
    assert lat.size == 5 * 6 and lat.width == 6
    r, c = lat.coordinates()
    assert list(zip(r[:5], c[:5], strict=True)) == [(1, 1), (1, 2), (1, 3), (1, 4), (2, 1)]
    assert list(lat.driven()) == [lat.index(1, 1), lat.index(2, 1), lat.index(3, 1)]
    grid = np.arange(12.0).reshape(3, 4)
    assert (lat.grid(lat.padded(grid)) == grid).all()
    top = lattice("square", (3, 4), "top=driven", edge_drive=True)
    assert list(top.driven()) == [top.index(1, c) for c in range(1, 5)]
    assert list(lattice("chain", 5, edge_drive=True).driven()) == [1]
    assert len(lattice("chain", 5, ends="periodic").driven()) == 0


def test_extent():
    lat = lattice("square", (4, 5), "periodic")
    first = np.full(lat.size, -1, dtype=np.int64)
    x, x0 = np.zeros(lat.size), np.zeros(lat.size)
    for r, c, s in ((2, 3, 0.5), (3, 3, 0.25), (3, 5, 1.0)):
        k = lat.index(r, c)
        first[k], x[k] = 10, s
    area, moment, r0, r1, c0, c1 = square.extent(first, x, x0, lat.geometry())
    assert (area, moment, r0, r1, c0, c1) == (3, 1.75, 2, 3, 3, 5)
    assert (first == -1).all()


@pytest.mark.parametrize(
    "shape, edges, message",
    [
        ("64", None, "shape must be ROWSxCOLS"),
        ("0x5", None, "rows >= 1"),
        ((3, 2.5), None, r"shape must be \(rows, cols\)"),
        ((3, 3), "top=periodic", "top and bottom must both be periodic"),
        ((3, 3), "middle=free", "side must be one of"),
        ((3, 3), "sticky", "top must be one of"),
        ((4097, 4096), None, "at most"),
    ],
)
def test_bad_shapes_and_edges(shape, edges, message):
    with pytest.raises(LatticeError, match=message):
        lattice("square", shape, edges)


def test_edges_and_drives_must_fit():
    with pytest.raises(LatticeError, match="drive acts on every block"):
        lattice("square", (3, 3), "left=driven")
    with pytest.raises(LatticeError, match="exactly one side"):
        lattice("square", (3, 3), "periodic", edge_drive=True)
    with pytest.raises(LatticeError, match="exactly one side"):
        lattice("square", (3, 3), "left=driven,right=driven", edge_drive=True)
    assert parse_shape("64x32") == (64, 32)
    assert parse_edges("top=fixed", default="periodic")["left"] == "periodic"


@pytest.mark.parametrize("draw", range(6))
def test_fill_at_rim_and_neighbours_are_the_stencil(draw):
    """The active-set path's pieces of a lattice against the whole ring and the stencil: fill_at
    writes, next to each block, what fill writes there; rim says whether the block reads a
    ghost cell; neighbours are the blocks whose 5-point stencil reads it."""
    rng = np.random.default_rng(draw)
    rows, cols = (int(n) for n in rng.integers(1, 6, 2))
    kinds = {}
    for a, b in (("top", "bottom"), ("left", "right")):
        if rng.random() < 0.4:
            kinds[a] = kinds[b] = "periodic"
        else:
            kinds[a], kinds[b] = rng.choice(["free", "fixed"], 2)
    lat = lattice("square", (rows, cols), ",".join(f"{s}={k}" for s, k in kinds.items()))
    geo = lat.geometry()
    x, th = rng.normal(size=lat.size), rng.normal(size=lat.size)
    ref_x, ref_th = x.copy(), th.copy()
    square.fill.py_func(ref_x, ref_th, geo, 0.25)
    is_block = np.zeros(lat.size, dtype=bool)
    is_block[lat.blocks()] = True
    W = lat.width
    out = np.zeros(4, dtype=np.int64)
    for k in lat.blocks():
        stencil = (k - 1, k + 1, k - W, k + W)
        ghosts = [j for j in stencil if not is_block[j]]
        ax, at = x.copy(), th.copy()
        square.fill_at.py_func(ax, at, geo, 0.25, k)
        changed = set(np.flatnonzero((ax != x) | (at != th)))
        assert changed <= set(ghosts)
        for j in ghosts:
            assert ax[j] == ref_x[j] and at[j] == ref_th[j]
        assert square.rim.py_func(k, geo) == bool(ghosts)
        # who reads k: each block whose stencil (ghosts mapped through a periodic side) holds k
        readers = set()
        for q in lat.blocks():
            for j in (q - 1, q + 1, q - W, q + W):
                if j == k or (not is_block[j] and _periodic_image(lat, q, j) == k):
                    readers.add(int(q))
        readers.discard(int(k))
        m = square.neighbours.py_func(k, geo, out)
        assert set(out[:m].tolist()) - {int(k)} == readers


def _periodic_image(lat, q, j):
    """The block a ghost cell j beside block q stands for across a periodic side (None else)."""
    W, R, C = lat.width, lat.rows, lat.cols
    r, c = divmod(int(q), W)
    top, bottom, left, right = lat.edges
    if j == q - 1 and c == 1 and left == "periodic":
        return q + C - 1
    if j == q + 1 and c == C and right == "periodic":
        return q - C + 1
    if j == q - W and r == 1 and top == "periodic":
        return q + (R - 1) * W
    if j == q + W and r == R and bottom == "periodic":
        return q - (R - 1) * W
    return None


def test_a_million_blocks_and_more_fit_their_memory():
    """1024 x 1024 (beyond a chain's largest N) is accepted, N is the lattice's, and the arrays a
    run holds are the footprint counted by hand: state, scratch and the active-set path's."""
    from stickslip.models.lattice.edges import MAX_LATTICE_BLOCKS
    from stickslip.models.presets import chain_params
    from stickslip.run.lattice import _sparse_args, initial_state

    big = chain_params("carlson-langer", lattice="square", shape="1024x1024")
    assert big.N == 1024 * 1024 and big.lattice.size == 1026 * 1026
    # state 6 x 8, scratch 6 x 8, active set 6 x 8 + heap 2 x 2 x 8 + table 5 x 4 bytes per cell
    assert big.footprint() == 1026 * 1026 * 196 < 2 * 10**9
    assert MAX_LATTICE_BLOCKS == 4096 * 4096
    p = chain_params("carlson-langer", lattice="square", shape=(5, 7))
    s = initial_state(p, "rest", amplitude=0.01)
    held = sum(getattr(s, f).nbytes for f in ("xg", "vg", "thg", "mov", "first_step", "x0ev"))
    held += 6 * np.zeros(p.lattice.size).nbytes  # run_lattice's scratch
    sp = _sparse_args(p)
    held += sum(a.nbytes for a in sp)
    # the heap's 16 spare entries of two int64 and the bookkeeping vector besides
    assert held - p.footprint() == 2 * 16 * 8 + sp.book.nbytes
