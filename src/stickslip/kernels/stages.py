"""The Heun stages of the fast interval path (:mod:`stickslip.kernels.exact`) over a contiguous
interval of blocks: the general stages with the start and stop rules, the all-sliding stages,
and the stages of blocks known to stay stopped, which change their state variable alone
(eq. 4, docs/model.md; the step is in :mod:`stickslip.kernels.laws`).

Each evaluates every quantity with the expressions of :mod:`stickslip.kernels.laws`, in the
reference's order, so the result equals :func:`stickslip.kernels.dense.run_dense` bit for bit.
The loops are branch-free and work on views that begin at block lo - 1, so that the compiler
drops the negative-index handling and vectorises them.
"""

from __future__ import annotations

from numba import njit

from stickslip.kernels.laws import _accel, _dtheta, _force, _threshold


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
