"""Pieces shared by the chain's kernels (:mod:`stickslip.kernels.chain` and
:mod:`stickslip.kernels.plate`): the indices of the state and parameter vectors, the piece
codes and status codes, the expressions of one Heun step (``_force``, ``_accel``,
``_dtheta``, ``_threshold``, ghost cells), the event bookkeeping, and the plate drive's first
start step of a stopped block (``_plate_trigger``).

Every kernel evaluates each quantity through these helpers, so the reference and the fast
integrators agree bit for bit. See :mod:`stickslip.kernels.chain` for the model, the step
and the events.
"""

from __future__ import annotations

import numpy as np
from numba import njit

# Indices into the int64 state vector ``ist``.
STEP = 0  # n: the state held is at t_n = n dt
N_MOVING = 1  # blocks moving at t_n
EV_ACTIVE = 2  # 1 while an event is in progress
EV_START_STEP = 3  # step in which the event's first block moved
EV_START_BLOCK = 4
EV_MAX_BLOCK = 5  # farthest block moved so far in the event
EV_N_MOVED = 6  # blocks moved so far in the event
ACT_LO = 7  # blocks that may change in the next step: [ACT_LO, ACT_HI] (empty if lo > hi)
ACT_HI = 8
N_EVENTS = 9  # events completed since the start of the run (the next event's id)
EV_COUNT = 10  # rows filled in the event buffer
FM_COUNT = 11  # rows filled in the first-move buffer
S_COUNT = 12  # samples filled in the sample buffer
P_COUNT = 13  # rows filled in the profile buffer
EV_P_FIRST = 14  # first profile row of the current event in the buffer
NEXT_PROFILE = 15  # next step at which a profile row is due
BAD_BLOCK = 16  # block found non-finite (status NONFINITE)
BLOCK_UPDATES = 17  # block updates performed (stage 2), for profiling
STEPS_COMPUTED = 18  # steps actually computed (not jumped over)
NEXT_SAMPLE = 19  # next step at which L = x_1 - x_N is sampled
MECH_LO = 20  # blocks that may move in the next step: [MECH_LO, MECH_HI] (exact only)
MECH_HI = 21
FULL_UPDATES = 22  # block updates of exact that were full (the rest updated the state variable alone)
IST_SIZE = 23

# Indices into the float64 parameter vector ``par``.
P_K, P_D, P_V, P_BETA, P_ALPHA, P_FS, P_DT, P_KP, P_SIGMA, P_F0 = range(10)
PAR_SIZE = 10

# The pieces of a model (compile-time constants of every kernel).
DRIVE_END, DRIVE_PLATE = 0, 1
FRICTION_STATE, FRICTION_WEAKENING, FRICTION_STRENGTHENING = 0, 1, 2
THRESHOLD_CONSTANT, THRESHOLD_STATE = 0, 1
ENDS_FREE, ENDS_FIXED, ENDS_PERIODIC = 0, 1, 2

# Columns of the int64 event buffer ``ev_int``.
E_ID, E_START_STEP, E_END_STEP, E_START_BLOCK, E_MAX_BLOCK, E_N_BLOCKS = range(6)
EV_INT_COLS = 6

# Status codes returned by the kernels.
DONE = 0
EVENTS_FULL = 1
FIRST_MOVES_FULL = 2
SAMPLES_FULL = 3
PROFILES_FULL = 4
NONFINITE = 5

_BIG = np.float64(1.7976931348623157e308)
_NEVER = np.int64(9223372036854775807)


@njit(cache=True, inline="always")
def _force(xl, xc, xr, K, Kp, p, drive):
    """Spring force on a block: K (x_{i+1} - 2 x_i + x_{i-1}) (eq. 4), plus Kp (V t - x_i)
    from the plate at p = V t with the plate drive (Burridge-Knopoff, Carlson-Langer)."""
    if drive == DRIVE_PLATE:
        return K * ((xl - xc) - (xc - xr)) + Kp * (p - xc)
    return K * ((xl - xc) - (xc - xr))


@njit(cache=True, inline="always")
def _accel(f, th, v, m, mp, friction):
    """dv/dt of a block times the moving mask m (1.0 moving, 0.0 stopped).

    state (eq. 4): f - theta - beta v; weakening (Carlson-Langer): f - phi(v) with
    phi(v) = (1 - sigma) / (1 + 2 alpha max(v, 0) / (1 - sigma)); strengthening (train
    model): f - F0 - beta v. ``mp`` = (K, Kp, beta, alpha, D, Fs, 1 - sigma, 2 alpha, F0).
    """
    if friction == FRICTION_WEAKENING:
        w = mp[6]
        return m * (f - w / (1.0 + mp[7] * max(v, 0.0) / w))
    if friction == FRICTION_STRENGTHENING:
        return m * (f - mp[8] - mp[2] * v)
    return m * (f - th - mp[2] * v)


@njit(cache=True, inline="always")
def _dtheta(thl, th, thr, v, mp, friction):
    """dtheta/dt of eq. (4) with diffusion D, for moving and stopped blocks alike (0 for
    frictions without a state variable)."""
    if friction == FRICTION_STATE:
        return th * (1.0 - th) - mp[3] * th * v + mp[4] * ((thl - th) - (th - thr))
    return 0.0


@njit(cache=True, inline="always")
def _threshold(th, Fs, threshold):
    """Static threshold of the start rule: Fs, or theta_i for the state threshold."""
    if threshold == THRESHOLD_STATE:
        return th
    return Fs


@njit(cache=True, inline="always")
def _pull(V, n, dt):
    """Pulling point (or plate) V t_n with t_n = n dt from the integer step count (docs/model.md)."""
    return V * (np.float64(n) * dt)


@njit(cache=True, inline="always")
def _set_ghosts(x, th, N, p, drive, ends):
    """Ghost cells 0 and N + 1 from the drive and the ends (module docstring)."""
    if drive == DRIVE_END:
        x[0] = p
    elif ends == ENDS_PERIODIC:
        x[0] = x[N]
    elif ends == ENDS_FIXED:
        x[0] = 0.0
    else:
        x[0] = x[1]
    if ends == ENDS_PERIODIC:
        x[N + 1] = x[1]
        th[0] = th[N]
        th[N + 1] = th[1]
    else:
        if ends == ENDS_FIXED:
            x[N + 1] = 0.0
        else:
            x[N + 1] = x[N]
        th[0] = th[1]
        th[N + 1] = th[N]


@njit(cache=True, inline="always")
def _right_of_first(x, N, ends):
    """x_2 as block 1's force reads it (the ghost cell when N = 1; end drive)."""
    if N > 1:
        return x[2]
    if ends == ENDS_FIXED:
        return 0.0
    return x[1]


@njit(cache=True)
def _service(n, x, N, ist, samp_L, samp_step, prof_x, prof_meta, sample_every, profile_every):
    """Samples and profile rows due at step n (state at t_n). Returns a status code."""
    if n == ist[NEXT_SAMPLE]:
        k = ist[S_COUNT]
        if k >= samp_L.shape[0]:
            return SAMPLES_FULL
        samp_L[k] = x[1] - x[N]
        samp_step[k] = n
        ist[S_COUNT] = k + 1
        ist[NEXT_SAMPLE] = n + sample_every
    if profile_every > 0 and ist[EV_ACTIVE] == 1 and n == ist[NEXT_PROFILE]:
        r = ist[P_COUNT]
        if r >= prof_x.shape[0]:
            return PROFILES_FULL
        for i in range(1, N + 1):
            prof_x[r, i - 1] = x[i]
        prof_meta[r, 0] = ist[N_EVENTS]
        prof_meta[r, 1] = n
        ist[P_COUNT] = r + 1
        ist[NEXT_PROFILE] = n + profile_every
    return DONE


@njit(cache=True, inline="always")
def _merge(a_lo, a_hi, b_lo, b_hi):
    """Hull of two intervals of blocks, either of which may be empty (lo > hi)."""
    if b_lo > b_hi:
        return a_lo, a_hi
    if a_lo > a_hi:
        return b_lo, b_hi
    return min(a_lo, b_lo), max(a_hi, b_hi)


@njit(cache=True, inline="always")
def _unpack(par):
    """(K, Kp, beta, alpha, D, Fs, 1 - sigma, 2 alpha, F0), V and dt from the parameter vector."""
    mp = (
        par[P_K],
        par[P_KP],
        par[P_BETA],
        par[P_ALPHA],
        par[P_D],
        par[P_FS],
        1.0 - par[P_SIGMA],
        2.0 * par[P_ALPHA],
        par[P_F0],
    )
    return mp, par[P_V], par[P_DT]


@njit(cache=True)
def _overflow(ist, N, cap_ev, cap_fm):
    """Which output buffer could overflow in the next step."""
    if ist[EV_COUNT] >= cap_ev:
        return EVENTS_FULL
    if ist[FM_COUNT] + N > cap_fm:
        return FIRST_MOVES_FULL
    return PROFILES_FULL


@njit(cache=True)
def _start_and_first_moves(n, lo, hi, x, mm, first_step, x0ev, ist, prof_x, prof_meta, N, profile_every):
    """Event bookkeeping before stage 2 (x still holds t_n): event start and first moves."""
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
        ist[EV_ACTIVE] = 1
        ist[EV_START_STEP] = n
        ist[EV_START_BLOCK] = first
        ist[EV_MAX_BLOCK] = 0
        ist[EV_N_MOVED] = 0
        if profile_every > 0:
            r = ist[P_COUNT]
            ist[EV_P_FIRST] = r
            for i in range(1, N + 1):
                prof_x[r, i - 1] = x[i]
            prof_meta[r, 0] = ist[N_EVENTS]
            prof_meta[r, 1] = n
            ist[P_COUNT] = r + 1
            ist[NEXT_PROFILE] = n + profile_every
    for i in range(lo, hi + 1):
        if mm[i] != 0.0 and first_step[i] < 0:
            first_step[i] = n
            x0ev[i] = x[i]
            ist[EV_N_MOVED] += 1
            if i > ist[EV_MAX_BLOCK]:
                ist[EV_MAX_BLOCK] = i


@njit(cache=True)
def _end_event(n, x, first_step, x0ev, ist, ev_int, ev_S, fm, prof_x, prof_meta, N, profile_every, profile_min_blocks):
    """Close the event that ended in step n (x holds t_{n+1}): S, its row, first-move rows."""
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
    if profile_every > 0:
        if ist[EV_N_MOVED] >= profile_min_blocks:
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


@njit(cache=True, inline="always")
def _plate_fires(xl, xc, xr, thr, K, Kp, V, dt, m):
    return _force(xl, xc, xr, K, Kp, _pull(V, m, dt), DRIVE_PLATE) > thr


@njit(cache=True)
def _plate_trigger(xl, xc, xr, thr, K, Kp, V, dt, n0, n_cap):
    """Plate drive: first step m in [n0, n_cap) at which a stopped block with neighbours xl, xr
    starts (f > thr), else n_cap.

    The force, evaluated with the step's own expression, is non-decreasing in m for V, Kp >= 0;
    a first guess from its rate Kp V dt is refined by bisection, so the answer is exact.
    """
    if n0 >= n_cap:
        return n_cap
    if _plate_fires(xl, xc, xr, thr, K, Kp, V, dt, n0):
        return n0
    if not _plate_fires(xl, xc, xr, thr, K, Kp, V, dt, n_cap - 1):
        return n_cap
    lo = n0  # does not fire
    hi = n_cap - 1  # fires
    f0 = _force(xl, xc, xr, K, Kp, _pull(V, n0, dt), DRIVE_PLATE)
    rate = Kp * V * dt
    if rate > 0.0:
        guess = (thr - f0) / rate
        if guess < np.float64(hi - lo):
            g = lo + 1 + np.int64(guess)
            if g < hi:
                if _plate_fires(xl, xc, xr, thr, K, Kp, V, dt, g):
                    hi = g
                    if not _plate_fires(xl, xc, xr, thr, K, Kp, V, dt, g - 1):
                        return g
                    hi = g - 1
                else:
                    lo = g
                    if _plate_fires(xl, xc, xr, thr, K, Kp, V, dt, g + 1):
                        return g + 1
                    lo = g + 1
    while hi - lo > 1:
        mid = lo + (hi - lo) // 2
        if _plate_fires(xl, xc, xr, thr, K, Kp, V, dt, mid):
            hi = mid
        else:
            lo = mid
    return hi


@njit(cache=True)
def _plate_triggers(x, th, mov, mm, trig, lo, hi, every, n0, n_cap, mp, V, dt, threshold):
    """Recompute ``trig`` for the stopped blocks lo..hi (ghost cells of x set); returns their
    smallest value (``_NEVER`` if none).

    Unless ``every``, only blocks whose x or a neighbour's x may have changed in the step just
    taken are redone: the ends of the interval (neighbours of its outermost movers), and inside
    it the blocks next to or at a block of the mid-step mask ``mm``, which holds this step's
    movers on the interval (only they change x).
    """
    K, Kp, Fs = mp[0], mp[1], mp[5]
    N = x.shape[0] - 2
    t_min = _NEVER
    for i in range(lo, hi + 1):
        redo = every or i == lo or i == hi or i == 1 or i == N
        if not redo:
            redo = mm[i - 1] != 0.0 or mm[i] != 0.0 or mm[i + 1] != 0.0
        if not redo:
            if mov[i] == 0.0 and trig[i] < t_min:
                t_min = trig[i]
            continue
        if mov[i] == 0.0:
            m = _plate_trigger(x[i - 1], x[i], x[i + 1], _threshold(th[i], Fs, threshold), K, Kp, V, dt, n0, n_cap)
            trig[i] = m
            if m < t_min:
                t_min = m
        else:
            trig[i] = _NEVER
    return t_min
