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
        ((2000, 2000), None, "at most"),
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
