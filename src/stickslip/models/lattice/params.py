"""A model on a lattice: the pieces and parameters of :class:`~stickslip.models.params.ChainParams`
with the lattice they sit on (docs/lattice.md)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from stickslip.models.lattice import LATTICES, LatticeError, lattice
from stickslip.models.params import MAX_BLOCKS, ChainParams, ParameterError


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

    def leaf(self) -> float:
        """The stiffness of the spring joining every block to the drive: the drive's ``leaf``
        (a plate's Kp; 0 for an edge drive and a force)."""
        import importlib

        pc = self.chain.drive_piece
        return float(importlib.import_module(pc.module).leaf(pc.kernel_params(self.chain)))

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
    the lattice's number of blocks. Refused with a one-line :class:`ParameterError`: a bad shape
    or edges, per-block parameters (not yet on lattices), edges that do not fit the drive."""
    if name not in LATTICES:
        raise ParameterError(f"lattice must be one of {', '.join(LATTICES)} (got {name!r})")
    if chain.per_block():
        names = ", ".join(chain.per_block())
        raise ParameterError(f"per-block parameters ({names}) are not yet available on lattice {name}")
    if chain.drive_piece.pack is not None:
        raise ParameterError(
            f"drive {chain.drive} is not yet available on a lattice (drive end, plate, constant-force)"
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
