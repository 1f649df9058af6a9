"""Outputs and event bookkeeping of the chain kernels: samples of L = x_1 - x_N, displacement
profiles, the start and end of slip events and their first moves (docs/model.md, "Events").

An event starts with the first step in which any block moves after a step that ended with
every block stopped, and ends with the first step that ends with every block stopped again;
S = sum_i (x_i(end) - x_i(start)) over the blocks that moved, summed in block order. Outputs
go to buffers passed in; a kernel returns a status code (:mod:`stickslip.kernels.layout`)
when one could overflow, and the driver empties them and calls again.
"""

from __future__ import annotations

from numba import njit, types
from numba.extending import overload

from stickslip.kernels.layout import (
    ALL_MOVING,
    DONE,
    E_END_STEP,
    E_ID,
    E_MAX_BLOCK,
    E_N_BLOCKS,
    E_START_BLOCK,
    E_START_STEP,
    EV_ACTIVE,
    EV_COUNT,
    EV_MAX_BLOCK,
    EV_N_MOVED,
    EV_P_FIRST,
    EV_START_BLOCK,
    EV_START_STEP,
    EVENTS_FULL,
    FIRST_MOVES_FULL,
    FM_COUNT,
    N_EVENTS,
    N_MOVING,
    NEXT_PROFILE,
    NEXT_SAMPLE,
    P_COUNT,
    PROFILES_FULL,
    S_COUNT,
    SAMPLES_FULL,
)


@njit(cache=True, inline="always")
def _profile_row(n, x, ist, prof_x, prof_meta, N, profile_every):
    """Write x_1..x_N at step n as the next profile row of the event in progress (Figs. 6-7's
    snapshots); the next one is due ``profile_every`` steps on. The caller has checked the room."""
    r = ist[P_COUNT]
    for i in range(1, N + 1):
        prof_x[r, i - 1] = x[i]
    prof_meta[r, 0] = ist[N_EVENTS]
    prof_meta[r, 1] = n
    ist[P_COUNT] = r + 1
    ist[NEXT_PROFILE] = n + profile_every


@njit(cache=True)
def _service(n, args):
    """Samples (L and the number of moving blocks) and profile rows due at step n (state at t_n;
    ``args`` the kernel's :class:`~stickslip.kernels.layout.ChainArgs`). Returns a status code:
    ALL_MOVING after a sample at which every block moves, if ``args.stop_all_moving`` (the driver
    then looks for steady sliding, ``until_steady``)."""
    x, ist, samp_L, prof_x = args.x, args.ist, args.samp_L, args.prof_x
    N = x.shape[0] - 2
    profile_every = args.profile_every
    sampled = n == ist[NEXT_SAMPLE]
    if sampled:
        k = ist[S_COUNT]
        if k >= samp_L.shape[0]:
            return SAMPLES_FULL
        samp_L[k] = x[1] - x[N]
        args.samp_step[k] = n
        args.samp_moving[k] = ist[N_MOVING]
        ist[S_COUNT] = k + 1
        ist[NEXT_SAMPLE] = n + args.sample_every
    if profile_every > 0 and ist[EV_ACTIVE] == 1 and n == ist[NEXT_PROFILE]:
        if ist[P_COUNT] >= prof_x.shape[0]:
            return PROFILES_FULL
        _profile_row(n, x, ist, prof_x, args.prof_meta, N, profile_every)
    if sampled and args.stop_all_moving != 0 and ist[N_MOVING] == N:
        return ALL_MOVING
    return DONE


@njit(cache=True)
def _overflow(ist, N, cap_ev, cap_fm):
    """Which output buffer could overflow in the next step."""
    if ist[EV_COUNT] >= cap_ev:
        return EVENTS_FULL
    if ist[FM_COUNT] + N > cap_fm:
        return FIRST_MOVES_FULL
    return PROFILES_FULL


@njit(cache=True, inline="always")
def _open_event(n, first, x, ist, prof_x, prof_meta, N, profile_every):
    """Open an event whose first block to move is ``first``, in step n (x holds t_n): its start
    and, with profiles, its first profile row."""
    ist[EV_ACTIVE] = 1
    ist[EV_START_STEP] = n
    ist[EV_START_BLOCK] = first
    ist[EV_MAX_BLOCK] = 0
    ist[EV_N_MOVED] = 0
    if profile_every > 0:
        ist[EV_P_FIRST] = ist[P_COUNT]
        _profile_row(n, x, ist, prof_x, prof_meta, N, profile_every)


@njit(cache=True)
def _start_and_first_moves(n, lo, hi, x, mm, first_step, x0ev, ist, prof_x, prof_meta, N, profile_every):
    """Event bookkeeping before stage 2 (x still holds t_n): event start and first moves.

    Called in every step of the reference: its arrays are passed one by one, not as the kernel's
    ChainArgs, which costs more per call (measured)."""
    if ist[EV_ACTIVE] == 0:
        if ist[N_MOVING] != 0:
            return
        first = -1
        for i in range(lo, hi + 1):
            if mm[i] != 0.0:
                first = i
                break
        if first < 0:
            return
        _open_event(n, first, x, ist, prof_x, prof_meta, N, profile_every)
    for i in range(lo, hi + 1):
        if mm[i] != 0.0 and first_step[i] < 0:
            first_step[i] = n
            x0ev[i] = x[i]
            ist[EV_N_MOVED] += 1
            if i > ist[EV_MAX_BLOCK]:
                ist[EV_MAX_BLOCK] = i


@njit(cache=True)
def _end_event(n, args):
    """Close the event that ended in step n (x holds t_{n+1}): S, its row, first-move rows."""
    x, first_step, x0ev, ist, fm = args.x, args.first_step, args.x0ev, args.ist, args.fm
    ev_int, ev_S, prof_x, prof_meta = args.ev_int, args.ev_S, args.prof_x, args.prof_meta
    N = x.shape[0] - 2
    eid = ist[N_EVENTS]
    S = 0.0
    k = ist[FM_COUNT]
    for i in range(1, ist[EV_MAX_BLOCK] + 1):
        if first_step[i] >= 0:
            S += x[i] - x0ev[i]
            fm[k, 0] = eid
            fm[k, 1] = i
            fm[k, 2] = first_step[i]
            k += 1
            first_step[i] = -1
    ist[FM_COUNT] = k
    r = ist[EV_COUNT]
    ev_int[r, E_ID] = eid
    ev_int[r, E_START_STEP] = ist[EV_START_STEP]
    ev_int[r, E_END_STEP] = n
    ev_int[r, E_START_BLOCK] = ist[EV_START_BLOCK]
    ev_int[r, E_MAX_BLOCK] = ist[EV_MAX_BLOCK]
    ev_int[r, E_N_BLOCKS] = ist[EV_N_MOVED]
    ev_S[r] = S
    ist[EV_COUNT] = r + 1
    if args.profile_every > 0:
        if ist[EV_N_MOVED] >= args.profile_min_blocks:
            p = ist[P_COUNT]
            for i in range(1, N + 1):
                prof_x[p, i - 1] = x[i]
            prof_meta[p, 0] = eid
            prof_meta[p, 1] = n + 1
            ist[P_COUNT] = p + 1
        else:
            ist[P_COUNT] = ist[EV_P_FIRST]  # too small to keep: drop its rows
    ist[EV_ACTIVE] = 0
    ist[N_EVENTS] = eid + 1


def _trace(trace, n, x, v, th, mov, N):
    """After step n (the arrays hold t_n): the range of v over blocks 1..N, and their state when n
    is the step due (:class:`~stickslip.kernels.layout.Trace`); nothing where ``trace`` is None, as
    for every chain."""


@overload(_trace, inline="always")
def _trace_impl(trace, n, x, v, th, mov, N):
    if isinstance(trace, types.NoneType):
        return lambda trace, n, x, v, th, mov, N: None

    def record(trace, n, x, v, th, mov, N):
        vr = trace.v_range
        for i in range(1, N + 1):
            vi = v[i]
            if vi < vr[0]:
                vr[0] = vi
            if vi > vr[1]:
                vr[1] = vi
        # count[1]: the next step to record (a comparison each step rather than a division)
        c = trace.count
        if n == c[1]:
            c[1] = n + trace.every
            k = c[0]
            if k < trace.step.shape[0]:
                for i in range(1, N + 1):
                    trace.x[k, i - 1] = x[i]
                    trace.v[k, i - 1] = v[i]
                    trace.th[k, i - 1] = th[i]
                    trace.mov[k, i - 1] = mov[i]
                trace.step[k] = n
                c[0] = k + 1

    return record
