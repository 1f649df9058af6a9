"""Heun with located switches, fast form: bit for bit the dense form
(:func:`stickslip.kernels.located.advance`), computing only what is not known in advance.

The dense form advances every block at every step. Most of that work has a known result:

1. **A stuck block's u**, which changes at every step by a known rule, is computed in one
   addition where it is needed (:mod:`stickslip.kernels.located_lazy`).
2. **The start test of a stuck block none of whose neighbours moves** is proven false up to a
   step found from the margin to the threshold and a bound on rounding, and made again there
   (:mod:`stickslip.kernels.located_lazy`).
3. **Theta of stuck blocks.** Its rate reads theta and v, not u: a block whose theta and
   whose neighbours' (two places out) did not change in the last full step does not change now
   (as in :mod:`stickslip.kernels.exact`); the others are updated with the exact path's
   theta-only stages (:mod:`stickslip.kernels.stages`).
4. **Stretches in which only the drive moves.** With every block stuck and no theta changing,
   nothing is computed until the earliest ``safe`` step: the kernel jumps there.

Blocks moving and their neighbours (``E``) are stepped with the dense form's expressions; a
step in which any start test or stop test fires, or a switch is due at its start, is a *switch
step*: every u is brought to the step and the dense form's own step runs
(:func:`stickslip.kernels.located._steps`), its switches located with trial steps restricted
to the switching block's neighbourhood (:func:`stickslip.kernels.located._heun_near`, the same
bits). The event bookkeeping sums every u where an event opens or closes, so every u is brought
forward there too. Fixed ends read t in their ghost cells (u = -V t): they run the dense form.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from stickslip.kernels.laws import _force as _spring_force
from stickslip.kernels.laws import _threshold, at, has, law_accel, law_rate
from stickslip.kernels.layout import (
    P_DT,
    P_K,
    P_V,
)
from stickslip.kernels.located import (
    DONE,
    EVENTS_FULL,
    I_EVENTS,
    I_MOVING,
    I_STEP,
    NONFINITE,
    _ghosts,
    _steps,
    _stop,
)
from stickslip.kernels.located_lazy import _BIG, _catch, _catch_all, _expire, _horizon, _horizons
from stickslip.kernels.stages import _stage1_theta_only, _stage2_theta


@njit(cache=True, inline="always")
def _finite(x, lo, hi):
    """Whether x[lo..hi] are all finite (x - x is 0 exactly then; unsigned indices and no
    branch, so that the loop is vectorised)."""
    ok = True
    if lo <= hi:
        for i in range(np.uint64(lo), np.uint64(hi) + np.uint64(1)):
            ok &= x[i] - x[i] == 0.0
    return ok


@njit(cache=True, _nrt=False)
def _near_movers(mov, lo, hi, N, ends):
    """Blocks lo..hi's moving ones and their neighbours, as one interval (empty: lo > hi); on a
    ring one that reaches an end is the whole chain."""
    a = hi + 1
    b = lo - 1
    for i in range(lo, hi + 1):
        if mov[i] != 0.0:
            if i < a:
                a = i
            b = i
    if a > b:
        return 1, 0
    a -= 1
    b += 1
    if has(ends, "ring") and (a < 1 or b > N):
        return 1, N
    return max(a, 1), min(b, N)


@njit(cache=True, _nrt=False)
def _dilate(lo, hi, N, ends):
    """An interval of changed blocks widened by two (a block's step reads two places out)."""
    if lo > hi:
        return 1, 0
    lo -= 2
    hi += 2
    if has(ends, "ring") and (lo < 1 or hi > N):
        return 1, N
    return max(lo, 1), min(hi, N)


@njit(cache=True, _nrt=False, inline="always")
def _stage1_near(a, b, u, v, th, mov, sc, h, V, K, dp, lp, drive, friction):
    """located._rates' k1 and _heun's predictor for blocks a..b: the same expressions, in a loop
    with unsigned indices and a select for the moving mask, so that it is vectorised."""
    k1u, k1v, k1th, pu, pv, pth = sc[0], sc[1], sc[2], sc[3], sc[4], sc[5]
    one = np.uint64(1)
    for i in range(np.uint64(a), np.uint64(b) + one):
        k1u[i] = v[i] - V
        acc = law_accel(
            friction, _spring_force(u[i - one], u[i], u[i + one], K, dp, 0.0, drive, i), v[i], th[i], at(lp, i)
        )
        k1v[i] = acc if mov[i] != 0.0 else 0.0
        k1th[i] = law_rate(friction, th[i - one], th[i], th[i + one], v[i], at(lp, i))
        pu[i] = u[i] + h * k1u[i]
        pv[i] = v[i] + h * k1v[i]
        pth[i] = th[i] + h * k1th[i]


@njit(cache=True, _nrt=False, inline="always")
def _stage2_near(a, b, u, v, th, mov, sc, h, V, K, dp, lp, drive, friction):
    """located._rates' k2 and _heun's o* for blocks a..b (as :func:`_stage1_near`)."""
    k1u, k1v, k1th, pu, pv, pth, k2u, k2v, k2th, ou, ov, oth = sc
    one = np.uint64(1)
    for i in range(np.uint64(a), np.uint64(b) + one):
        k2u[i] = pv[i] - V
        acc = law_accel(
            friction, _spring_force(pu[i - one], pu[i], pu[i + one], K, dp, 0.0, drive, i), pv[i], pth[i], at(lp, i)
        )
        k2v[i] = acc if mov[i] != 0.0 else 0.0
        k2th[i] = law_rate(friction, pth[i - one], pth[i], pth[i + one], pv[i], at(lp, i))
        ou[i] = u[i] + 0.5 * h * (k1u[i] + k2u[i])
        ov[i] = v[i] + 0.5 * h * (k1v[i] + k2v[i])
        oth[i] = th[i] + 0.5 * h * (k1th[i] + k2th[i])


@njit(cache=True, _nrt=False, inline="always")
def _fires(a, b, x, th, v0, v1, mov, K, dp, tp, drive, threshold, end):
    """Whether a switch test of blocks a..b fires, on the state x, th (end = False: a stuck block
    above its threshold, a moving one with v0 < 0, due at the step's start) or on o* (end = True:
    a moving one with v0 > 0 and v1 <= 0); located's expressions, branch-free."""
    one = np.uint64(1)
    f = False
    for i in range(np.uint64(a), np.uint64(b) + one):
        g = _spring_force(x[i - one], x[i], x[i + one], K, dp, 0.0, drive, i) - _threshold(th[i], tp, threshold, i)
        stops = (v0[i] > 0.0) & (v1[i] <= 0.0) if end else v0[i] < 0.0
        f |= (g > 0.0) if mov[i] == 0.0 else stops
    return f


@njit(cache=True, _nrt=False)
def advance_fast(
    u,
    v,
    th,
    mov,
    n_end,
    par,
    lp,
    tp,
    dp,
    drive,
    friction,
    threshold,
    ends,
    sc,
    cand,
    moved,
    ist,
    evf,
    ev_t,
    ev_i,
    us,
    safe,
    sd,
    se,
):
    """:func:`stickslip.kernels.located.advance` (same arguments, results and status codes, bit
    for bit), skipping the work whose result is known (module docstring); ``us`` and ``safe``
    (int64, N + 2), ``sd`` (float64) and ``se`` (int64) are scratch. Returns with every block at the step reached.
    Not for ends with a wall (``PIECE.wall``): their ghost cells move with t in the drive's frame,
    and :class:`~stickslip.run.located.LocatedStepper` runs the dense form there."""
    N = u.shape[0] - 2
    dt = par[P_DT]
    V = par[P_V]
    K = par[P_K]
    mp = (K, dp, tp, lp)
    k1u, k1v, k1th, pu, pv, pth, k2u, k2v, k2th, ou, ov, oth = sc
    h = dt - 0.0
    h2 = 0.5 * h
    c = 0.5 * h * ((0.0 - V) + (0.0 - V))  # a stuck block's du over a full step
    n = ist[I_STEP]
    for j in range(1, N + 1):
        us[j] = n
        safe[j] = _BIG
        se[j] = -1
    # Counts of the work done (the slots of the ghost cells): switch steps, steps stepped with
    # the moving blocks' neighbourhood or theta alone, jumps, start tests redone.
    us[0] = 0
    us[N + 1] = 0
    safe[0] = 0
    safe[N + 1] = 0
    status = DONE
    dense = True  # the next step is a switch step (at entry: nothing known yet)
    el, eh = 1, 0  # E: the moving blocks and their neighbours
    tl, tr = 1, N  # T: the blocks whose theta may change in the next step
    low = _BIG  # the smallest safe step
    fresh = True  # E's switch tests at the step's start are not known to be false
    while n < n_end:
        if ist[I_EVENTS] > ev_t.shape[0] - 4:
            status = EVENTS_FULL
            break
        if not dense and low <= n:
            dense, low = _expire(n, el, eh, u, us, sd, se, th, mov, safe, N, c, par, tp, dp, drive, threshold, ends)
        if not dense and el > eh and tl > tr:
            # Only the drive moves: jump to the first step at which a start test must be redone
            # (after _expire, low > n).
            n = min(n_end, low)
            ist[I_STEP] = n
            safe[0] += 1
            continue
        t = n * dt + 0.0
        a1, b1 = 1, 0
        if not dense:
            if el <= eh:
                a1 = el - 1 if el > 1 else 1
                b1 = eh + 1 if eh < N else N
                for j in range(a1, b1 + 1):
                    _catch(j, n, u, us, sd, se, c)
            _ghosts(u, th, N, t, V, dp, drive, ends)
            if fresh and el <= eh:
                dense = _fires(el, eh, u, th, v, v, mov, K, dp, tp, drive, threshold, False)
        if not dense:
            # Stage 1 on E's neighbourhood, theta alone on T's outside it.
            if el <= eh:
                _stage1_near(a1, b1, u, v, th, mov, sc, h, V, K, dp, lp, drive, friction)
            if tl <= tr:
                sl = tl - 1 if tl > 1 else 1
                sr = tr + 1 if tr < N else N
                if a1 > b1:
                    _stage1_theta_only(v, th, pth, k1th, sl, sr, 0.0, mp, h, drive, friction)
                else:
                    if sl < a1:
                        _stage1_theta_only(v, th, pth, k1th, sl, min(sr, a1 - 1), 0.0, mp, h, drive, friction)
                    if sr > b1:
                        _stage1_theta_only(v, th, pth, k1th, max(sl, b1 + 1), sr, 0.0, mp, h, drive, friction)
            _ghosts(pu, pth, N, t + h, V, dp, drive, ends)
            # Stage 2 on E, o* of u on its two neighbours, the tests of the step's end.
            if el <= eh:
                _stage2_near(el, eh, u, v, th, mov, sc, h, V, K, dp, lp, drive, friction)
                for i in (a1, b1):
                    if i < el or i > eh:
                        k2u[i] = pv[i] - V
                        ou[i] = u[i] + 0.5 * h * (k1u[i] + k2u[i])
                _ghosts(ou, oth, N, t + h, V, dp, drive, ends)
                dense = _fires(el, eh, ou, oth, v, ov, mov, K, dp, tp, drive, threshold, True)
        if dense:
            # A switch step: the dense form's own step, every block.
            _catch_all(n, u, us, sd, se, c, N)
            us[0] += 1
            st = _steps(
                u,
                v,
                th,
                mov,
                n + 1,
                par,
                lp,
                tp,
                dp,
                drive,
                friction,
                threshold,
                ends,
                sc,
                cand,
                moved,
                ist,
                evf,
                ev_t,
                ev_i,
                True,
            )
            n = ist[I_STEP]
            for j in range(1, N + 1):
                us[j] = n
                se[j] = -1  # the sub-steps left every segment
            if st != DONE:
                status = st
                break
            el, eh = _near_movers(mov, 1, N, N, ends)
            tl, tr = 1, N
            if has(threshold, "has_state"):
                el, eh = 1, N
            dense, low = _horizons(n, el, eh, u, us, sd, se, th, mov, safe, N, c, par, tp, dp, drive, threshold, ends)
            fresh = True
            continue
        # Commit E; theta alone on T outside E (in place); stops at the step's end.
        for i in range(el, eh + 1):
            u[i] = ou[i]
            th[i] = oth[i]
            v[i] = ov[i]
            us[i] = n + 1
            if mov[i] != 0.0:
                se[i] = -1
        cl, ch = el, eh  # changed blocks (E counted whole)
        if tl <= tr:
            if el > eh:
                cl, ch = _stage2_theta(th, pth, v, v, k1th, tl, tr, 0.0, mp, h2, drive, friction)
            else:
                if tl < el:
                    a, b = _stage2_theta(th, pth, v, v, k1th, tl, min(tr, el - 1), 0.0, mp, h2, drive, friction)
                    if a <= b:
                        cl = min(cl, a)
                if tr > eh:
                    a, b = _stage2_theta(th, pth, v, v, k1th, max(tl, eh + 1), tr, 0.0, mp, h2, drive, friction)
                    if a <= b:
                        ch = max(ch, b)
        # After a full step the tests at the next step's start are those just made, except for
        # blocks that stop at the step's end or enter E.
        n_stop = 0
        for i in range(el, eh + 1):
            if mov[i] != 0.0 and v[i] <= 0.0:
                n_stop += 1
        if n_stop > 0:
            if n_stop == ist[I_MOVING]:
                _catch_all(n + 1, u, us, sd, se, c, N)  # the event closes: its size sums every u
            for i in range(el, eh + 1):
                if mov[i] != 0.0 and v[i] <= 0.0:
                    _stop(i, u, v, mov, t + h, par, ist, evf, N, ev_t, ev_i)
        n += 1
        ist[I_STEP] = n
        us[N + 1] += 1
        # Only E and theta on T changed (x - x is 0 exactly when x is finite; branch-free).
        if not (_finite(u, el, eh) and _finite(v, el, eh) and _finite(th, min(el, tl), max(eh, tr))):
            status = NONFINITE
            break
        fresh = n_stop > 0
        tl, tr = _dilate(cl, ch, N, ends)
        ol, oh = el, eh
        el, eh = _near_movers(mov, ol, oh, N, ends)
        if has(threshold, "has_state") and tl <= tr:
            # The threshold is theta: a block whose theta changes is tested step by step.
            el, eh = (tl, tr) if el > eh else (min(el, tl), max(eh, tr))
            fresh |= el < ol or eh > oh
        for j in range(ol, oh + 1):
            if (j < el or j > eh) and mov[j] == 0.0:
                f, last = _horizon(j, n, 0, u, us, sd, se, th, N, c, par, tp, dp, drive, threshold, ends)
                dense |= f
                safe[j] = last
                low = min(low, last)
                safe[N + 1] += 1
    _catch_all(n, u, us, sd, se, c, N)
    return status
