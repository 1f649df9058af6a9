"""Compiled time stepping of the single block and spring, eq. (1).

One kernel, :func:`heun_block`, over plain floats and preallocated arrays: no I/O, no Python
objects. Its friction and state law are eq. (4)'s, the functions every integrator of the chain
calls (:mod:`stickslip.models.friction.state` through :mod:`stickslip.kernels.laws`; the kernel
is compiled for the law's module path, a literal): eq. (1)'s sigma theta + beta v is that law's
theta + beta v read at the state term sigma theta, and its theta' is the law's rate with no
neighbours (D = 0). The tests hold it to a plain-Python step of eq. (1) and to its ``py_func``.
"""

from __future__ import annotations

import numba

from stickslip.kernels.laws import call, law_accel, law_rate


@numba.njit(cache=True)
def heun_block(
    x,
    v,
    theta,
    stopped,
    n_steps,
    every,
    K,
    V,
    law,
    lp,
    threshold,
    tp,
    M,
    sigma,
    dt,
    out_t,
    out_x,
    out_v,
    out_theta,
    out_stopped,
    slip_start,
    slip_end,
    slip_x_start,
    slip_x_end,
):
    """Advance eq. (1) by ``n_steps`` Heun steps with the start and stop rules of docs/model.md.

    State (x, v, theta, stopped); spring force f = K (V t - x) with t_n = n dt taken from the
    integer step count. ``law`` is the friction law's module path and ``lp`` its parameters
    (beta, alpha and D = 0 of eq. (4)'s law).

    - moving:  x' = v,  M v' = f - sigma theta - beta v,  theta' = theta (1 - theta) - alpha theta v
    - stopped: x fixed, v = 0, theta' = theta (1 - theta)

    Step n (t_n -> t_{n+1}):

    1. start rule: a stopped block with f(t_n) > the threshold piece's value (``threshold``, its
       module path, and ``tp``, its parameters: Fs, or sigma theta for the state threshold, the
       paper's reading of Batista-Carlson) becomes moving, still with v = 0;
    2. Heun (explicit trapezoid) with the status fixed for the whole step: stage 1 derivatives
       k1 at (y_n, t_n), predictor y* = y_n + dt k1, stage 2 derivatives k2 at (y*, t_{n+1}),
       y_{n+1} = y_n + (dt/2) (k1 + k2);
    3. stop rule: a moving block whose new v <= 0 gets v = 0 and becomes stopped.

    Output: the state after step n is written to ``out_*[j]`` when n % every == 0 and after the
    last step (step 0 is the initial state); ``out_t`` gets t_n. The caller sizes the arrays as
    n_steps // every + 1, plus 1 when every does not divide n_steps.

    Slips: a slip starts at the step whose start rule fires (its start time t_c = n dt) and ends
    at the step whose stop rule fires (end time t_e = (n + 1) dt). For each slip that starts and
    ends inside the run, the step numbers of t_c and t_e and the positions x(t_c), x(t_e) are
    written to ``slip_*[k]`` while k is below their length; the count is returned in any case, so
    a caller whose arrays were too short can run again with longer ones.

    Returns (x, v, theta, stopped, n_slips, n_starts, n_stops, v_min, v_max): the final state,
    the number of complete slips, of starts and of stops (every moving -> stopped transition,
    including the end of a slip under way at step 0), and the least and greatest v over the
    states after steps 0..n_steps, whether stored or not.
    """
    half = 0.5 * dt
    capacity = slip_start.shape[0]
    moving = not stopped
    v_min = v
    v_max = v
    n_slips = 0
    n_starts = 0
    n_stops = 0
    current = -1  # step at which the slip under way started, -1 if none started in this run
    x_start = 0.0

    out_t[0] = 0.0
    out_x[0] = x
    out_v[0] = v
    out_theta[0] = theta
    out_stopped[0] = not moving
    j = 1

    for n in range(n_steps):
        t0 = n * dt
        t1 = (n + 1) * dt
        if not moving:
            if K * (V * t0 - x) > call(threshold, "value", sigma * theta, tp):
                moving = True
                n_starts += 1
                current = n
                x_start = x
        if moving:
            a1 = law_accel(law, K * (V * t0 - x), v, sigma * theta, lp) / M
            g1 = law_rate(law, theta, theta, theta, v, lp)
            xp = x + dt * v
            vp = v + dt * a1
            thp = theta + dt * g1
            a2 = law_accel(law, K * (V * t1 - xp), vp, sigma * thp, lp) / M
            g2 = law_rate(law, thp, thp, thp, vp, lp)
            x = x + half * (v + vp)
            v = v + half * (a1 + a2)
            theta = theta + half * (g1 + g2)
            if v <= 0.0:
                v = 0.0
                moving = False
                n_stops += 1
                if current >= 0:
                    if n_slips < capacity:
                        slip_start[n_slips] = current
                        slip_end[n_slips] = n + 1
                        slip_x_start[n_slips] = x_start
                        slip_x_end[n_slips] = x
                    n_slips += 1
                    current = -1
        else:
            g1 = law_rate(law, theta, theta, theta, 0.0, lp)
            thp = theta + dt * g1
            g2 = law_rate(law, thp, thp, thp, 0.0, lp)
            theta = theta + half * (g1 + g2)

        if v < v_min:
            v_min = v
        if v > v_max:
            v_max = v
        if (n + 1) % every == 0 or n + 1 == n_steps:
            out_t[j] = t1
            out_x[j] = x
            out_v[j] = v
            out_theta[j] = theta
            out_stopped[j] = not moving
            j += 1

    return x, v, theta, not moving, n_slips, n_starts, n_stops, v_min, v_max
