"""Stuck blocks of the located integrator's fast form (:mod:`stickslip.kernels.located_fast`):
their u along exact binade segments, and how long their start tests provably stay false.

* **u.** In the frame of the drive a stuck block has v = 0, so both Heun stages give du = 0 - V
  and a full step maps u to fl(u + c), c = fl(dt/2 (-V - V)), whatever the other blocks do.
  Inside one binade of u (abs(u) in [2^(e-1), 2^e), floats spaced q apart) and away from its
  edges, fl(w + c) = w + d for every w on the way, d the multiple of q nearest to c: w is a
  multiple of q, and a c exactly halfway between two multiples is refused. So k steps give
  u + k d exactly, in one addition (k d is a multiple of q below the binade's width, hence a
  float). :func:`_segment` finds d and how many steps the rule holds; a block's u is held at
  the step it was last needed (``us``) with its segment (``sd``, ``se``) and brought forward on
  demand (:func:`_catch`).
* **Start tests.** A stuck block whose neighbours are stuck has a force that reads three such u.
  With the end drive and the same d for the three, the differences, hence the force, keep every
  bit. Otherwise the exact force of the three floats is affine in the step count (slope r), and
  the computed force lies within a rounding bound E of it, so its test (f > threshold) provably
  stays false while f_computed(now) + 2 E + k r_up <= threshold, r_up >= r
  (:func:`_horizon`, ``safe``). There the test is made again, exactly, and a new horizon taken;
  within rounding of the threshold, step by step.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from stickslip.kernels.laws import _force as _spring_force
from stickslip.kernels.laws import _threshold, at, call, has
from stickslip.kernels.layout import P_K

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
    if not has(drive, "leaf_spring"):
        return -1
    if has(ends, "ring"):
        return N
    return 1


@njit(cache=True, inline="always")
def _right(j, N, ends):
    if j < N:
        return j + 1
    if has(ends, "ring"):
        return 1
    return N


@njit(cache=True, _nrt=False)
def _horizon(j, m, ahead, u, us, sd, se, th, N, c, par, tp, dp, drive, threshold, ends):
    """(fires, last) for stuck block j on the state at step m: whether its start test fires
    there, else the last step up to which it provably does not (module docstring, 2), its
    neighbours staying stuck and the steps full. The u are brought to m - ahead and taken
    ``ahead`` (0 or 1) steps further without storing."""
    K, Kp = par[P_K], call(drive, "leaf", at(dp, j))
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
    F = _spring_force(ul, uc, ur, K, dp, 0.0, drive, j)
    thr = _threshold(th[j], tp, threshold, j)
    if F - thr > 0.0:
        return True, m
    if L == 0:
        return False, m
    if not has(drive, "leaf_spring") and dl == dc and dc == dr:
        return False, m + L  # the differences, hence the force, keep their bits
    # The exact force moves by r per step; the computed one lies within E of it (each |u|
    # stays below twice its value within its binade).
    r = K * ((dl - dc) - (dc - dr))
    if has(drive, "leaf_spring"):
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


@njit(cache=True, _nrt=False)
def _horizons(n, el, eh, u, us, sd, se, th, mov, safe, N, c, par, tp, dp, drive, threshold, ends):
    """``safe`` of every stuck block outside el..eh from the state at step n; returns (fires,
    the smallest)."""
    fires = False
    low = _BIG
    for j in range(1, N + 1):
        if mov[j] != 0.0 or (el <= j and j <= eh):
            safe[j] = _BIG
            continue
        f, last = _horizon(j, n, 0, u, us, sd, se, th, N, c, par, tp, dp, drive, threshold, ends)
        fires |= f
        safe[j] = last
        low = min(low, last)
        safe[N + 1] += 1
    return fires, low


@njit(cache=True, _nrt=False)
def _expire(n, el, eh, u, us, sd, se, th, mov, safe, N, c, par, tp, dp, drive, threshold, ends):
    """Test again, on the state at step n + 1, the stuck blocks whose ``safe`` step is n or
    earlier; returns (some start test fires, the new smallest ``safe``)."""
    fires = False
    low = _BIG
    for j in range(1, N + 1):
        if safe[j] <= n:
            if mov[j] != 0.0 or (el <= j and j <= eh):
                safe[j] = _BIG
            else:
                f, last = _horizon(j, n + 1, 1, u, us, sd, se, th, N, c, par, tp, dp, drive, threshold, ends)
                fires |= f
                safe[j] = last
                safe[N + 1] += 1
        low = min(low, safe[j])
    return fires, low
