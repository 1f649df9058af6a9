"""The lattices a model's blocks sit on, one module each (docs/lattice.md).

A lattice owns the geometry that the pieces (drive, friction, threshold; :mod:`stickslip.models.pieces`)
leave out: the padded flat layout of the state arrays, the ghost cells around the blocks, the
discrete Laplacians of x and theta the pieces receive, the blocks an edge drive pulls, the blocks'
coordinates, the Laplacian's eigenvalues (the normal modes of the stability analysis) and an
event's extent. :data:`LATTICES` lists them:

* ``chain`` (:mod:`~stickslip.models.lattice.chain`): eq. (4)'s N blocks on a line, ghost cells
  at 0 and N + 1; its Laplacian is the chain kernels' own expression, bit for bit;
* ``square`` (:mod:`~stickslip.models.lattice.square`): L_rows x L_cols blocks, the 5-point
  Laplacian, an edge of its own kind on each side (free, fixed, periodic, or driven by an edge
  drive).

Each module holds a frozen dataclass (the geometry, in plain numpy) and the compiled functions a
lattice kernel calls through :func:`stickslip.kernels.laws.call`, the module's import path being
a literal of the kernel like a piece's: ``fill(x, th, geo, p)`` (ghost cells), ``lap(a, k, W)``
(the Laplacian at flat index k), ``neighbours(k, geo, out)`` (the blocks whose force reads block
k, for the active-set path) and ``extent(first_step, x, x0ev, geo)`` (an event's area, moment and
bounding box). ``geo`` is the int64 vector of :meth:`geometry`:
(rows, cols, row stride W, flat index of the first block, edge codes of top, bottom, left, right).
"""

from __future__ import annotations

import importlib

from stickslip.models.lattice.edges import (
    CODES,
    DRIVEN,
    EDGE_KINDS,
    FIXED,
    FREE,
    PERIODIC,
    SIDES,
    LatticeError,
    eigenvalues_1d,
    parse_edges,
    parse_shape,
)

__all__ = [
    "CODES",
    "DRIVEN",
    "EDGE_KINDS",
    "FIXED",
    "FREE",
    "LATTICES",
    "PERIODIC",
    "SIDES",
    "LatticeError",
    "eigenvalues_1d",
    "lattice",
    "module_of",
    "parse_edges",
    "parse_shape",
]

#: The lattices, one module each in :mod:`stickslip.models.lattice`.
LATTICES = ("chain", "square")


def module_of(name: str) -> str:
    """The import path of the module of lattice ``name`` (what a lattice kernel is compiled for)."""
    if name not in LATTICES:
        raise LatticeError(f"lattice must be one of {', '.join(LATTICES)} (got {name!r})")
    return f"stickslip.models.lattice.{name}"


def lattice(name: str, shape, edges=None, *, edge_drive: bool = False, ends: str = "free"):
    """The lattice ``name`` of ``shape`` with ``edges`` (docs/lattice.md).

    Parameters
    ----------
    name : {'chain', 'square'}
        The lattice.
    shape : int, tuple of int or str
        The chain's N; the square's (rows, cols), or ``"64x64"``.
    edges : str or dict, optional
        The square's edges per side (:func:`~stickslip.models.lattice.edges.parse_edges`); the
        chain's are the drive's and ``ends``.
    edge_drive : bool
        The drive pulls one edge (the end drive of eq. (4), a load history): block 1 of the chain,
        the left column of the square unless ``edges`` names another side ``driven``.
    ends : str
        The chain's ends piece (free, fixed, periodic), and the square's kind of every side
        ``edges`` leaves out.

    Returns
    -------
    Chain or Square
        A frozen dataclass; a bad shape or edge raises :class:`LatticeError` in one line.
    """
    mod = importlib.import_module(module_of(name))
    return mod.build(shape, edges, edge_drive=edge_drive, ends=ends)
