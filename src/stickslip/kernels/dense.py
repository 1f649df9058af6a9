"""The reference integrator of the chain (eq. 4 and its relatives, docs/model.md): Heun over every
block at every step, written plainly. The fast paths (:mod:`stickslip.kernels.exact`,
:mod:`stickslip.kernels.plate`) give its answer bit for bit.
"""

from __future__ import annotations

from numba import njit

from stickslip.kernels.events import _end_event, _overflow, _service, _start_and_first_moves, _trace
from stickslip.kernels.laws import (
    NO_CARRY,
    _accel,
    _dtheta_in,
    _force,
    _set_ghosts,
    _threshold,
    drive_view,
    load_rate,
    pull_carried,
    set_velocity_ghosts,
)
from stickslip.kernels.layout import (
    _BIG,
    BAD_BLOCK,
    BLOCK_UPDATES,
    DONE,
    EV_ACTIVE,
    EV_COUNT,
    FM_COUNT,
    N_MOVING,
    NEXT_PROFILE,
    NEXT_SAMPLE,
    NONFINITE,
    P_COUNT,
    STEP,
    STEPS_COMPUTED,
    _unpack,
)


@njit(cache=True)
def run_dense(args, drive, friction, threshold, ends):
    """Reference integrator of the chain (eq. 4 and its relatives): Heun over every block at
    every step, written plainly.

    ``args`` is a :class:`~stickslip.kernels.layout.ChainArgs` (arrays and integers); the pieces
    are codes (:mod:`stickslip.kernels.layout`), compile-time constants. Advances the state
    arrays to step ``n_end`` or until an output buffer is full; returns a status code. The step is in
    :mod:`stickslip.kernels.laws`, the events in :mod:`stickslip.kernels.events`. ``trig`` is
    scratch of :func:`stickslip.kernels.exact.run_exact`, unused here. Where ``args.trace`` is a
    :class:`~stickslip.kernels.layout.Trace` (the single block, eq. 1, as the chain's N = 1) it
    records the state every few steps and the range of v over every step; None compiles to
    nothing.
    """
    x, v, th, mov, xs = args.x, args.v, args.th, args.mov, args.xs
    vs, ths, mm, a1, b1 = args.vs, args.ths, args.mm, args.a1, args.b1
    ist, par, ev_int, fm, prof_x = args.ist, args.par, args.ev_int, args.fm, args.prof_x
    first_step, x0ev, prof_meta = args.first_step, args.x0ev, args.prof_meta
    n_end, profile_every = args.n_end, args.profile_every
    N = x.shape[0] - 2
    mp, V, dt = _unpack(par, drive_view(args.dp, drive), args.tp, args.law, args.kb, args.mass)
    K, dp, tp = mp[0], mp[1], mp[2]
    h2 = 0.5 * dt
    cap_ev, cap_fm, cap_p = ev_int.shape[0], fm.shape[0], prof_x.shape[0]
    carry = NO_CARRY  # a load history's last step read (laws.pull_carried)
    while True:
        n = ist[STEP]
        # Outputs due, the end, buffers that could overflow. Written out here rather than in a
        # helper: as a function this costs several times a short step (measured).
        if n == ist[NEXT_SAMPLE] or (profile_every > 0 and ist[EV_ACTIVE] == 1 and n == ist[NEXT_PROFILE]):
            st = _service(n, args)
            if st != DONE:
                return st
        if n >= n_end:
            return DONE
        if ist[EV_COUNT] >= cap_ev or ist[FM_COUNT] + N > cap_fm or (profile_every > 0 and ist[P_COUNT] + 2 > cap_p):
            return _overflow(ist, N, cap_ev, cap_fm)
        p1, carry = pull_carried(V, n, dt, dp, drive, carry)
        q1 = load_rate(V, n, dt, dp, drive, carry, friction)  # 0.0 unless the law reads the stress rate
        _set_ghosts(x, th, N, p1, drive, ends)
        set_velocity_ghosts(v, N, q1, drive, ends, friction)
        for i in range(1, N + 1):
            f = _force(x[i - 1], x[i], x[i + 1], K, dp, p1, drive, i)
            if mov[i] != 0.0 or f > _threshold(th[i], tp, threshold, i):
                mm[i] = 1.0
            else:
                mm[i] = 0.0
            a1[i] = _accel(f, th[i], v[i], mm[i], mp, friction, i)
            b1[i] = _dtheta_in(th[i - 1], th[i], th[i + 1], v[i], v, q1, mp, drive, friction, i)
            xs[i] = x[i] + dt * v[i]
            vs[i] = v[i] + dt * a1[i]
            ths[i] = th[i] + dt * b1[i]
        p2, carry = pull_carried(V, n + 1, dt, dp, drive, carry)
        q2 = load_rate(V, n + 1, dt, dp, drive, carry, friction)
        _set_ghosts(xs, ths, N, p2, drive, ends)
        set_velocity_ghosts(vs, N, q2, drive, ends, friction)
        _start_and_first_moves(n, 1, N, x, mm, first_step, x0ev, ist, prof_x, prof_meta, N, profile_every)
        n_moving = 0
        bad = 0
        for i in range(1, N + 1):
            f2 = _force(xs[i - 1], xs[i], xs[i + 1], K, dp, p2, drive, i)
            a2 = _accel(f2, ths[i], vs[i], mm[i], mp, friction, i)
            b2 = _dtheta_in(ths[i - 1], ths[i], ths[i + 1], vs[i], vs, q2, mp, drive, friction, i)
            th[i] = th[i] + h2 * (b1[i] + b2)
            if mm[i] != 0.0:
                x[i] = x[i] + h2 * (v[i] + vs[i])
                vn = v[i] + h2 * (a1[i] + a2)
                if vn <= 0.0:
                    v[i] = 0.0
                    mov[i] = 0.0
                else:
                    v[i] = vn
                    mov[i] = 1.0
                    n_moving += 1
            else:
                v[i] = 0.0
                mov[i] = 0.0
            if bad == 0 and not (abs(x[i]) <= _BIG and abs(v[i]) <= _BIG and abs(th[i]) <= _BIG):
                bad = i
        ist[N_MOVING] = n_moving
        ist[BLOCK_UPDATES] += N
        ist[STEPS_COMPUTED] += 1
        ist[STEP] = n + 1
        _trace(args.trace, n + 1, x, v, th, mov, N)
        if bad > 0:
            ist[BAD_BLOCK] = bad
            return NONFINITE
        if ist[EV_ACTIVE] == 1 and n_moving == 0:
            _end_event(n, args)
