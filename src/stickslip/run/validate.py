"""Checks of a chain state (eq. 4) before any kernel sees it: a start state and a checkpoint's.

The kernels index their arrays with the integers of the state and trust its shapes: a state
whose ``v`` is shorter than ``x``, or whose active range reaches past the chain, would have them
read and write outside the arrays. A checkpoint's checksum proves only that the file is the one
written. These checks make sure that what a run starts or goes on from is a state the kernels
can continue: arrays of the right shape and type, finite values in the model's range, integer
bookkeeping in range and consistent with the arrays, the model the state belongs to, and, for a
checkpoint, output parts that account for every event. They run once, before a run.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from stickslip.kernels import layout
from stickslip.models.params import MAX_STEPS, ChainParams, ParameterError
from stickslip.run.errors import ChainRunError

__all__ = ["check_chain_params", "check_start_state", "check_checkpoint_state", "state_problem", "array_problem"]

#: The arrays of a state: their type and length (N + 2 with the ghost cells, or the integer vector's).
_FLOAT = ("x", "v", "th", "mov", "x0ev")
_INT = ("first_step",)


def array_problem(state, N: int) -> str | None:
    """What is wrong with the arrays of ``state`` for a chain of N blocks (type, shape), or None."""
    fields = getattr(state, "FIELDS", {})
    for name in (*_FLOAT, *_INT, "ist"):
        a = getattr(state, fields.get(name, name), None)
        dtype = np.int64 if name in (*_INT, "ist") else np.float64
        shape = (layout.IST_SIZE,) if name == "ist" else (N + 2,)
        if not isinstance(a, np.ndarray):
            return f"{name} is a {type(a).__name__}, not a numpy array"
        if a.dtype != dtype or a.shape != shape:
            return f"{name} has shape {a.shape} and type {a.dtype}, not {shape} and {np.dtype(dtype)} (N = {N})"
    return None


def _interval(ist: np.ndarray, lo: int, hi: int, N: int) -> bool:
    """[lo, hi] is empty (lo > hi, both within the ghost cells) or inside [1, N]."""
    a, b = int(ist[lo]), int(ist[hi])
    if a > b:
        return 0 <= b and a <= N + 1
    return 1 <= a and b <= N


def state_problem(state, params: ChainParams) -> str | None:
    """What makes ``state`` (arrays already of the right shape) one no kernel may continue, or None:
    non-finite or out-of-range values, integer bookkeeping outside the chain or inconsistent with
    the arrays (the event in progress, the active range, the moving count)."""
    N = params.N
    ist = state.ist
    step = int(ist[layout.STEP])
    inner = slice(1, N + 1)
    for name, a in (("x", state.xg), ("v", state.vg), ("th", state.thg), ("x0ev", state.x0ev)):
        if not np.isfinite(a[inner]).all():
            return f"{name} is not finite"
    bounds = params.friction_piece.theta_range
    if bounds is not None:
        low, high, low_open = bounds
        th = state.thg[inner]
        if ((th <= low) if low_open else (th < low)).any() or (th > high).any():
            allowed = f"{'>' if low_open else '>='} {low:g}" + (f" and <= {high:g}" if np.isfinite(high) else "")
            return f"theta must be {allowed} for friction {params.friction} (got {th.min():g} to {th.max():g})"
    if not 0 <= step <= MAX_STEPS:
        return f"step {step} outside [0, {MAX_STEPS}]"
    mov = state.mov[inner]
    if not np.isin(mov, (0.0, 1.0)).all():
        return "the moving mask holds values other than 0 and 1"
    if (state.vg[inner][mov == 0.0] != 0.0).any():
        return "a stopped block has a velocity other than 0"
    if int(ist[layout.N_MOVING]) != int(np.count_nonzero(mov)):
        return f"N_MOVING {int(ist[layout.N_MOVING])} != {int(np.count_nonzero(mov))} moving blocks"
    for lo, hi, name in ((layout.ACT_LO, layout.ACT_HI, "ACT"), (layout.MECH_LO, layout.MECH_HI, "MECH")):
        if not _interval(ist, lo, hi, N):
            return f"{name} interval [{int(ist[lo])}, {int(ist[hi])}] is neither empty nor within [1, {N}]"
    moving = np.flatnonzero(mov) + 1
    if moving.size and not int(ist[layout.ACT_LO]) <= moving.min() <= moving.max() <= int(ist[layout.ACT_HI]):
        return f"moving blocks lie outside the ACT interval [{int(ist[layout.ACT_LO])}, {int(ist[layout.ACT_HI])}]"
    for idx, name in (
        (layout.EV_COUNT, "EV_COUNT"),
        (layout.FM_COUNT, "FM_COUNT"),
        (layout.S_COUNT, "S_COUNT"),
        (layout.P_COUNT, "P_COUNT"),
        (layout.EV_P_FIRST, "EV_P_FIRST"),
    ):
        if int(ist[idx]) != 0:
            return f"{name} is {int(ist[idx])}, not 0 after a flush"
    for idx, name in (
        (layout.N_EVENTS, "N_EVENTS"),
        (layout.NEXT_PROFILE, "NEXT_PROFILE"),
        (layout.BLOCK_UPDATES, "BLOCK_UPDATES"),
        (layout.STEPS_COMPUTED, "STEPS_COMPUTED"),
        (layout.FULL_UPDATES, "FULL_UPDATES"),
    ):
        if int(ist[idx]) < 0:
            return f"{name} is negative"
    if not 0 <= int(ist[layout.BAD_BLOCK]) <= N + 1:
        return f"BAD_BLOCK {int(ist[layout.BAD_BLOCK])} outside [0, {N + 1}]"
    first = state.first_step[inner]
    if ((first < -1) | (first > step)).any():
        return f"first_step outside [-1, {step}]"
    moved = np.flatnonzero(first >= 0) + 1
    active = int(ist[layout.EV_ACTIVE])
    if active not in (0, 1):
        return f"EV_ACTIVE is {active}, not 0 or 1"
    if active == 0 and moved.size:
        return "blocks carry first moves but no event is in progress"
    if active == 1:
        start, block, farthest = (
            int(ist[layout.EV_START_STEP]),
            int(ist[layout.EV_START_BLOCK]),
            int(ist[layout.EV_MAX_BLOCK]),
        )
        if not 0 <= start <= step:
            return f"EV_START_STEP {start} outside [0, {step}]"
        if not 1 <= block <= N:
            return f"EV_START_BLOCK {block} outside [1, {N}]"
        if not 0 <= farthest <= N or (moved.size and moved.max() > farthest):
            return f"EV_MAX_BLOCK {farthest} does not cover the blocks moved in the event"
        if int(ist[layout.EV_N_MOVED]) != moved.size:
            return f"EV_N_MOVED {int(ist[layout.EV_N_MOVED])} != {moved.size} blocks with a first move"
    return None


def _model_text(model: dict) -> str:
    pieces = ", ".join(f"{k} {model.get(k)}" for k in ("drive", "friction", "threshold", "ends"))
    return f"{model.get('model')} ({pieces})"


def check_chain_params(params, name: str = "params") -> None:
    """Raise TypeError unless ``params`` are :class:`ChainParams` (eq. 4 or a relative)."""
    if not isinstance(params, ChainParams):
        raise TypeError(
            f"{name} must be ChainParams (stickslip.models.presets.chain_params(MODEL, ...)), "
            f"not {type(params).__name__} {params!r:.40}"
        )


def check_start_state(state, params: ChainParams, where: str = "the start state", t_end: float | None = None) -> None:
    """Raise :class:`ParameterError` (one line) unless ``state`` is a state of the chain of
    ``params`` (eq. 4 or the relative they name) that a run may start from: a
    :class:`~stickslip.run.state.ChainState` of N blocks with arrays of the kernels' types, of
    the model of ``params`` where the state knows its model, :func:`state_problem` finds
    nothing wrong with it, and a run to ``t_end`` (if given) has a step to make."""
    from stickslip.run.state import ChainState, model_of

    if not isinstance(state, ChainState):
        raise ParameterError(f"{where} must be a ChainState or a start name (got {type(state).__name__})")
    n_state = getattr(state.xg, "shape", (0,))[0] - 2 if getattr(state.xg, "ndim", 0) == 1 else None
    if n_state is not None and n_state != params.N:
        raise ParameterError(f"{where} has {n_state} blocks but N = {params.N}")
    problem = array_problem(state, params.N)
    if problem is None and state.model is not None:
        mine = model_of(params)
        if any(state.model.get(k) != mine[k] for k in ("drive", "friction", "threshold", "ends")):
            problem = f"it is a state of {_model_text(state.model)}, this run is {_model_text(mine)}"
    if problem is None:
        problem = state_problem(state, params)
    if problem is not None:
        raise ParameterError(f"{where} cannot be run: {problem}")
    t0 = int(state.ist[layout.STEP]) * params.dt
    if t_end is not None and not t_end > t0:
        raise ParameterError(f"t_end must be after the start state's time {t0:g} (got {t_end:g})")


def check_checkpoint_state(state, params: ChainParams, options, parts: dict, where: str | Path) -> None:
    """Raise ChainRunError (one line) unless ``state`` and ``parts`` form a state a run can go on from."""

    def bad(what: str) -> ChainRunError:
        return ChainRunError(f"checkpoint in {where} holds an invalid state: {what}")

    problem = array_problem(state, params.N) or state_problem(state, params)
    if problem is not None:
        raise bad(problem)
    ist = state.ist
    step = int(ist[layout.STEP])
    sample_every = int(round(options.sample_interval / params.dt))
    next_sample = int(ist[layout.NEXT_SAMPLE])
    if not step <= next_sample <= step + sample_every:
        raise bad(f"NEXT_SAMPLE {next_sample} outside [{step}, {step + sample_every}]")
    n_events = int(ist[layout.N_EVENTS])
    rows = [np.asarray(a) for a in parts.get("ev_int", [])]
    listed = sum(a.shape[0] for a in rows)
    if n_events < 0 or listed != n_events:
        raise bad(f"{n_events} events completed but its parts list {listed}")
    if rows:
        ev = np.concatenate(rows)
        if ev.ndim != 2 or ev.shape[1] != layout.EV_INT_COLS or (ev[:, layout.E_ID] != np.arange(n_events)).any():
            raise bad("the event parts are not the events 0, 1, ... in order")
        fm_rows = sum(np.asarray(a).shape[0] for a in parts.get("fm", []))
        if fm_rows != int(ev[:, layout.E_N_BLOCKS].sum()):
            raise bad("the first-move parts do not match the events' moved blocks")
    if len(parts.get("samp_L", [])) != len(parts.get("samp_step", [])):
        raise bad("the sample parts are incomplete")
