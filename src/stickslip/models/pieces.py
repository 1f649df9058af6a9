"""The four pieces a block-spring model is made of (docs/model.md, "The family the paper stands in").

The chain of eq. (4) and its relatives share blocks on a line, nearest-neighbour springs K,
the start and stop rules and Heun with t_n = n dt. They differ in

========== ==========================================================================
drive      ``end``: a pulling point x_0 = V t joined to block 1 (eq. 4);
           ``plate``: every block joined to a plate at V t by a leaf spring Kp (BK, CL);
           ``constant-force``: a force F on every block; ``force-ramp``: F_start + r t on every
           block (random-medium protocols, Sakaguchi and Kadowaki); ``history``: the pulling
           point of eq. (4) moved along a load history p(t) (steps, holds, tables)
friction   ``state``: theta_i + beta v_i, theta from eq. (4);
           ``weakening``: phi(v) = (1 - sigma) / (1 + 2 alpha max(v, 0) / (1 - sigma)) (CL);
           ``strengthening``: F0 + beta v, no state variable (train model);
           ``rate-state``: Dieterich-Ruina with the aging law; ``rate-state-slip``: with Ruina's
           slip law; ``rate-state-prz``: with the Perrin-Rice-Zheng law;
           ``rate-state-nagata``: with the Nagata law (reads the stress rate);
           one module each in :mod:`stickslip.models.friction`, listed in :data:`FRICTIONS`
threshold  ``constant``: Fs; ``state``: theta_i (the paper's reading of Batista-Carlson);
           ``none``: no static threshold, for rate-and-state (a block starts when f_i > 0)
ends       ``free``, ``fixed``, ``periodic`` (a drive acting on every block only)
========== ==========================================================================

A composition is valid when docs/model.md allows it (:data:`RULES`): periodic ends need a drive
that acts on every block (the end drive pulls block 1 only, so the ring has no place for the
pulling point), and the state threshold needs the state friction (it reads eq. (4)'s theta).
:func:`check_composition` says so in one line. Each piece lists the parameters it reads, so a run
records exactly those.
"""

from __future__ import annotations

import importlib

from stickslip.models.friction.weakening import weakening_g
from stickslip.models.piece import CompositionError, Linearisation, Param, Piece

__all__ = [
    "PIECES",
    "KINDS",
    "DRIVES",
    "FRICTIONS",
    "THRESHOLDS",
    "ENDS",
    "CompositionError",
    "Linearisation",
    "Param",
    "Piece",
    "weakening_g",
]

#: The friction laws, one module each in :mod:`stickslip.models.friction` (a law is its module
#: and its line here).
FRICTIONS = (
    "state",
    "weakening",
    "strengthening",
    "rate_state",
    "rate_state_slip",
    "rate_state_prz",
    "rate_state_nagata",
)

#: The drives, one module each in :mod:`stickslip.models.drive`.
DRIVES = ("end", "plate", "constant_force", "force_ramp", "history")

#: The static thresholds, one module each in :mod:`stickslip.models.threshold`.
THRESHOLDS = ("constant", "state", "none")

#: The end conditions, one module each in :mod:`stickslip.models.ends`.
ENDS = ("free", "fixed", "periodic")


PIECES: dict[str, tuple[Piece, ...]] = {
    "drive": tuple(importlib.import_module(f"stickslip.models.drive.{m}").PIECE for m in DRIVES),
    "friction": tuple(importlib.import_module(f"stickslip.models.friction.{m}").PIECE for m in FRICTIONS),
    "threshold": tuple(importlib.import_module(f"stickslip.models.threshold.{m}").PIECE for m in THRESHOLDS),
    "ends": tuple(importlib.import_module(f"stickslip.models.ends.{m}").PIECE for m in ENDS),
}

KINDS = tuple(PIECES)


def names(kind: str) -> tuple[str, ...]:
    """The allowed choices of one piece, in the order of :data:`PIECES`."""
    return tuple(p.name for p in PIECES[kind])


def piece(kind: str, name: str) -> Piece:
    """The piece ``name`` of ``kind``; a CompositionError names the allowed choices."""
    for p in PIECES.get(kind, ()):
        if p.name == name:
            return p
    raise CompositionError(f"{kind} must be one of {', '.join(names(kind))} (got {name!r})")


def code(kind: str, name: str) -> str:
    """What a kernel is compiled for, for one piece: the import path of the module holding its
    compiled functions."""
    return piece(kind, name).module


#: The frictions that run without a static threshold (threshold none): the regularised
#: rate-and-state laws, which hold no force at v = 0 (:attr:`Piece.rate_and_state`).
RATE_AND_STATE = tuple(p.name for p in PIECES["friction"] if p.rate_and_state)

#: The rules of composition (docs/model.md), as ``stickslip models`` states them.
RULES = (
    "ends periodic needs a drive that acts on every block (plate, constant-force, force-ramp)",
    "threshold state needs friction state",
    f"threshold none needs a rate-and-state friction ({', '.join(RATE_AND_STATE)})",
)


def check_composition(drive: str, friction: str, threshold: str, ends: str) -> None:
    """Refuse a composition docs/model.md does not allow, in one line."""
    for kind, name in zip(KINDS, (drive, friction, threshold, ends), strict=False):
        piece(kind, name)
    if piece("ends", ends).ring and not piece("drive", drive).leaf_spring:
        every = ", ".join(p.name for p in PIECES["drive"] if p.leaf_spring)
        raise CompositionError(
            f"ends {ends} needs a drive that acts on every block ({every}; drive {drive} pulls block 1 only)"
        )
    if threshold == "state" and friction != "state":
        raise CompositionError(f"threshold state needs friction state (friction {friction} has no theta)")
    if threshold == "none" and not piece("friction", friction).rate_and_state:
        raise CompositionError(
            f"threshold none needs a rate-and-state friction ({', '.join(RATE_AND_STATE)}; got friction {friction})"
        )


def context_refusal(friction: str, what: str) -> str | None:
    """The one-line refusal of a friction law whose rate reads a context (the stress rate of the
    Nagata law, :attr:`Piece.context`) by ``what``, whose kernels do not build it (the located
    integrator, the lattices); None for every other law."""
    ctx = piece("friction", friction).context
    if not ctx:
        return None
    return (
        f"friction {friction} reads the {', '.join(c.replace('_', ' ') for c in ctx)}, which {what} "
        "does not build (the chain's grid integrators, dense and exact, do)"
    )


def stopped_blocks_still(drive: Piece, friction: Piece) -> bool:
    """Whether a stopped block keeps every bit until a neighbour moves or the plate brings it to
    its threshold: a leaf spring to the plate starts blocks at steps known in advance, and a
    friction without theta leaves nothing of a stopped block to evolve. The exact integrator
    then updates lists of blocks (:mod:`stickslip.kernels.plate`) instead of an interval."""
    return drive.leaf_spring and not friction.has_state


def reads(drive: str, friction: str, threshold: str, ends: str) -> tuple[str, ...]:
    """Parameters a composition reads, besides N, K, V and dt that every chain reads."""
    out: list[str] = []
    for kind, name in zip(KINDS, (drive, friction, threshold, ends), strict=False):
        for r in piece(kind, name).reads:
            if r not in out:
                out.append(r)
    return tuple(out)
