"""Model parameters: frozen dataclasses, validated when built.

Every field carries the paper's symbol. Defaults are the paper's values (section 2 for the
single block, section 3 for the chain). A bad value raises :class:`ParameterError` whose
message names the parameter and the allowed range, in one line.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from stickslip.models.pieces import Piece, piece
from stickslip.models.preset_table import PRESETS


class ParameterError(ValueError):
    """A parameter is outside its allowed range, or not one the model reads.

    Parameters
    ----------
    message : str
        One line naming the parameter, its allowed range and the value given, e.g.
        ``K must be > 0 (got -1)``; the commands print it as it is, without a traceback.
    """


def _range_text(low: float | None, high: float | None, low_open: bool, high_open: bool) -> str:
    parts = []
    if low is not None:
        parts.append(f"{'>' if low_open else '>='} {low:g}")
    if high is not None:
        parts.append(f"{'<' if high_open else '<='} {high:g}")
    return " and ".join(parts)


def check_number(
    name: str,
    value: Any,
    *,
    low: float | None = None,
    high: float | None = None,
    low_open: bool = False,
    high_open: bool = False,
    integer: bool = False,
) -> float | int:
    """Return ``value`` as a float (or int) if it is finite and in range, else raise.

    The error names ``name`` and the allowed range, e.g. ``K must be > 0 (got -1)``.
    """

    def refused(what: str) -> ParameterError:
        # Written only when it is raised: a check that passes costs no formatting.
        allowed = _range_text(low, high, low_open, high_open)
        if what == "kind":
            allowed = f"{'an integer' if integer else 'a finite number'} {allowed}".rstrip()
        return ParameterError(f"{name} must be {allowed} (got {_shown(value)})")

    try:
        number = float(value)
    except (TypeError, ValueError, OverflowError):
        raise refused("kind") from None
    if not math.isfinite(number):
        raise refused("kind")
    if integer:
        if number != int(number):
            raise refused("kind")
        number = int(number)
    too_low = low is not None and (number <= low if low_open else number < low)
    too_high = high is not None and (number >= high if high_open else number > high)
    if too_low or too_high:
        raise refused("range")
    return number


def _shown(value: Any) -> str:
    """A value for an error message, huge integers in short form."""
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) >= 10**16:
        return f"{float(value):.6g}"
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


#: Largest number of time steps of one run (docs/model.md's longest run, t = 2e7 at dt = 0.005, is 4e9):
#: far inside int64, and times n dt stay exact to the step.
MAX_STEPS = 10**12
#: Largest chain (blocks).
MAX_BLOCKS = 1_000_000
#: Largest perturbation of a start: the uniform draw in [-A, A] spans 2 A, which must stay a finite float.
MAX_PERTURBATION = 1e300


def _positive(default: float, doc: str) -> Any:
    return field(default=default, metadata={"low": 0.0, "low_open": True, "doc": doc})


def _nonnegative(default: float, doc: str) -> Any:
    return field(default=default, metadata={"low": 0.0, "doc": doc})


def _per_block(value: Any) -> bool:
    from stickslip.models.disorder import PerBlock

    return isinstance(value, PerBlock)


class _Validated:
    """Mixin: validate every field from its metadata after construction."""

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):  # type: ignore[arg-type]
            meta = f.metadata
            if meta.get("text") or _per_block(getattr(self, f.name)):
                continue
            if "choices" in meta:
                value = getattr(self, f.name)
                if value not in meta["choices"]:
                    raise ParameterError(f"{f.name} must be one of {', '.join(meta['choices'])} (got {value!r})")
                continue
            value = check_number(
                f.name,
                getattr(self, f.name),
                low=meta.get("low"),
                high=meta.get("high"),
                low_open=meta.get("low_open", False),
                high_open=meta.get("high_open", False),
                integer=meta.get("integer", False),
            )
            object.__setattr__(self, f.name, value)
        self._check()

    def _check(self) -> None:
        """Cross-field checks; subclasses override."""

    def to_dict(self) -> dict[str, float | int]:
        """All fields as a plain dict (for JSON and run metadata)."""
        return dataclasses.asdict(self)  # type: ignore[call-overload]

    def replace(self, **changes: Any):
        """A copy with some fields changed (validated again)."""
        return dataclasses.replace(self, **changes)  # type: ignore[type-var]

    @classmethod
    def field_docs(cls) -> dict[str, str]:
        """Field name -> one-line description (used for command-line help)."""
        return {f.name: f.metadata.get("doc", "") for f in dataclasses.fields(cls)}  # type: ignore[arg-type]


@dataclass(frozen=True)
class BlockParams(_Validated):
    """Parameters of the single block and spring, eq. (1).

    M x'' = K (V t - x) - F(theta, v),  F = sigma theta + beta v,
    theta' = theta (1 - theta) - alpha theta v, with static friction Fs.
    Defaults are the paper's (section 2, Fig. 1): M = sigma = alpha = beta = 1, K = 10,
    V = 0.001, Fs = 3, Heun step dt = 0.005.

    Parameters
    ----------
    K, V, beta, alpha, Fs, M, sigma, dt : float
        Spring constant, pulling velocity, viscous friction, weakening of theta, static
        threshold, mass, state-friction scale, Heun time step.
    threshold : {'constant', 'state'}
        Static threshold: Fs, or sigma theta (the paper's reading of Batista-Carlson).

    Examples
    --------
    >>> BlockParams(V=0.01)
    BlockParams(K=10.0, V=0.01, beta=1.0, alpha=1.0, Fs=3.0, M=1.0, sigma=1.0, dt=0.005, threshold='constant')
    """

    K: float = _positive(10.0, "spring constant K")
    V: float = _nonnegative(0.001, "pulling velocity V")
    beta: float = _nonnegative(1.0, "viscous friction coefficient beta")
    alpha: float = _nonnegative(1.0, "weakening coefficient alpha of the state variable")
    Fs: float = _positive(3.0, "static friction limit Fs")
    M: float = _positive(1.0, "block mass M")
    sigma: float = _positive(1.0, "state-variable friction scale sigma")
    dt: float = _positive(0.005, "Heun time step dt")
    threshold: str = field(
        default="constant",
        metadata={
            "choices": ("constant", "state"),
            "doc": "static threshold: constant (Fs) or state (sigma theta: the paper's reading of Batista-Carlson)",
        },
    )

    def to_dict(self) -> dict[str, Any]:
        """All parameters; the threshold only when it is not the paper's constant Fs."""
        d = dataclasses.asdict(self)
        if self.threshold == "constant":
            d.pop("threshold")
        else:
            d.pop("Fs")
        return d

    @property
    def threshold_piece(self) -> Piece:
        """The static threshold as a :class:`~stickslip.models.pieces.Piece`."""
        return piece("threshold", self.threshold)

    @property
    def friction_piece(self) -> Piece:
        """eq. (1)'s friction: eq. (4)'s law (:mod:`stickslip.models.friction.state`), its state
        term scaled by sigma."""
        return piece("friction", "state")

    @property
    def D(self) -> float:
        """No diffusion of theta: a single block has no neighbours (the law's D reads 0)."""
        return 0.0


def scale_block(p: BlockParams) -> BlockParams:
    """Rescale eq. (1) to M = sigma = 1 (section 2 of the paper).

    With x = (sigma/M) x~, v = (sigma/M) v~, V = (sigma/M) V~, K~ = K/M, beta~ = beta/M and
    alpha~ = alpha sigma / M, eq. (1) divided by M reads
    x~'' = K~ (V~ t - x~) - theta - beta~ v~,  theta' = theta (1 - theta) - alpha~ theta v~.
    The static friction scales like a force per unit mass over sigma/M: Fs~ = Fs / sigma.
    Time is not rescaled, so dt is unchanged.
    """
    return BlockParams(
        K=p.K / p.M,
        V=p.V * p.M / p.sigma,
        beta=p.beta / p.M,
        alpha=p.alpha * p.sigma / p.M,
        Fs=p.Fs / p.sigma,
        M=1.0,
        sigma=1.0,
        dt=p.dt,
    )


#: The named models: the presets of :mod:`stickslip.models.preset_table`, in its order (written there once).
MODELS = tuple(PRESETS)


def _choice(default: str, kind: str, doc: str) -> Any:
    from stickslip.models.pieces import names

    return field(default=default, metadata={"choices": names(kind), "doc": doc})


def _with_piece_params(cls):
    """Give ``cls`` a field for every parameter a piece declares (:class:`~stickslip.models.piece.Param`).

    So a friction law's parameters, defaults and ranges live in its own module
    (:mod:`stickslip.models.friction`); the fields follow the class's own, in the pieces' order.
    """
    from stickslip.models.pieces import PIECES

    for choices in PIECES.values():
        for pc in choices:
            for prm in pc.params:
                if prm.name in cls.__annotations__:
                    raise TypeError(f"parameter {prm.name} of {pc.kind} {pc.name} is declared twice")
                cls.__annotations__[prm.name] = "float"
                setattr(cls, prm.name, field(default=prm.default, metadata=prm.metadata()))
    return cls


@dataclass(frozen=True)
@_with_piece_params
class ChainParams(_Validated):
    """Parameters of the chain of eq. (4) and of its relatives, pinned down in docs/model.md.

    N blocks on a line joined by springs K. The defaults are the paper's model and run
    (section 3): the end drive (only the first block pulled, x_0 = V t), state friction with
    diffusion D and no-flux ends, the constant threshold Fs, free end; N = 399, K = 10,
    D = 5, V = 0.001, Fs = 3, dt = 0.005, alpha = 1, beta = 1. The pieces ``drive``,
    ``friction``, ``threshold`` and ``ends`` (:mod:`stickslip.models.pieces`) select the
    relatives: Carlson-Langer (plate drive with leaf spring Kp, velocity weakening with
    alpha and sigma), the train model (strengthening friction F0 + beta v), the state
    threshold of Batista-Carlson. ``model`` names the preset the parameters came from
    (:mod:`stickslip.models.presets`). Parameters a composition does not read are kept at
    their defaults and left out of :meth:`to_dict`. A piece may declare further parameters
    (a friction law's own, :mod:`stickslip.models.friction`): they become fields after these.

    Parameters
    ----------
    N, K, D, V, beta, alpha, Fs, dt : int, float
        Blocks, spring constant, diffusion of theta, pulling velocity, viscous friction,
        weakening of theta, static threshold, Heun time step (the paper's values by default).
    model : str
        The preset the parameters came from (:func:`stickslip.chain_params` sets it).
    drive, friction, threshold, ends : str
        The pieces (``stickslip models`` lists the choices).
    Kp, sigma, F0, ... : float
        The pieces' own parameters (:attr:`~stickslip.models.piece.Piece.params`): the leaf
        spring of the plate drive, the friction drop of velocity weakening, the constant friction
        of the train model; the rate-and-state laws add ``rs_a``, ``rs_b``, ``Dc``, ``v0``,
        ``mu0``, ``sigma_n``. Each is read only by the pieces that name it (:meth:`used`).

    Examples
    --------
    >>> p = ChainParams(N=49, beta=0.5)
    >>> p
    ChainParams(model='sakaguchi', N=49, K=10.0, D=5.0, V=0.001, beta=0.5, alpha=1.0, Fs=3.0, dt=0.005)
    >>> p.used()
    ('N', 'K', 'V', 'dt', 'beta', 'alpha', 'D', 'Fs')
    >>> ChainParams(K=-1)
    Traceback (most recent call last):
    ...
    stickslip.models.params.ParameterError: K must be > 0 (got -1)
    """

    N: int = field(default=399, metadata={"low": 1, "high": MAX_BLOCKS, "integer": True, "doc": "number of blocks N"})
    K: float = _positive(10.0, "spring constant K")
    D: float = _nonnegative(5.0, "diffusion constant D of the state variable")
    V: float = _nonnegative(0.001, "pulling velocity V of the first spring")
    beta: float = _nonnegative(1.0, "viscous friction coefficient beta")
    alpha: float = _nonnegative(1.0, "weakening coefficient alpha of the state variable")
    Fs: float = _positive(3.0, "static friction limit Fs")
    dt: float = _positive(0.005, "Heun time step dt")
    model: str = field(default="sakaguchi", metadata={"choices": MODELS, "doc": "preset the parameters came from"})
    drive: str = _choice("end", "drive", "drive: end (pulling point at block 1) or plate (every block)")
    friction: str = _choice("state", "friction", "friction of a moving block: state, weakening or strengthening")
    threshold: str = _choice("constant", "threshold", "static threshold: constant (Fs) or state (theta_i)")
    ends: str = _choice("free", "ends", "ends of the chain: free, fixed or periodic (plate drive only)")
    M: float = _positive(1.0, "mass M of a block (1: unit masses, the paper's; per block: M_i)")
    history: Any = field(
        default=None,
        metadata={"text": True, "doc": "load history p(t) of drive history (a stickslip.lab.LoadHistory)"},
    )

    def __post_init__(self) -> None:
        """Per-block values (arrays, :class:`~stickslip.models.disorder.Quenched` specs, ``file:``
        names) drawn and checked first (:func:`stickslip.models.disorder.resolve`), then every
        field as :class:`_Validated` does."""
        from stickslip.models.disorder import NOT_PER_BLOCK, DisorderError, resolve

        N = check_number("N", self.N, low=1, high=MAX_BLOCKS, integer=True)
        for f in dataclasses.fields(self):
            meta = f.metadata
            if meta.get("text") or "choices" in meta or meta.get("integer") or f.name in NOT_PER_BLOCK:
                value = getattr(self, f.name)
                if f.name in NOT_PER_BLOCK and not isinstance(value, (int, float, str)) and value is not None:
                    if resolve(f.name, value, N, None, None) is not None:
                        raise ParameterError(f"{f.name} cannot differ from block to block (one number)")
                continue
            low, high = meta.get("low"), meta.get("high")
            allowed = _range_text(low, high, meta.get("low_open", False), meta.get("high_open", False))
            try:
                pb = resolve(f.name, getattr(self, f.name), N, low, high)
            except DisorderError as exc:
                raise ParameterError(f"{f.name} must be {allowed} at every block: {exc}") from None
            if pb is None:
                continue
            bad = ~np.isfinite(pb.values)
            if low is not None:
                bad |= pb.values <= low if meta.get("low_open") else pb.values < low
            if high is not None:
                bad |= pb.values >= high if meta.get("high_open") else pb.values > high
            if bad.any():
                i = int(np.flatnonzero(bad)[0])
                raise ParameterError(
                    f"{f.name} must be {allowed} at every block (got {pb.values[i]:g} at block {i + 1} "
                    f"of {pb.spec_text})"
                )
            object.__setattr__(self, f.name, pb)
        super().__post_init__()

    def per_block(self) -> dict[str, Any]:
        """The parameters that differ from block to block, each a
        :class:`~stickslip.models.disorder.PerBlock` (docs/model.md, "Per-block parameters")."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if _per_block(getattr(self, f.name))}

    def _extremes(self, pick: str) -> Any:
        """The parameters with each per-block value replaced by its smallest (``pick="min"``) or
        largest value: what the pieces' cross-field checks read."""
        from types import SimpleNamespace

        values = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        for name, pb in self.per_block().items():
            values[name] = float(getattr(pb.values, pick)())
        return SimpleNamespace(**values)

    def _check(self) -> None:
        from stickslip.models.pieces import CompositionError, check_composition

        try:
            check_composition(self.drive, self.friction, self.threshold, self.ends)
        except CompositionError as exc:
            raise ParameterError(str(exc)) from None
        views = (self._extremes("min"), self._extremes("max")) if self.per_block() else (self,)
        for pc in (self.drive_piece, self.friction_piece, self.threshold_piece, self.ends_piece):
            for view in views:
                message = pc.check(view) if pc.check is not None else None
                if message:
                    raise ParameterError(message)

    @property
    def pieces(self) -> dict[str, str]:
        """The four pieces of the model."""
        return {"drive": self.drive, "friction": self.friction, "threshold": self.threshold, "ends": self.ends}

    @property
    def drive_piece(self) -> Piece:
        """The drive as a :class:`~stickslip.models.pieces.Piece` (what it reads, its code)."""
        return piece("drive", self.drive)

    @property
    def friction_piece(self) -> Piece:
        """The friction law as a :class:`~stickslip.models.pieces.Piece`."""
        return piece("friction", self.friction)

    @property
    def threshold_piece(self) -> Piece:
        """The static threshold as a :class:`~stickslip.models.pieces.Piece`."""
        return piece("threshold", self.threshold)

    @property
    def ends_piece(self) -> Piece:
        """The end condition as a :class:`~stickslip.models.pieces.Piece`."""
        return piece("ends", self.ends)

    @property
    def codes(self) -> tuple[str, ...]:
        """What the kernels are compiled for, per piece (drive, friction, threshold, ends):
        :func:`stickslip.models.pieces.code`."""
        from stickslip.models.pieces import code

        return tuple(code(k, v) for k, v in self.pieces.items())

    def used(self) -> tuple[str, ...]:
        """The numerical parameters this composition reads."""
        from stickslip.models.pieces import reads

        mass = ("M",) if _per_block(self.M) or self.M != 1.0 else ()
        return ("N", "K", "V", "dt") + reads(**self.pieces) + mass

    def to_dict(self) -> dict[str, Any]:
        """The model (preset name and pieces) and every parameter it reads."""
        d = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        d = {k: v.record() if _per_block(v) else v for k, v in d.items()}
        if d["history"] is not None:
            from stickslip.models.drive.history import record

            d["history"] = record(d["history"])
        used = set(self.used())
        return {k: v for k, v in d.items() if k in used or k in ("model", "drive", "friction", "threshold", "ends")}

    @classmethod
    def field_docs(cls) -> dict[str, str]:
        return {
            k: v
            for k, v in super().field_docs().items()
            if k not in ("model", "drive", "friction", "threshold", "ends", "history")
        }

    @classmethod
    def symbol(cls, name: str) -> str:
        """The parameter ``name`` as a figure label writes it (matplotlib mathtext, no dollars):
        the paper's symbol, or the one a piece declares (:attr:`~stickslip.models.piece.Param.symbol`).

        >>> print(ChainParams.symbol("beta"), ChainParams.symbol("Fs"), ChainParams.symbol("sigma_n"))
        \\beta F_s \\sigma_n
        """
        meta = {f.name: f.metadata for f in dataclasses.fields(cls)}.get(name, {})
        return meta.get("symbol") or SYMBOLS.get(name, name)

    def __repr__(self) -> str:
        """The model and the parameters it reads (those it ignores stay at their defaults), so
        that ``eval(repr(p)) == p``."""
        d = {k: getattr(self, k) if isinstance(v, dict) else v for k, v in self.to_dict().items()}
        shown = {"model": d.pop("model")}
        shown.update({k: d.pop(k) for k in PIECE_DEFAULTS if d[k] != PIECE_DEFAULTS[k]})
        for k in PIECE_DEFAULTS:
            d.pop(k, None)
        return "ChainParams(" + ", ".join(f"{k}={v!r}" for k, v in {**shown, **d}.items()) + ")"


#: The pieces a ChainParams has unless told otherwise: the paper's chain of eq. (4).
PIECE_DEFAULTS = {"drive": "end", "friction": "state", "threshold": "constant", "ends": "free"}

#: The paper's symbols of the fields of BlockParams and ChainParams in figure labels (mathtext).
SYMBOLS = {
    "beta": r"\beta",
    "alpha": r"\alpha",
    "sigma": r"\sigma",
    "Fs": "F_s",
    "dt": r"\Delta t",
}


def steps_for(t_end: float, dt: float, name: str) -> int:
    """Number of steps n with t_n = n dt reaching ``t_end`` (rounded to the nearest step);
    at most :data:`MAX_STEPS`. ``name`` is what a refusal calls the time: the parameter or option
    the caller was given (``transient``, ``t-end``), never one it was not."""
    t_end = check_number(name, t_end, low=0.0)
    if t_end / dt > MAX_STEPS + 0.5:
        raise ParameterError(
            f"{name} must be <= {MAX_STEPS * dt:g} (at most {MAX_STEPS:.0e} steps of dt = {dt:g}; got {t_end:g})"
        )
    return int(round(t_end / dt))
