"""Numba kernels of the chain of eq. (4) and its relatives: the reference (`dense`) and the
fast (`exact`) Heun.

A model is a choice of four pieces (docs/model.md, "The family the paper stands in"), passed to
every kernel as compile-time constants (numba integer literals), so that each composition is
compiled into its own machine code with the branches on pieces removed:

* drive ``DRIVE_END``: a pulling point x_0 = V t joined to block 1 (eq. 4);
  ``DRIVE_PLATE``: every block joined to a plate at V t by a leaf spring Kp (Burridge-Knopoff,
  Carlson-Langer): f_i gains Kp (V t - x_i);
* friction of a moving block ``FRICTION_STATE``: theta_i + beta v_i with the theta equation
  of eq. (4); ``FRICTION_WEAKENING``: phi(v) = (1 - sigma) / (1 + 2 alpha max(v, 0) / (1 - sigma))
  (Carlson-Langer); ``FRICTION_STRENGTHENING``: F0 + beta v (train model), no state variable;
* static threshold ``THRESHOLD_CONSTANT``: Fs; ``THRESHOLD_STATE``: theta_i;
* ends ``ENDS_FREE``: x_{N+1} = x_N (plate drive: also x_0 = x_1); ``ENDS_FIXED``: x_{N+1} = 0
  (plate drive: also x_0 = 0); ``ENDS_PERIODIC``: x_0 = x_N, x_{N+1} = x_1 (plate drive only).

Layout. Blocks i = 1..N live at index i of arrays of length N + 2; index 0 and N + 1 are
ghost cells set from the drive and the ends. The state variable has no-flux ends,
th[0] = th[1] and th[N+1] = th[N] (periodic ends: th[0] = th[N], th[N+1] = th[1]); models
without a state variable leave theta untouched. ``mov`` holds 1.0 for a moving block and 0.0
for a stopped one, so a stopped block's acceleration is ``0 * (...)``.

One Heun step from t_n = n dt to t_{n+1} (docs/model.md):

1. start rule: a stopped block with f_i > threshold moves (with v = 0) for this step; ``mm``
   is this mid-step mask;
2. stage 1 at t_n: f_i = K ((x_{i-1} - x_i) - (x_i - x_{i+1})) [+ Kp (V t_n - x_i)],
   a_i = mm (f_i - friction), b_i = dtheta_i/dt; predictor xs = x + dt v, vs = v + dt a,
   ths = th + dt b;
3. stage 2 at t_{n+1} on the predictor, with the same mask; corrector
   x += dt/2 (v + vs), v += dt/2 (a + a2), th += dt/2 (b + b2);
4. stop rule: a moving block whose new v <= 0 gets v = 0 and stops.

Both integrators evaluate every quantity with the very same expressions (the helpers of
:mod:`stickslip.kernels.common`), so they agree bit for bit. ``exact`` only skips
work whose result is known: one step of block i reads blocks i-2..i+2 (stage 2 reads the
neighbours' predictors, which read theirs), so a block none of whose neighbours out to two
places changed in the last step cannot change now, except through the start rule. The blocks
to update form the changed set dilated by two (kept as one bounding interval, which is
conservative; on a periodic chain an interval that would wrap becomes the whole chain).

Which stopped blocks can start:

* end drive: the force on a stopped block changes only when a neighbour moves or, for block
  1, with the pulling point; so the candidates are the last step's movers +- 1 plus block 1.
  When nothing is active, nothing can change until block 1's force exceeds its threshold: the
  kernel jumps to that step, found with the step's own expression for the force (monotone
  in n).
* plate drive: every stopped block is loaded by the plate. For each stopped block the kernel
  keeps the first step at which its force, evaluated with the step's own expression, exceeds
  its threshold (``trig``); it is recomputed whenever the block's neighbourhood changes, so a
  block that starts because of the plate alone is found by comparing the step with these
  numbers. When nothing is active the kernel jumps to the smallest of them. Without a state
  variable a stopped block never changes, so ``exact`` updates lists of blocks instead of an
  interval (:mod:`stickslip.kernels.plate`).
* state threshold: a block whose theta changes may start without any neighbour moving, so
  every block whose state variable may change is a candidate.

Events (docs/model.md): an event starts with the first step in which any block moves after a
step that ended with every block stopped, and ends with the first step that ends with every
block stopped again; S = sum_i (x_i(end) - x_i(start)) over the blocks that moved, summed in
block order.

Kernels return a status code; the driver empties the output buffers and calls again. All
state lives in the arrays passed in, so a run can stop and resume at any step boundary.
:func:`specialise` compiles :func:`run_dense` or :func:`run_exact` for one model's pieces,
handed on as literals.

Modules: :mod:`stickslip.kernels.common` holds the shared pieces (indices, codes, the
step's expressions, event bookkeeping, plate start steps) and is re-exported here;
:mod:`stickslip.kernels.plate` the sparse exact path of the plate drive without a state
variable; this module the reference, the interval-based exact path and the entry points.
"""

from __future__ import annotations

from numba import njit

from stickslip.kernels.common import (  # noqa: F401 (re-exported: the kernels' public names)
    _BIG,
    _NEVER,
    ACT_HI,
    ACT_LO,
    BAD_BLOCK,
    BLOCK_UPDATES,
    DONE,
    DRIVE_END,
    DRIVE_PLATE,
    E_END_STEP,
    E_ID,
    E_MAX_BLOCK,
    E_N_BLOCKS,
    E_START_BLOCK,
    E_START_STEP,
    ENDS_FIXED,
    ENDS_FREE,
    ENDS_PERIODIC,
    EV_ACTIVE,
    EV_COUNT,
    EV_INT_COLS,
    EV_MAX_BLOCK,
    EV_N_MOVED,
    EV_P_FIRST,
    EV_START_BLOCK,
    EV_START_STEP,
    EVENTS_FULL,
    FIRST_MOVES_FULL,
    FM_COUNT,
    FRICTION_STATE,
    FRICTION_STRENGTHENING,
    FRICTION_WEAKENING,
    FULL_UPDATES,
    IST_SIZE,
    MECH_HI,
    MECH_LO,
    N_EVENTS,
    N_MOVING,
    NEXT_PROFILE,
    NEXT_SAMPLE,
    NONFINITE,
    P_ALPHA,
    P_BETA,
    P_COUNT,
    P_D,
    P_DT,
    P_F0,
    P_FS,
    P_K,
    P_KP,
    P_SIGMA,
    P_V,
    PAR_SIZE,
    PROFILES_FULL,
    S_COUNT,
    SAMPLES_FULL,
    STEP,
    STEPS_COMPUTED,
    THRESHOLD_CONSTANT,
    THRESHOLD_STATE,
    _accel,
    _dtheta,
    _end_event,
    _force,
    _merge,
    _overflow,
    _plate_fires,
    _plate_trigger,
    _plate_triggers,
    _pull,
    _right_of_first,
    _service,
    _set_ghosts,
    _start_and_first_moves,
    _threshold,
    _unpack,
)
from stickslip.kernels.plate import run_sparse


@njit(cache=True)
def run_dense(
    x,
    v,
    th,
    mov,
    xs,
    vs,
    ths,
    mm,
    a1,
    b1,
    trig,
    first_step,
    x0ev,
    ist,
    par,
    ev_int,
    ev_S,
    fm,
    samp_L,
    samp_step,
    prof_x,
    prof_meta,
    n_end,
    sample_every,
    profile_every,
    profile_min_blocks,
    drive,
    friction,
    threshold,
    ends,
):
    """Reference integrator of the chain (eq. 4 and its relatives): Heun over every block at
    every step, written plainly.

    Advances the state arrays to step ``n_end`` or until an output buffer is full; returns a
    status code (module constants). See the module docstring for the step, the pieces and the
    events. ``trig`` is scratch of :func:`run_exact`, unused here.
    """
    N = x.shape[0] - 2
    mp, V, dt = _unpack(par)
    K, Kp, Fs = mp[0], mp[1], mp[5]
    h2 = 0.5 * dt
    cap_ev, cap_fm, cap_p = ev_int.shape[0], fm.shape[0], prof_x.shape[0]
    while True:
        n = ist[STEP]
        # Outputs due, the end, buffers that could overflow. Written out here rather than in a
        # helper: as a function this costs several times a short step (measured).
        if n == ist[NEXT_SAMPLE] or (profile_every > 0 and ist[EV_ACTIVE] == 1 and n == ist[NEXT_PROFILE]):
            st = _service(n, x, N, ist, samp_L, samp_step, prof_x, prof_meta, sample_every, profile_every)
            if st != DONE:
                return st
        if n >= n_end:
            return DONE
        if ist[EV_COUNT] >= cap_ev or ist[FM_COUNT] + N > cap_fm or (profile_every > 0 and ist[P_COUNT] + 2 > cap_p):
            return _overflow(ist, N, cap_ev, cap_fm)
        p1 = _pull(V, n, dt)
        _set_ghosts(x, th, N, p1, drive, ends)
        for i in range(1, N + 1):
            f = _force(x[i - 1], x[i], x[i + 1], K, Kp, p1, drive)
            if mov[i] != 0.0 or f > _threshold(th[i], Fs, threshold):
                mm[i] = 1.0
            else:
                mm[i] = 0.0
            a1[i] = _accel(f, th[i], v[i], mm[i], mp, friction)
            b1[i] = _dtheta(th[i - 1], th[i], th[i + 1], v[i], mp, friction)
            xs[i] = x[i] + dt * v[i]
            vs[i] = v[i] + dt * a1[i]
            ths[i] = th[i] + dt * b1[i]
        p2 = _pull(V, n + 1, dt)
        _set_ghosts(xs, ths, N, p2, drive, ends)
        _start_and_first_moves(n, 1, N, x, mm, first_step, x0ev, ist, prof_x, prof_meta, N, profile_every)
        n_moving = 0
        bad = 0
        for i in range(1, N + 1):
            f2 = _force(xs[i - 1], xs[i], xs[i + 1], K, Kp, p2, drive)
            a2 = _accel(f2, ths[i], vs[i], mm[i], mp, friction)
            b2 = _dtheta(ths[i - 1], ths[i], ths[i + 1], vs[i], mp, friction)
            th[i] = th[i] + h2 * (b1[i] + b2)
            if mm[i] != 0.0:
                x[i] = x[i] + h2 * (v[i] + vs[i])
                vn = v[i] + h2 * (a1[i] + a2)
                if vn <= 0.0:
                    v[i] = 0.0
                    mov[i] = 0.0
                else:
                    v[i] = vn
                    mov[i] = 1.0
                    n_moving += 1
            else:
                v[i] = 0.0
                mov[i] = 0.0
            if bad == 0 and not (abs(x[i]) <= _BIG and abs(v[i]) <= _BIG and abs(th[i]) <= _BIG):
                bad = i
        ist[N_MOVING] = n_moving
        ist[BLOCK_UPDATES] += N
        ist[STEPS_COMPUTED] += 1
        ist[STEP] = n + 1
        if bad > 0:
            ist[BAD_BLOCK] = bad
            return NONFINITE
        if ist[EV_ACTIVE] == 1 and n_moving == 0:
            _end_event(
                n, x, first_step, x0ev, ist, ev_int, ev_S, fm, prof_x, prof_meta, N, profile_every, profile_min_blocks
            )


@njit(cache=True)
def _first_trigger(x, N, V, dt, K, thr, n_lo, n_hi, ends):
    """End drive: first step m in [n_lo, n_hi) at which stopped block 1 starts (f_1 > thr),
    else n_hi.

    Uses the step's own expression for the force, which is non-decreasing in m for V >= 0.
    """
    x1 = x[1]
    x2 = _right_of_first(x, N, ends)
    if n_lo >= n_hi or not (_force(_pull(V, n_hi - 1, dt), x1, x2, K, 0.0, 0.0, DRIVE_END) > thr):
        return n_hi
    lo = n_lo
    hi = n_hi - 1  # invariant: fires at hi
    while lo < hi:
        mid = lo + (hi - lo) // 2
        if _force(_pull(V, mid, dt), x1, x2, K, 0.0, 0.0, DRIVE_END) > thr:
            hi = mid
        else:
            lo = mid + 1
    return lo


@njit(cache=True, _nrt=False, inline="always")
def _stage1(x, v, th, mov, xs, vs, ths, mm, a1, b1, lo, hi, p, mp, dt, drive, friction, threshold):
    """Start rule, stage-1 derivatives and predictor for blocks lo..hi (branch-free).

    Works on views that begin at block lo - 1, so that every index is provably
    non-negative: the compiler then drops the negative-index handling and vectorises.
    Returns the first and the last block that move in this step (lo > hi if none) and
    whether a stopped block starts.
    """
    x = x[lo - 1 : hi + 2]
    v = v[lo - 1 : hi + 2]
    th = th[lo - 1 : hi + 2]
    mov = mov[lo - 1 : hi + 2]
    xs = xs[lo - 1 : hi + 2]
    vs = vs[lo - 1 : hi + 2]
    ths = ths[lo - 1 : hi + 2]
    mm = mm[lo - 1 : hi + 2]
    a1 = a1[lo - 1 : hi + 2]
    b1 = b1[lo - 1 : hi + 2]
    K, Kp, Fs = mp[0], mp[1], mp[5]
    n = hi - lo + 1
    first = n + 1
    last = 0
    starts = False
    for j in range(1, n + 1):
        f = _force(x[j - 1], x[j], x[j + 1], K, Kp, p, drive)
        mo = mov[j]
        m = 1.0 if f > _threshold(th[j], Fs, threshold) else mo
        mm[j] = m
        first = min(first, j if m != 0.0 else n + 1)
        last = max(last, j if m != 0.0 else 0)
        starts |= m != mo
        a = _accel(f, th[j], v[j], m, mp, friction)
        b = _dtheta(th[j - 1], th[j], th[j + 1], v[j], mp, friction)
        a1[j] = a
        b1[j] = b
        xs[j] = x[j] + dt * v[j]
        vs[j] = v[j] + dt * a
        ths[j] = th[j] + dt * b
    return first + lo - 1, last + lo - 1, starts


@njit(cache=True, inline="always")
def _stage1_all(x, v, th, xs, vs, ths, a1, b1, N, p, mp, dt, drive, friction):
    """Stage 1 over the whole chain when every block moves (no start can happen).

    The mid-step mask is 1 everywhere and is not stored: no later use reads it.
    """
    K, Kp = mp[0], mp[1]
    for i in range(1, N + 1):
        f = _force(x[i - 1], x[i], x[i + 1], K, Kp, p, drive)
        a = _accel(f, th[i], v[i], 1.0, mp, friction)
        b = _dtheta(th[i - 1], th[i], th[i + 1], v[i], mp, friction)
        a1[i] = a
        b1[i] = b
        xs[i] = x[i] + dt * v[i]
        vs[i] = v[i] + dt * a
        ths[i] = th[i] + dt * b


@njit(cache=True, inline="always")
def _stage2_all(x, v, th, xs, vs, ths, a1, b1, N, p, mp, h2, drive, friction):
    """Stage 2, corrector and stop rule over the whole chain when every block moves.

    Skips the bookkeeping of changes (every block is kept active) and returns only whether
    some block stopped. The moving flags are not written: after the step a block moves
    exactly when its v > 0, and the caller rebuilds them from v when a block stopped.
    """
    K, Kp = mp[0], mp[1]
    stops = False
    for i in range(1, N + 1):
        f2 = _force(xs[i - 1], xs[i], xs[i + 1], K, Kp, p, drive)
        a2 = _accel(f2, ths[i], vs[i], 1.0, mp, friction)
        b2 = _dtheta(ths[i - 1], ths[i], ths[i + 1], vs[i], mp, friction)
        x[i] = x[i] + h2 * (v[i] + vs[i])
        vn = v[i] + h2 * (a1[i] + a2)
        th[i] = th[i] + h2 * (b1[i] + b2)
        keep = vn > 0.0
        v[i] = vn if keep else 0.0
        stops |= not keep
    return stops


@njit(cache=True, _nrt=False, inline="always")
def _stage1_theta(x, v, th, xs, vs, ths, mm, b1, lo, hi, mp, dt, friction):
    """Stage 1 for blocks lo..hi known to stay stopped in this step (mid-step mask 0).

    For such a block v = 0 and the acceleration is 0 * (...), so the full stage gives
    xs = x, vs = v exactly; only the state variable needs its derivative.
    """
    x = x[lo - 1 : hi + 2]
    v = v[lo - 1 : hi + 2]
    th = th[lo - 1 : hi + 2]
    xs = xs[lo - 1 : hi + 2]
    vs = vs[lo - 1 : hi + 2]
    ths = ths[lo - 1 : hi + 2]
    mm = mm[lo - 1 : hi + 2]
    b1 = b1[lo - 1 : hi + 2]
    for j in range(1, hi - lo + 2):
        b = _dtheta(th[j - 1], th[j], th[j + 1], v[j], mp, friction)
        b1[j] = b
        xs[j] = x[j] + dt * v[j]
        vs[j] = v[j]
        ths[j] = th[j] + dt * b
        mm[j] = 0.0


@njit(cache=True, _nrt=False)
def _stage1_theta_only(v, th, ths, b1, lo, hi, mp, dt, friction):
    """Stage 1 for blocks lo..hi in a step in which no block moves.

    Then nothing reads the predictors of x and v or the mask, so only the state variable's
    derivative and predictor are written (see _stage1_theta for why this is exact).
    """
    v = v[lo - 1 : hi + 2]
    th = th[lo - 1 : hi + 2]
    ths = ths[lo - 1 : hi + 2]
    b1 = b1[lo - 1 : hi + 2]
    for j in range(1, hi - lo + 2):
        b = _dtheta(th[j - 1], th[j], th[j + 1], v[j], mp, friction)
        b1[j] = b
        ths[j] = th[j] + dt * b


@njit(cache=True, _nrt=False, inline="always")
def _stage2_theta(th, ths, v, b1, lo, hi, mp, h2, friction):
    """Stage 2 and corrector of the state variable alone, for blocks lo..hi that stay stopped.

    Their x, v and stopped flag provably keep every bit (see _stage1_theta), and their
    predicted velocity equals v = 0, which is read instead. Returns the first and last block
    whose state variable changed (lo > hi if none).
    """
    th = th[lo - 1 : hi + 2]
    ths = ths[lo - 1 : hi + 2]
    v = v[lo - 1 : hi + 2]
    b1 = b1[lo - 1 : hi + 2]
    n = hi - lo + 1
    c_lo = n + 1
    c_hi = 0
    for j in range(1, n + 1):
        b2 = _dtheta(ths[j - 1], ths[j], ths[j + 1], v[j], mp, friction)
        tho = th[j]
        thn = tho + h2 * (b1[j] + b2)
        th[j] = thn
        ch = thn != tho
        c_lo = min(c_lo, j if ch else n + 1)
        c_hi = max(c_hi, j if ch else 0)
    return c_lo + lo - 1, c_hi + lo - 1


@njit(cache=True, _nrt=False, inline="always")
def _stage2(x, v, th, mov, xs, vs, ths, mm, a1, b1, lo, hi, p, mp, h2, drive, friction):
    """Stage 2, corrector and stop rule for blocks lo..hi (branch-free, on views as _stage1).

    Returns the first and last block that changed (lo > hi if none) and the number of
    moving blocks among lo..hi before and after.
    """
    x = x[lo - 1 : hi + 2]
    v = v[lo - 1 : hi + 2]
    th = th[lo - 1 : hi + 2]
    mov = mov[lo - 1 : hi + 2]
    xs = xs[lo - 1 : hi + 2]
    vs = vs[lo - 1 : hi + 2]
    ths = ths[lo - 1 : hi + 2]
    mm = mm[lo - 1 : hi + 2]
    a1 = a1[lo - 1 : hi + 2]
    b1 = b1[lo - 1 : hi + 2]
    K, Kp = mp[0], mp[1]
    n = hi - lo + 1
    c_lo = n + 1
    c_hi = 0
    moved_before = 0
    moved_after = 0
    for j in range(1, n + 1):
        m = mm[j]
        f2 = _force(xs[j - 1], xs[j], xs[j + 1], K, Kp, p, drive)
        a2 = _accel(f2, ths[j], vs[j], m, mp, friction)
        b2 = _dtheta(ths[j - 1], ths[j], ths[j + 1], vs[j], mp, friction)
        xo = x[j]
        vo = v[j]
        tho = th[j]
        mo = mov[j]
        xn = xo + h2 * (vo + vs[j])
        vn = vo + h2 * (a1[j] + a2)
        thn = tho + h2 * (b1[j] + b2)
        keep = vn > 0.0
        vn = vn if keep else 0.0
        mn = m if keep else 0.0
        x[j] = xn
        v[j] = vn
        th[j] = thn
        mov[j] = mn
        ch = (xn != xo) | (vn != vo) | (thn != tho) | (mn != mo)
        c_lo = min(c_lo, j if ch else n + 1)
        c_hi = max(c_hi, j if ch else 0)
        moved_before += 1 if mo != 0.0 else 0
        moved_after += 1 if mn != 0.0 else 0
    return c_lo + lo - 1, c_hi + lo - 1, moved_before, moved_after


@njit(cache=True)
def run_exact(
    x,
    v,
    th,
    mov,
    xs,
    vs,
    ths,
    mm,
    a1,
    b1,
    trig,
    first_step,
    x0ev,
    ist,
    par,
    ev_int,
    ev_S,
    fm,
    samp_L,
    samp_step,
    prof_x,
    prof_meta,
    n_end,
    sample_every,
    profile_every,
    profile_min_blocks,
    drive,
    friction,
    threshold,
    ends,
):
    """Fast integrator of the chain, bit for bit equal to :func:`run_dense`.

    Updates only the blocks that can change (see the module docstring), in branch-free
    loops over one contiguous interval, and jumps over steps in which nothing can change.
    Same arguments, state layout and status codes as :func:`run_dense`, except that it does
    not look for non-finite values: the driver checks the state after each call and replays
    the call with :func:`run_dense`, which does, to name the step and the block. ``trig``
    (int64, N + 2) is scratch: the plate drive's first start step of each stopped block,
    rebuilt on entry.
    """
    if drive == DRIVE_PLATE:
        if friction != FRICTION_STATE:
            # No state variable: stopped blocks never change, so update a list, not an interval.
            return run_sparse(
                x,
                v,
                th,
                mov,
                xs,
                vs,
                ths,
                mm,
                a1,
                b1,
                trig,
                first_step,
                x0ev,
                ist,
                par,
                ev_int,
                ev_S,
                fm,
                samp_L,
                samp_step,
                prof_x,
                prof_meta,
                n_end,
                sample_every,
                profile_every,
                profile_min_blocks,
                drive,
                friction,
                threshold,
                ends,
            )
    N = x.shape[0] - 2
    mp, V, dt = _unpack(par)
    K, Kp, Fs = mp[0], mp[1], mp[5]
    h2 = 0.5 * dt
    cap_ev, cap_fm, cap_p = ev_int.shape[0], fm.shape[0], prof_x.shape[0]
    t_next = _NEVER  # plate drive: no stopped block starts before this step unless listed in trig
    if drive == DRIVE_PLATE:
        _set_ghosts(x, th, N, 0.0, drive, ends)
        t_next = _plate_triggers(x, th, mov, mm, trig, 1, N, True, ist[STEP], n_end, mp, V, dt, threshold)
    while True:
        n = ist[STEP]
        # Outputs due, the end, buffers that could overflow. Written out here rather than in a
        # helper: as a function this costs several times a short step (measured).
        if n == ist[NEXT_SAMPLE] or (profile_every > 0 and ist[EV_ACTIVE] == 1 and n == ist[NEXT_PROFILE]):
            st = _service(n, x, N, ist, samp_L, samp_step, prof_x, prof_meta, sample_every, profile_every)
            if st != DONE:
                return st
        if n >= n_end:
            return DONE
        if ist[EV_COUNT] >= cap_ev or ist[FM_COUNT] + N > cap_fm or (profile_every > 0 and ist[P_COUNT] + 2 > cap_p):
            return _overflow(ist, N, cap_ev, cap_fm)
        lo = ist[ACT_LO]
        hi = ist[ACT_HI]
        # Blocks that may move in this step: those that could last step, plus those the drive
        # brings to their threshold.
        ml = ist[MECH_LO]
        mh = ist[MECH_HI]
        if drive == DRIVE_END:
            x2 = _right_of_first(x, N, ends)
            if mov[1] != 0.0 or _force(_pull(V, n, dt), x[1], x2, K, Kp, 0.0, drive) > _threshold(th[1], Fs, threshold):
                lo = 1
                if hi < 1:
                    hi = 1
                ml = 1
                if mh < 1:
                    mh = 1
        elif n >= t_next:
            t_next = _NEVER
            for i in range(1, N + 1):
                if mov[i] == 0.0:
                    if trig[i] <= n:
                        ml, mh = _merge(ml, mh, i, i)
                    elif trig[i] < t_next:
                        t_next = trig[i]
            lo, hi = _merge(lo, hi, ml, mh)
        if threshold == THRESHOLD_STATE:
            # A changing state variable moves the threshold itself.
            ml, mh = _merge(ml, mh, lo, hi)
        if ends == ENDS_PERIODIC and lo <= hi and (lo == 1 or hi == N):
            # Blocks 1 and N read each other's predictors: update the whole ring.
            lo = 1
            hi = N
        if lo > hi:
            # Nothing can change before the drive starts a block: jump, but stop at due outputs.
            target = n_end
            if ist[NEXT_SAMPLE] < target:
                target = ist[NEXT_SAMPLE]
            if profile_every > 0 and ist[EV_ACTIVE] == 1 and ist[NEXT_PROFILE] < target:
                target = ist[NEXT_PROFILE]
            if drive == DRIVE_END:
                ist[STEP] = _first_trigger(x, N, V, dt, K, _threshold(th[1], Fs, threshold), n + 1, target, ends)
            else:
                ist[STEP] = t_next if t_next < target else target
            continue

        if ist[N_MOVING] == N and lo == 1 and hi == N:
            # Every block slides: no start, no first move, nothing to track but stops.
            p1 = _pull(V, n, dt)
            _set_ghosts(x, th, N, p1, drive, ends)
            _stage1_all(x, v, th, xs, vs, ths, a1, b1, N, p1, mp, dt, drive, friction)
            p2 = _pull(V, n + 1, dt)
            _set_ghosts(xs, ths, N, p2, drive, ends)
            stops = _stage2_all(x, v, th, xs, vs, ths, a1, b1, N, p2, mp, h2, drive, friction)
            ist[BLOCK_UPDATES] += N
            ist[FULL_UPDATES] += N
            ist[STEPS_COMPUTED] += 1
            ist[STEP] = n + 1
            # Every block changed: all stay candidates for the next step.
            ist[ACT_LO] = 1
            ist[ACT_HI] = N
            ist[MECH_LO] = 1
            ist[MECH_HI] = N
            if stops:
                n_moving = 0
                for i in range(1, N + 1):
                    mov[i] = 1.0 if v[i] > 0.0 else 0.0
                    n_moving += 1 if v[i] > 0.0 else 0
                ist[N_MOVING] = n_moving
                if drive == DRIVE_PLATE:
                    # The blocks that stopped need their first start step under the plate.
                    _set_ghosts(x, th, N, 0.0, drive, ends)
                    t = _plate_triggers(x, th, mov, mm, trig, 1, N, True, n + 1, n_end, mp, V, dt, threshold)
                    if t < t_next:
                        t_next = t
                if ist[EV_ACTIVE] == 1 and n_moving == 0:
                    _end_event(
                        n,
                        x,
                        first_step,
                        x0ev,
                        ist,
                        ev_int,
                        ev_S,
                        fm,
                        prof_x,
                        prof_meta,
                        N,
                        profile_every,
                        profile_min_blocks,
                    )
            continue

        p1 = _pull(V, n, dt)
        _set_ghosts(x, th, N, p1, drive, ends)
        l1 = lo - 1 if lo > 1 else 1
        h1 = hi + 1 if hi < N else N
        # Stage 1: full over [ml, mh] within [l1, h1], state variable alone elsewhere.
        fl = ml if ml > l1 else l1
        fh = mh if mh < h1 else h1
        first = h1 + 1
        last = l1 - 1
        starts = False
        if fl <= fh:
            first, last, starts = _stage1(
                x, v, th, mov, xs, vs, ths, mm, a1, b1, fl, fh, p1, mp, dt, drive, friction, threshold
            )
            if l1 < fl:
                _stage1_theta(x, v, th, xs, vs, ths, mm, b1, l1, fl - 1, mp, dt, friction)
            if fh < h1:
                _stage1_theta(x, v, th, xs, vs, ths, mm, b1, fh + 1, h1, mp, dt, friction)
        elif friction == FRICTION_STATE:
            _stage1_theta_only(v, th, ths, b1, l1, h1, mp, dt, friction)
        p2 = _pull(V, n + 1, dt)
        _set_ghosts(xs, ths, N, p2, drive, ends)
        # Only a block that starts in this step can move for the first time in an event.
        if (ist[EV_ACTIVE] == 1 and starts) or (ist[N_MOVING] == 0 and first <= last):
            _start_and_first_moves(
                n, max(first, lo), min(last, hi), x, mm, first_step, x0ev, ist, prof_x, prof_meta, N, profile_every
            )
        # Stage 2: full over the blocks that move, state variable alone elsewhere.
        sl = first if first > lo else lo
        sh = last if last < hi else hi
        c_lo = hi + 1
        c_hi = lo - 1
        moved_before = 0
        moved_after = 0
        if sl <= sh:
            c_lo, c_hi, moved_before, moved_after = _stage2(
                x, v, th, mov, xs, vs, ths, mm, a1, b1, sl, sh, p2, mp, h2, drive, friction
            )
            ist[FULL_UPDATES] += sh - sl + 1
            if friction == FRICTION_STATE:
                if lo < sl:
                    t_lo, t_hi = _stage2_theta(th, ths, v, b1, lo, sl - 1, mp, h2, friction)
                    c_lo, c_hi = _merge(c_lo, c_hi, t_lo, t_hi)
                if sh < hi:
                    t_lo, t_hi = _stage2_theta(th, ths, v, b1, sh + 1, hi, mp, h2, friction)
                    c_lo, c_hi = _merge(c_lo, c_hi, t_lo, t_hi)
        elif friction == FRICTION_STATE:
            c_lo, c_hi = _stage2_theta(th, ths, v, b1, lo, hi, mp, h2, friction)
        # Next step's movers: a stopped block starts only if its force or threshold changed;
        # through the springs that takes a neighbour's move, and only moving blocks change x.
        # So: this step's movers +- 1 (and, as above, the drive's starts and changing thetas).
        if first <= last:
            if ends == ENDS_PERIODIC and (first == 1 or last == N):
                ist[MECH_LO] = 1
                ist[MECH_HI] = N
            else:
                ist[MECH_LO] = first - 1 if first > 1 else 1
                ist[MECH_HI] = last + 1 if last < N else N
        else:
            ist[MECH_LO] = 1
            ist[MECH_HI] = 0
        n_moving = ist[N_MOVING] + moved_after - moved_before
        ist[N_MOVING] = n_moving
        ist[BLOCK_UPDATES] += hi - lo + 1
        ist[STEPS_COMPUTED] += 1
        ist[STEP] = n + 1
        # Next step's candidates: changes dilated by two, and every block that may move (a
        # start rule that fires is an event's move even when it changes no bit).
        if c_lo <= c_hi:
            if ends == ENDS_PERIODIC and (c_lo <= 2 or c_hi >= N - 1):
                c_lo = 1
                c_hi = N
            else:
                c_lo = c_lo - 2 if c_lo > 2 else 1
                c_hi = c_hi + 2 if c_hi < N - 2 else N
        ist[ACT_LO], ist[ACT_HI] = _merge(c_lo, c_hi, ist[MECH_LO], ist[MECH_HI])
        if drive == DRIVE_PLATE:
            # Stopped blocks whose force or threshold changed: their first start step anew.
            if threshold == THRESHOLD_STATE:
                w_lo, w_hi = _merge(ist[MECH_LO], ist[MECH_HI], lo, hi)
                every = True
            else:
                w_lo, w_hi = ist[MECH_LO], ist[MECH_HI]
                every = False
            if w_lo <= w_hi:
                _set_ghosts(x, th, N, 0.0, drive, ends)
                t = _plate_triggers(x, th, mov, mm, trig, w_lo, w_hi, every, n + 1, n_end, mp, V, dt, threshold)
                if t < t_next:
                    t_next = t
        if ist[EV_ACTIVE] == 1 and n_moving == 0:
            _end_event(
                n, x, first_step, x0ev, ist, ev_int, ev_S, fm, prof_x, prof_meta, N, profile_every, profile_min_blocks
            )


def specialise(kernel, args, pieces):
    """The compiled entry point of ``run_dense`` or ``run_exact`` for one model's pieces.

    ``args`` are the kernel's other arguments (arrays and integers, in order) and ``pieces``
    the codes (drive, friction, threshold, ends). Each composition is compiled once, with the
    pieces as literal constants (so branches on them vanish), and cached on disk; calling the
    returned entry point skips the dispatcher's type matching.
    """
    from numba import typeof, types

    sig = tuple(typeof(a) for a in args) + tuple(types.literal(int(c)) for c in pieces)
    key = (kernel.py_func.__name__, sig)
    entry = _ENTRIES.get(key)
    if entry is None:
        entry = kernel.compile(sig)
        _ENTRIES[key] = entry
    return entry


_ENTRIES: dict = {}
