"""Heun with located switches: the reference integrator of the family's equations with switches.

The engine (:mod:`stickslip.kernels.chain`, :mod:`stickslip.kernels.plate`) tests starts at the
beginning of a step and stops at its end (docs/model.md): a map on the time grid whose switches
are late by up to dt, so its trajectories approach the solution of the equations with switches
at first order only. Here a block starts at the time its force reaches the threshold and stops at
the time its velocity reaches zero, inside the step:

1. from the state at t (offset s inside the grid step n, t = n dt + s) a trial Heun step of the
   rest of the step, h = dt - s, is taken with the current modes (moving or stuck);
2. if a stuck block's g = f_i - threshold_i turns positive, or a moving block's v_i turns <= 0,
   its switch time is the root in (0, h] of g (or v) along the step's own continuous extension,
   tau -> Heun step of length tau from t (second-order accurate in tau, like the step). The root
   is bracketed and narrowed by the Illinois rule with bisection safeguards until no float lies
   between the ends: round-off;
3. the chain is advanced by a Heun step of the earliest root, the block switches there (a stop
   sets v_i = 0), and the rest of the step is taken from there (step 1 again).

Every stretch between switches is smooth, so the trajectories converge to the solution of the
equations with switches at Heun's order, two (tests/test_located.py). Grid points stay at
t_n = n dt. Positions are held relative to the drive, u_i = x_i - V t: the frame in which the
equations are autonomous (except for fixed ends), and in which a stuck block's coordinate stays
of order one however long the run, so no precision is lost as V t grows.

Pieces as the other integrators take them (:mod:`stickslip.kernels.layout`): drive end (u_0 = 0),
history (u_0 = p(t) in the lab's frame, V = 0 in ``par``: :func:`stickslip.kernels.laws.load_point`)
or plate (f_i gains Kp (0 - u_i), the plate at u = 0); any friction law, through its module's
compiled functions (:mod:`stickslip.kernels.laws`: the force less the friction, the state
variable's rate, on stuck blocks too); threshold constant (Fs) or state (theta_i); ends free,
fixed (x = 0, so u = -V t) or periodic. The spring force, the threshold and the law are the
functions the engine evaluates; only the ghost cells are set here, in the frame of the drive.

:func:`advance` is the dense form: every block at every step. :mod:`stickslip.kernels.located_fast`
is its fast form, the same bits with the work whose result is known left out; it runs
:func:`_steps` for the steps in which a switch happens. In both, the trial steps of a switch's
location compute only what the switching block's test reads (:func:`_heun_near`).

The integer vector ``ist``: [step, events recorded, blocks moving, event active, starts, stops,
event's first block, blocks moved in the event]; the float vector ``evf``: [event start time,
sum of u at its start]. Events are recorded as in docs/model.md ("Slip events of the chain")
with located times: rows of ``ev_t`` are (start time, end time, size S) and of ``ev_i`` (first
block, blocks moved).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from stickslip.kernels.laws import _force as _spring_force
from stickslip.kernels.laws import _threshold, at, call, has, law_accel, law_rate, load_point
from stickslip.kernels.layout import P_DT, P_K, P_V

# Integer state vector.
I_STEP, I_EVENTS, I_MOVING, I_ACTIVE, I_STARTS, I_STOPS, I_FIRST, I_NMOVED = range(8)
IST_SIZE = 8
# Float state vector.
F_T_START, F_SUM_START = range(2)
EVF_SIZE = 2

DONE, EVENTS_FULL, NONFINITE, NO_PROGRESS = 0, 1, 2, 3
#: Switches one grid step may locate before :func:`_steps` gives up on it (NO_PROGRESS): each
#: block starts and stops at most a few times in a step; more means switches that repeat at one time.
SWITCHES_PER_BLOCK = 8


@njit(cache=True, inline="always")
def _ghosts(u, th, N, t, V, dp, drive, ends):
    """Ghost cells 0 and N + 1 of u = x - V t and theta (docs/model.md, the ends); the load point
    at u = 0, or at p(t) for a load history (V = 0: the lab's frame, :func:`laws.load_point`)."""
    u[0] = call(drive, "left", load_point(t, dp, drive), call(ends, "ghost", u[1], u[N], -V * t))
    u[N + 1] = call(ends, "ghost", u[N], u[1], -V * t)
    th[0] = call(ends, "ghost", th[1], th[N], th[1])
    th[N + 1] = call(ends, "ghost", th[N], th[1], th[N])


@njit(cache=True, inline="always")
def _force(u, i, par, dp, drive):
    """Spring force on block i (eq. 4), plus Kp (0 - u_i) from the plate (at u = 0 in this frame)
    with the plate drive: the engine's expression."""
    return _spring_force(u[i - 1], u[i], u[i + 1], par[P_K], dp, 0.0, drive, i)


@njit(cache=True, inline="always")
def _gap(u, th, i, par, tp, dp, drive, threshold):
    """g_i = f_i - threshold_i: a stuck block starts where it turns positive."""
    return _force(u, i, par, dp, drive) - _threshold(th[i], tp, threshold, i)


@njit(cache=True, inline="always")
def _rates(u, v, th, mov, N, t, par, lp, dp, drive, friction, ends, du, dv, dth):
    """Right-hand side at time t: du = v - V, dv = the law's f - friction while moving, dtheta of
    the law on every block."""
    V = par[P_V]
    _ghosts(u, th, N, t, V, dp, drive, ends)
    for i in range(1, N + 1):
        du[i] = v[i] - V
        if mov[i] != 0.0:
            dv[i] = law_accel(friction, _force(u, i, par, dp, drive), v[i], th[i], at(lp, i))
        else:
            dv[i] = 0.0
        dth[i] = law_rate(friction, th[i - 1], th[i], th[i + 1], v[i], at(lp, i))


@njit(cache=True, inline="always")
def _heun(h, t, u, v, th, mov, N, par, lp, dp, drive, friction, ends, sc):
    """One Heun step of length h from (u, v, theta) at t; sc holds the rates k1 at t (given), the
    predictor p*, the rates k2 and the result o*."""
    k1u, k1v, k1th, pu, pv, pth, k2u, k2v, k2th, ou, ov, oth = sc
    for i in range(1, N + 1):
        pu[i] = u[i] + h * k1u[i]
        pv[i] = v[i] + h * k1v[i]
        pth[i] = th[i] + h * k1th[i]
    _rates(pu, pv, pth, mov, N, t + h, par, lp, dp, drive, friction, ends, k2u, k2v, k2th)
    for i in range(1, N + 1):
        ou[i] = u[i] + 0.5 * h * (k1u[i] + k2u[i])
        ov[i] = v[i] + 0.5 * h * (k1v[i] + k2v[i])
        oth[i] = th[i] + 0.5 * h * (k1th[i] + k2th[i])
    _ghosts(ou, oth, N, t + h, par[P_V], dp, drive, ends)


@njit(cache=True, _nrt=False)
def _start(i, u, v, th, mov, t, par, ist, evf, moved, N):
    """Block i starts at time t (v_i stays 0); opens an event if every block was stuck."""
    mov[i] = 1.0
    v[i] = 0.0
    ist[I_STARTS] += 1
    if ist[I_MOVING] == 0:
        ist[I_ACTIVE] = 1
        ist[I_FIRST] = i
        ist[I_NMOVED] = 0
        evf[F_T_START] = t
        s = 0.0
        for k in range(1, N + 1):
            s += u[k]
            moved[k] = 0
        evf[F_SUM_START] = s
    ist[I_MOVING] += 1
    if moved[i] == 0:
        moved[i] = 1
        ist[I_NMOVED] += 1


@njit(cache=True, _nrt=False)
def _stop(i, u, v, mov, t, par, ist, evf, N, ev_t, ev_i):
    """Block i stops at time t (v_i = 0); closes the event if it was the last one moving."""
    mov[i] = 0.0
    v[i] = 0.0
    ist[I_STOPS] += 1
    ist[I_MOVING] -= 1
    if ist[I_MOVING] == 0 and ist[I_ACTIVE] == 1:
        ist[I_ACTIVE] = 0
        r = ist[I_EVENTS]
        if r < ev_t.shape[0]:
            s = 0.0
            for k in range(1, N + 1):
                s += u[k]
            # S = sum (x_end - x_start), x = u + V t
            ev_t[r, 0] = evf[F_T_START]
            ev_t[r, 1] = t
            ev_t[r, 2] = (s - evf[F_SUM_START]) + N * par[P_V] * (t - evf[F_T_START])
            ev_i[r, 0] = ist[I_FIRST]
            ev_i[r, 1] = ist[I_NMOVED]
            ist[I_EVENTS] = r + 1


@njit(cache=True, _nrt=False)
def _switched(i, stop, ou, ov, oth, par, tp, dp, drive, threshold):
    """(value, switched) of block i's switching function on the state o*: v (stop) or -g (start)."""
    if stop:
        return ov[i], ov[i] <= 0.0
    g = _gap(ou, oth, i, par, tp, dp, drive, threshold)
    return -g, g > 0.0


@njit(cache=True, inline="always")
def _predict_u(j, h, u, v, th, V, sc):
    """Block j's predictors and o* of u in a Heun step (the expressions of :func:`_heun`)."""
    k1u, k1v, k1th, pu, pv, pth, k2u, k2v, k2th, ou, ov, oth = sc
    pu[j] = u[j] + h * k1u[j]
    pv[j] = v[j] + h * k1v[j]
    pth[j] = th[j] + h * k1th[j]
    k2u[j] = pv[j] - V
    ou[j] = u[j] + 0.5 * h * (k1u[j] + k2u[j])


@njit(cache=True, _nrt=False)
def _heun_near(i, h, t, u, v, th, mov, N, par, lp, dp, drive, friction, ends, sc):
    """Of one Heun step (:func:`_heun`), the values block i's switching functions read: the
    predictors of blocks i-1..i+1, o* of u on them, o* of v and theta on block i, and the ghost
    cells (periodic ends: blocks 1 and N too, which the ghosts copy).

    Each value is computed by the expression :func:`_heun` evaluates for it, from the same
    inputs, so it has the same bits; the other blocks' values are left as they were.
    """
    k1u, k1v, k1th, pu, pv, pth, k2u, k2v, k2th, ou, ov, oth = sc
    V = par[P_V]
    a = i - 1 if i > 1 else 1
    b = i + 1 if i < N else N
    for j in range(a, b + 1):
        _predict_u(j, h, u, v, th, V, sc)
    if has(ends, "ring"):
        _predict_u(1, h, u, v, th, V, sc)
        _predict_u(N, h, u, v, th, V, sc)
    _ghosts(pu, pth, N, t + h, V, dp, drive, ends)
    if mov[i] != 0.0:
        k2v[i] = law_accel(friction, _force(pu, i, par, dp, drive), pv[i], pth[i], at(lp, i))
    else:
        k2v[i] = 0.0
    k2th[i] = law_rate(friction, pth[i - 1], pth[i], pth[i + 1], pv[i], at(lp, i))
    ov[i] = v[i] + 0.5 * h * (k1v[i] + k2v[i])
    oth[i] = th[i] + 0.5 * h * (k1th[i] + k2th[i])
    _ghosts(ou, oth, N, t + h, V, dp, drive, ends)


@njit(cache=True, _nrt=False)
def _locate(i, stop, h, t, u, v, th, mov, N, par, lp, tp, dp, drive, friction, threshold, ends, sc, near):
    """The switch time of block i in (0, h]: the smallest float b found with the switch done at b.

    Illinois (modified regula falsi) on the bracket [a, b], a bisection whenever a step fails to
    halve the bracket, until no float lies strictly between a and b. With ``near`` each trial
    step computes only what block i's switching function reads (:func:`_heun_near`: the same
    bits), otherwise the whole chain's step.
    """
    k1u, k1v, k1th, pu, pv, pth, k2u, k2v, k2th, ou, ov, oth = sc
    if stop:
        fa = v[i]
    else:
        _ghosts(u, th, N, t, par[P_V], dp, drive, ends)
        fa = -_gap(u, th, i, par, tp, dp, drive, threshold)
    a = 0.0
    b = h
    if near:
        _heun_near(i, h, t, u, v, th, mov, N, par, lp, dp, drive, friction, ends, sc)
    else:
        _heun(h, t, u, v, th, mov, N, par, lp, dp, drive, friction, ends, sc)
    fb, _ = _switched(i, stop, ou, ov, oth, par, tp, dp, drive, threshold)
    side = 0
    width = b - a
    for it in range(400):
        mid = a + 0.5 * (b - a)
        if not (a < mid < b):
            break
        c = mid
        if it % 2 == 0 or (b - a) < 0.5 * width:
            if fa != fb:
                c = b - fb * (b - a) / (fb - fa)
            if not (a < c < b):
                c = mid
        if it % 2 == 1:
            width = b - a
        if near:
            _heun_near(i, c, t, u, v, th, mov, N, par, lp, dp, drive, friction, ends, sc)
        else:
            _heun(c, t, u, v, th, mov, N, par, lp, dp, drive, friction, ends, sc)
        fc, sw = _switched(i, stop, ou, ov, oth, par, tp, dp, drive, threshold)
        if sw:
            b, fb = c, fc
            if side == -1:
                fa *= 0.5
            side = -1
        else:
            a, fa = c, fc
            if side == 1:
                fb *= 0.5
            side = 1
    return b


@njit(cache=True, _nrt=False)
def _steps(
    u, v, th, mov, n_end, par, lp, tp, dp, drive, friction, threshold, ends, sc, cand, moved, ist, evf, ev_t, ev_i, near
):
    """:func:`advance`; ``near``: :func:`_locate`'s trial steps on the neighbourhood alone."""
    N = u.shape[0] - 2
    dt = par[P_DT]
    k1u, k1v, k1th, pu, pv, pth, k2u, k2v, k2th, ou, ov, oth = sc
    n = ist[I_STEP]
    while n < n_end:
        if ist[I_EVENTS] > ev_t.shape[0] - 4:
            return EVENTS_FULL
        s = 0.0
        located = 0
        while True:
            t = n * dt + s
            # Switches due now: a stuck block above its threshold, a moving one below v = 0.
            _ghosts(u, th, N, t, par[P_V], dp, drive, ends)
            for i in range(1, N + 1):
                if mov[i] == 0.0:
                    if _gap(u, th, i, par, tp, dp, drive, threshold) > 0.0:
                        _start(i, u, v, th, mov, t, par, ist, evf, moved, N)
                elif v[i] < 0.0:
                    _stop(i, u, v, mov, t, par, ist, evf, N, ev_t, ev_i)
            h = dt - s
            _rates(u, v, th, mov, N, t, par, lp, dp, drive, friction, ends, k1u, k1v, k1th)
            _heun(h, t, u, v, th, mov, N, par, lp, dp, drive, friction, ends, sc)
            n_cand = 0
            for i in range(1, N + 1):
                if mov[i] == 0.0:
                    if _gap(ou, oth, i, par, tp, dp, drive, threshold) > 0.0:
                        cand[n_cand] = i
                        n_cand += 1
                elif v[i] > 0.0 and ov[i] <= 0.0:
                    cand[n_cand] = -i
                    n_cand += 1
            if n_cand == 0:
                for i in range(1, N + 1):
                    u[i] = ou[i]
                    th[i] = oth[i]
                    v[i] = ov[i]
                # A block that started with v = 0 and did not take off stops at the step's end.
                for i in range(1, N + 1):
                    if mov[i] != 0.0 and v[i] <= 0.0:
                        _stop(i, u, v, mov, t + h, par, ist, evf, N, ev_t, ev_i)
                break
            # Locate every candidate's switch; the earliest happens first.
            tau = h
            blk = 0
            stop = False
            for k in range(n_cand):
                i = abs(cand[k])
                is_stop = cand[k] < 0
                b = _locate(
                    i, is_stop, h, t, u, v, th, mov, N, par, lp, tp, dp, drive, friction, threshold, ends, sc, near
                )
                if blk == 0 or b < tau:
                    tau, blk, stop = b, i, is_stop
            _heun(tau, t, u, v, th, mov, N, par, lp, dp, drive, friction, ends, sc)
            for i in range(1, N + 1):
                u[i] = ou[i]
                th[i] = oth[i]
                v[i] = ov[i] if mov[i] != 0.0 else 0.0
            if stop:
                _stop(blk, u, v, mov, t + tau, par, ist, evf, N, ev_t, ev_i)
            else:
                _start(blk, u, v, th, mov, t + tau, par, ist, evf, moved, N)
            s_new = s + tau
            if tau >= h or s_new >= dt:
                break
            located += 1
            if located > SWITCHES_PER_BLOCK * N + 16:
                ist[I_STEP] = n
                return NO_PROGRESS
            s = s_new
        n += 1
        ist[I_STEP] = n
        for i in range(1, N + 1):
            if not (np.isfinite(u[i]) and np.isfinite(v[i]) and np.isfinite(th[i])):
                return NONFINITE
    return DONE


@njit(cache=True, _nrt=False)
def advance(
    u, v, th, mov, n_end, par, lp, tp, dp, drive, friction, threshold, ends, sc, cand, moved, ist, evf, ev_t, ev_i
):
    """Advance the state (u, v, theta, moving mask) at step ist[I_STEP] to step n_end.

    Returns DONE, EVENTS_FULL (the event buffer has fewer than 4 free rows; the state is at the
    grid step ist[I_STEP], continue after emptying it), NONFINITE or NO_PROGRESS (switches that
    repeat at one time in step ist[I_STEP], :data:`SWITCHES_PER_BLOCK`). See the module docstring.
    This is the dense form: every block at every step, and each trial step of a switch's
    location over the whole chain (the reference of :mod:`stickslip.kernels.located_fast`).
    """
    return _steps(
        u, v, th, mov, n_end, par, lp, tp, dp, drive, friction, threshold, ends,
        sc, cand, moved, ist, evf, ev_t, ev_i, False,
    )  # fmt: skip


@njit(cache=True, _nrt=False)
def rates(u, v, th, mov, t, par, lp, dp, drive, friction, ends, du, dv, dth):
    """The right-hand side of the equations at time t (ghost cells of u and th are overwritten)."""
    _rates(u, v, th, mov, u.shape[0] - 2, t, par, lp, dp, drive, friction, ends, du, dv, dth)
