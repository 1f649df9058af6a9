"""Checks of a chain state read from a checkpoint (eq. 4) before any kernel sees it.

A checkpoint's checksum proves only that the file is the one written; these checks make sure
that what it holds is a state the kernels can continue: integer bookkeeping in range and
consistent with the arrays, finite values, and output parts that account for every event.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from stickslip.kernels import layout
from stickslip.models.params import MAX_STEPS, ChainParams
from stickslip.run.errors import ChainRunError


def _interval(ist: np.ndarray, lo: int, hi: int, N: int) -> bool:
    """[lo, hi] is empty (lo > hi, both within the ghost cells) or inside [1, N]."""
    a, b = int(ist[lo]), int(ist[hi])
    if a > b:
        return 0 <= b and a <= N + 1
    return 1 <= a and b <= N


def check_checkpoint_state(state, params: ChainParams, options, parts: dict, where: str | Path) -> None:
    """Raise ChainRunError (one line) unless ``state`` and ``parts`` form a state a run can go on from."""
    N = params.N
    ist = state.ist
    step = int(ist[layout.STEP])
    inner = slice(1, N + 1)

    def bad(what: str) -> ChainRunError:
        return ChainRunError(f"checkpoint in {where} holds an invalid state: {what}")

    for name in ("x", "v", "th", "x0ev"):
        if not np.isfinite(getattr(state, name)[inner]).all():
            raise bad(f"{name} is not finite")
    if not 0 <= step <= MAX_STEPS:
        raise bad(f"step {step} outside [0, {MAX_STEPS}]")
    mov = state.mov[inner]
    if not np.isin(mov, (0.0, 1.0)).all():
        raise bad("the moving mask holds values other than 0 and 1")
    if int(ist[layout.N_MOVING]) != int(np.count_nonzero(mov)):
        raise bad(f"N_MOVING {int(ist[layout.N_MOVING])} != {int(np.count_nonzero(mov))} moving blocks")
    for lo, hi, name in ((layout.ACT_LO, layout.ACT_HI, "ACT"), (layout.MECH_LO, layout.MECH_HI, "MECH")):
        if not _interval(ist, lo, hi, N):
            raise bad(f"{name} interval [{int(ist[lo])}, {int(ist[hi])}] is neither empty nor within [1, {N}]")
    for idx, name in (
        (layout.EV_COUNT, "EV_COUNT"),
        (layout.FM_COUNT, "FM_COUNT"),
        (layout.S_COUNT, "S_COUNT"),
        (layout.P_COUNT, "P_COUNT"),
        (layout.EV_P_FIRST, "EV_P_FIRST"),
    ):
        if int(ist[idx]) != 0:
            raise bad(f"{name} is {int(ist[idx])}, not 0 after a flush")
    if not 0 <= int(ist[layout.BAD_BLOCK]) <= N + 1:
        raise bad(f"BAD_BLOCK {int(ist[layout.BAD_BLOCK])} outside [0, {N + 1}]")
    sample_every = int(round(options.sample_interval / params.dt))
    next_sample = int(ist[layout.NEXT_SAMPLE])
    if not step <= next_sample <= step + sample_every:
        raise bad(f"NEXT_SAMPLE {next_sample} outside [{step}, {step + sample_every}]")
    if options.profile_window is not None and int(ist[layout.NEXT_PROFILE]) < 0:
        raise bad("NEXT_PROFILE is negative")
    first = state.first_step[inner]
    if ((first < -1) | (first > step)).any():
        raise bad(f"first_step outside [-1, {step}]")
    moved = np.flatnonzero(first >= 0) + 1
    active = int(ist[layout.EV_ACTIVE])
    if active not in (0, 1):
        raise bad(f"EV_ACTIVE is {active}, not 0 or 1")
    if active == 0 and moved.size:
        raise bad("blocks carry first moves but no event is in progress")
    if active == 1:
        start, block, farthest = (
            int(ist[layout.EV_START_STEP]),
            int(ist[layout.EV_START_BLOCK]),
            int(ist[layout.EV_MAX_BLOCK]),
        )
        if not 0 <= start <= step:
            raise bad(f"EV_START_STEP {start} outside [0, {step}]")
        if not 1 <= block <= N:
            raise bad(f"EV_START_BLOCK {block} outside [1, {N}]")
        if not 0 <= farthest <= N or (moved.size and moved.max() > farthest):
            raise bad(f"EV_MAX_BLOCK {farthest} does not cover the blocks moved in the event")
        if int(ist[layout.EV_N_MOVED]) != moved.size:
            raise bad(f"EV_N_MOVED {int(ist[layout.EV_N_MOVED])} != {moved.size} blocks with a first move")
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
