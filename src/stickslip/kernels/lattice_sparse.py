"""The active-set exact path of a lattice (docs/lattice.md): the answer of
:func:`stickslip.kernels.lattice.run_lattice_dense` bit for bit, computing only the blocks whose
state can change in a step.

For the compositions whose stopped blocks keep every bit until a neighbour moves or the drive
brings them to their threshold (:func:`stickslip.models.pieces.stopped_blocks_still`: a drive on
every block, a friction without theta; Carlson-Langer and Burridge-Knopoff on the square), a
stopped block whose neighbours are still is computed by dense as x, v = 0 and theta unchanged,
with the mask 0 as long as its force stays at or below its threshold. So each step computes, with
dense's own expressions and in its order within a block:

* the candidates: the blocks that moved in the previous step, their neighbours through the stencil
  (the lattice's ``neighbours``, read from a table built once), and the stopped blocks whose
  trigger is due; the ghost cells next to a candidate on a side (the lattice's ``fill_at``), not
  the whole ring;
* stage 1 of every candidate; stage 2 and the corrector only of those whose mask is set: a
  stopped block that stays stopped ends the step with dense's x, v = 0 and theta;
* for every other block, its stage-1 predictors are x + dt * 0 and theta + dt * 0 (written when
  it was last a candidate), which is what dense writes there.

The step's cost is that of its candidates and due triggers: no loop over the lattice, no flags to
clear (a block's ``mark`` is the step whose candidate list holds it). These are the rules of
:mod:`stickslip.kernels.active`, with the candidates as a list gathered anew each step.

A stopped block that leaves the candidates gets its trigger: the first step at which its force,
evaluated with the step's own expression (the drive's ``force_lap`` on its Laplacian, which no
longer changes, and the load point p(t_m)), exceeds its threshold: non-decreasing in m for a load
point that never moves back, so the chain's start-step search
(:func:`stickslip.kernels.triggers.first_start`) finds it exactly. Triggers wait
in a heap; when no block is a candidate the run jumps to the earliest. An event's epicentre is the
smallest flat index among the blocks that start it (dense's row-major order), and its extent sums
the moved blocks' slips in that order too.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from stickslip.kernels.lattice import (
    L_AREA,
    L_COL_MAX,
    L_COL_MIN,
    L_END_STEP,
    L_EPICENTRE,
    L_ID,
    L_ROW_MAX,
    L_ROW_MIN,
    L_START_STEP,
)
from stickslip.kernels.laws import _accel, _pull, _threshold, at, call
from stickslip.kernels.layout import (
    _BIG,
    _NEVER,
    BAD_BLOCK,
    BLOCK_UPDATES,
    DONE,
    EV_ACTIVE,
    EV_COUNT,
    EV_N_MOVED,
    EV_START_BLOCK,
    EV_START_STEP,
    EVENTS_FULL,
    N_EVENTS,
    N_MOVING,
    NONFINITE,
    STEP,
    STEPS_COMPUTED,
)
from stickslip.kernels.triggers import HORIZON, first_start

# Indices of the sparse path's own int64 bookkeeping ``book``.
B_N_CAND = 0  # candidates of the next step, in ``cand``
B_HEAP = 1  # triggers in the heap
B_MOVED = 2  # blocks moved in the event in progress, in ``moved``
B_FRESH = 3  # 1: no candidate list yet (the first call): every block is a candidate
B_MOVING_UPDATES = 4  # block updates of blocks that moved (the mask set), summed over the steps
B_TRIGGERS = 5  # triggers computed (blocks that left the candidates)
BOOK_SIZE = 6


class SparseArgs(NamedTuple):
    """The sparse path's own arrays besides a :class:`~stickslip.kernels.lattice.LatticeArgs`;
    they persist between calls (the driver keeps them with the state)."""

    cand: np.ndarray  # int64: candidates of the next step
    nxt: np.ndarray  # int64 scratch: candidates being gathered
    act: np.ndarray  # int64 scratch: the candidates that move in the step
    mark: np.ndarray  # int64 per flat index: the step whose candidates hold it (-1: none)
    trig: np.ndarray  # int64 per flat index: trigger step of a quiet stopped block (_NEVER: none)
    heap_t: np.ndarray  # int64 binary heap of (trigger, block)
    heap_k: np.ndarray
    moved: np.ndarray  # int64: the event's moved blocks
    nbr: np.ndarray  # int32 (flat index, 5): the lattice's neighbours of each block (-1: none), then 1 on the rim
    book: np.ndarray  # int64 bookkeeping (indices above)


@njit(cache=True, inline="always")
def _push(ht, hk, size, t, k):
    i = size
    ht[i] = t
    hk[i] = k
    while i > 0:
        parent = (i - 1) // 2
        if ht[parent] <= ht[i]:
            break
        ht[parent], ht[i] = ht[i], ht[parent]
        hk[parent], hk[i] = hk[i], hk[parent]
        i = parent
    return size + 1


@njit(cache=True, inline="always")
def _pop(ht, hk, size):
    size -= 1
    ht[0] = ht[size]
    hk[0] = hk[size]
    i = 0
    while True:
        left = 2 * i + 1
        if left >= size:
            break
        child = left
        if left + 1 < size and ht[left + 1] < ht[left]:
            child = left + 1
        if ht[i] <= ht[child]:
            break
        ht[child], ht[i] = ht[i], ht[child]
        hk[child], hk[i] = hk[i], hk[child]
        i = child
    return size


@njit(cache=True)
def _rebuild(ht, hk, trig, geo):
    """The heap anew from the triggers (when it fills up with stale entries)."""
    R, C, W, base = geo[0], geo[1], geo[2], geo[3]
    size = 0
    for r in range(R):
        row = base + r * W
        for k in range(row, row + C):
            if trig[k] != _NEVER:
                size = _push(ht, hk, size, trig[k], k)
    return size


@njit(cache=True, inline="always")
def force_at(fa, m, drive):
    """The force on block k at step m, the step's own expression (the drive's ``force_lap`` on
    its Laplacian ``lap``), ``fa`` = (lap, x_k, K, V, dt, the drive's parameters, k)."""
    lap, xk, K, V, dt, dp, k = fa
    return call(drive, "force_lap", lap, xk, K, _pull(V, m, dt, dp, drive), at(dp, k))


@njit(cache=True)
def _trigger(lap, xk, thr, K, V, dt, dp, n0, drive, k):
    """First step m >= n0 at which a stopped block of Laplacian ``lap`` starts (its force, the
    step's own expression, exceeds ``thr``), else _NEVER: the chain's start-step search
    (:func:`stickslip.kernels.triggers.first_start`) on the lattice's force, up to its horizon
    (a trigger outlives the kernel's call, so the run's end does not bound it)."""
    rate = call(drive, "leaf", at(dp, k)) * V * dt
    t = first_start("stickslip.kernels.lattice_sparse", (lap, xk, K, V, dt, dp, k), drive, thr, rate, n0, HORIZON + 1)
    return _NEVER if t == HORIZON + 1 else t


@njit(cache=True)
def _table(nbr, geo, lattice):
    """The lattice's neighbours of every block (``neighbours``) and whether it reads a ghost cell
    (``rim``), once: the steps then read a table instead of calling the lattice per block."""
    R, C, W, base = geo[0], geo[1], geo[2], geo[3]
    nb = np.zeros(4, dtype=np.int64)
    for r in range(R):
        row = base + r * W
        for k in range(row, row + C):
            m = call(lattice, "neighbours", k, geo, nb)
            for q in range(4):
                nbr[k, q] = nb[q] if q < m else -1
            nbr[k, 4] = 1 if call(lattice, "rim", k, geo) else 0


@njit(cache=True)
def _close(n, a, sp, lattice):
    """Close the event that ended in step n: its row, the moved blocks' slips summed in flat order."""
    ist, ev_int, geo = a.ist, a.ev_int, a.geo
    W = geo[2]
    m = sp.book[B_MOVED]
    blocks = np.sort(sp.moved[:m])
    moment = 0.0
    r0, r1, c0, c1 = geo[0] + 1, 0, geo[1] + 1, 0
    chain = geo[4] < 0
    for j in range(m):
        k = blocks[j]
        moment += a.x[k] - a.x0ev[k]
        a.first_step[k] = -1
        r = 1 if chain else k // W
        c = k if chain else k - r * W
        r0, r1, c0, c1 = min(r0, r), max(r1, r), min(c0, c), max(c1, c)
    eid = ist[N_EVENTS]
    row = ist[EV_COUNT]
    ev_int[row, L_ID] = eid
    ev_int[row, L_START_STEP] = ist[EV_START_STEP]
    ev_int[row, L_END_STEP] = n
    ev_int[row, L_EPICENTRE] = ist[EV_START_BLOCK]
    ev_int[row, L_AREA] = m
    ev_int[row, L_ROW_MIN] = r0
    ev_int[row, L_ROW_MAX] = r1
    ev_int[row, L_COL_MIN] = c0
    ev_int[row, L_COL_MAX] = c1
    a.ev_moment[row] = moment
    ist[EV_COUNT] = row + 1
    ist[EV_ACTIVE] = 0
    ist[N_EVENTS] = eid + 1
    sp.book[B_MOVED] = 0


@njit(cache=True)
def run_lattice_sparse(a, sp, drive, friction, threshold, lattice):
    """The active-set exact path (module docstring): :func:`stickslip.kernels.lattice.run_lattice_dense`'s
    answer, bit for bit, for compositions whose stopped blocks keep every bit; ``a`` a
    :class:`~stickslip.kernels.lattice.LatticeArgs`, ``sp`` a :class:`SparseArgs`."""
    x, v, th, mov, xs = a.x, a.v, a.th, a.mov, a.xs
    vs, ths, mm, a1, b1 = a.vs, a.ths, a.mm, a.a1, a.b1
    ist, geo, par = a.ist, a.geo, a.par
    cand, nxt, act, mark, trig = sp.cand, sp.nxt, sp.act, sp.mark, sp.trig
    ht, hk, book = sp.heap_t, sp.heap_k, sp.book
    R, C, W, base = geo[0], geo[1], geo[2], geo[3]
    K, V, dt = par[0], par[1], par[2]
    dp, tp, lp = a.dp, a.tp, a.law
    mp = (K, dp, tp, lp, a.mass)
    h2 = 0.5 * dt
    cap_ev = a.ev_int.shape[0]
    nbr = sp.nbr
    if book[B_FRESH] == 1:
        _table(nbr, geo, lattice)
        # Every block a candidate; the moved blocks of an event in progress (a state handed over
        # from another run) from their first moves.
        nc = 0
        m = 0
        for r in range(R):
            row = base + r * W
            for k in range(row, row + C):
                cand[nc] = k
                mark[k] = ist[STEP]
                nc += 1
                if a.first_step[k] >= 0:
                    sp.moved[m] = k
                    m += 1
        book[B_N_CAND] = nc
        book[B_MOVED] = m
        book[B_FRESH] = 0
    while True:
        n = ist[STEP]
        if n >= a.n_end:
            return DONE
        if ist[EV_COUNT] >= cap_ev:
            return EVENTS_FULL
        nc = book[B_N_CAND]
        hs = book[B_HEAP]
        # Due triggers join the candidates (``mark`` = n: already one; stale entries dropped).
        while hs > 0 and ht[0] <= n:
            k = hk[0]
            t = ht[0]
            hs = _pop(ht, hk, hs)
            if trig[k] == t and mark[k] != n:
                mark[k] = n
                cand[nc] = k
                nc += 1
        book[B_HEAP] = hs

        if nc == 0:
            # Nothing can change before the earliest trigger: jump there.
            target = a.n_end if hs == 0 else min(ht[0], a.n_end)
            if target > n:
                ist[STEP] = target
                continue
        # Stage 1. A stopped block that stays stopped ends the step as it began (x, v = 0 and
        # theta: its rate is 0); its predictors are what dense writes, read by its neighbours.
        p1 = _pull(V, n, dt, dp, drive)
        na = 0
        first = -1
        for j in range(nc):
            k = cand[j]
            trig[k] = _NEVER
            if nbr[k, 4] != 0:
                call(lattice, "fill_at", x, th, geo, p1, k)
            f = call(drive, "force_lap", call(lattice, "lap", x, k, W), x[k], K, p1, at(dp, k))
            b1[k] = call(friction, "rate_lap", call(lattice, "lap", th, k, W), th[k], v[k], at(lp, k))
            xs[k] = x[k] + dt * v[k]
            ths[k] = th[k] + dt * b1[k]
            if mov[k] != 0.0 or f > _threshold(th[k], tp, threshold, k):
                mm[k] = 1.0
                a1[k] = _accel(f, th[k], v[k], mm[k], mp, friction, k)
                vs[k] = v[k] + dt * a1[k]
                act[na] = k
                na += 1
                if first < 0 or k < first:
                    first = k
            else:
                mm[k] = 0.0
        p2 = _pull(V, n + 1, dt, dp, drive)
        # Event start (dense's: the first block in flat order opens it).
        if ist[EV_ACTIVE] == 0 and ist[N_MOVING] == 0 and first >= 0:
            ist[EV_ACTIVE] = 1
            ist[EV_START_STEP] = n
            ist[EV_START_BLOCK] = first
            ist[EV_N_MOVED] = 0
            book[B_MOVED] = 0
        # Stage 2 and the corrector of the blocks that move; they and their neighbours are the
        # next step's candidates (``mark`` = n + 1).
        n_moving = 0
        bad = 0
        nn = 0
        for j in range(na):
            k = act[j]
            if ist[EV_ACTIVE] == 1 and a.first_step[k] < 0:
                a.first_step[k] = n
                a.x0ev[k] = x[k]
                ist[EV_N_MOVED] += 1
                sp.moved[book[B_MOVED]] = k
                book[B_MOVED] += 1
            if nbr[k, 4] != 0:
                call(lattice, "fill_at", xs, ths, geo, p2, k)
            f2 = call(drive, "force_lap", call(lattice, "lap", xs, k, W), xs[k], K, p2, at(dp, k))
            a2 = _accel(f2, ths[k], vs[k], mm[k], mp, friction, k)
            b2 = call(friction, "rate_lap", call(lattice, "lap", ths, k, W), ths[k], vs[k], at(lp, k))
            th[k] = th[k] + h2 * (b1[k] + b2)
            x[k] = x[k] + h2 * (v[k] + vs[k])
            vn = v[k] + h2 * (a1[k] + a2)
            if vn <= 0.0:
                v[k] = 0.0
                mov[k] = 0.0
            else:
                v[k] = vn
                mov[k] = 1.0
                n_moving += 1
            if bad == 0 and not (abs(x[k]) <= _BIG and abs(v[k]) <= _BIG and abs(th[k]) <= _BIG):
                bad = k
            # (written out: a helper taking the arrays costs two atomic reference counts a call)
            if mark[k] != n + 1:
                mark[k] = n + 1
                nxt[nn] = k
                nn += 1
            for q in range(4):
                kq = nbr[k, q]
                if kq >= 0 and mark[kq] != n + 1:
                    mark[kq] = n + 1
                    nxt[nn] = kq
                    nn += 1
        # The others leave with a trigger (their Laplacian no longer changes).
        hs = book[B_HEAP]
        for j in range(nc):
            k = cand[j]
            if mark[k] == n + 1:
                continue
            t = _trigger(
                call(lattice, "lap", x, k, W), x[k], _threshold(th[k], tp, threshold, k), K, V, dt, dp, n + 1, drive, k
            )
            trig[k] = t
            book[B_TRIGGERS] += 1
            if t != _NEVER:
                if hs >= ht.shape[0]:
                    hs = _rebuild(ht, hk, trig, geo)
                hs = _push(ht, hk, hs, t, k)
        book[B_HEAP] = hs
        for j in range(nn):
            cand[j] = nxt[j]
        book[B_N_CAND] = nn
        book[B_MOVING_UPDATES] += na
        ist[N_MOVING] = n_moving
        ist[BLOCK_UPDATES] += nc
        ist[STEPS_COMPUTED] += 1
        ist[STEP] = n + 1
        if bad > 0:
            ist[BAD_BLOCK] = bad
            return NONFINITE
        if ist[EV_ACTIVE] == 1 and n_moving == 0:
            _close(n, a, sp, lattice)
