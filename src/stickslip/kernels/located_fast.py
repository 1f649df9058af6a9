"""Heun with located switches, fast form: bit for bit the dense form
(:func:`stickslip.kernels.located.advance`), computing only what is not known in advance.

The dense form advances every block at every step. Most of that work has a known result:

1. **A stuck block's u.** In the frame of the drive a stuck block has v = 0, so both Heun
   stages give du = 0 - V and a full step maps u to fl(u + c), c = fl(dt/2 (-V - V)), whatever
   the other blocks do. Inside one binade of u (|u| in [2^(e-1), 2^e), floats spaced q apart),
   and away from its edges, fl(w + c) = w + d for every w on the way, d the multiple of q
   nearest to c (w is a multiple of q; a c exactly halfway is excluded). So k steps give
   u + k d exactly, one float addition (:func:`_segment`, :func:`_advance_lazy`). A stuck
   block's u is held at the step it was last needed (``us``) and brought forward on demand.
2. **The start test of a stuck block none of whose neighbours moves.** Its force reads three
   such u. With the end drive and equal d the differences, hence the force, keep every bit.
   Otherwise the exact force of the three u is affine in the step count, and the computed
   force lies within a rounding bound E of it, so the test provably stays false up to a step
   found from the margin to the threshold (:func:`_horizon`); it is evaluated exactly again
   there (``safe``), step by step when the margin is within rounding.
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

import math

import numpy as np
from numba import njit

from stickslip.kernels.laws import _force as _spring_force
from stickslip.kernels.laws import _threshold, law_accel, law_rate
from stickslip.kernels.layout import (
    DRIVE_END,
    DRIVE_PLATE,
    ENDS_FIXED,
    ENDS_PERIODIC,
    P_DT,
    P_FS,
    P_K,
    P_KP,
    P_V,
    THRESHOLD_STATE,
)
from stickslip.kernels.located import (
    DONE,
    EVENTS_FULL,
    I_EVENTS,
    I_MOVING,
    I_STEP,
    NONFINITE,
    _force,
    _gap,
    _ghosts,
    _steps,
    _stop,
    advance,
)
from stickslip.kernels.stages import _stage1_theta_only, _stage2_theta

_BIG = np.int64(1) << np.int64(62)
# Powers of two, as constants of the compiled code.
_2M40 = math.ldexp(1.0, -40)
_2M45 = math.ldexp(1.0, -45)
_2M53 = math.ldexp(1.0, -53)


@njit(cache=True)
def _segment(w, c):
    """(d, L): from w, each of L steps w -> fl(w + c) adds exactly d (module docstring, 1);
    L = 0 where that is not proven (w zero, tiny or huge, c halfway between two multiples of
    the spacing, the binade's edge within reach)."""
    if c == 0.0:
        # fl(w + 0) = w, except -0.0 + 0.0 = +0.0.
        if w == 0.0 and math.copysign(1.0, w) < 0.0:
            return 0.0, np.int64(0)
        return 0.0, _BIG
    a = abs(w)
    if not (a >= 1e-250 and a <= 1e250):
        return 0.0, np.int64(0)
    mant, _ = math.frexp(a)
    top = a / mant  # 2^e (exact), a in [2^(e-1), 2^e)
    q = top * _2M53  # the spacing of floats there
    lo = 0.5 * top + 8.0 * q
    hi = top - 8.0 * q
    t = c / q  # exact: q is a power of two
    ft = math.floor(t)
    fr = t - ft
    if fr == 0.5:
        return 0.0, np.int64(0)
    d = (ft if fr < 0.5 else ft + 1.0) * q
    sg = 1.0 if w > 0.0 else -1.0
    z = a + sg * c  # |w + c| while the sign stays
    if not (lo <= z and z <= hi):
        return 0.0, np.int64(0)
    if (w + c) - w != d:  # the rule, checked on the first step (both in the binade: exact)
        return 0.0, np.int64(0)
    sd = sg * d
    if sd > 0.0:
        x = (hi - z) / sd
    elif sd < 0.0:
        x = (z - lo) / (-sd)
    else:
        return d, _BIG
    if x > 1e15:
        return d, np.int64(1) << np.int64(50)
    L = np.int64(x) - 2
    return d, (L if L > 0 else np.int64(0))


@njit(cache=True)
def _advance_lazy(w, k, c):
    """w after k steps w -> fl(w + c), by segments of :func:`_segment` (single steps between)."""
    while k > 0:
        d, L = _segment(w, c)
        if L == 0:
            w = w + c
            k -= 1
        else:
            m = k if k < L else L
            w = w + np.float64(m) * d
            k -= m
    return w


@njit(cache=True, inline="always")
def _catch(j, n, u, us, sd, se, c):
    """Bring stuck block j's u to step n (full steps since ``us[j]``): along its segment (d in
    ``sd[j]``, exact up to step ``se[j]``) in one addition, a new segment where it ends."""
    if us[j] < n:
        _catch_up(j, n, u, us, sd, se, c)


@njit(cache=True, _nrt=False)
def _catch_up(j, n, u, us, sd, se, c):
    while us[j] < n:
        if se[j] > us[j]:
            m = n if n < se[j] else se[j]
            u[j] = u[j] + np.float64(m - us[j]) * sd[j]
            us[j] = m
        else:
            d, L = _segment(u[j], c)
            if L == 0:
                u[j] = u[j] + c
                us[j] += 1
            else:
                sd[j] = d
                se[j] = us[j] + L


@njit(cache=True, inline="always")
def _seg(j, u, us, sd, se, c):
    """(d, L) of stuck block j from its u at step us[j]: L more steps add d each."""
    if se[j] <= us[j]:
        d, L = _segment(u[j], c)
        if L == 0:
            return 0.0, np.int64(0)
        sd[j] = d
        se[j] = us[j] + L
    return sd[j], se[j] - us[j]


@njit(cache=True, _nrt=False)
def _catch_all(n, u, us, sd, se, c, N):
    for j in range(1, N + 1):
        _catch(j, n, u, us, sd, se, c)


@njit(cache=True, inline="always")
def _left(j, N, drive, ends):
    """The block whose u block j's force reads on its left (-1: the drive's end, u_0 = 0);
    :func:`stickslip.kernels.located._ghosts` without fixed ends."""
    if j > 1:
        return j - 1
    if drive == DRIVE_END:
        return -1
    if ends == ENDS_PERIODIC:
        return N
    return 1


@njit(cache=True, inline="always")
def _right(j, N, ends):
    if j < N:
        return j + 1
    if ends == ENDS_PERIODIC:
        return 1
    return N


@njit(cache=True, _nrt=False)
def _horizon(j, m, ahead, u, us, sd, se, th, N, c, par, drive, threshold, ends):
    """(fires, last) for stuck block j on the state at step m: whether its start test fires
    there, else the last step up to which it provably does not (module docstring, 2), its
    neighbours staying stuck and the steps full. The u are brought to m - ahead and taken
    ``ahead`` (0 or 1) steps further without storing."""
    K, Kp = par[P_K], par[P_KP]
    jl = _left(j, N, drive, ends)
    jr = _right(j, N, ends)
    m0 = m - ahead
    _catch(j, m0, u, us, sd, se, c)
    _catch(jr, m0, u, us, sd, se, c)
    dc, L = _seg(j, u, us, sd, se, c)
    dr, Lr = _seg(jr, u, us, sd, se, c)
    uc = u[j]
    ur = u[jr]
    ul = 0.0
    dl, Ll = 0.0, _BIG
    if jl >= 0:
        _catch(jl, m0, u, us, sd, se, c)
        dl, Ll = _seg(jl, u, us, sd, se, c)
        ul = u[jl]
    L = min(L, Lr, Ll)
    if ahead:
        # One step on (d, where the segment holds it; the step itself otherwise).
        if L > 0:
            uc, ur, ul = uc + dc, ur + dr, ul + dl
            L -= 1
        else:
            uc, ur = uc + c, ur + c
            if jl >= 0:
                ul = ul + c
    F = _spring_force(ul, uc, ur, K, Kp, 0.0, drive)
    thr = _threshold(th[j], par[P_FS], threshold)
    if F - thr > 0.0:
        return True, m
    if L == 0:
        return False, m
    if drive == DRIVE_END and dl == dc and dc == dr:
        return False, m + L  # the differences, hence the force, keep their bits
    # The exact force moves by r per step; the computed one lies within E of it (each |u|
    # stays below twice its value within its binade).
    r = K * ((dl - dc) - (dc - dr))
    if drive == DRIVE_PLATE:
        r = r + Kp * (0.0 - dc)
    al, ac, ar = abs(ul), abs(uc), abs(ur)
    E = _2M45 * (K * (al + 2.0 * ac + ar) + Kp * ac + abs(thr)) + 1e-300
    rup = r + abs(r) * _2M40 + _2M45 * (K * (abs(dl) + 2.0 * abs(dc) + abs(dr)) + Kp * abs(dc))
    room = (thr - F) - 4.0 * E
    if not (room > 0.0):
        return False, m
    k = _BIG
    if rup > 0.0:
        x = room / rup
        if x < 1e17:
            k = np.int64(x * (1.0 - _2M40)) - 1
    if k < 0:
        k = 0
    return False, m + min(k, L)


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
    if ends == ENDS_PERIODIC and (a < 1 or b > N):
        return 1, N
    return max(a, 1), min(b, N)


@njit(cache=True, _nrt=False)
def _dilate(lo, hi, N, ends):
    """An interval of changed blocks widened by two (a block's step reads two places out)."""
    if lo > hi:
        return 1, 0
    lo -= 2
    hi += 2
    if ends == ENDS_PERIODIC and (lo < 1 or hi > N):
        return 1, N
    return max(lo, 1), min(hi, N)


@njit(cache=True, _nrt=False)
def _horizons(n, el, eh, u, us, sd, se, th, mov, safe, N, c, par, drive, threshold, ends):
    """``safe`` of every stuck block outside el..eh from the state at step n; returns (fires,
    the smallest)."""
    fires = False
    low = _BIG
    for j in range(1, N + 1):
        if mov[j] != 0.0 or (el <= j and j <= eh):
            safe[j] = _BIG
            continue
        f, last = _horizon(j, n, 0, u, us, sd, se, th, N, c, par, drive, threshold, ends)
        fires |= f
        safe[j] = last
        low = min(low, last)
        safe[N + 1] += 1
    return fires, low


@njit(cache=True, _nrt=False)
def _expire(n, el, eh, u, us, sd, se, th, mov, safe, N, c, par, drive, threshold, ends):
    """Test again, on the state at step n + 1, the stuck blocks whose ``safe`` step is n or
    earlier; returns (some start test fires, the new smallest ``safe``)."""
    fires = False
    low = _BIG
    for j in range(1, N + 1):
        if safe[j] <= n:
            if mov[j] != 0.0 or (el <= j and j <= eh):
                safe[j] = _BIG
            else:
                f, last = _horizon(j, n + 1, 1, u, us, sd, se, th, N, c, par, drive, threshold, ends)
                fires |= f
                safe[j] = last
                safe[N + 1] += 1
        low = min(low, safe[j])
    return fires, low


@njit(cache=True, _nrt=False)
def advance_fast(
    u,
    v,
    th,
    mov,
    n_end,
    par,
    lp,
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
    (int64, N + 2), ``sd`` (float64) and ``se`` (int64) are scratch. Returns with every block at the step reached."""
    if ends == ENDS_FIXED:
        return advance(
            u, v, th, mov, n_end, par, lp, drive, friction, threshold, ends, sc, cand, moved, ist, evf, ev_t, ev_i
        )
    N = u.shape[0] - 2
    dt = par[P_DT]
    V = par[P_V]
    mp = (par[P_K], par[P_KP], par[P_FS], lp)
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
    while n < n_end:
        if ist[I_EVENTS] > ev_t.shape[0] - 4:
            status = EVENTS_FULL
            break
        if not dense and low <= n:
            dense, low = _expire(n, el, eh, u, us, sd, se, th, mov, safe, N, c, par, drive, threshold, ends)
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
            _ghosts(u, th, N, t, V, drive, ends)
            for i in range(el, eh + 1):
                if mov[i] == 0.0:
                    if _gap(u, th, i, par, drive, threshold) > 0.0:
                        dense = True
                elif v[i] < 0.0:
                    dense = True
        if not dense:
            # Stage 1 (located._rates, _heun's predictor) on E's neighbourhood ...
            for i in range(a1, b1 + 1):
                k1u[i] = v[i] - V
                if mov[i] != 0.0:
                    k1v[i] = law_accel(friction, _force(u, i, par, drive), v[i], th[i], lp)
                else:
                    k1v[i] = 0.0
                k1th[i] = law_rate(friction, th[i - 1], th[i], th[i + 1], v[i], lp)
                pu[i] = u[i] + h * k1u[i]
                pv[i] = v[i] + h * k1v[i]
                pth[i] = th[i] + h * k1th[i]
            # ... and theta alone on T's outside it.
            if tl <= tr:
                sl = tl - 1 if tl > 1 else 1
                sr = tr + 1 if tr < N else N
                if a1 > b1:
                    _stage1_theta_only(v, th, pth, k1th, sl, sr, mp, h, friction)
                else:
                    if sl < a1:
                        _stage1_theta_only(v, th, pth, k1th, sl, min(sr, a1 - 1), mp, h, friction)
                    if sr > b1:
                        _stage1_theta_only(v, th, pth, k1th, max(sl, b1 + 1), sr, mp, h, friction)
            _ghosts(pu, pth, N, t + h, V, drive, ends)
            # Stage 2 on E, o* of u on its two neighbours, the tests of the step's end.
            for i in range(el, eh + 1):
                k2u[i] = pv[i] - V
                if mov[i] != 0.0:
                    k2v[i] = law_accel(friction, _force(pu, i, par, drive), pv[i], pth[i], lp)
                else:
                    k2v[i] = 0.0
                k2th[i] = law_rate(friction, pth[i - 1], pth[i], pth[i + 1], pv[i], lp)
                ou[i] = u[i] + 0.5 * h * (k1u[i] + k2u[i])
                ov[i] = v[i] + 0.5 * h * (k1v[i] + k2v[i])
                oth[i] = th[i] + 0.5 * h * (k1th[i] + k2th[i])
            if el <= eh:
                for i in (a1, b1):
                    if i < el or i > eh:
                        k2u[i] = pv[i] - V
                        ou[i] = u[i] + 0.5 * h * (k1u[i] + k2u[i])
                _ghosts(ou, oth, N, t + h, V, drive, ends)
            for i in range(el, eh + 1):
                if mov[i] == 0.0:
                    if _gap(ou, oth, i, par, drive, threshold) > 0.0:
                        dense = True
                elif v[i] > 0.0 and ov[i] <= 0.0:
                    dense = True
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
            if threshold == THRESHOLD_STATE:
                el, eh = 1, N
            dense, low = _horizons(n, el, eh, u, us, sd, se, th, mov, safe, N, c, par, drive, threshold, ends)
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
                cl, ch = _stage2_theta(th, pth, v, k1th, tl, tr, mp, h2, friction)
            else:
                if tl < el:
                    a, b = _stage2_theta(th, pth, v, k1th, tl, min(tr, el - 1), mp, h2, friction)
                    if a <= b:
                        cl = min(cl, a)
                if tr > eh:
                    a, b = _stage2_theta(th, pth, v, k1th, max(tl, eh + 1), tr, mp, h2, friction)
                    if a <= b:
                        ch = max(ch, b)
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
        tl, tr = _dilate(cl, ch, N, ends)
        ol, oh = el, eh
        el, eh = _near_movers(mov, ol, oh, N, ends)
        if threshold == THRESHOLD_STATE and tl <= tr:
            # The threshold is theta: a block whose theta changes is tested step by step.
            el, eh = (tl, tr) if el > eh else (min(el, tl), max(eh, tr))
        for j in range(ol, oh + 1):
            if (j < el or j > eh) and mov[j] == 0.0:
                f, last = _horizon(j, n, 0, u, us, sd, se, th, N, c, par, drive, threshold, ends)
                dense |= f
                safe[j] = last
                low = min(low, last)
                safe[N + 1] += 1
    _catch_all(n, u, us, sd, se, c, N)
    return status
