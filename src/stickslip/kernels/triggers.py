"""Which stopped block the drive starts, and at which step (the start rule of docs/model.md
seen from the drive), for the fast integrators' jumps over steps in which nothing changes.

* end drive: the force on a stopped block changes only when a neighbour moves or, for block
  1, with the pulling point; when nothing is active, nothing can change until block 1's force
  exceeds its threshold: :func:`_first_trigger` finds that step with the step's own expression
  for the force (monotone in n).
* plate drive: every stopped block is loaded by the plate. For each stopped block the kernels
  keep the first step at which its force, evaluated with the step's own expression, exceeds
  its threshold (``trig``, :func:`_plate_trigger`); it is recomputed whenever the block's
  neighbourhood changes, so a block that starts because of the plate alone is found by
  comparing the step with these numbers.

Each answer is exact: a bisection on the very expression the step evaluates, not a solved
inequality. The plate's search is :func:`first_start`, which the lattice's active-set path
(:mod:`stickslip.kernels.lattice_sparse`) shares with its own expression for the force.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numba.extending import overload

from stickslip.kernels.laws import _force, _pull, _right_of_first, _threshold, at, call, piece_attr
from stickslip.kernels.layout import _NEVER


@njit(cache=True)
def _first_trigger(x, N, V, dt, K, thr, n_lo, n_hi, dp, drive, ends):
    """End drive: first step m in [n_lo, n_hi) at which stopped block 1 starts (f_1 > thr),
    else n_hi.

    Uses the step's own expression for the force, which is non-decreasing in m for V >= 0.
    """
    x1 = x[1]
    x2 = _right_of_first(x, N, ends)
    if n_lo >= n_hi or not (_force(_pull(V, n_hi - 1, dt, dp, drive), x1, x2, K, dp, 0.0, drive, 1) > thr):
        return n_hi
    lo = n_lo
    hi = n_hi - 1  # invariant: fires at hi
    while lo < hi:
        mid = lo + (hi - lo) // 2
        if _force(_pull(V, mid, dt, dp, drive), x1, x2, K, dp, 0.0, drive, 1) > thr:
            hi = mid
        else:
            lo = mid + 1
    return lo


#: The latest step :func:`first_start` looks at where the caller has no end of its own (the
#: lattice's triggers outlive a call of its kernel): a trigger later than this is ``_NEVER``.
HORIZON = np.int64(1) << np.int64(61)


@njit(cache=True)
def first_start(form, fa, drive, thr, rate, n0, n_cap):
    """The start-step search of every exact path (docs/model.md, the start rule): the first step
    m in [n0, n_cap) at which a stopped block starts, ``force_at(fa, m, drive) > thr``, else
    n_cap; ``force_at`` is the step's own expression for the block's force at step m (the
    chain's from its two neighbours, the lattice's from its Laplacian), the function of that name
    in the module ``form`` (a literal import path, resolved when the kernel is compiled, as the
    pieces' functions are), ``fa`` its operands.

    That force is non-decreasing in m (the load point never moves back, every rounding is
    monotone), so the first firing step is found exactly: a guess from its rate per step
    ``rate`` (the leaf spring's Kp V dt) is bracketed by galloping from it (one step either way
    when the guess is right, as it nearly always is), then bisected.
    """
    if n0 >= n_cap:
        return n_cap
    f0 = call(form, "force_at", fa, n0, drive)
    if f0 > thr:
        return n0
    if not call(form, "force_at", fa, n_cap - 1, drive) > thr:
        return n_cap
    lo = n0  # does not fire
    hi = n_cap - 1  # fires
    if rate > 0.0:
        guess = (thr - f0) / rate
        if guess < np.float64(hi - lo):
            g = lo + 1 + np.int64(guess)
            if g < hi:
                step = np.int64(1)
                if call(form, "force_at", fa, g, drive) > thr:
                    hi = g
                    while hi - step > lo:
                        if not call(form, "force_at", fa, hi - step, drive) > thr:
                            lo = hi - step
                            break
                        hi -= step
                        step *= 2
                else:
                    lo = g
                    while lo + step < hi:
                        if call(form, "force_at", fa, lo + step, drive) > thr:
                            hi = lo + step
                            break
                        lo += step
                        step *= 2
    while hi - lo > 1:
        mid = lo + (hi - lo) // 2
        if call(form, "force_at", fa, mid, drive) > thr:
            hi = mid
        else:
            lo = mid
    return hi


@njit(cache=True, inline="always")
def force_at(fa, m, drive):
    """The chain's force on block i at step m, the step's own expression (eq. 4 with the drive's
    term), ``fa`` = (x_{i-1}, x_i, x_{i+1}, K, the drive's parameters, V, dt, i)."""
    xl, xc, xr, K, dp, V, dt, i = fa
    return _force(xl, xc, xr, K, dp, _pull(V, m, dt, dp, drive), drive, i)


@njit(cache=True)
def _plate_trigger(xl, xc, xr, thr, K, dp, V, dt, n0, n_cap, drive, i):
    """Plate drive: first step m in [n0, n_cap) at which a stopped block with neighbours xl, xr
    starts (f > thr), else n_cap: :func:`first_start` on the chain's force."""
    rate = call(drive, "leaf", at(dp, i)) * V * dt
    return first_start("stickslip.kernels.triggers", (xl, xc, xr, K, dp, V, dt, i), drive, thr, rate, n0, n_cap)


@njit(cache=True)
def _plate_triggers(x, th, mov, mm, trig, lo, hi, every, n0, n_cap, mp, V, dt, drive, threshold):
    """Recompute ``trig`` for the stopped blocks lo..hi (ghost cells of x set); returns their
    smallest value (``_NEVER`` if none).

    Unless ``every``, only blocks whose x or a neighbour's x may have changed in the step just
    taken are redone: the ends of the interval (neighbours of its outermost movers), and inside
    it the blocks next to or at a block of the mid-step mask ``mm``, which holds this step's
    movers on the interval (only they change x).
    """
    K, dp, tp = mp[0], mp[1], mp[2]
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
            m = _plate_trigger(
                x[i - 1], x[i], x[i + 1], _threshold(th[i], tp, threshold, i), K, dp, V, dt, n0, n_cap, drive, i
            )
            trig[i] = m
            if m < t_min:
                t_min = m
        else:
            trig[i] = _NEVER
    return t_min


def leaf_triggers(x, th, mov, mm, trig, lo, hi, every, n0, n_cap, mp, V, dt, drive, threshold):
    """:func:`_plate_triggers` for a drive with a leaf spring to every block; ``_NEVER`` for one
    that pulls block 1 only (resolved when the kernel is compiled, so that drive's kernels do not
    compile the search)."""
    if piece_attr(drive, "leaf_spring"):
        return _plate_triggers(x, th, mov, mm, trig, lo, hi, every, n0, n_cap, mp, V, dt, drive, threshold)
    return _NEVER


def pull_trigger(x, N, V, dt, K, thr, n_lo, n_hi, dp, drive, ends):
    """:func:`_first_trigger` for a drive that pulls block 1 only; ``n_hi`` for a drive with a
    leaf spring (resolved when the kernel is compiled, as :func:`leaf_triggers`)."""
    if piece_attr(drive, "leaf_spring"):
        return n_hi
    return _first_trigger(x, N, V, dt, K, thr, n_lo, n_hi, dp, drive, ends)


@overload(leaf_triggers, prefer_literal=True)
def _leaf_triggers(x, th, mov, mm, trig, lo, hi, every, n0, n_cap, mp, V, dt, drive, threshold):
    leaf = piece_attr(drive, "leaf_spring")
    if leaf is None:
        return None
    if leaf:
        return lambda x, th, mov, mm, trig, lo, hi, every, n0, n_cap, mp, V, dt, drive, threshold: _plate_triggers(
            x, th, mov, mm, trig, lo, hi, every, n0, n_cap, mp, V, dt, drive, threshold
        )
    return lambda x, th, mov, mm, trig, lo, hi, every, n0, n_cap, mp, V, dt, drive, threshold: _NEVER


@overload(pull_trigger, prefer_literal=True)
def _pull_trigger(x, N, V, dt, K, thr, n_lo, n_hi, dp, drive, ends):
    leaf = piece_attr(drive, "leaf_spring")
    if leaf is None:
        return None
    if leaf:
        return lambda x, N, V, dt, K, thr, n_lo, n_hi, dp, drive, ends: n_hi
    return lambda x, N, V, dt, K, thr, n_lo, n_hi, dp, drive, ends: _first_trigger(
        x, N, V, dt, K, thr, n_lo, n_hi, dp, drive, ends
    )
