"""The fast integrator of the chain (eq. 4 and its relatives, docs/model.md), bit for bit equal to
the reference :func:`stickslip.kernels.dense.run_dense`.

It skips only work whose result is known: one step of block i reads blocks i-2..i+2 (stage 2
reads the neighbours' predictors, which read theirs), so a block none of whose neighbours out
to two places changed in the last step cannot change now, except through the start rule. The
blocks to update form the changed set dilated by two (kept as one bounding interval, which is
conservative; on a periodic chain an interval that would wrap becomes the whole chain). These
are the rules of :mod:`stickslip.kernels.active`, which names the intervals below and holds the
interval's bookkeeping (the widening, the pauses, the plate's due starts) for this kernel and
:func:`_slide_steps`.

Which stopped blocks can start:

* end drive: the candidates are the last step's movers +- 1 plus block 1. When nothing is
  active, the kernel jumps to the step at which block 1 starts
  (:func:`stickslip.kernels.triggers._first_trigger`).
* plate drive: every stopped block keeps its first start step under the plate (``trig``,
  :mod:`stickslip.kernels.triggers`); a block that starts because of the plate alone is found
  by comparing the step with these numbers, and when nothing is active the kernel jumps to the
  smallest of them. Without a state variable a stopped block never changes, and the driver
  runs the sparse path instead, which updates lists of blocks instead of an interval
  (:mod:`stickslip.kernels.plate`), so that this kernel does not compile it.
* state threshold: a block whose theta changes may start without any neighbour moving, so
  every block whose state variable may change is a candidate.

A run of blocks that all move at t_n (the longest such run, kept across steps while none of
it stops) is updated by the stages of :mod:`stickslip.kernels.stages` that skip the start rule
and the bookkeeping of changes, as when the whole chain slides: in a partly stuck chain most of
a step's work is one such run. Its blocks are counted as changed, which can only widen the
interval of the next step; a wider interval gives the same bits. The steps of one run form an
inner loop in which the run's bounds are fixed, so that the run stages' overlap checks are made
once per run. The driver hands over arrays whose block 1 starts a 64-byte line
(:func:`stickslip.run.state.line_aligned`; docs/performance.md, "The run's bounds per run, and
aligned arrays").

Steps that repeat with nothing changing but the sliding (a run from block 1 with stopped blocks
past it, or the whole chain sliding) are taken in a tight loop in a function of their own,
:func:`_slide_steps`, whose loops compile to fewer instructions than inside run_exact; it returns
at the first step that needs the general step (docs/performance.md, "The sliding steps in a
function of their own").

Three more savings keep every bit (docs/performance.md, "Fewer scalar blocks in the partly stuck
step"): stage 1 of the run covers whole groups of 8 blocks, the up to seven blocks past it
getting a moving block's values that the general stages then overwrite; the one block past the
run that the start rule leaves stopped gets the stopped blocks' stage 1; and a stopped block of
the interval gets its stage-1 predictors of x and v and its mask only next to the blocks that may
move (stage 2 reads them from the neighbours of its movers alone), the others their state
variable's derivative and predictor only.
"""

from __future__ import annotations

from numba import njit

from stickslip.kernels import lanes
from stickslip.kernels.active import (
    CHANGE_REACH,
    MOVE_REACH,
    dilate,
    due_plate_starts,
    due_step,
    may_overflow,
    outputs_due,
)
from stickslip.kernels.events import _end_event, _overflow, _service, _start_and_first_moves
from stickslip.kernels.laws import (
    NO_CARRY,
    _force,
    _right_of_first,
    _set_ghosts,
    _threshold,
    drive_view,
    has,
    load_rate,
    pull_carried,
    pull_peek,
    set_velocity_ghosts,
)
from stickslip.kernels.layout import (
    _NEVER,
    ACT_HI,
    ACT_LO,
    BLOCK_UPDATES,
    DONE,
    EV_ACTIVE,
    EV_COUNT,
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
    _merge,
    _unpack,
)
from stickslip.kernels.stages import (
    _longest_run,
    _run_padded,
    _stage1,
    _stage1_run,
    _stage1_theta,
    _stage1_theta_only,
    _stage2,
    _stage2_run,
    _stage2_theta,
    _stop_run,
)
from stickslip.kernels.triggers import leaf_triggers, pull_trigger


@njit(cache=True, _nrt=False)
def _slide_steps(args, ra0, rb0, hi, mp, V, dt, drive, friction, threshold, ends):
    """Steps of :func:`run_exact` in which the run ra0 = 1..rb0 slides and blocks rb0+1..hi stay
    stopped, or (rb0 = hi = N) every block slides: the steps that run_exact would take, in a tight
    loop, until block rb0+1 starts, a block of the run stops, the interval changes, or an output,
    the end or a full buffer is due (then run_exact goes on from that step).

    The stages' loops compile to fewer instructions in this small function than inside run_exact
    (docs/performance.md, "The sliding steps in a function of their own"). Returns the run of the
    next step, (ra0, rb0) unless a block of the run stopped, and with a plate the first start
    step of the blocks that stopped (``_NEVER`` if none).
    """
    x, v, th, mov, xs = args.x, args.v, args.th, args.mov, args.xs
    vs, ths, mm, a1, b1, ist = args.vs, args.ths, args.mm, args.a1, args.b1, args.ist
    n_end, profile_every = args.n_end, args.profile_every
    cap_ev, cap_fm, cap_p = args.ev_int.shape[0], args.fm.shape[0], args.prof_x.shape[0]
    N = x.shape[0] - 2
    K, dp, tp = mp[0], mp[1], mp[2]
    h2 = 0.5 * dt
    every = rb0 == N  # the whole chain slides: no stopped blocks, no start rule
    fh = rb0 + 1
    h1 = hi + 1
    rp = _run_padded(ra0, rb0, N)
    carry = NO_CARRY  # a load history's last step read (laws.pull_carried)
    while True:
        n = ist[STEP]
        if (
            outputs_due(n, ist[NEXT_SAMPLE], ist[NEXT_PROFILE], profile_every, ist[EV_ACTIVE] == 1)
            or n >= n_end
            or may_overflow(ist[EV_COUNT], ist[FM_COUNT], ist[P_COUNT], N, cap_ev, cap_fm, cap_p, profile_every)
        ):
            return ra0, rb0, _NEVER
        p1, carry = pull_carried(V, n, dt, dp, drive, carry)
        q1 = load_rate(V, n, dt, dp, drive, carry, friction)  # 0.0 unless the law reads the stress rate
        _set_ghosts(x, th, N, p1, drive, ends)
        set_velocity_ghosts(v, N, q1, drive, ends, friction)
        if not every and _force(x[fh - 1], x[fh], x[fh + 1], K, dp, p1, drive, fh) > _threshold(
            th[fh], tp, threshold, fh
        ):
            return ra0, rb0, _NEVER  # block rb0+1 starts: run_exact's general step
        _stage1_run(x, v, th, xs, vs, ths, a1, b1, ra0, rp, p1, q1, mp, dt, drive, friction)
        if not every:
            _stage1_theta(x, v, th, xs, vs, ths, mm, b1, fh, h1, q1, mp, dt, drive, friction)
        p2, carry = pull_carried(V, n + 1, dt, dp, drive, carry)
        q2 = load_rate(V, n + 1, dt, dp, drive, carry, friction)
        _set_ghosts(xs, ths, N, p2, drive, ends)
        set_velocity_ghosts(vs, N, q2, drive, ends, friction)
        c_hi = rb0
        if has(friction, "has_state") and not every:
            _, t_hi = _stage2_theta(th, ths, v, vs, b1, fh, hi, q2, mp, h2, drive, friction)
            c_hi = t_hi if t_hi > rb0 else rb0
        stops = _stage2_run(x, v, th, xs, vs, ths, a1, b1, ra0, rb0, p2, q2, mp, h2, drive, friction)
        ist[FULL_UPDATES] += rb0
        ist[BLOCK_UPDATES] += hi
        ist[STEPS_COMPUTED] += 1
        ist[STEP] = n + 1
        # The next step's candidates, as run_exact's: the changes dilated by two (block 1 is the
        # lowest), and the movers and their neighbours.
        _, c_hi = dilate(1, c_hi, CHANGE_REACH, N, False)
        a_hi = c_hi if c_hi > fh or every else fh
        ist[ACT_LO], ist[ACT_HI] = 1, a_hi
        ist[MECH_LO], ist[MECH_HI] = 1, N if every else fh
        if stops:
            n_moving = ist[N_MOVING] - (rb0 - ra0 + 1) + _stop_run(v, mov, ra0, rb0)
            ist[N_MOVING] = n_moving
            ra, rb = _longest_run(mov, ra0, rb0)
            t = _NEVER
            if has(drive, "leaf_spring"):
                # The blocks that stopped need their first start step under the plate (only the
                # whole chain sliding comes here with a plate).
                _set_ghosts(x, th, N, 0.0, drive, ends)
                t = leaf_triggers(x, th, mov, mm, args.trig, 1, N, True, n + 1, n_end, mp, V, dt, drive, threshold)
            if ist[EV_ACTIVE] == 1 and n_moving == 0:
                _end_event(n, args)
            return ra, rb, t
        if a_hi != hi:
            # Stopped blocks whose theta changes, and two past them: a wider interval.
            if a_hi >= N:
                return ra0, rb0, _NEVER
            hi = a_hi
            h1 = hi + 1


@njit(cache=True)
def run_exact(args, drive, friction, threshold, ends):
    """Fast integrator of the chain, bit for bit equal to :func:`~stickslip.kernels.dense.run_dense`.

    Updates only the blocks that can change (see the module docstring), in branch-free
    loops over one contiguous interval, and jumps over steps in which nothing can change.
    Same arguments (a :class:`~stickslip.kernels.layout.ChainArgs` and the pieces' codes), state
    layout and status codes as ``run_dense``, except that it does not
    look for non-finite values: the driver checks the state after each call and replays the
    call with ``run_dense``, which does, to name the step and the block. ``trig``
    (int64, N + 2) is scratch: the plate drive's first start step of each stopped block,
    rebuilt on entry.
    """
    x, v, th, mov, xs = args.x, args.v, args.th, args.mov, args.xs
    vs, ths, mm, a1, b1 = args.vs, args.ths, args.mm, args.a1, args.b1
    trig, ist, par, ev_int, fm = args.trig, args.ist, args.par, args.ev_int, args.fm
    prof_x, n_end, profile_every = args.prof_x, args.n_end, args.profile_every
    first_step, x0ev, prof_meta = args.first_step, args.x0ev, args.prof_meta
    N = x.shape[0] - 2
    mp, V, dt = _unpack(par, drive_view(args.dp, drive), args.tp, args.law, args.kb, args.mass)
    K, dp, tp = mp[0], mp[1], mp[2]
    h2 = 0.5 * dt
    cap_ev, cap_fm, cap_p = ev_int.shape[0], fm.shape[0], prof_x.shape[0]
    # A run of blocks moving at t_n (empty if ra > rb): updated without the start rule and the
    # bookkeeping of changes (stages._stage1_run, _stage2_run).
    ra, rb = _longest_run(mov, 1, N)
    t_next = _NEVER  # plate drive: no stopped block starts before this step unless listed in trig
    if has(drive, "leaf_spring"):
        _set_ghosts(x, th, N, 0.0, drive, ends)
        t_next = leaf_triggers(x, th, mov, mm, trig, 1, N, True, ist[STEP], n_end, mp, V, dt, drive, threshold)
    carry = NO_CARRY  # a load history's last step read (laws.pull_carried)
    while True:
        # The run's bounds, fixed over the inner loop of steps: the compiler then checks the
        # run stages' arrays for overlap once per run rather than once per step (measured).
        ra0 = ra
        rb0 = rb
        # The mid-step mask on the run is 1 in every step of it: written once, in the first step
        # with the run within the updated blocks, and again after a step without (whose general
        # stages may have written it).
        mm_run = False
        while True:
            if ra != ra0 or rb != rb0:
                break
            n = ist[STEP]
            # Outputs due, the end, buffers that could overflow. The helpers take numbers, not
            # arrays: a helper taking ``args`` or an array, even inlined, counts references to
            # them at every step, which costs several times a short step (measured).
            if outputs_due(n, ist[NEXT_SAMPLE], ist[NEXT_PROFILE], profile_every, ist[EV_ACTIVE] == 1):
                st = _service(n, args)
                if st != DONE:
                    return st
            if n >= n_end:
                return DONE
            if may_overflow(ist[EV_COUNT], ist[FM_COUNT], ist[P_COUNT], N, cap_ev, cap_fm, cap_p, profile_every):
                return _overflow(ist, N, cap_ev, cap_fm)
            lo = ist[ACT_LO]
            hi = ist[ACT_HI]
            # Blocks that may move in this step: those that could last step, plus those the drive
            # brings to their threshold.
            ml = ist[MECH_LO]
            mh = ist[MECH_HI]
            if not has(drive, "leaf_spring"):
                x2 = _right_of_first(x, N, ends)
                # Block 1's load point is read only while it is stopped (the `or` short-circuits).
                if mov[1] != 0.0 or _force(
                    pull_peek(V, n, dt, dp, drive, carry), x[1], x2, K, dp, 0.0, drive, 1
                ) > _threshold(th[1], tp, threshold, 1):
                    lo = 1
                    if hi < 1:
                        hi = 1
                    ml = 1
                    if mh < 1:
                        mh = 1
            elif n >= t_next:
                ml, mh, t_next = due_plate_starts(mov, trig, n, ml, mh)
                lo, hi = _merge(lo, hi, ml, mh)
            if has(friction, "context"):
                # The law reads the drive's velocity, which a load history changes at its
                # breakpoints: block 1's state variable is updated at every step.
                lo = 1
                if hi < 1:
                    hi = 1
            if has(threshold, "has_state"):
                # A changing state variable moves the threshold itself.
                ml, mh = _merge(ml, mh, lo, hi)
            if has(ends, "ring") and lo <= hi and (lo == 1 or hi == N):
                # Blocks 1 and N read each other's predictors: update the whole ring.
                lo = 1
                hi = N
            if lo > hi:
                # Nothing can change before the drive starts a block: jump, but stop at due outputs.
                target = due_step(n_end, ist[NEXT_SAMPLE], ist[NEXT_PROFILE], profile_every, ist[EV_ACTIVE] == 1)
                if not has(drive, "leaf_spring"):
                    ist[STEP] = pull_trigger(
                        x, N, V, dt, K, _threshold(th[1], tp, threshold, 1), n + 1, target, dp, drive, ends
                    )
                else:
                    ist[STEP] = t_next if t_next < target else target
                continue

            # A chain shorter than a group of lanes takes the general stages: the run stages would
            # make it one masked group per stage, which the next stage reads again at once, and a
            # masked store is not forwarded to a load (measured for N = 1: 1.65 s against 1.35 s;
            # docs/performance.md, "Eight blocks at once").
            if ist[N_MOVING] == N and lo == 1 and hi == N and N >= lanes.WIDTH:
                # Every block slides: no start, no first move, nothing to track but stops; steps
                # in the tight loop of _slide_steps until a block stops or an output is due.
                ra, rb, t = _slide_steps(args, lo, hi, hi, mp, V, dt, drive, friction, threshold, ends)
                if t < t_next:
                    t_next = t
                continue

            p1, carry = pull_carried(V, n, dt, dp, drive, carry)
            q1 = load_rate(V, n, dt, dp, drive, carry, friction)  # 0.0 unless the law reads the stress rate
            _set_ghosts(x, th, N, p1, drive, ends)
            set_velocity_ghosts(v, N, q1, drive, ends, friction)
            l1 = lo - 1 if lo > 1 else 1
            h1 = hi + 1 if hi < N else N
            # Stage 1: full over [ml, mh] within [l1, h1], state variable alone elsewhere.
            fl = ml if ml > l1 else l1
            fh = mh if mh < h1 else h1
            first = h1 + 1
            last = l1 - 1
            starts = False
            # The run, when it lies within [fl, fh] and [lo, hi] (as it should: its blocks moved in
            # the last step): no start rule there; the general stages on either side of it.
            run_in = N >= lanes.WIDTH and ra0 <= rb0 and fl <= ra0 and rb0 <= fh and lo <= ra0 and rb0 <= hi
            if not run_in:
                mm_run = False
            if fl <= fh:
                if run_in:
                    first = ra0
                    last = rb0
                    if fl < ra0:
                        f_, l_, starts = _stage1(
                            x, v, th, mov, xs, vs, ths, mm, a1, b1, fl, ra0 - 1, p1, q1, mp, dt, drive, friction,
                            threshold,
                        )  # fmt: skip
                        if f_ <= l_:
                            first = f_
                    # Over whole groups of 8 blocks, with no masked or scalar rest: the up to 7
                    # blocks past the run get a moving block's values, which the stages below
                    # overwrite wherever stage 2 and the bookkeeping read them (measured: 2%).
                    rp = _run_padded(ra0, rb0, N)
                    _stage1_run(x, v, th, xs, vs, ths, a1, b1, ra0, rp, p1, q1, mp, dt, drive, friction)
                    if not mm_run:
                        for i in range(ra0, rb0 + 1):
                            mm[i] = 1.0
                        mm_run = True
                    if (
                        fh == rb0 + 1
                        and mov[fh] == 0.0
                        and not _force(x[fh - 1], x[fh], x[fh + 1], K, dp, p1, drive, fh)
                        > _threshold(th[fh], tp, threshold, fh)
                    ):
                        # The one block past the run stays stopped (the start rule of _stage1): it
                        # gets the stopped blocks' stage 1 below, equal to _stage1's but for a1 and
                        # vs, which are read only for a block that moves.
                        fh = rb0
                    elif rb0 < fh:
                        f_, l_, s_ = _stage1(
                            x, v, th, mov, xs, vs, ths, mm, a1, b1, rb0 + 1, fh, p1, q1, mp, dt, drive, friction,
                            threshold,
                        )  # fmt: skip
                        starts |= s_
                        if f_ <= l_:
                            last = l_
                else:
                    first, last, starts = _stage1(
                        x, v, th, mov, xs, vs, ths, mm, a1, b1, fl, fh, p1, q1, mp, dt, drive, friction, threshold
                    )
                # Blocks that stay stopped: stage 2 reads the predictors and the mask only next to
                # [fl, fh] (the neighbours of its movers), so farther blocks need their theta alone
                # (on a ring, blocks 1 and N are neighbours: all of them).
                if has(friction, "lanes") or has(friction, "context"):
                    # As lanes one pass is cheaper than two, and the full stopped stage 1 is exact
                    # for every one of these blocks (see stages._stage1_theta_loop). A law that
                    # reads the stress rate reads every neighbour's predicted velocity in stage 2.
                    if l1 < fl:
                        _stage1_theta(x, v, th, xs, vs, ths, mm, b1, l1, fl - 1, q1, mp, dt, drive, friction)
                    if fh < h1:
                        _stage1_theta(x, v, th, xs, vs, ths, mm, b1, fh + 1, h1, q1, mp, dt, drive, friction)
                else:
                    if l1 < fl:
                        a_ = l1 if has(ends, "ring") else fl - 1
                        if l1 < a_:
                            _stage1_theta_only(v, th, ths, b1, l1, a_ - 1, q1, mp, dt, drive, friction)
                        _stage1_theta(x, v, th, xs, vs, ths, mm, b1, a_, fl - 1, q1, mp, dt, drive, friction)
                    if fh < h1:
                        b_ = h1 if has(ends, "ring") else fh + 1
                        _stage1_theta(x, v, th, xs, vs, ths, mm, b1, fh + 1, b_, q1, mp, dt, drive, friction)
                        if b_ < h1:
                            _stage1_theta_only(v, th, ths, b1, b_ + 1, h1, q1, mp, dt, drive, friction)
            elif has(friction, "context"):
                _stage1_theta(x, v, th, xs, vs, ths, mm, b1, l1, h1, q1, mp, dt, drive, friction)
            elif has(friction, "has_state"):
                _stage1_theta_only(v, th, ths, b1, l1, h1, q1, mp, dt, drive, friction)
            p2, carry = pull_carried(V, n + 1, dt, dp, drive, carry)
            q2 = load_rate(V, n + 1, dt, dp, drive, carry, friction)
            _set_ghosts(xs, ths, N, p2, drive, ends)
            set_velocity_ghosts(vs, N, q2, drive, ends, friction)
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
            stops_run = False
            whole = False  # the whole run went through _stage2_run
            if sl <= sh:
                if has(friction, "has_state"):
                    # The state variable of the stopped blocks on either side first: it reads
                    # nothing the full stages write, and its short chain of dependent operations
                    # then overlaps their loops instead of holding up the bookkeeping (measured).
                    if lo < sl:
                        c_lo, c_hi = _stage2_theta(th, ths, v, vs, b1, lo, sl - 1, q2, mp, h2, drive, friction)
                    if sh < hi:
                        t_lo, t_hi = _stage2_theta(th, ths, v, vs, b1, sh + 1, hi, q2, mp, h2, drive, friction)
                        c_lo, c_hi = _merge(c_lo, c_hi, t_lo, t_hi)
                whole = run_in
                if run_in:
                    if sl < ra0:
                        t_lo, t_hi, moved_before, moved_after = _stage2(
                            x, v, th, mov, xs, vs, ths, mm, a1, b1, sl, ra0 - 1, p2, q2, mp, h2, drive, friction
                        )
                        c_lo, c_hi = _merge(c_lo, c_hi, t_lo, t_hi)
                    stops_run = _stage2_run(x, v, th, xs, vs, ths, a1, b1, ra0, rb0, p2, q2, mp, h2, drive, friction)
                    # Every block of the run moved: count it as changed.
                    c_lo, c_hi = _merge(c_lo, c_hi, ra0, rb0)
                    moved_before += rb0 - ra0 + 1
                    if stops_run:
                        moved_after += _stop_run(v, mov, ra0, rb0)
                    else:
                        moved_after += rb0 - ra0 + 1
                    if rb0 < sh:
                        t_lo, t_hi, mb, ma = _stage2(
                            x, v, th, mov, xs, vs, ths, mm, a1, b1, rb0 + 1, sh, p2, q2, mp, h2, drive, friction
                        )
                        c_lo, c_hi = _merge(c_lo, c_hi, t_lo, t_hi)
                        moved_before += mb
                        moved_after += ma
                else:
                    t_lo, t_hi, moved_before, moved_after = _stage2(
                        x, v, th, mov, xs, vs, ths, mm, a1, b1, sl, sh, p2, q2, mp, h2, drive, friction
                    )
                    c_lo, c_hi = _merge(c_lo, c_hi, t_lo, t_hi)
                ist[FULL_UPDATES] += sh - sl + 1
            elif has(friction, "has_state"):
                c_lo, c_hi = _stage2_theta(th, ths, v, vs, b1, lo, hi, q2, mp, h2, drive, friction)
            # Next step's movers: a stopped block starts only if its force or threshold changed;
            # through the springs that takes a neighbour's move, and only moving blocks change x.
            # So: this step's movers +- 1 (and, as above, the drive's starts and changing thetas).
            if first <= last:
                ist[MECH_LO], ist[MECH_HI] = dilate(first, last, MOVE_REACH, N, has(ends, "ring"))
            else:
                ist[MECH_LO] = 1
                ist[MECH_HI] = 0
            n_moving = ist[N_MOVING] + moved_after - moved_before
            ist[N_MOVING] = n_moving
            # The run of the next step: while none of it stops, it grows by the blocks that joined
            # it at either end; otherwise the longest run among this step's movers.
            if stops_run or not whole or ra > rb:
                if first <= last:
                    ra, rb = _longest_run(mov, first, last)
                else:
                    ra, rb = 1, 0
            else:
                while ra > 1 and mov[ra - 1] != 0.0:
                    ra -= 1
                while rb < N and mov[rb + 1] != 0.0:
                    rb += 1
            ist[BLOCK_UPDATES] += hi - lo + 1
            ist[STEPS_COMPUTED] += 1
            ist[STEP] = n + 1
            # Next step's candidates: changes dilated by two, and every block that may move (a
            # start rule that fires is an event's move even when it changes no bit).
            if c_lo <= c_hi:
                c_lo, c_hi = dilate(c_lo, c_hi, CHANGE_REACH, N, has(ends, "ring"))
            ist[ACT_LO], ist[ACT_HI] = _merge(c_lo, c_hi, ist[MECH_LO], ist[MECH_HI])
            if has(drive, "leaf_spring"):
                # Stopped blocks whose force or threshold changed: their first start step anew.
                if has(threshold, "has_state"):
                    w_lo, w_hi = _merge(ist[MECH_LO], ist[MECH_HI], lo, hi)
                    every = True
                else:
                    w_lo, w_hi = ist[MECH_LO], ist[MECH_HI]
                    every = False
                if w_lo <= w_hi:
                    _set_ghosts(x, th, N, 0.0, drive, ends)
                    t = leaf_triggers(
                        x, th, mov, mm, trig, w_lo, w_hi, every, n + 1, n_end, mp, V, dt, drive, threshold
                    )
                    if t < t_next:
                        t_next = t
            if ist[EV_ACTIVE] == 1 and n_moving == 0:
                _end_event(n, args)
            if (
                not has(drive, "leaf_spring")
                and not has(ends, "ring")
                and not has(threshold, "has_state")
                and whole
                and ra0 == 1
                and first == 1
                and last == rb0
                and rb0 < hi
                and hi < N
                and not (starts or stops_run)
                and ra == ra0
                and rb == rb0
                and ist[ACT_LO] == 1
                and ist[ACT_HI] == hi
                and ist[MECH_LO] == 1
                and ist[MECH_HI] == rb0 + 1
            ):
                # The same step again and again while nothing changes but the run's sliding (a
                # chain loading towards steady sliding): the tight loop of _slide_steps.
                ra, rb, _ = _slide_steps(args, ra0, rb0, hi, mp, V, dt, drive, friction, threshold, ends)
