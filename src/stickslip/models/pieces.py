"""The four pieces a block-spring model is made of (docs/model.md, "The family the paper stands in").

The chain of eq. (4) and its relatives share blocks on a line, nearest-neighbour springs K,
the start and stop rules and Heun with t_n = n dt. They differ in

========== ==========================================================================
drive      ``end``: a pulling point x_0 = V t joined to block 1 (eq. 4);
           ``plate``: every block joined to a plate at V t by a leaf spring Kp (BK, CL)
friction   ``state``: theta_i + beta v_i, theta from eq. (4);
           ``weakening``: phi(v) = (1 - sigma) / (1 + 2 alpha max(v, 0) / (1 - sigma)) (CL);
           ``strengthening``: F0 + beta v, no state variable (train model)
threshold  ``constant``: Fs; ``state``: theta_i (the paper's reading of Batista-Carlson)
ends       ``free``, ``fixed``, ``periodic`` (plate drive only)
========== ==========================================================================

A composition is valid when docs/model.md allows it: periodic ends need the plate drive (the end
drive pulls block 1 only, so the ring has no place for the pulling point), and the state
threshold needs the state friction (it reads theta). :func:`check_composition` says so in one
line. Each piece lists the parameters it reads, so a run records exactly those.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any


def weakening_g(p: Any) -> float:
    """g = (1 + 2 alpha V / (1 - sigma))^-2 of CL's velocity weakening; -phi'(V) = 2 alpha g."""
    return float((1.0 + 2.0 * p.alpha * p.V / (1.0 - p.sigma)) ** -2)


def _weakening_slope(p: Any) -> float:
    """phi'(V) of CL's weakening, phi(v) = (1 - sigma) / (1 + 2 alpha v / (1 - sigma)): -2 alpha g."""
    return -2.0 * p.alpha * weakening_g(p)


def _state_theta_terms(alpha: float, V: float) -> tuple[float, float, float]:
    """eq. (4)'s theta law linearised about steady sliding at v = V (eq. 2, eq. 5).

    Returns (theta_0, d/dv, d/dtheta) of g = theta (1 - theta) - alpha theta v at the stable
    steady state theta_0 = max(1 - alpha V, 0): d/dv = -alpha theta_0 and
    d/dtheta = 1 - 2 theta_0 - alpha V (the diffusion term -D q is the chain's, not the law's).
    """
    theta0 = max(1.0 - alpha * V, 0.0)
    return theta0, -alpha * theta0, 1.0 - 2.0 * theta0 - alpha * V


def _weakening_extras(p: Any) -> dict[str, float]:
    """alpha g, the number CL's stability criterion compares with the springs (docs/model.md)."""
    return {"alpha_g": p.alpha * weakening_g(p)}


def _strengthening_slope(p: Any) -> float:
    """phi'(V) of the train model's F0 + beta v: beta."""
    return float(p.beta)


class CompositionError(ValueError):
    """A choice of pieces that docs/model.md does not allow; the message is one line."""


@dataclass(frozen=True)
class Piece:
    """One choice for one piece: its name, what it means, and the parameters it reads."""

    kind: str
    name: str
    meaning: str
    reads: tuple[str, ...] = ()
    #: friction and threshold: the piece carries or reads the state variable theta
    has_state: bool = False
    #: friction: theta_i at the start of a run (eq. 4 starts at 0.1; laws without theta at 0)
    theta0: float = 0.0
    #: drive: every block is joined to the plate by the leaf spring Kp
    leaf_spring: bool = False
    #: friction without theta: phi'(V), the slope at steady sliding that the linearisation
    #: lambda^2 + phi'(V) lambda + w_k^2 = 0 reads (docs/model.md); None for the state law,
    #: whose linearisation is the 3 x 3 block of eq. (5)
    slope: Callable[[Any], float] | None = None
    #: friction with theta: (theta_0, d/dv, d/dtheta) of its law at steady sliding, from (alpha, V)
    theta_terms: Callable[[float, float], tuple[float, float, float]] | None = None
    #: friction without theta: extra numbers the mode-stability report shows for this law
    stability_extras: Callable[[Any], dict[str, float]] | None = None
    #: ends: steady sliding exists (a spring to a fixed wall stretches without bound)
    steady_sliding: bool = True
    #: ends: the chain closes into a ring (x_0 = x_N, x_{N+1} = x_1)
    ring: bool = False
    #: ends: a spring to a wall at x = 0, which moves at -V in the frame of the drive, so the
    #: equations read t there (the other ends leave them autonomous in that frame)
    wall: bool = False

    @property
    def code(self) -> int:
        """The kernel's integer code of the piece (its position in :data:`PIECES`)."""
        return names(self.kind).index(self.name)


PIECES: dict[str, tuple[Piece, ...]] = {
    "drive": (
        Piece("drive", "end", "pulling point x_0 = V t joined to block 1 by the spring K (eq. 4)"),
        Piece(
            "drive",
            "plate",
            "every block joined to a plate at V t by a leaf spring Kp: f_i gains Kp (V t - x_i)",
            ("Kp",),
            leaf_spring=True,
        ),
    ),
    "friction": (
        Piece(
            "friction",
            "state",
            "theta_i + beta v_i while moving; dtheta_i/dt = theta_i (1 - theta_i) "
            "- alpha theta_i v_i + D (theta_{i+1} - 2 theta_i + theta_{i-1}) (eq. 4)",
            ("beta", "alpha", "D"),
            has_state=True,
            theta0=0.1,
            theta_terms=_state_theta_terms,
        ),
        Piece(
            "friction",
            "weakening",
            "phi(v) = (1 - sigma) / (1 + 2 alpha max(v, 0) / (1 - sigma)) (Carlson-Langer)",
            ("alpha", "sigma"),
            slope=_weakening_slope,
            stability_extras=_weakening_extras,
        ),
        Piece(
            "friction",
            "strengthening",
            "F0 + beta v, no state variable (train model)",
            ("beta", "F0"),
            slope=_strengthening_slope,
        ),
    ),
    "threshold": (
        Piece("threshold", "constant", "a stuck block starts when f_i > Fs", ("Fs",)),
        Piece(
            "threshold",
            "state",
            "a stuck block starts when f_i > theta_i (the paper's reading of Batista-Carlson)",
            has_state=True,
        ),
    ),
    "ends": (
        Piece("ends", "free", "x_{N+1} = x_N (plate drive: also x_0 = x_1)"),
        Piece("ends", "fixed", "x_{N+1} = 0 (plate drive: also x_0 = 0)", steady_sliding=False, wall=True),
        Piece("ends", "periodic", "x_0 = x_N, x_{N+1} = x_1 (plate drive only)", ring=True),
    ),
}

KINDS = tuple(PIECES)


def names(kind: str) -> tuple[str, ...]:
    """The allowed choices of one piece, in the order of their kernel codes."""
    return tuple(p.name for p in PIECES[kind])


def piece(kind: str, name: str) -> Piece:
    """The piece ``name`` of ``kind``; a CompositionError names the allowed choices."""
    for p in PIECES.get(kind, ()):
        if p.name == name:
            return p
    raise CompositionError(f"{kind} must be one of {', '.join(names(kind))} (got {name!r})")


def code(kind: str, name: str) -> int:
    """The kernel's integer code of a piece (its position in :data:`PIECES`)."""
    return names(kind).index(piece(kind, name).name)


def check_composition(drive: str, friction: str, threshold: str, ends: str) -> None:
    """Refuse a composition docs/model.md does not allow, in one line."""
    for kind, name in zip(KINDS, (drive, friction, threshold, ends), strict=False):
        piece(kind, name)
    if ends == "periodic" and drive != "plate":
        raise CompositionError("ends periodic needs drive plate (the end drive pulls block 1 only)")
    if threshold == "state" and friction != "state":
        raise CompositionError(f"threshold state needs friction state (friction {friction} has no theta)")


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
