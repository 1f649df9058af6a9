"""A model on a lattice: the pieces and parameters of :class:`~stickslip.models.params.ChainParams`
with the lattice they sit on (docs/lattice.md)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from stickslip.models.disorder import PerBlock
from stickslip.models.lattice import LATTICES, LatticeError, lattice
from stickslip.models.params import MAX_BLOCKS, ChainParams, ParameterError
from stickslip.models.pieces import context_refusal


@dataclass(frozen=True)
class LatticeParams:
    """The model ``chain`` (pieces and parameters, eq. (4) and its relatives) on ``lattice``
    (:mod:`stickslip.models.lattice`): every parameter of the model is the chain's, read at each
    block; the chain's N is the lattice's number of blocks (up to a chain's largest; ``N`` here is
    always the lattice's). Attributes of the model are read
    through (``p.K``, ``p.drive_piece``)."""

    chain: ChainParams
    lattice: Any

    @property
    def N(self) -> int:
        """The number of blocks, the lattice's (the chain's N stops at a chain's largest)."""
        return self.lattice.n_blocks

    def footprint(self) -> int:
        """Bytes of the arrays a run on the lattice holds, state, scratch and the active-set
        path's bookkeeping (:data:`~stickslip.models.lattice.edges.BYTES_PER_CELL` per cell of
        the padded layout); snapshots and the event table come on top."""
        from stickslip.models.lattice.edges import BYTES_PER_CELL

        return BYTES_PER_CELL * self.lattice.size

    def __getattr__(self, name: str) -> Any:
        # Only after construction (not for the fields themselves, which unpickling looks up first).
        if name.startswith("__") or name in ("chain", "lattice"):
            raise AttributeError(name)
        return getattr(self.chain, name)

    def replace(self, **changes: Any) -> LatticeParams:
        """The same lattice with some of the model's fields changed (validated again, as
        :meth:`ChainParams.replace <stickslip.models.params._Validated.replace>` does, and against
        the lattice as :func:`on_lattice` does); N is the lattice's, so it is refused here."""
        if "N" in changes:
            raise ParameterError("N of a model on a lattice is its shape's: give the lattice a new shape instead")
        chain = self.chain.replace(**changes)
        if chain.drive_piece is self.chain.drive_piece and chain.ends == self.chain.ends and "K" not in changes:
            return LatticeParams(chain, self.lattice)
        return on_lattice(chain, self.lattice.name, self.lattice.shape, self._edges())

    def _edges(self) -> dict[str, str] | None:
        return self.to_dict().get("edges")

    def leaf(self) -> float | np.ndarray:
        """The stiffness of the spring joining every block to the drive: the drive's ``leaf``
        (a plate's Kp; 0 for an edge drive and a force), a float, or the values over (row, col)
        where it differs from block to block (a per-block Kp)."""
        import importlib

        pc = self.chain.drive_piece
        leaf = importlib.import_module(pc.module).leaf
        # the plain-Python form of the drive's compiled function: read once, nothing to compile
        value = getattr(leaf, "py_func", leaf)(self.kernel_params(pc))
        return float(value) if np.ndim(value) == 0 else self.lattice.grid(np.asarray(value, dtype=np.float64))

    def pad(self, values) -> np.ndarray:
        """The N values of a per-block parameter (row-major over the lattice's blocks) in the
        lattice's padded flat layout, 0 at the ghost cells: what the lattice kernels read at each
        block (:func:`stickslip.kernels.laws.at`)."""
        return self.lattice.padded(np.reshape(np.asarray(values, dtype=np.float64), self.lattice.shape))

    def kernel_params(self, piece) -> tuple:
        """The parameters of ``piece`` (the drive, friction or threshold piece) as the lattice
        kernels read them: :meth:`~stickslip.models.piece.Piece.kernel_params` with each per-block
        parameter in the lattice's layout (:meth:`pad`)."""
        return piece.kernel_params(self.chain, pad=self.pad)

    def kernel_mass(self) -> Any:
        """The masses as the lattice kernels read them: None for unit masses, a float M, or the
        M_i in the lattice's layout (:meth:`pad`)."""
        M = self.chain.M
        if isinstance(M, PerBlock):
            return self.pad(M.values)
        return None if M == 1.0 else float(M)

    def to_dict(self) -> dict[str, Any]:
        """The model's parameters with the lattice's name, shape and edges (N left out)."""
        d = {k: v for k, v in self.chain.to_dict().items() if k != "N"}
        d["lattice"] = self.lattice.name
        d["shape"] = "x".join(str(n) for n in self.lattice.shape)
        if self.lattice.name == "square":
            d["edges"] = dict(zip(("top", "bottom", "left", "right"), self.lattice.edges, strict=True))
        return d

    def __repr__(self) -> str:
        return f"LatticeParams({self.lattice.describe()}, {self.chain!r})"


def on_lattice(chain: ChainParams, name: str, shape: Any = None, edges: Any = None) -> LatticeParams:
    """``chain``'s model on the lattice ``name`` of ``shape`` with ``edges``; the chain's N becomes
    the lattice's number of blocks (a drawn per-block parameter is drawn again for them, with its
    seed; an array must already hold them, row-major). Refused with a one-line
    :class:`ParameterError`: a bad shape or edges, edges that do not fit the drive, springs K
    that differ from block to block (per bond in two dimensions: not yet there)."""
    if name not in LATTICES:
        raise ParameterError(f"lattice must be one of {', '.join(LATTICES)} (got {name!r})")
    message = context_refusal(chain.friction, f"lattice {name}")
    if message:
        raise ParameterError(message)
    K = chain.K
    if isinstance(K, PerBlock) and bool((K.values != K.values[0]).any()):
        raise ParameterError(
            f"K must be one number on lattice {name} (springs that differ from bond to bond are not yet "
            f"available on a lattice; got {K.spec_text})"
        )
    edge_drive = not chain.drive_piece.leaf_spring
    try:
        lat = lattice(name, chain.N if shape is None else shape, edges, edge_drive=edge_drive, ends=chain.ends)
    except LatticeError as exc:
        raise ParameterError(str(exc)) from None
    # The chain's N is the lattice's number of blocks up to a chain's largest (ChainParams' bound,
    # the chain kernels'); nothing on a lattice reads it (p.N is the lattice's, per-block values
    # are refused above).
    n = min(lat.n_blocks, MAX_BLOCKS)
    if n != chain.N:
        chain = chain.replace(N=n)
    return LatticeParams(chain, lat)


def row_major(name: str, value: Any, shape: tuple[int, int]) -> Any:
    """A per-block value given over the square's (rows, cols) (an array, or ``file:PATH`` of a
    table of rows x cols) as the N = rows cols values in row-major order that
    :class:`~stickslip.models.params.ChainParams` reads; anything else as it is. A 2-d array of
    another shape raises a one-line :class:`ParameterError` naming ``name``."""
    if isinstance(value, str) and value.startswith("file:"):
        from stickslip.models.disorder import DisorderError, _load

        try:
            table = _load(value[len("file:") :])
        except DisorderError as exc:
            raise ParameterError(f"{name}: {exc}") from None
        if table.ndim == 2:
            return PerBlock(row_major(name, table, shape), value)
        return value
    if isinstance(value, (list, tuple, np.ndarray)):
        try:
            arr = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError):
            return value  # ChainParams names the parameter in its refusal
        if arr.ndim == 2:
            if arr.shape != tuple(shape):
                raise ParameterError(
                    f"{name} must be {shape[0]}x{shape[1]} values over (row, col), or {shape[0] * shape[1]} "
                    f"in row-major order (got {arr.shape[0]}x{arr.shape[1]})"
                )
            return arr.ravel()
    return value
