"""What a piece of a model carries (docs/model.md, "The family the paper stands in").

A :class:`Piece` is one choice for one of the four pieces (drive, friction, threshold, ends):
its name and meaning, the parameters it reads (and those it declares itself, with their checks),
and what the package asks of it: the state variable, steady sliding, the linearisation the
stability analysis reads. Every piece is one module of :mod:`stickslip.models` (``friction``,
``drive``, ``threshold``, ``ends``) that also holds the compiled functions every integrator calls
(:attr:`Piece.module`, the contract in :mod:`stickslip.kernels.laws`) and the named tuple of the
parameters they read (:func:`kernel_params`).

Those functions are compiled with numba when first asked for (:func:`njit`), not when their module
is imported: the pieces describe every model to the command line and to ``import stickslip``,
which then print help or check parameters without loading numba (and scipy through it).
"""

from __future__ import annotations

import importlib
import sys
import types
from collections import namedtuple
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any


class CompositionError(ValueError):
    """A choice of pieces that docs/model.md does not allow; the message is one line."""


class _Pending:
    """A piece's function waiting for :func:`numba.njit` with ``options``; called from Python
    before then, it compiles its module's functions (:func:`_compile_module`) and calls its own."""

    __slots__ = ("fn", "options", "__wrapped__")

    def __init__(self, fn: Callable, options: dict[str, Any]):
        self.fn, self.options, self.__wrapped__ = fn, options, fn

    def __call__(self, *args: Any) -> Any:
        return _compile_module(sys.modules[self.fn.__module__])[self.fn.__name__](*args)


def _compile_module(module: types.ModuleType) -> dict[str, Any]:
    """Compile every pending function of ``module`` (into its namespace) and return the namespace.

    All at once, so that a compiled function finds the others it calls by name compiled too. The
    kernels' cache directory is set first (:mod:`stickslip.kernels`, on import), as numba picks a
    function's cache directory when it decorates it.
    """
    namespace = vars(module)
    pending = {k: v for k, v in namespace.items() if isinstance(v, _Pending)}
    if pending:
        from numba import njit as numba_njit

        import stickslip.kernels  # noqa: F401  (the cache directory, before numba decorates)

        if "NUMBA_EXTENSIONS" in namespace:  # a piece's own numba extensions (overloads), first
            importlib.import_module(namespace["NUMBA_EXTENSIONS"])

        for name, waiting in pending.items():
            namespace[name] = numba_njit(**waiting.options)(waiting.fn)
    return namespace


class _PieceModule(types.ModuleType):
    """A piece's module whose pending functions (:func:`njit`) are compiled when one is read as an
    attribute (``module.accel``, as the kernels read a piece's functions when they are compiled)."""

    def __getattribute__(self, name: str) -> Any:
        value = super().__getattribute__(name)
        if isinstance(value, _Pending):
            return _compile_module(self)[name]
        return value


def njit(**options: Any) -> Callable[[Callable], Any]:
    """:func:`numba.njit` with ``options`` (``cache=True, inline="always"``), applied when the
    function is first asked for: read from its module by the kernels, or called. The compiled
    function is numba's own, so the kernels inline it and its bits are those of a function
    decorated on import; only numba's import (and compilation) waits until a model runs."""

    def mark(fn: Callable) -> _Pending:
        module = sys.modules[fn.__module__]
        if not isinstance(module, _PieceModule):
            module.__class__ = _PieceModule
        return _Pending(fn, options)

    return mark


def kernel_params(module: str, reads: tuple[str, ...], optional: tuple[str, ...] = ()) -> type:
    """The named tuple of the parameters a piece's compiled functions read, in the order of
    ``reads``: the one declaration the driver packs from and the compiled code reads by name
    (``lp.beta``). Defined as ``Params`` in the piece's own module (numba's cache finds it there).

    ``optional`` fields follow, None unless a caller sets them (eq. (1)'s sigma, which only the
    single block sets): a kernel is compiled for None or a float, so a None field costs nothing
    and leaves every expression as it was."""
    return namedtuple("Params", reads + optional, defaults=(None,) * len(optional), module=module)


def _kernel_value(value: Any, pad: Callable[[Any], Any] | None = None) -> Any:
    """A parameter as the kernels read it: a float, or a per-block one padded like x (the chain's
    layout, or ``pad(values)``: a lattice's, :meth:`~stickslip.models.lattice.params.LatticeParams.kernel_params`)."""
    padded = getattr(value, "padded", None)
    if padded is None:
        return float(value)
    return padded() if pad is None else pad(value.values)


@dataclass(frozen=True)
class Param:
    """A parameter a piece declares: name, default, allowed range and one-line meaning.

    :class:`~stickslip.models.params.ChainParams` gains a field for each, checked like its own
    (``low``/``high`` bounds, open or closed), so a law's parameters live with the law.
    """

    name: str
    default: float
    doc: str
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    #: the parameter in figure labels (matplotlib mathtext without the dollars); the name if empty
    symbol: str = ""

    def metadata(self) -> dict[str, Any]:
        """The field metadata ChainParams validates with (and labels figures with)."""
        meta: dict[str, Any] = {"doc": self.doc, "low_open": self.low_open, "high_open": self.high_open}
        if self.symbol:
            meta["symbol"] = self.symbol
        if self.low is not None:
            meta["low"] = self.low
        if self.high is not None:
            meta["high"] = self.high
        return meta


@dataclass(frozen=True)
class Linearisation:
    """A friction law with state variable, linearised about steady sliding at v = V.

    Friction force phi(v, theta) of a moving block and state law dtheta/dt = g(v, theta)
    (+ ``diffusion`` times the discrete Laplacian of theta): ``theta0`` the steady state,
    ``phi_v`` = dphi/dv, ``phi_theta`` = dphi/dtheta, ``g_v`` = dg/dv, ``g_theta`` = dg/dtheta
    there. The chain's Fourier mode matrix and finite Jacobian (analysis.dynamics.stability) read these.
    """

    theta0: float
    phi_v: float
    phi_theta: float
    g_v: float
    g_theta: float
    diffusion: float = 0.0


@dataclass(frozen=True)
class LabLaw:
    """A friction law's state evolution as the rock-friction lab writes it (:mod:`stickslip.lab.laws`):
    its name there, the scale s of D_c in x = v theta / (s D_c) (so that x = 1 in steady sliding),
    its equation and its reference. The law's module holds the compiled rate
    ``lab_rate(x, th, cb, dtau)``: dtheta/dt from x, theta, c / b and the stress rate dtau/dt (the
    last two read by the Nagata law only), which the lab's quasi-static right-hand side calls
    (:mod:`stickslip.lab.compiled`)."""

    name: str
    scale: float
    equation: str
    reference: str


@dataclass(frozen=True)
class Piece:
    """One choice for one piece: its name, what it means, and the parameters it reads.

    A kernel is compiled for its module (:attr:`module`, :func:`stickslip.models.pieces.code`).
    """

    kind: str
    name: str
    meaning: str
    #: the parameters the piece reads (a friction law's compiled functions get them as its
    #: ``Params``, in this order)
    reads: tuple[str, ...] = ()
    #: parameters the piece declares itself (ChainParams gains a field for each)
    params: tuple[Param, ...] = ()
    #: cross-field check of a composition using the piece: an error message, or None
    check: Callable[[Any], str | None] | None = None
    #: friction and threshold: the piece carries or reads the state variable theta
    has_state: bool = False
    #: friction: theta_i at the start of a run, a number or a function of the parameters
    #: (eq. 4 starts at 0.1; laws without theta at 0)
    theta0: float | Callable[[Any], float] = 0.0
    #: friction with theta: the values theta_i may take, (low, high, low excluded); a start state
    #: outside is refused before a run (:func:`stickslip.run.validate.check_start_state`)
    theta_range: tuple[float, float, bool] | None = None
    #: friction: (friction c, theta_0) of steady sliding at v = V
    steady: Callable[[Any], tuple[float, float]] | None = None
    #: drive: the drive acts on every block (a leaf spring Kp to the plate, or a force), not on
    #: block 1 alone, so a stopped block starts at a step known in advance (the kernels' start
    #: searches, :mod:`stickslip.kernels.triggers`) and x_0 is the ends' ghost cell
    leaf_spring: bool = False
    #: drive: the constant force on every block at the parameters of one block (a force drive),
    #: which steady sliding balances with friction (:func:`stickslip.models.physics.steady_velocity`);
    #: None for a drive that sets the velocity V
    applied: Callable[[Any], float] | None = None
    #: drive: the velocity of the kernels' pull point p = V t_n at the parameters ``p``, when it is
    #: not V (a force ramp reads p = r t_n as its r t); packed as the kernels' V
    pull_velocity: Callable[[Any], float] | None = None
    #: the kernels' ``Params`` of the parameters ``p``, where the piece packs them itself (a load
    #: history's table of breakpoints); None: each parameter of :attr:`reads` as a float or per block
    pack: Callable[[Any], tuple] | None = None
    #: drive: whether its load point never moves back at the parameters ``p`` (None: always), which
    #: the exact integrator's start searches need; a drive that does runs dense
    monotone: Callable[[Any], bool] | None = None
    #: drive: runs on the located integrator (:mod:`stickslip.kernels.located`), whose frame
    #: u = x - V t holds the drive at u = 0
    located: bool = True
    #: friction without theta: phi'(V), the slope at steady sliding that the linearisation
    #: lambda^2 + phi'(V) lambda + w_k^2 = 0 reads (docs/model.md); None for laws with theta
    slope: Callable[[Any], float] | None = None
    #: friction with theta: its law linearised at steady sliding (the 3 x 3 block per mode)
    linear: Callable[[Any], Linearisation] | None = None
    #: friction with theta: the linearisation is eq. (5)'s, with Fig. 4's closed-form critical beta
    eq5: bool = False
    #: the import path of the module holding the compiled functions the integrators call (a
    #: friction law's ``accel`` and ``rate``, a drive's ``force``, ``leaf`` and ``left``, a
    #: threshold's ``value``, an end condition's ``ghost``; :mod:`stickslip.kernels.laws`) and its
    #: ``Params``
    module: str = ""
    #: friction: the law as a figure label (matplotlib mathtext)
    label: str = ""
    #: friction: extra numbers the stability report shows for this law (closed forms to compare)
    stability_extras: Callable[[Any], dict[str, float]] | None = None
    #: friction: a regularised rate-and-state law, which holds no force at v = 0 (mu(0, theta) = 0),
    #: so that it runs without a static threshold (threshold ``none``)
    rate_and_state: bool = False
    #: friction: what its ``rate`` reads besides its block's own state and velocity, which the
    #: kernels build as a :class:`stickslip.kernels.laws.RateContext` and pass as its last argument,
    #: ``rate(thl, th, thr, v, lp, ctx)``: ``("stress_rate",)``, the rate of the elastic force on
    #: the block. Empty for every other law, whose kernels build nothing (a compile-time choice);
    #: the located integrator and the lattices refuse such a law
    context: tuple[str, ...] = ()
    #: friction and drive: the compiled functions the run stages call (``accel``, ``rate``;
    #: ``force``) use only + - * / on their arguments and float parameters, so they run on 8
    #: blocks at once (:mod:`stickslip.kernels.lanes`)
    lanes: bool = False
    #: ends and drive: steady sliding exists (a spring to a fixed wall stretches without bound;
    #: a force ramp never lets the velocity settle)
    steady_sliding: bool = True
    #: ends: the chain closes into a ring (x_0 = x_N, x_{N+1} = x_1)
    ring: bool = False
    #: friction: its state law as the lab's quasi-static spring-slider runs it (module's
    #: ``lab_rate``); None for a law the lab does not offer
    lab: LabLaw | None = None
    #: ends: a spring to a wall at x = 0, which moves at -V in the frame of the drive, so the
    #: equations read t there (the other ends leave them autonomous in that frame)
    wall: bool = False

    def kernel_params(self, p: Any, pad: Callable[[Any], Any] | None = None) -> tuple:
        """The parameters of ``p`` the piece's compiled functions read, as the ``Params`` named
        tuple of its module, in the order of :attr:`reads`: floats, and a per-block parameter
        (:class:`~stickslip.models.disorder.PerBlock`) as a float64 array of N + 2 with block i
        at index i, which the kernels read at each block (:func:`stickslip.kernels.laws.at`);
        ``pad`` puts the N values into another layout (a lattice's padded flat arrays)."""
        if self.pack is not None:
            return self.pack(p)
        params = importlib.import_module(self.module).Params
        return params(*(_kernel_value(getattr(p, name), pad) for name in self.reads))

    def kernel_velocity(self, p: Any) -> float:
        """The drive's V as the kernels read it (their pull point p = V t_n): :attr:`pull_velocity`
        where the drive declares one, else the parameters' V."""
        return float(self.pull_velocity(p)) if self.pull_velocity is not None else float(p.V)

    def start_theta(self, p: Any) -> float:
        """theta_i at the start of a run of the parameters ``p`` (:attr:`theta0`)."""
        return float(self.theta0(p)) if callable(self.theta0) else self.theta0
