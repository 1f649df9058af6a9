"""Sparse exact steps of the plate drive for frictions without a state variable
(weakening, strengthening): the Carlson-Langer and train models.

There a stopped block does not change at all, and the plate's start of a stopped block is
known in advance (``trig``, see :mod:`stickslip.kernels.chain`). So a step touches only

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

Every quantity uses the expressions of :mod:`stickslip.kernels.common`, so the result
equals run_dense bit for bit.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from stickslip.kernels import common as c

_QUEUED = np.int64(-1)  # trig of a stopped block queued as a candidate of the next step


@njit(cache=True, inline="always")
def _retrig(i, n1, n_end, x, th, mov, trig, queue, nq, mp, V, dt, threshold):
    """Redo trig of block i from step n1 if it is stopped and not queued; queue it when it
    starts at n1.
    Returns the new queue length and the block's trig (``_NEVER`` if moving or queued)."""
    if mov[i] != 0.0 or trig[i] == _QUEUED:
        return nq, c._NEVER
    m = c._plate_trigger(x[i - 1], x[i], x[i + 1], c._threshold(th[i], mp[5], threshold),
                         mp[0], mp[1], V, dt, n1, n_end)
    if m <= n1:
        trig[i] = _QUEUED
        queue[nq] = i
        return nq + 1, c._NEVER
    trig[i] = m
    return nq, m


@njit(cache=True)
def run_sparse(x, v, th, mov, xs, vs, ths, mm, a1, b1, trig, first_step, x0ev, ist, par,
               ev_int, ev_S, fm, samp_L, samp_step, prof_x, prof_meta,
               n_end, sample_every, profile_every, profile_min_blocks, drive, friction, threshold, ends):
    """:func:`stickslip.kernels.chain.run_exact` for the plate drive with weakening or
    strengthening friction: same arguments, state and status codes (module docstring)."""
    N = x.shape[0] - 2
    mp, V, dt = c._unpack(par)
    K, Kp, Fs = mp[0], mp[1], mp[5]
    h2 = 0.5 * dt
    cap_ev, cap_fm, cap_p = ev_int.shape[0], fm.shape[0], prof_x.shape[0]
    movers = np.empty(N, np.int64)    # moving blocks
    queue = np.empty(N, np.int64)     # stopped blocks that start in the next step
    cand = np.empty(N, np.int64)      # blocks of this step
    nxt = np.empty(N, np.int64)
    stopped = np.empty(N, np.int64)
    # The interval bookkeeping of run_exact is not used here: leave it conservative.
    ist[c.ACT_LO], ist[c.ACT_HI], ist[c.MECH_LO], ist[c.MECH_HI] = 1, N, 1, N
    c._set_ghosts(x, th, N, 0.0, drive, ends)
    n0 = ist[c.STEP]
    nmov = 0
    nq = 0
    t_next = c._NEVER  # no stopped block outside the queue starts before this step
    for i in range(1, N + 1):
        if mov[i] != 0.0:
            movers[nmov] = i
            nmov += 1
            trig[i] = c._NEVER
        else:
            xs[i] = x[i] + dt * v[i]
            trig[i] = c._NEVER
    for i in range(1, N + 1):
        nq, m = _retrig(i, n0, n_end, x, th, mov, trig, queue, nq, mp, V, dt, threshold)
        t_next = min(t_next, m)
    while True:
        n = ist[c.STEP]
        if n == ist[c.NEXT_SAMPLE] or (profile_every > 0 and ist[c.EV_ACTIVE] == 1 and n == ist[c.NEXT_PROFILE]):
            st = c._service(n, x, N, ist, samp_L, samp_step, prof_x, prof_meta, sample_every, profile_every)
            if st != c.DONE:
                return st
        if n >= n_end:
            return c.DONE
        if ist[c.EV_COUNT] >= cap_ev or ist[c.FM_COUNT] + N > cap_fm or (profile_every > 0 and ist[c.P_COUNT] + 2 > cap_p):
            return c._overflow(ist, N, cap_ev, cap_fm)
        # This step's blocks: movers, queued starts, and (rarely) starts due to the plate alone.
        nc = 0
        for k in range(nmov):
            cand[nc] = movers[k]
            nc += 1
        for k in range(nq):
            i = queue[k]
            trig[i] = c._NEVER
            cand[nc] = i
            nc += 1
        nq = 0
        if n >= t_next:
            t_next = c._NEVER
            for i in range(1, N + 1):
                if mov[i] == 0.0:
                    t = trig[i]
                    if 0 <= t and t <= n:
                        trig[i] = c._NEVER
                        cand[nc] = i
                        nc += 1
                    elif t > n and t < t_next:
                        t_next = t
        if nc == 0:
            # Nothing can change before the plate starts a block: jump, but stop at due outputs.
            target = n_end
            if ist[c.NEXT_SAMPLE] < target:
                target = ist[c.NEXT_SAMPLE]
            if profile_every > 0 and ist[c.EV_ACTIVE] == 1 and ist[c.NEXT_PROFILE] < target:
                target = ist[c.NEXT_PROFILE]
            ist[c.STEP] = t_next if t_next < target else target
            continue

        # Stage 1 (x holds t_n everywhere; ghost cells are set).
        p1 = c._pull(V, n, dt)
        starts = False
        first = N + 1
        for k in range(nc):
            i = cand[k]
            f = c._force(x[i - 1], x[i], x[i + 1], K, Kp, p1, drive)
            mo = mov[i]
            m = 1.0 if f > c._threshold(th[i], Fs, threshold) else mo
            mm[i] = m
            if m == 0.0:
                continue  # stays stopped: its predictor is kept, nothing reads the rest
            if i < first:
                first = i
            starts |= m != mo
            a = c._accel(f, th[i], v[i], m, mp, friction)
            b = c._dtheta(th[i - 1], th[i], th[i + 1], v[i], mp, friction)
            a1[i] = a
            b1[i] = b
            xs[i] = x[i] + dt * v[i]
            vs[i] = v[i] + dt * a
            ths[i] = th[i] + dt * b
        p2 = c._pull(V, n + 1, dt)
        c._set_ghosts(xs, ths, N, p2, drive, ends)
        # Event start and first moves (as common._start_and_first_moves, on the list).
        if first <= N and (ist[c.EV_ACTIVE] == 1 or ist[c.N_MOVING] == 0) and (starts or ist[c.EV_ACTIVE] == 0):
            if ist[c.EV_ACTIVE] == 0:
                ist[c.EV_ACTIVE] = 1
                ist[c.EV_START_STEP] = n
                ist[c.EV_START_BLOCK] = first
                ist[c.EV_MAX_BLOCK] = 0
                ist[c.EV_N_MOVED] = 0
                if profile_every > 0:
                    r = ist[c.P_COUNT]
                    ist[c.EV_P_FIRST] = r
                    for i in range(1, N + 1):
                        prof_x[r, i - 1] = x[i]
                    prof_meta[r, 0] = ist[c.N_EVENTS]
                    prof_meta[r, 1] = n
                    ist[c.P_COUNT] = r + 1
                    ist[c.NEXT_PROFILE] = n + profile_every
            for k in range(nc):
                i = cand[k]
                if mm[i] != 0.0 and first_step[i] < 0:
                    first_step[i] = n
                    x0ev[i] = x[i]
                    ist[c.EV_N_MOVED] += 1
                    if i > ist[c.EV_MAX_BLOCK]:
                        ist[c.EV_MAX_BLOCK] = i
        # Stage 2, corrector and stop rule for the blocks that move (others keep every bit).
        nn = 0
        ns = 0
        nfull = 0
        for k in range(nc):
            i = cand[k]
            m = mm[i]
            if m == 0.0:
                stopped[ns] = i  # its start rule did not fire
                ns += 1
                continue
            nfull += 1
            f2 = c._force(xs[i - 1], xs[i], xs[i + 1], K, Kp, p2, drive)
            a2 = c._accel(f2, ths[i], vs[i], m, mp, friction)
            b2 = c._dtheta(ths[i - 1], ths[i], ths[i + 1], vs[i], mp, friction)
            x[i] = x[i] + h2 * (v[i] + vs[i])
            vn = v[i] + h2 * (a1[i] + a2)
            th[i] = th[i] + h2 * (b1[i] + b2)
            if vn > 0.0:
                v[i] = vn
                mov[i] = m
                nxt[nn] = i
                nn += 1
            else:
                v[i] = 0.0
                mov[i] = 0.0
                stopped[ns] = i
                ns += 1
        # Blocks that stopped: the predictor run_dense writes for them from now on.
        for k in range(ns):
            i = stopped[k]
            xs[i] = x[i] + dt * v[i]
        c._set_ghosts(x, th, N, 0.0, drive, ends)
        # Stopped blocks next to a block that moved: their force changed, so evaluate their
        # start rule in the next step (cheaper than finding a start step while a front passes).
        for k in range(nc):
            i = cand[k]
            if mm[i] != 0.0:
                l = i - 1
                r = i + 1
                if ends == c.ENDS_PERIODIC:
                    if l < 1:
                        l = N
                    if r > N:
                        r = 1
                if l >= 1 and mov[l] == 0.0 and trig[l] != _QUEUED:
                    trig[l] = _QUEUED
                    queue[nq] = l
                    nq += 1
                if r <= N and mov[r] == 0.0 and trig[r] != _QUEUED:
                    trig[r] = _QUEUED
                    queue[nq] = r
                    nq += 1
        # The other stopped blocks of this step have settled neighbours: their start step.
        for k in range(ns):
            nq, t = _retrig(stopped[k], n + 1, n_end, x, th, mov, trig, queue, nq, mp, V, dt, threshold)
            t_next = min(t_next, t)
        for k in range(nn):
            movers[k] = nxt[k]
        moved_before = nmov
        nmov = nn
        ist[c.N_MOVING] = ist[c.N_MOVING] + nn - moved_before
        ist[c.BLOCK_UPDATES] += nc
        ist[c.FULL_UPDATES] += nfull
        ist[c.STEPS_COMPUTED] += 1
        ist[c.STEP] = n + 1
        if ist[c.EV_ACTIVE] == 1 and nmov == 0:
            c._end_event(n, x, first_step, x0ev, ist, ev_int, ev_S, fm, prof_x, prof_meta, N,
                         profile_every, profile_min_blocks)
