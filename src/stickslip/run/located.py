"""Runs with located switches: the reference integrator of the equations with switches.

:func:`run_located` integrates any model of the family (docs/model.md, "The family the paper
stands in") with Heun's method in which a block starts at the time its force reaches the
threshold and stops at the time its velocity reaches zero, both located inside the step to
round-off (:mod:`stickslip.kernels.located`). Its trajectories converge to the solution of the
equations with switches at second order in dt. It is a reference for studies (the exponent of
the flow, :mod:`stickslip.analysis.dynamics.lyapunov_flow`), not the engine: :func:`stickslip.run_chain`
keeps the gridded rules of docs/model.md and its bit-exact results. It runs in a fast form by
default (:mod:`stickslip.kernels.located_fast`, docs/performance.md), bit for bit the dense one
(``form="dense"``).
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass

import numpy as np
import pandas as pd

from stickslip.kernels import layout
from stickslip.kernels import located as L
from stickslip.kernels import located_fast as LF
from stickslip.kernels.entry import specialise_call, specialised
from stickslip.models.params import ChainParams, ParameterError, steps_for
from stickslip.models.pieces import context_refusal
from stickslip.run.state import ChainState, initial_state
from stickslip.run.validate import check_start_state

INTEGRATOR = "heun with located switches (start at f_i = threshold, stop at v_i = 0, to round-off)"

EVENT_COLUMNS = ["t_start", "t_end", "size", "start_block", "n_blocks"]


@dataclass
class LocatedState:
    """State of the located integrator at the grid step ``step`` (t = step dt).

    u = x - V t (positions relative to the drive; u = x for a load history, :func:`frame_velocity`),
    v, th, mov (1.0 moving, 0.0 stuck), with ghost
    cells 0 and N + 1 as in the kernels; ist, evf, moved: the event bookkeeping of
    :mod:`stickslip.kernels.located`.
    """

    u: np.ndarray
    v: np.ndarray
    th: np.ndarray
    mov: np.ndarray
    moved: np.ndarray
    ist: np.ndarray
    evf: np.ndarray

    @property
    def N(self) -> int:
        return self.u.shape[0] - 2

    @property
    def step(self) -> int:
        return int(self.ist[L.I_STEP])

    @property
    def stopped(self) -> np.ndarray:
        """Stuck flags of blocks 1..N."""
        return self.mov[1:-1] == 0.0

    @classmethod
    def from_blocks(cls, u, v, theta, stopped, step: int = 0, t: float = 0.0) -> LocatedState:
        """A state from per-block arrays of u = x - V t, v, theta and stuck flags at grid ``step``
        (time t = step dt); stuck blocks get v = 0, and an event is open if any block moves."""
        u = np.asarray(u, dtype=np.float64)
        N = u.shape[0]
        stopped = np.asarray(stopped, dtype=bool)
        arrays = {}
        for name, values in (("u", u), ("v", v), ("th", theta)):
            a = np.zeros(N + 2)
            a[1:-1] = np.asarray(values, dtype=np.float64)
            arrays[name] = a
        arrays["v"][1:-1][stopped] = 0.0
        mov = np.zeros(N + 2)
        mov[1:-1] = np.where(stopped, 0.0, 1.0)
        ist = np.zeros(L.IST_SIZE, dtype=np.int64)
        ist[L.I_STEP] = step
        n_moving = int(np.count_nonzero(~stopped))
        ist[L.I_MOVING] = n_moving
        moved = np.zeros(N + 2, dtype=np.int64)
        evf = np.zeros(L.EVF_SIZE)
        if n_moving:
            ist[L.I_ACTIVE] = 1
            ist[L.I_FIRST] = int(np.argmax(~stopped)) + 1
            ist[L.I_NMOVED] = n_moving
            moved[1:-1] = (~stopped).astype(np.int64)
            evf[L.F_T_START] = t
            evf[L.F_SUM_START] = float(np.sum(arrays["u"][1:-1]))
        return cls(mov=mov, moved=moved, ist=ist, evf=evf, **arrays)

    @classmethod
    def from_chain_state(
        cls, state: ChainState, params: ChainParams, *, restart_clock: bool = False, dt: float | None = None
    ) -> LocatedState:
        """The engine's state (absolute positions x at step n of ``dt``, default params.dt) in the
        located integrator's frame, u = x - V t.

        With ``restart_clock`` the state is put at t = 0 (step 0): in the frame of the drive the
        equations do not read t, so the continuation is the same, and runs at any dt can start
        from it. Fixed ends read t (x_{N+1} = 0), so they refuse it.
        """
        b = state.blocks()
        t = state.step * (params.dt if dt is None else dt)
        u = b["x"] - frame_velocity(params) * t
        if restart_clock:
            if params.ends_piece.wall:
                raise ParameterError("restart_clock needs ends that do not read t (fixed ends do)")
            if is_history(params):
                raise ParameterError("restart_clock needs a drive that does not read t (a load history does)")
            return cls.from_blocks(u, b["v"], b["theta"], b["stopped"], 0, 0.0)
        return cls.from_blocks(u, b["v"], b["theta"], b["stopped"], state.step, t)

    def blocks(self, params: ChainParams) -> dict[str, np.ndarray]:
        """Per-block copies: x = u + V t (V the frame's, :func:`frame_velocity`), u, v, theta and
        stopped, block i at index i - 1."""
        t = self.step * params.dt
        return {
            "x": self.u[1:-1] + frame_velocity(params) * t,
            "u": self.u[1:-1].copy(),
            "v": self.v[1:-1].copy(),
            "theta": self.th[1:-1].copy(),
            "stopped": self.stopped,
        }

    def copy(self) -> LocatedState:
        return LocatedState(**{k: getattr(self, k).copy() for k in ("u", "v", "th", "mov", "moved", "ist", "evf")})


def is_history(p: ChainParams) -> bool:
    """Whether the drive moves its load point along a history p(t) (its module has ``load``,
    :mod:`stickslip.models.drive.history`) rather than at the constant V."""
    return hasattr(importlib.import_module(p.drive_piece.module), "load")


def frame_velocity(p: ChainParams) -> float:
    """The velocity of the located integrator's frame, u = x - V t: the drive's V (the frame in
    which the equations are autonomous), or 0 for a load history, whose load point p(t) the
    kernels read in the lab's frame (:func:`stickslip.kernels.laws.load_point`)."""
    return 0.0 if is_history(p) else p.V


def parameter_vector(p: ChainParams) -> np.ndarray:
    """The kernel's parameter vector, laid out as the engine's (:mod:`stickslip.kernels.layout`),
    with the frame's velocity (:func:`frame_velocity`) as V; the threshold's and the friction
    law's parameters go separately (:meth:`~stickslip.models.piece.Piece.kernel_params`)."""
    par = np.zeros(layout.PAR_SIZE)
    par[layout.P_K] = p.K if isinstance(p.K, float) else float(p.K.values[0])
    par[layout.P_V], par[layout.P_DT] = frame_velocity(p), p.dt
    return par


def refuse_bonds_and_masses(params: ChainParams, what: str) -> None:
    """Refuse springs that differ from bond to bond and masses other than 1, which ``what`` does
    not take (the pieces' per-block parameters it does; docs/model.md, "Per-block parameters")."""
    K, M = params.per_block().get("K"), params.M
    if K is not None and bool((K.values != K.values[0]).any()):
        raise ParameterError(f"K must be one number for {what} (springs per bond are for the grid integrators)")
    if not isinstance(M, float) or M != 1.0:
        raise ParameterError(f"M must be 1 for {what} (masses are for the grid integrators)")


# Positions of the pieces among the arguments of L.advance and L.rates (compiled as literals).
_ADVANCE_PIECES = frozenset(range(9, 13))
_RATES_PIECES = frozenset(range(8, 11))


def rates(state: LocatedState, params: ChainParams) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """du, dv, dtheta (arrays of N + 2) of the equations at ``state`` (:func:`stickslip.kernels.located.rates`)."""
    N = state.N
    du, dv, dth = np.zeros(N + 2), np.zeros(N + 2), np.zeros(N + 2)
    drive, friction, _, ends = params.codes
    t = state.step * params.dt
    args = (state.u.copy(), state.v, state.th.copy(), state.mov, t, parameter_vector(params))
    args += (params.friction_piece.kernel_params(params), params.drive_piece.kernel_params(params))
    args += (drive, friction, ends, du, dv, dth)
    specialise_call(L.rates, args, _RATES_PIECES)
    return du, dv, dth


#: The forms of the located integrator: "fast" (:mod:`stickslip.kernels.located_fast`, the
#: default) skips work whose result is known and equals "dense" (every block at every step,
#: :func:`stickslip.kernels.located.advance`) bit for bit.
FORMS = ("fast", "dense")


class LocatedStepper:
    """Advances :class:`LocatedState` objects of one model with located switches (in place), in
    the form ``form`` (:data:`FORMS`; the results are the same bits)."""

    def __init__(self, params: ChainParams, capacity: int = 4096, form: str = "fast"):
        if form not in FORMS:
            raise ParameterError(f"form must be one of {', '.join(FORMS)} (got {form!r})")
        refuse_bonds_and_masses(params, "the located integrator")
        if not params.drive_piece.located:
            raise ParameterError(f"drive {params.drive} does not run on the located integrator (use the grid's)")
        message = context_refusal(params.friction, "the located integrator")
        if message:
            raise ParameterError(message)
        self.form = form
        # A wall's ghost cells move with t in the drive's frame, and a load history's load point
        # moves with t in the lab's: the dense form, which the fast form skips no work of there.
        self.fast = form == "fast" and not params.ends_piece.wall and not is_history(params)
        self.params = params
        self.par = parameter_vector(params)
        self.lp = params.friction_piece.kernel_params(params)
        self.tp = params.threshold_piece.kernel_params(params)
        self.dp = params.drive_piece.kernel_params(params)
        self.codes = params.codes
        N = params.N
        self.sc = tuple(np.zeros(N + 2) for _ in range(12))
        self.cand = np.zeros(N + 2, dtype=np.int64)
        self.lazy = (
            np.zeros(N + 2, dtype=np.int64),
            np.zeros(N + 2, dtype=np.int64),
            np.zeros(N + 2),
            np.zeros(N + 2, dtype=np.int64),
        )  # fast form's scratch
        self.ev_t = np.zeros((capacity, 3))
        self.ev_i = np.zeros((capacity, 2), dtype=np.int64)
        self._entries: dict = {}
        #: Work of the fast form, summed over calls (:mod:`stickslip.kernels.located_fast`): grid
        #: steps through the dense form's step, steps stepped on the moving blocks' neighbourhood
        #: or on theta alone, jumps over steps in which only the drive moves, start tests redone.
        self.work = {"switch_steps": 0, "stepped": 0, "jumps": 0, "start_tests": 0}

    def advance(self, state: LocatedState, step: int) -> tuple[LocatedState, np.ndarray]:
        """The state at grid ``step`` and the slip events completed on the way (docs/model.md),
        one row (columns :data:`EVENT_COLUMNS`) per event; :func:`events_frame` labels them."""
        if state.N != self.params.N:
            raise ParameterError(f"the state has {state.N} blocks, the parameters N = {self.params.N}")
        drive, friction, threshold, ends = self.codes
        parts = []
        while True:
            state.ist[L.I_EVENTS] = 0
            args = (state.u, state.v, state.th, state.mov, np.int64(step), self.par, self.lp, self.tp, self.dp)
            args += (drive, friction, threshold, ends, self.sc, self.cand, state.moved, state.ist, state.evf)
            args += (self.ev_t, self.ev_i)
            if self.fast:
                args += self.lazy
            # Typed once per layout of the state's arrays (the stepper's own never change).
            key = tuple((a.dtype, a.flags.c_contiguous, a.flags.writeable) for a in args[:4] + args[15:18])
            entry = self._entries.get(key)
            if entry is None:
                kernel = LF.advance_fast if self.fast else L.advance
                entry = self._entries[key] = specialised(kernel, args, _ADVANCE_PIECES)
            status = entry(*args)
            if self.fast:
                us, safe = self.lazy[0], self.lazy[1]
                for k, x in zip(self.work, (us[0], us[-1], safe[0], safe[-1]), strict=True):
                    self.work[k] += int(x)
            r = int(state.ist[L.I_EVENTS])
            if r:
                parts.append(np.column_stack((self.ev_t[:r], self.ev_i[:r])))
            if status == L.NO_PROGRESS:
                raise FloatingPointError(
                    f"the located integrator made no progress in step {state.step}: switches repeat at one"
                    " time (a block that starts where its friction at v = 0+ exceeds its force stops again"
                    " at once; the grid integrators take such a chain)"
                )
            if status == L.NONFINITE:
                raise FloatingPointError(f"the located integrator met a non-finite value at step {state.step}")
            if status == L.DONE:
                break
        if len(parts) == 1:
            return state, parts[0]
        return state, (np.concatenate(parts) if parts else np.zeros((0, len(EVENT_COLUMNS))))


def events_frame(rows: np.ndarray) -> pd.DataFrame:
    """Event rows of :meth:`LocatedStepper.advance` as a table (times and sizes, block numbers)."""
    ev = pd.DataFrame(rows, columns=EVENT_COLUMNS)
    ev[["start_block", "n_blocks"]] = ev[["start_block", "n_blocks"]].astype(np.int64)
    return ev


@dataclass(frozen=True)
class LocatedRun:
    """A run with located switches: its final state and its slip events (located times)."""

    params: ChainParams
    state: LocatedState
    events: pd.DataFrame

    @property
    def t_end(self) -> float:
        return self.state.step * self.params.dt


def start_state(
    params: ChainParams, start: str | ChainState | LocatedState = "paper", *, perturbation: float = 0.0, seed: int = 0
) -> LocatedState:
    """The initial state: a name of :func:`stickslip.run.state.initial_state`, an engine state or
    a located state (copied)."""
    if isinstance(start, LocatedState):
        return start.copy()
    if isinstance(start, str):
        start = initial_state(params, start, amplitude=perturbation, seed=seed)
    else:
        check_start_state(start, params)
    return LocatedState.from_chain_state(start, params)


def run_located(
    params: ChainParams,
    t_end: float,
    *,
    start: str | ChainState | LocatedState = "paper",
    perturbation: float = 0.0,
    seed: int = 0,
    form: str = "fast",
) -> LocatedRun:
    """Integrate the model of ``params`` (eq. (4) or a relative, docs/model.md) to ``t_end`` with
    Heun and located switches (:mod:`stickslip.kernels.located`), from ``start``.

    Second order in dt up to and across switches; the events carry located start and end times.
    ``form``: "fast" or "dense" (:data:`FORMS`), the same bits. A load history (drive history,
    :mod:`stickslip.models.drive.history`) is read at the located times, in the lab's frame, and
    runs dense.
    """
    state = start_state(params, start, perturbation=perturbation, seed=seed)
    n_end = steps_for(t_end, params.dt, "t_end")
    state, events = LocatedStepper(params, form=form).advance(state, n_end)
    return LocatedRun(params, state, events_frame(events))
