"""The Heun stages of the fast interval path (:mod:`stickslip.kernels.exact`) over a contiguous
interval of blocks: the general stages with the start and stop rules, the stages of a run of
blocks that all slide (the whole chain when it slides throughout), and the stages of blocks known
to stay stopped, which change their state variable alone
(eq. 4, docs/model.md; the step is in :mod:`stickslip.kernels.laws`).

Each evaluates every quantity with the expressions of :mod:`stickslip.kernels.laws`, in the
reference's order, so the result equals :func:`stickslip.kernels.dense.run_dense` bit for bit.
The loops are branch-free and index the blocks with unsigned integers, so that the compiler
drops the negative-index handling and vectorises them (views that begin at block lo - 1 do the
same, but setting up ten views costs more than a short interval's update: measured).

A vectorised loop does 8 blocks per iteration and the rest one at a time, at about four times
the cost of a block in the vector part; each loop also checks at entry, array pair by array
pair, that its arrays do not overlap (numba cannot say so). So a few long loops per step are
cheap, many short ones are not: the exact path runs the blocks that move throughout as one
run (:func:`_stage1_run`, :func:`_stage2_run`, which skip the start rule and the bookkeeping
of changes), with the run's bounds fixed over the steps of one run so that the compiler makes
these checks once per run.

Where the drive and the friction law run as lanes (their ``PIECE.lanes``), the run stages and the
stopped blocks' state-variable stages take 8 blocks at a time instead
(:mod:`stickslip.kernels.lanes`): each group loads its blocks and their neighbours, calls the
pieces' functions on the 8 lanes and stores the results, the last group under a mask, with no
overlap checks and no scalar remainder (``*_lanes``; the loops are ``*_loop``). Which of the two a
kernel runs is resolved when it is compiled (numba's ``overload`` on the pieces' literals).

The loops take the state variable's rate through :func:`stickslip.kernels.laws._dtheta_in`, with
the velocities (v in stage 1, the predictor vs in stage 2) and the drive's velocity ``q``: for a law
that reads the stress rate (``PIECE.context``) it builds the rate of the elastic force on the block
from them, and for every other law it is :func:`~stickslip.kernels.laws._dtheta`, ``q`` and the
arrays unread (0.0 and compiled away), so those laws' loops are as before. Such a law runs the loops.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numba.extending import overload

from stickslip.kernels import lanes
from stickslip.kernels.laws import _accel, _dtheta, _dtheta_in, _force, _threshold, piece_attr, reads_context


@njit(cache=True, _nrt=False, inline="always")
def _stage1(x, v, th, mov, xs, vs, ths, mm, a1, b1, lo, hi, p, q, mp, dt, drive, friction, threshold):
    """Start rule, stage-1 derivatives and predictor for blocks lo..hi (branch-free).

    Returns the first and the last block that move in this step (lo > hi if none) and
    whether a stopped block starts.
    """
    K, dp, tp = mp[0], mp[1], mp[2]
    one = np.uint64(1)
    u0 = np.uint64(lo)
    n = hi - lo + 1
    first = n
    last = -1
    starts = False
    for k in range(n):
        i = u0 + np.uint64(k)
        f = _force(x[i - one], x[i], x[i + one], K, dp, p, drive, i)
        mo = mov[i]
        m = 1.0 if f > _threshold(th[i], tp, threshold, i) else mo
        mm[i] = m
        first = min(first, k if m != 0.0 else n)
        last = max(last, k if m != 0.0 else -1)
        starts |= m != mo
        a = _accel(f, th[i], v[i], m, mp, friction, i)
        b = _dtheta_in(th[i - one], th[i], th[i + one], v[i], v, q, mp, drive, friction, i)
        a1[i] = a
        b1[i] = b
        xs[i] = x[i] + dt * v[i]
        vs[i] = v[i] + dt * a
        ths[i] = th[i] + dt * b
    return first + lo, last + lo, starts


@njit(cache=True, _nrt=False, inline="always")
def _stage1_theta_loop(x, v, th, xs, vs, ths, mm, b1, lo, hi, q, mp, dt, drive, friction):
    """Stage 1 for blocks lo..hi known to stay stopped in this step (mid-step mask 0).

    For such a block v = 0 and the acceleration is 0 * (...), so the full stage gives
    xs = x, vs = v exactly; only the state variable needs its derivative.
    """
    one = np.uint64(1)
    for i in range(np.uint64(lo), np.uint64(hi) + one):
        b = _dtheta_in(th[i - one], th[i], th[i + one], v[i], v, q, mp, drive, friction, i)
        b1[i] = b
        xs[i] = x[i] + dt * v[i]
        vs[i] = v[i]
        ths[i] = th[i] + dt * b
        mm[i] = 0.0


@njit(cache=True, _nrt=False)
def _stage1_theta_only_loop(v, th, ths, b1, lo, hi, q, mp, dt, drive, friction):
    """Stage 1 for stopped blocks lo..hi whose predictors of x and v and mask nothing reads: in a
    step in which no block moves, or not next to a block that may move (stage 2 reads those of
    its movers' neighbours only).

    So only the state variable's derivative and predictor are written (see _stage1_theta_loop for why
    this is exact).
    """
    one = np.uint64(1)
    for i in range(np.uint64(lo), np.uint64(hi) + one):
        b = _dtheta_in(th[i - one], th[i], th[i + one], v[i], v, q, mp, drive, friction, i)
        b1[i] = b
        ths[i] = th[i] + dt * b


@njit(cache=True, _nrt=False, inline="always")
def _stage2_theta_loop(th, ths, v, vs, b1, lo, hi, q, mp, h2, drive, friction):
    """Stage 2 and corrector of the state variable alone, for blocks lo..hi that stay stopped.

    Their x, v and stopped flag provably keep every bit (see _stage1_theta_loop), and their
    predicted velocity equals v = 0, which is read instead. Returns the first and last block
    whose state variable changed (lo > hi if none).
    """
    one = np.uint64(1)
    u0 = np.uint64(lo)
    n = hi - lo + 1
    c_lo = n
    c_hi = -1
    for k in range(n):
        i = u0 + np.uint64(k)
        b2 = _dtheta_in(ths[i - one], ths[i], ths[i + one], v[i], vs, q, mp, drive, friction, i)
        tho = th[i]
        thn = tho + h2 * (b1[i] + b2)
        th[i] = thn
        ch = thn != tho
        c_lo = min(c_lo, k if ch else n)
        c_hi = max(c_hi, k if ch else -1)
    return c_lo + lo, c_hi + lo


@njit(cache=True, _nrt=False, inline="always")
def _stage2(x, v, th, mov, xs, vs, ths, mm, a1, b1, lo, hi, p, q, mp, h2, drive, friction):
    """Stage 2, corrector and stop rule for blocks lo..hi (branch-free).

    Returns the first and last block that changed (lo > hi if none) and the number of
    moving blocks among lo..hi before and after.
    """
    K, dp = mp[0], mp[1]
    one = np.uint64(1)
    u0 = np.uint64(lo)
    n = hi - lo + 1
    c_lo = n
    c_hi = -1
    moved_before = 0
    moved_after = 0
    for k in range(n):
        i = u0 + np.uint64(k)
        m = mm[i]
        f2 = _force(xs[i - one], xs[i], xs[i + one], K, dp, p, drive, i)
        a2 = _accel(f2, ths[i], vs[i], m, mp, friction, i)
        b2 = _dtheta_in(ths[i - one], ths[i], ths[i + one], vs[i], vs, q, mp, drive, friction, i)
        xo = x[i]
        vo = v[i]
        tho = th[i]
        mo = mov[i]
        xn = xo + h2 * (vo + vs[i])
        vn = vo + h2 * (a1[i] + a2)
        thn = tho + h2 * (b1[i] + b2)
        keep = vn > 0.0
        vn = vn if keep else 0.0
        mn = m if keep else 0.0
        x[i] = xn
        v[i] = vn
        th[i] = thn
        mov[i] = mn
        ch = (xn != xo) | (vn != vo) | (thn != tho) | (mn != mo)
        c_lo = min(c_lo, k if ch else n)
        c_hi = max(c_hi, k if ch else -1)
        moved_before += 1 if mo != 0.0 else 0
        moved_after += 1 if mn != 0.0 else 0
    return c_lo + lo, c_hi + lo, moved_before, moved_after


@njit(cache=True, _nrt=False, inline="always")
def _stage1_run_loop(x, v, th, xs, vs, ths, a1, b1, lo, hi, p, q, mp, dt, drive, friction):
    """Stage 1 for blocks lo..hi that all move at t_n (a run of sliding blocks).

    A moving block moves in this step whatever its force (start rule), so the mask is 1 and
    no start is looked for; the expressions are those of :func:`_stage1` with m = 1. The mask
    itself is not written: it stays 1 on the run from step to step, and the caller sets it
    once per run.
    """
    K, dp = mp[0], mp[1]
    one = np.uint64(1)
    for i in range(np.uint64(lo), np.uint64(hi) + one):
        # The block's own values read once, before the stores: the compiler cannot tell that the
        # arrays do not overlap and would read again after each store (measured: 2% of the run).
        xi = x[i]
        vi = v[i]
        ti = th[i]
        f = _force(x[i - one], xi, x[i + one], K, dp, p, drive, i)
        a = _accel(f, ti, vi, 1.0, mp, friction, i)
        b = _dtheta_in(th[i - one], ti, th[i + one], vi, v, q, mp, drive, friction, i)
        xs[i] = xi + dt * vi
        vs[i] = vi + dt * a
        ths[i] = ti + dt * b
        a1[i] = a
        b1[i] = b


@njit(cache=True, _nrt=False, inline="always")
def _stage2_run_loop(x, v, th, xs, vs, ths, a1, b1, lo, hi, p, q, mp, h2, drive, friction):
    """Stage 2, corrector and stop rule for a run lo..hi of blocks moving in this step.

    The moving flags are not written and the changes not tracked (the caller counts the run as
    changed); returns whether some block stopped. The velocity is stored as computed: where a
    block stopped (rare), the caller sets it to 0. With lo..hi = 1..N it is the step of a chain
    that slides throughout.
    """
    K, dp = mp[0], mp[1]
    one = np.uint64(1)
    stops = False
    for i in range(np.uint64(lo), np.uint64(hi) + one):
        # Read once, stored last (as in _stage1_run_loop).
        vi = v[i]
        vsi = vs[i]
        tsi = ths[i]
        f2 = _force(xs[i - one], xs[i], xs[i + one], K, dp, p, drive, i)
        a2 = _accel(f2, tsi, vsi, 1.0, mp, friction, i)
        b2 = _dtheta_in(ths[i - one], tsi, ths[i + one], vsi, vs, q, mp, drive, friction, i)
        xn = x[i] + h2 * (vi + vsi)
        vn = vi + h2 * (a1[i] + a2)
        thn = th[i] + h2 * (b1[i] + b2)
        x[i] = xn
        v[i] = vn
        th[i] = thn
        stops |= not vn > 0.0
    return stops


@njit(cache=True, _nrt=False)
def _stage1_group(x, v, th, xs, vs, ths, a1, b1, i, n, p, mp, dt, drive, friction):
    """Stage 1 of a run for blocks i..i+n-1 (n <= 8) as lanes: :func:`_stage1_run_loop`'s
    expressions on 8 blocks at once (:mod:`stickslip.kernels.lanes`). The arrays are given by the
    addresses of their data (``a.ctypes.data``), as in every ``*_group``."""
    K, dp = mp[0], mp[1]
    one = np.uint64(1)
    xi = lanes.load(x, i, n)
    vi = lanes.load(v, i, n)
    ti = lanes.load(th, i, n)
    g = (i, n)
    f = _force(lanes.load(x, i - one, n), xi, lanes.load(x, i + one, n), K, dp, p, drive, g)
    a = _accel(f, ti, vi, 1.0, mp, friction, g)
    b = _dtheta(lanes.load(th, i - one, n), ti, lanes.load(th, i + one, n), vi, mp, friction, g)
    lanes.store(xs, i, n, xi + dt * vi)
    lanes.store(vs, i, n, vi + dt * a)
    lanes.store(ths, i, n, ti + dt * b)
    lanes.store(a1, i, n, a)
    lanes.store(b1, i, n, b)


@njit(cache=True, _nrt=False)
def _stage2_group(x, v, th, xs, vs, ths, a1, b1, i, n, p, mp, h2, drive, friction):
    """Stage 2 of a run for blocks i..i+n-1 (n <= 8) as lanes (:func:`_stage2_run_loop`'s
    expressions); returns whether one of them stopped."""
    K, dp = mp[0], mp[1]
    one = np.uint64(1)
    vi = lanes.load(v, i, n)
    vsi = lanes.load(vs, i, n)
    tsi = lanes.load(ths, i, n)
    g = (i, n)
    f2 = _force(lanes.load(xs, i - one, n), lanes.load(xs, i, n), lanes.load(xs, i + one, n), K, dp, p, drive, g)
    a2 = _accel(f2, tsi, vsi, 1.0, mp, friction, g)
    b2 = _dtheta(lanes.load(ths, i - one, n), tsi, lanes.load(ths, i + one, n), vsi, mp, friction, g)
    vn = vi + h2 * (lanes.load(a1, i, n) + a2)
    lanes.store(x, i, n, lanes.load(x, i, n) + h2 * (vi + vsi))
    lanes.store(v, i, n, vn)
    lanes.store(th, i, n, lanes.load(th, i, n) + h2 * (lanes.load(b1, i, n) + b2))
    return lanes.any_not_positive(vn, n)


@njit(cache=True, _nrt=False, inline="always")
def _stage1_run_lanes(x, v, th, xs, vs, ths, a1, b1, lo, hi, p, q, mp, dt, drive, friction):
    """:func:`_stage1_run_loop` in groups of 8 blocks, the last group masked."""
    X, V, T = x.ctypes.data, v.ctypes.data, th.ctypes.data
    XS, VS, TS, A1, B1 = xs.ctypes.data, vs.ctypes.data, ths.ctypes.data, a1.ctypes.data, b1.ctypes.data
    w = np.uint64(lanes.WIDTH)
    i = np.uint64(lo)
    end = np.uint64(hi) + np.uint64(1)
    while i + w <= end:
        _stage1_group(X, V, T, XS, VS, TS, A1, B1, i, w, p, mp, dt, drive, friction)
        i += w
    if i < end:
        _stage1_group(X, V, T, XS, VS, TS, A1, B1, i, end - i, p, mp, dt, drive, friction)


@njit(cache=True, _nrt=False, inline="always")
def _stage2_run_lanes(x, v, th, xs, vs, ths, a1, b1, lo, hi, p, q, mp, h2, drive, friction):
    """:func:`_stage2_run_loop` in groups of 8 blocks, the last group masked."""
    X, V, T = x.ctypes.data, v.ctypes.data, th.ctypes.data
    XS, VS, TS, A1, B1 = xs.ctypes.data, vs.ctypes.data, ths.ctypes.data, a1.ctypes.data, b1.ctypes.data
    w = np.uint64(lanes.WIDTH)
    i = np.uint64(lo)
    end = np.uint64(hi) + np.uint64(1)
    stops = False
    while i + w <= end:
        stops |= _stage2_group(X, V, T, XS, VS, TS, A1, B1, i, w, p, mp, h2, drive, friction)
        i += w
    if i < end:
        stops |= _stage2_group(X, V, T, XS, VS, TS, A1, B1, i, end - i, p, mp, h2, drive, friction)
    return stops


@njit(cache=True, _nrt=False)
def _theta1_group(x, v, th, xs, vs, ths, mm, b1, i, n, mp, dt, friction, full):
    """Stage 1 of the state variable for stopped blocks i..i+n-1 as lanes, and with ``full``
    their predictors of x and v and their mask (:func:`_stage1_theta_loop`)."""
    one = np.uint64(1)
    vi = lanes.load(v, i, n)
    ti = lanes.load(th, i, n)
    b = _dtheta(lanes.load(th, i - one, n), ti, lanes.load(th, i + one, n), vi, mp, friction, (i, n))
    lanes.store(b1, i, n, b)
    lanes.store(ths, i, n, ti + dt * b)
    if full:
        lanes.store(xs, i, n, lanes.load(x, i, n) + dt * vi)
        lanes.store(vs, i, n, vi)
        lanes.store(mm, i, n, 0.0)


@njit(cache=True, _nrt=False, inline="always")
def _theta1_lanes(x, v, th, xs, vs, ths, mm, b1, lo, hi, mp, dt, friction, full):
    """The state variable's stage 1 for stopped blocks lo..hi in groups of 8, the last masked
    (with ``full``, their predictors of x and v and their mask too: :func:`_theta1_group`)."""
    X, V, T = x.ctypes.data, v.ctypes.data, th.ctypes.data
    XS, VS, TS, MM, B1 = xs.ctypes.data, vs.ctypes.data, ths.ctypes.data, mm.ctypes.data, b1.ctypes.data
    w = np.uint64(lanes.WIDTH)
    i = np.uint64(lo)
    end = np.uint64(hi) + np.uint64(1)
    while i + w <= end:
        _theta1_group(X, V, T, XS, VS, TS, MM, B1, i, w, mp, dt, friction, full)
        i += w
    if i < end:
        _theta1_group(X, V, T, XS, VS, TS, MM, B1, i, end - i, mp, dt, friction, full)


@njit(cache=True, _nrt=False, inline="always")
def _stage1_theta_lanes(x, v, th, xs, vs, ths, mm, b1, lo, hi, q, mp, dt, drive, friction):
    """:func:`_stage1_theta_loop` as lanes."""
    _theta1_lanes(x, v, th, xs, vs, ths, mm, b1, lo, hi, mp, dt, friction, True)


@njit(cache=True, _nrt=False)
def _stage1_theta_only_lanes(v, th, ths, b1, lo, hi, q, mp, dt, drive, friction):
    """:func:`_stage1_theta_only_loop` as lanes."""
    # Without ``full`` the arrays in the places of x, xs, vs and mm are not touched.
    _theta1_lanes(v, v, th, ths, ths, ths, b1, b1, lo, hi, mp, dt, friction, False)


@njit(cache=True, _nrt=False)
def _theta2_group(th, ths, v, b1, i, n, mp, h2, friction):
    """:func:`_stage2_theta_loop` for blocks i..i+n-1 as lanes; returns the mask of the lanes
    whose state variable changed (:func:`stickslip.kernels.lanes.changed`)."""
    one = np.uint64(1)
    tsl, tsi, tsr = lanes.load(ths, i - one, n), lanes.load(ths, i, n), lanes.load(ths, i + one, n)
    b2 = _dtheta(tsl, tsi, tsr, lanes.load(v, i, n), mp, friction, (i, n))
    tho = lanes.load(th, i, n)
    thn = tho + h2 * (lanes.load(b1, i, n) + b2)
    lanes.store(th, i, n, thn)
    return lanes.changed(thn, tho, n)


@njit(cache=True, _nrt=False)
def _theta2_changes(T, TS, V, B1, i, n, mp, h2, friction, c_lo, c_hi):
    """:func:`_theta2_group`, and the first and last changed block so far (branch-free)."""
    m = _theta2_group(T, TS, V, B1, i, n, mp, h2, friction)
    first = np.int64(i) + lanes.lowest(m)
    last = np.int64(i) + 63 - lanes.leading_zeros(m)
    c_lo = first if m != 0 and c_lo > first else c_lo
    c_hi = last if m != 0 else c_hi
    return c_lo, c_hi


@njit(cache=True, _nrt=False, inline="always")
def _stage2_theta_lanes(th, ths, v, vs, b1, lo, hi, q, mp, h2, drive, friction):
    """:func:`_stage2_theta_loop` as lanes."""
    T, TS, V, B1 = th.ctypes.data, ths.ctypes.data, v.ctypes.data, b1.ctypes.data
    w = np.uint64(lanes.WIDTH)
    i = np.uint64(lo)
    end = np.uint64(hi) + np.uint64(1)
    c_lo = hi + 1
    c_hi = lo - 1
    while i + w <= end:
        c_lo, c_hi = _theta2_changes(T, TS, V, B1, i, w, mp, h2, friction, c_lo, c_hi)
        i += w
    if i < end:
        c_lo, c_hi = _theta2_changes(T, TS, V, B1, i, end - i, mp, h2, friction, c_lo, c_hi)
    return c_lo, c_hi


def _choose(by_lanes, by_loop, *pieces):
    """The implementation of a stage stub: the Python function of ``by_lanes`` where the pieces
    (literal module paths) all run as lanes (their ``PIECE.lanes``), else of ``by_loop``; both
    take the stub's arguments. None while the pieces are not literals."""
    flags = [piece_attr(piece, "lanes") for piece in pieces]
    if None in flags:
        return None
    # A law that reads a context (the stress rate) takes the loops: the lanes pass it none.
    context = reads_context(pieces[-1])
    return (by_lanes if all(flags) and not context else by_loop).py_func


def _stage1_run(x, v, th, xs, vs, ths, a1, b1, lo, hi, p, q, mp, dt, drive, friction):
    """Stage 1 for blocks lo..hi that all move at t_n (a run of sliding blocks):
    :func:`_stage1_run_lanes` where the drive and the law run as lanes, else
    :func:`_stage1_run_loop` (resolved when the kernel is compiled)."""


def _stage2_run(x, v, th, xs, vs, ths, a1, b1, lo, hi, p, q, mp, h2, drive, friction):
    """Stage 2, corrector and stop rule for a run lo..hi (:func:`_stage2_run_lanes` or
    :func:`_stage2_run_loop`). Returns whether some block stopped (v is stored as computed)."""


def _stage1_theta(x, v, th, xs, vs, ths, mm, b1, lo, hi, q, mp, dt, drive, friction):
    """Stage 1 for blocks lo..hi known to stay stopped (:func:`_stage1_theta_loop`, as lanes
    where the law allows)."""


def _stage1_theta_only(v, th, ths, b1, lo, hi, q, mp, dt, drive, friction):
    """The state variable's stage 1 alone for stopped blocks lo..hi
    (:func:`_stage1_theta_only_loop`, as lanes where the law allows)."""


def _stage2_theta(th, ths, v, vs, b1, lo, hi, q, mp, h2, drive, friction):
    """Stage 2 of the state variable alone for stopped blocks lo..hi; the first and last block
    whose state variable changed (:func:`_stage2_theta_loop`, as lanes where the law allows)."""


@overload(_stage1_run, prefer_literal=True)
def _stage1_run_choice(x, v, th, xs, vs, ths, a1, b1, lo, hi, p, q, mp, dt, drive, friction):
    return _choose(_stage1_run_lanes, _stage1_run_loop, drive, friction)


@overload(_stage2_run, prefer_literal=True)
def _stage2_run_choice(x, v, th, xs, vs, ths, a1, b1, lo, hi, p, q, mp, h2, drive, friction):
    return _choose(_stage2_run_lanes, _stage2_run_loop, drive, friction)


@overload(_stage1_theta, prefer_literal=True)
def _stage1_theta_choice(x, v, th, xs, vs, ths, mm, b1, lo, hi, q, mp, dt, drive, friction):
    return _choose(_stage1_theta_lanes, _stage1_theta_loop, friction)


@overload(_stage1_theta_only, prefer_literal=True)
def _stage1_theta_only_choice(v, th, ths, b1, lo, hi, q, mp, dt, drive, friction):
    return _choose(_stage1_theta_only_lanes, _stage1_theta_only_loop, friction)


@overload(_stage2_theta, prefer_literal=True)
def _stage2_theta_choice(th, ths, v, vs, b1, lo, hi, q, mp, h2, drive, friction):
    return _choose(_stage2_theta_lanes, _stage2_theta_loop, friction)


@njit(cache=True, _nrt=False, inline="always")
def _stop_run(v, mov, lo, hi):
    """The stop rule on a run lo..hi whose stage 2 stored v as computed (:func:`_stage2_run`): a
    block with v <= 0 gets v = 0 and stops. Returns how many of the run still move."""
    kept = 0
    for i in range(lo, hi + 1):
        keep = v[i] > 0.0
        v[i] = v[i] if keep else 0.0
        mov[i] = 1.0 if keep else 0.0
        kept += 1 if keep else 0
    return kept


@njit(cache=True, _nrt=False, inline="always")
def _run_padded(lo, hi, N):
    """The last block of stage 1 of a run lo..hi over whole groups of 8 (the blocks past hi get a
    moving block's values, which the stages after it overwrite where they are read), or hi where
    the groups would pass block N."""
    end = hi + (lo - hi - 1) % lanes.WIDTH
    return end if end <= N else hi


@njit(cache=True, _nrt=False)
def _longest_run(mov, lo, hi):
    """The longest run of moving blocks within lo..hi (lo > hi if none)."""
    ba, bb = 1, 0
    a = -1
    for i in range(lo, hi + 2):
        if i <= hi and mov[i] != 0.0:
            if a < 0:
                a = i
        elif a >= 0:
            if i - a > bb - ba + 1:
                ba, bb = a, i - 1
            a = -1
    return ba, bb
