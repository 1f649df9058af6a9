"""Edge kinds of a lattice and the 1-d spectra of its Laplacian (docs/lattice.md).

A side of a lattice is ``free`` (the ghost cell repeats the edge block: no spring beyond),
``fixed`` (a spring to a wall at x = 0), ``periodic`` (the opposite side is the neighbour) or
``driven`` (the ghost cell is the drive's load point p = V t: the end drive of eq. (4) pulls the
edge). The state variable has no flux through any side but a periodic one.
"""

from __future__ import annotations

import re

import numpy as np

FREE, FIXED, PERIODIC, DRIVEN = 0, 1, 2, 3
#: Edge kinds by name, and their codes in a lattice's ``geo`` vector.
CODES = {"free": FREE, "fixed": FIXED, "periodic": PERIODIC, "driven": DRIVEN}
EDGE_KINDS = tuple(CODES)
#: The sides of the square, in the order of its ``geo`` vector (top is row 1, left is column 1).
SIDES = ("top", "bottom", "left", "right")
#: Bytes per cell of the padded layout that a run on a lattice holds (docs/lattice.md, "Memory"):
#: the state (x, v, theta, the moving mask, the first moves and x there: 6 x 8), the Heun scratch
#: (6 x 8) and the active-set path's own arrays (candidates, next, moving, marks, triggers, moved
#: blocks: 6 x 8; the heap of 2 size entries of two int64: 32; the neighbour table of 5 int32: 20).
BYTES_PER_CELL = 6 * 8 + 6 * 8 + 6 * 8 + 32 + 20
#: The largest lattice (blocks), 4096 x 4096: its arrays take BYTES_PER_CELL x the padded cells,
#: about 3.3 GB, and every flat index fits the neighbour table's int32. A chain's largest N
#: (:data:`stickslip.models.params.MAX_BLOCKS`) is the chain kernels' and does not bound a lattice.
MAX_LATTICE_BLOCKS = 4096 * 4096


class LatticeError(ValueError):
    """A lattice's shape or edges that cannot be built; the message is one line."""


def parse_shape(shape, name: str = "shape") -> tuple[int, int]:
    """(rows, cols) from ``(rows, cols)`` or ``"RxC"``, each an integer >= 1, at most
    :data:`MAX_LATTICE_BLOCKS` blocks in all."""
    text = None
    if isinstance(shape, str):
        m = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", shape)
        if m is None:
            raise LatticeError(f"{name} must be ROWSxCOLS with integers >= 1, e.g. 64x64 (got {shape!r})")
        text = (int(m.group(1)), int(m.group(2)))
    else:
        try:
            rows, cols = shape
            text = (int(rows), int(cols))
            if text != (rows, cols):
                raise ValueError
        except (TypeError, ValueError):
            raise LatticeError(f"{name} must be (rows, cols), integers >= 1 (got {shape!r})") from None
    rows, cols = text
    if rows < 1 or cols < 1:
        raise LatticeError(f"{name} must have rows >= 1 and cols >= 1 (got {rows}x{cols})")
    if rows * cols > MAX_LATTICE_BLOCKS:
        raise LatticeError(f"{name} must have at most {MAX_LATTICE_BLOCKS} blocks (got {rows}x{cols})")
    return rows, cols


def parse_edges(edges, default: str = "free") -> dict[str, str]:
    """Edge kind per side from ``edges``: None (every side ``default``), one kind for every side
    (``"periodic"``), ``"top=fixed,left=driven"`` (sides not named are ``default``) or a dict.
    ``default`` "-" marks the sides not named."""
    if default not in CODES and default != "-":
        raise LatticeError(f"edges must be {', '.join(EDGE_KINDS)} (got {default!r})")
    out = dict.fromkeys(SIDES, default)
    if edges is None:
        return out
    if isinstance(edges, str):
        if "=" not in edges:
            edges = {side: edges.strip() for side in SIDES}
        else:
            pairs = {}
            for item in edges.split(","):
                side, sep, kind = item.partition("=")
                if not sep:
                    raise LatticeError(f"edges must be KIND or SIDE=KIND,... (got {item!r})")
                pairs[side.strip()] = kind.strip()
            edges = pairs
    if not isinstance(edges, dict):
        raise LatticeError(f"edges must be a kind, SIDE=KIND,... or a dict (got {edges!r})")
    for side, kind in edges.items():
        if side not in SIDES:
            raise LatticeError(f"edges: side must be one of {', '.join(SIDES)} (got {side!r})")
        if kind not in CODES:
            raise LatticeError(f"edges: {side} must be one of {', '.join(EDGE_KINDS)} (got {kind!r})")
        out[side] = kind
    return out


def check_pairs(edges: dict[str, str], edge_drive: bool) -> None:
    """Refuse edges that do not close: a periodic side whose opposite is not periodic, a driven
    side without an edge drive, an edge drive with no driven side or more than one."""
    for a, b in (("top", "bottom"), ("left", "right")):
        if (edges[a] == "periodic") != (edges[b] == "periodic"):
            raise LatticeError(f"edges: {a} and {b} must both be periodic or neither (got {edges[a]}, {edges[b]})")
    driven = [s for s in SIDES if edges[s] == "driven"]
    if edge_drive and len(driven) != 1:
        raise LatticeError(f"edges: an edge drive pulls exactly one side (got driven sides: {driven or 'none'})")
    if not edge_drive and driven:
        raise LatticeError(f"edges: side {driven[0]} is driven, but the drive acts on every block (no edge to pull)")


def _dirichlet(kind: str) -> bool:
    return kind in ("fixed", "driven")


def eigenvalues_1d(n: int, low: str, high: str) -> np.ndarray:
    """Eigenvalues of minus the 1-d discrete Laplacian of n blocks with the sides ``low`` and
    ``high`` (ascending): 4 sin^2(k/2) with k = 2 pi m / n (periodic), pi m / n (free, free),
    pi m / (n + 1) (fixed or driven at both: the ghost cell is 0 in the frame of the drive and the
    wall) and pi (2 m - 1) / (2 n + 1) (one of each), m over the n modes."""
    if low == "periodic" or high == "periodic":
        k = 2.0 * np.pi * np.arange(n) / n
    elif _dirichlet(low) and _dirichlet(high):
        k = np.pi * np.arange(1, n + 1) / (n + 1)
    elif _dirichlet(low) or _dirichlet(high):
        k = np.pi * (2 * np.arange(1, n + 1) - 1) / (2 * n + 1)
    else:
        k = np.pi * np.arange(n) / n
    return np.sort(4.0 * np.sin(k / 2.0) ** 2)
