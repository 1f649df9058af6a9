"""Sparse exact steps of the plate drive for frictions without a state variable
(weakening, strengthening): the Carlson-Langer and train models (docs/model.md, "The family the
paper stands in").

There a stopped block does not change at all, and the plate's start of a stopped block is
known in advance (``trig``, see :mod:`stickslip.kernels.triggers`). So a step touches only

* the moving blocks,
* the stopped blocks next to a block that moved in the last step (their force changed), and
* the stopped blocks whose plate start is due: ``trig[i] == n``,

through lists of block indices (periodic neighbours wrap through the ghost cells, with no
interval to widen around the ring). A stopped block j keeps xs[j] = x[j] + dt v[j], the
predictor that run_dense writes for it at every step (written when it stops, and on entry),
so a mover's stage 2 reads its stopped neighbours' predictors without recomputing them.
``trig`` of a stopped block is found once its neighbours are still again (after a step in
which it was a candidate and no neighbour moved); a block due in the next step goes on the
queue, the others are found when the step reaches the smallest of their ``trig``.

These lists are the active set of :mod:`stickslip.kernels.active` (which blocks get which stage),
kept from step to step while no block starts or stops. The pause for outputs, the end and the
buffers is written out rather than taken from there: with those helpers this kernel measured
about 10% slower (docs/performance.md, "One active set, three forms").

A step costs little more than its moving blocks (most steps move one to a few of them):

1. the start rule of the stopped candidates: a first pass only asks whether any fires (it
   rarely does); if one does, a second pass splits them, without branches, into starters
   (appended to the list of movers) and blocks that stay stopped;
2. stage 1 and then stage 2 (with the stop rule) of the movers. With more than a few movers
   each stage runs in three loops: gather the forces and velocities into packed arrays,
   evaluate the friction phi(v) = (1 - sigma) / (1 + 2 alpha max(v, 0) / (1 - sigma)) and the
   Heun sums on the packed arrays (a loop the compiler vectorises: its two divisions per
   block dominate a scalar step), scatter the results back. With a few movers a vector loop
   does not pay for its set-up, and each stage is one scalar loop over the list. Vector and
   scalar divisions round alike, so the order of evaluation and every bit are those of
   run_dense;
3. if no block started or stopped (and the last step stopped none), the movers' list and the
   queue of candidates stay as they are. Otherwise the lists are rebuilt from what changed:
   ``cnt`` counts the moving neighbours of each block, so the next queue (the stopped
   neighbours of the blocks that moved) is found from the candidates that stayed stopped,
   the starters' neighbours and the blocks that stopped and their neighbours, not from every
   mover. The stopped blocks that leave the queue get their plate start (``trig``).

Outputs, the end of the call and the buffers are looked at only from the step ``n_chk``: the
next sample, profile row or end, or the step after an event started or ended (the only
steps at which a buffer can fill).

Block indices in the lists are unsigned: numba then indexes the arrays without the
wraparound code of negative indices. The kernel uses numpy's error model (a float division
by zero is not checked, so the packed loops have no exit): the only divisor, 1 - sigma, is
positive since ChainParams holds sigma in [0, 1), and 1 + 2 alpha max(v, 0) / (1 - sigma)
is at least 1. Every quantity uses the expressions of :mod:`stickslip.kernels.laws`, so
the result equals run_dense bit for bit.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from stickslip.kernels.events import _end_event, _open_event, _overflow, _service
from stickslip.kernels.laws import _accel, _force, _pull, _set_ghosts, _threshold, call, has
from stickslip.kernels.layout import (
    _NEVER,
    ACT_HI,
    ACT_LO,
    BLOCK_UPDATES,
    DONE,
    EV_ACTIVE,
    EV_COUNT,
    EV_MAX_BLOCK,
    EV_N_MOVED,
    FM_COUNT,
    FULL_UPDATES,
    MECH_HI,
    MECH_LO,
    N_MOVING,
    NEXT_PROFILE,
    NEXT_SAMPLE,
    P_COUNT,
    STEP,
    STEPS_COMPUTED,
    _unpack,
)
from stickslip.kernels.triggers import _plate_trigger

_QUEUED = np.int64(-1)  # trig of a stopped block queued as a candidate of the next step
_FEW = 8  # up to this many movers, each stage is one scalar loop (faster than the packed loops: measured)


@njit(cache=True, inline="always")
def _x_ghosts(x, N, ends):
    """Ghost cells of x under the plate drive, as laws._set_ghosts sets them (theta's do not
    change here)."""
    x[0] = call(ends, "ghost", x[1], x[N], 0.0)
    x[N + 1] = call(ends, "ghost", x[N], x[1], 0.0)


@njit(cache=True, inline="always")
def _sides(i, one, uN, periodic):
    """Left and right neighbour of block i (through the ring with periodic ends)."""
    l = i - one
    r = i + one
    if periodic:
        l = l if l >= one else uN
        r = r if r <= uN else one
    return l, r


@njit(cache=True, inline="always")
def _enqueue(j, ok, mov, trig, queue, nq, one, uN):
    """Queue block j for the next step if ok and it is a stopped block not queued yet; returns
    the new length. Without branches (they mispredict): a slot not taken is overwritten."""
    t = trig[j]
    q = ok & (j >= one) & (j <= uN) & (mov[j] == 0.0) & (t != _QUEUED)
    trig[j] = _QUEUED if q else t
    queue[nq] = j
    return nq + (1 if q else 0)


@njit(cache=True, inline="always")
def _settle(i, m, n, trig, queue, nq, t_next):
    """Stopped block i with still neighbours and plate start step m: queued for step n if m is
    due by then, else m kept in ``trig``. Returns the queue's length and the smallest start step."""
    if m <= n:
        trig[i] = _QUEUED
        queue[nq] = i
        return nq + 1, t_next
    trig[i] = m
    return nq, min(t_next, m)


@njit(cache=True, error_model="numpy")
def run_sparse(args, drive, friction, threshold, ends):
    """:func:`stickslip.kernels.exact.run_exact` for the plate drive with weakening or
    strengthening friction: same arguments, state and status codes (module docstring).

    ``mm``, ``a1``, ``b1``, ``vs`` and ``ths`` are not used: the mask is 1 on the movers' list,
    and the stage-1 accelerations and predicted velocities are kept in the list's order.
    """
    x, v, th, mov, xs = args.x, args.v, args.th, args.mov, args.xs
    trig, first_step, x0ev, ist, par = args.trig, args.first_step, args.x0ev, args.ist, args.par
    ev_int, fm, prof_x, n_end, profile_every = args.ev_int, args.fm, args.prof_x, args.n_end, args.profile_every
    prof_meta = args.prof_meta
    N = x.shape[0] - 2
    mp, V, dt = _unpack(par, args.dp, args.tp, args.law, args.kb, args.mass)
    K, dp, tp = mp[0], mp[1], mp[2]
    h2 = 0.5 * dt
    cap_ev, cap_fm, cap_p = ev_int.shape[0], fm.shape[0], prof_x.shape[0]
    one = np.uint64(1)
    uN = np.uint64(N)
    periodic = has(ends, "ring")
    movers = np.empty(N, np.uint64)  # moving blocks, then this step's starters
    nxt = np.empty(N, np.uint64)  # the movers of the next step
    queue = np.empty(N + 1, np.uint64)  # stopped candidates of the next step (a spare slot: _enqueue)
    cnt = np.zeros(N + 2, np.int64)  # how many neighbours of each block are movers
    still = np.empty(N + 1, np.uint64)  # stopped candidates whose start rule did not fire (swaps with queue)
    stopped = np.empty(N, np.uint64)  # movers that stopped in this step
    acc = np.empty(N)  # stage-1 acceleration of movers[k]
    fb = np.empty(N)  # packed: force on movers[k] (stage 1, then stage 2)
    vb = np.empty(N)  # packed: v of movers[k], then its new v
    vsb = np.empty(N)  # packed: predicted v of movers[k]
    kept = np.empty(N, np.bool_)  # packed: movers[k] still moves after the step
    # The interval bookkeeping of run_exact is not used here: leave it conservative.
    ist[ACT_LO], ist[ACT_HI], ist[MECH_LO], ist[MECH_HI] = 1, N, 1, N
    _set_ghosts(x, th, N, 0.0, drive, ends)
    n0 = ist[STEP]
    nmov = 0
    nq = 0
    t_next = _NEVER  # no stopped block outside the queue starts before this step
    for i in range(1, N + 1):
        trig[i] = _NEVER
        if mov[i] != 0.0:
            movers[nmov] = i
            nmov += 1
            l, r = _sides(np.uint64(i), one, uN, periodic)
            cnt[l] += 1
            cnt[r] += 1
        else:
            xs[i] = x[i] + dt * v[i]
    for i in range(1, N + 1):
        if mov[i] == 0.0:
            m = _plate_trigger(
                x[i - 1], x[i], x[i + 1], _threshold(th[i], tp, threshold, i), K, dp, V, dt, n0, n_end, drive, i
            )
            nq, t_next = _settle(i, m, n0, trig, queue, nq, t_next)
    if n0 < n_end:
        # run_dense adds dt/2 (0 + 0) to every theta in each step (no state variable); nothing
        # here reads theta, and after the first step the sum changes no bit: do it once.
        for i in range(1, N + 1):
            th[i] = th[i] + h2 * (0.0 + 0.0)
    steps_computed = 0
    block_updates = 0
    full_updates = 0
    active = ist[EV_ACTIVE] == 1
    # The queue holds the stopped neighbours of the movers (and the plate's due starts); while
    # no block starts or stops it stays so, and the next step's queue is this one.
    qexact = False
    full = True  # the next rebuild of the queue looks at every mover
    n = n0
    n_chk = n0  # outputs, the end and the buffers are looked at from this step on
    st = DONE
    while True:
        if n >= n_chk:
            # Outputs due, the end, buffers that could overflow. These change only at the steps
            # named here or when an event starts or ends, after which n_chk is the next step.
            ist[STEP] = n
            ist[N_MOVING] = nmov
            if n == ist[NEXT_SAMPLE] or (profile_every > 0 and active and n == ist[NEXT_PROFILE]):
                st = _service(n, args)
                if st != DONE:
                    break
            if n >= n_end:
                st = DONE
                break
            if (
                ist[EV_COUNT] >= cap_ev
                or ist[FM_COUNT] + N > cap_fm
                or (profile_every > 0 and ist[P_COUNT] + 2 > cap_p)
            ):
                st = _overflow(ist, N, cap_ev, cap_fm)
                break
            n_chk = n_end if n_end < ist[NEXT_SAMPLE] else ist[NEXT_SAMPLE]
            if profile_every > 0 and active and ist[NEXT_PROFILE] < n_chk:
                n_chk = ist[NEXT_PROFILE]
        p1 = _pull(V, n, dt, dp, drive)
        # Start rule of the stopped candidates: the queue, and (rarely) the plate's due starts.
        # Each goes to the starters (after the movers) or to the blocks that stay stopped; the
        # latter stay marked as queued.
        nst = 0
        nsl = 0
        fired = False
        for k in range(nq):
            i = queue[k]
            f = _force(x[i - one], x[i], x[i + one], K, dp, p1, drive, i)
            fired |= f > _threshold(th[i], tp, threshold, i)
        if fired:
            for k in range(nq):
                i = queue[k]
                f = _force(x[i - one], x[i], x[i + one], K, dp, p1, drive, i)
                fire = f > _threshold(th[i], tp, threshold, i)
                movers[nmov + nst] = i
                still[nsl] = i
                nst += 1 if fire else 0
                nsl += 0 if fire else 1
        else:
            # Usually none starts: the queue is the list of blocks that stay stopped.
            still, queue = queue, still
            nsl = nq
        for k in range(nmov, nmov + nst):
            trig[movers[k]] = _NEVER
        scanned = n >= t_next
        if scanned:
            t_next = _NEVER
            for j in range(1, N + 1):
                if mov[j] == 0.0:
                    t = trig[j]
                    if 0 <= t and t <= n:
                        i = np.uint64(j)
                        trig[i] = _NEVER
                        f = _force(x[i - one], x[i], x[i + one], K, dp, p1, drive, i)
                        if f > _threshold(th[i], tp, threshold, i):
                            movers[nmov + nst] = i
                            nst += 1
                        else:
                            still[nsl] = i
                            nsl += 1
                    elif t > n and t < t_next:
                        t_next = t
        na = nmov + nst
        if na + nsl == 0:
            # Nothing can change before the plate starts a block: jump, but stop at due outputs.
            target = n_end
            if ist[NEXT_SAMPLE] < target:
                target = ist[NEXT_SAMPLE]
            if profile_every > 0 and active and ist[NEXT_PROFILE] < target:
                target = ist[NEXT_PROFILE]
            n = t_next if t_next < target else target
            continue

        # Stage 1 of the movers (x holds t_n everywhere; ghost cells are set). The mask is 1.
        # The predictor of x goes to xs (stage 2 reads it), that of v stays packed.
        packed = na > _FEW
        if packed:
            for k in range(na):
                i = movers[k]
                fb[k] = _force(x[i - one], x[i], x[i + one], K, dp, p1, drive, i)
                vi = v[i]
                vb[k] = vi
                xs[i] = x[i] + dt * vi
            for k in range(na):
                a = _accel(fb[k], 0.0, vb[k], 1.0, mp, friction, movers[k])
                acc[k] = a
                vsb[k] = vb[k] + dt * a
        else:
            for k in range(na):
                i = movers[k]
                f = _force(x[i - one], x[i], x[i + one], K, dp, p1, drive, i)
                vi = v[i]
                a = _accel(f, 0.0, vi, 1.0, mp, friction, i)
                vb[k] = vi
                acc[k] = a
                vsb[k] = vi + dt * a
                xs[i] = x[i] + dt * vi
        _x_ghosts(xs, N, ends)
        p2 = _pull(V, n + 1, dt, dp, drive)
        # Event start and first moves (as events._start_and_first_moves): a block moves for
        # the first time in an event only in the step it starts.
        if nst > 0 and (active or nmov == 0):
            if not active:
                first = N + 1
                for k in range(nst):
                    first = min(first, np.int64(movers[k]))
                active = True
                n_chk = n + 1
                _open_event(n, first, x, ist, prof_x, prof_meta, N, profile_every)
            for k in range(nmov, na):
                i = movers[k]
                if first_step[i] < 0:
                    first_step[i] = n
                    x0ev[i] = x[i]
                    ist[EV_N_MOVED] += 1
                    if np.int64(i) > ist[EV_MAX_BLOCK]:
                        ist[EV_MAX_BLOCK] = np.int64(i)
        # Stage 2, corrector and stop rule of the movers (stopped blocks keep every bit).
        # Theta is left as run_dense leaves it (both derivatives 0, no state variable).
        ns = 0
        if packed:
            for k in range(na):
                i = movers[k]
                fb[k] = _force(xs[i - one], xs[i], xs[i + one], K, dp, p2, drive, i)
            for k in range(na):
                a2 = _accel(fb[k], 0.0, vsb[k], 1.0, mp, friction, movers[k])
                vn = vb[k] + h2 * (acc[k] + a2)
                keep = vn > 0.0
                vb[k] = vn if keep else 0.0
                kept[k] = keep
            for k in range(na):
                i = movers[k]
                x[i] = x[i] + h2 * (v[i] + vsb[k])
                keep = kept[k]
                v[i] = vb[k]
                mov[i] = 1.0 if keep else 0.0
                ns += 0 if keep else 1
        else:
            for k in range(na):
                i = movers[k]
                f2 = _force(xs[i - one], xs[i], xs[i + one], K, dp, p2, drive, i)
                sv = vsb[k]
                vo = vb[k]
                vn = vo + h2 * (acc[k] + _accel(f2, 0.0, sv, 1.0, mp, friction, i))
                keep = vn > 0.0
                x[i] = x[i] + h2 * (vo + sv)
                v[i] = vn if keep else 0.0
                mov[i] = 1.0 if keep else 0.0
                kept[k] = keep
                ns += 0 if keep else 1
        _x_ghosts(x, N, ends)
        block_updates += na + nsl
        full_updates += na
        steps_computed += 1
        if qexact and nst == 0 and ns == 0 and not scanned:
            still, queue = queue, still  # the candidates stay the queue
        else:
            # The movers changed: rebuild the lists. (Otherwise every candidate stayed stopped
            # and stays queued, and the movers' list is the same.)
            if ns > 0:
                nn = 0
                q = 0
                for k in range(na):
                    i = movers[k]
                    keep = kept[k]
                    nxt[nn] = i
                    stopped[q] = i
                    nn += 1 if keep else 0
                    q += 0 if keep else 1
                # Blocks that stopped: the predictor run_dense writes for them from now on.
                for k in range(ns):
                    i = stopped[k]
                    xs[i] = x[i] + dt * v[i]
            # Moving neighbours: this step's starters joined the movers, the blocks that stopped left.
            for k in range(nmov, na):
                l, r = _sides(movers[k], one, uN, periodic)
                cnt[l] += 1
                cnt[r] += 1
            for k in range(ns):
                l, r = _sides(stopped[k], one, uN, periodic)
                cnt[l] -= 1
                cnt[r] -= 1
            for k in range(nsl):
                trig[still[k]] = _NEVER
            # Stopped blocks next to a block that moved: their force changed, so evaluate their
            # start rule in the next step (cheaper than finding a start step while a front passes).
            nq = 0
            if full:
                for k in range(na):
                    l, r = _sides(movers[k], one, uN, periodic)
                    nq = _enqueue(l, True, mov, trig, queue, nq, one, uN)
                    nq = _enqueue(r, True, mov, trig, queue, nq, one, uN)
                full = False
            else:
                # The same set from what changed: the last queue holds the stopped neighbours of
                # the movers before this step, so only the candidates that stayed stopped (if
                # still next to a mover), the starters' neighbours, and the blocks that stopped
                # and their neighbours can be in the new one.
                for k in range(nsl):
                    j = still[k]
                    nq = _enqueue(j, cnt[j] > 0, mov, trig, queue, nq, one, uN)
                for k in range(nmov, na):
                    l, r = _sides(movers[k], one, uN, periodic)
                    nq = _enqueue(l, True, mov, trig, queue, nq, one, uN)
                    nq = _enqueue(r, True, mov, trig, queue, nq, one, uN)
                for k in range(ns):
                    j = stopped[k]
                    nq = _enqueue(j, cnt[j] > 0, mov, trig, queue, nq, one, uN)
                    l, r = _sides(j, one, uN, periodic)
                    nq = _enqueue(l, True, mov, trig, queue, nq, one, uN)
                    nq = _enqueue(r, True, mov, trig, queue, nq, one, uN)
            # The other stopped blocks of this step have settled neighbours: their start step.
            for k in range(nsl + ns):
                i = still[k] if k < nsl else stopped[k - nsl]
                if trig[i] != _QUEUED:
                    m = _plate_trigger(
                        x[i - one],
                        x[i],
                        x[i + one],
                        _threshold(th[i], tp, threshold, i),
                        K,
                        dp,
                        V,
                        dt,
                        n + 1,
                        n_end,
                        drive,
                        i,
                    )
                    nq, t_next = _settle(i, m, n + 1, trig, queue, nq, t_next)
            if ns > 0:
                movers, nxt = nxt, movers
            qexact = ns == 0
        nmov = na - ns
        if active and nmov == 0:
            _end_event(n, args)
            active = False
            n_chk = n + 1
        n += 1
    if steps_computed > 0:
        # Ghost cells of theta as run_dense leaves them (x's are set).
        _set_ghosts(x, th, N, 0.0, drive, ends)
        ist[N_MOVING] = nmov
    ist[BLOCK_UPDATES] += block_updates
    ist[FULL_UPDATES] += full_updates
    ist[STEPS_COMPUTED] += steps_computed
    return st
