"""The slip in the limit V -> 0, eq. (3): accurate integration, the paper's numbers, Fig. 2."""

from __future__ import annotations

import numpy as np
import pytest

from stickslip.analysis.dynamics.slip_limit import NoStopError, heun_slip_limit, solve_slip_limit
from stickslip.models.params import BlockParams, ParameterError
from stickslip.plotting.block import slip_window
from stickslip.run.block import simulate_block

PAPER_DT = 0.005


@pytest.fixture(scope="module")
def accurate():
    return solve_slip_limit()


def rk4_eq3(K=10.0, beta=1.0, Fs=3.0, h=2e-4):
    """Eq. (3) by classical RK4 at a small step, stop located by cubic Hermite on v.

    Written here from the equation, independently of the package.
    """

    def rhs(y):
        x, v, th = y
        return np.array([v, Fs - K * x - th - beta * v, th * (1.0 - th) - th * v])

    y = np.array([0.0, 0.0, 1.0])
    t = 0.0
    while True:
        k1 = rhs(y)
        k2 = rhs(y + 0.5 * h * k1)
        k3 = rhs(y + 0.5 * h * k2)
        k4 = rhs(y + h * k3)
        y_new = y + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        if t > 0.1 and y_new[1] <= 0.0:
            break
        y, t = y_new, t + h
    # v and its derivative at both ends give a cubic; find its root by bisection.
    v0, a0, v1, a1 = y[1], rhs(y)[1], y_new[1], rhs(y_new)[1]

    def cubic(s):
        h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, s**3 - s**2
        return h00 * v0 + h10 * h * a0 + h01 * v1 + h11 * h * a1

    lo, hi = 0.0, 1.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if cubic(mid) > 0 else (lo, mid)
    s = 0.5 * (lo + hi)
    x_stop = y[0] + s * (y_new[0] - y[0])  # v ~ 0 here, so x is flat to O(h^2 s^2)
    return t + s * h, Fs - K * x_stop


def test_accurate_against_independent_rk4(accurate):
    t_e, f_end = rk4_eq3()
    assert accurate.duration == pytest.approx(t_e, abs=1e-8)
    assert accurate.force_at_stop == pytest.approx(f_end, abs=1e-7)
    # the event is a zero of v, crossed downwards
    assert abs(accurate.at([accurate.duration])["v"][0]) < 1e-10
    assert accurate.at([0.5 * accurate.duration])["v"][0] > 0.0


def test_against_paper_numbers(accurate):
    """Section 2: t_e - t_c = 1.035 and Fs - K x' = -0.432 at t_e.

    The paper's run steps by dt = 0.005, so its t_e is a grid time; 1.035 is the last grid time
    at which the block still moves: the true stop lies within one step after it. The force is
    printed to three decimals.
    """
    assert 1.035 < accurate.duration < 1.035 + PAPER_DT
    assert accurate.force_at_stop == pytest.approx(-0.432, abs=5e-4)
    assert accurate.law_b == pytest.approx(3.432, abs=5e-4)
    assert accurate.law_a == accurate.duration
    assert accurate.period(0.001) == pytest.approx(1.035 + 3.432 / (10 * 0.001), rel=1e-4)


@pytest.mark.parametrize("dt", [0.01, 0.005, 0.0025])
def test_heun_differs_by_stop_step_and_dt_squared(accurate, dt):
    """Heun with the stop rule: t_e is the end of the step in which v crosses 0 (within one step
    after the true stop); the force at stop and the extrapolated stop time are O(dt^2)."""
    heun = heun_slip_limit(dt=dt)
    assert heun.duration - dt < accurate.duration <= heun.duration
    assert abs(heun.force_at_stop - accurate.force_at_stop) < 10 * dt**2
    c = heun.curve
    x, v, th = c["x"].values[-2], c["v"].values[-2], c["theta"].values[-2]
    accel = 3.0 - 10.0 * x - th - v  # eq. (3) at the last moving step
    t_stop = float(c["t"][-2]) + v / -accel
    assert abs(t_stop - accurate.duration) < 10 * dt**2


def test_heun_curve_overlaps_accurate(accurate):
    heun = heun_slip_limit(dt=PAPER_DT)
    t = heun.curve["t"].values
    inside = t <= accurate.duration
    ref = accurate.at(t[inside])
    assert np.max(np.abs(heun.curve["v"].values[inside] - ref["v"])) < 1e-4
    assert np.max(np.abs(heun.curve["theta"].values[inside] - ref["theta"])) < 1e-4


def test_eq1_at_small_V_overlaps_eq3(accurate):
    """Fig. 2: v(t - t_c) and (v, theta) of eq. (1) at V = 0.001 overlap those of eq. (3).

    The remaining difference is O(V): the pulling point moves K V (t_e - t_c) ~ 0.01 in force
    during the slip. Bound: 1% of the peak velocity, 0.1% in theta.
    """
    run = simulate_block(BlockParams(), 700.0)
    w = slip_window(run)
    t = w["t"].values
    inside = t <= accurate.duration
    ref = accurate.at(t[inside])
    v_peak = w["v"].values.max()
    assert np.max(np.abs(w["v"].values[inside] - ref["v"])) < 0.01 * v_peak
    assert np.max(np.abs(w["theta"].values[inside] - ref["theta"])) < 1e-3
    # and the difference shrinks with V (O(V), not a numerical floor)
    # first slip at Fs / (K V) = 1500, from theta = 1 recovered during the stick
    run_slow = simulate_block(BlockParams(V=0.0002), 1510.0)
    w_slow = slip_window(run_slow, 0)
    ts = w_slow["t"].values
    inside_slow = ts <= accurate.duration
    err_slow = np.max(np.abs(w_slow["v"].values[inside_slow] - accurate.at(ts[inside_slow])["v"]))
    err = np.max(np.abs(w["v"].values[inside] - ref["v"]))
    assert err_slow < 0.4 * err


def test_general_parameters_and_errors():
    p = BlockParams(K=5.0, beta=0.5, Fs=2.0)
    law = solve_slip_limit(p)
    assert law.duration > 0 and law.force_at_stop < p.Fs
    assert law.curve["v"].values[1:-1].min() > 0.0
    # scale_block: K, beta scale with M, Fs with sigma, alpha with M / sigma; time is unchanged
    q = BlockParams(K=2 * 5.0, beta=2 * 0.5, Fs=2 * 2.0, M=2.0, sigma=2.0)
    law_q = solve_slip_limit(q)
    assert law_q.duration == pytest.approx(law.duration, rel=1e-8)
    assert law_q.force_at_stop == pytest.approx(2.0 * law.force_at_stop, rel=1e-7)
    with pytest.raises(ParameterError, match="Fs must be > sigma"):
        solve_slip_limit(BlockParams(Fs=0.9))
    with pytest.raises(NoStopError):
        solve_slip_limit(BlockParams(beta=100.0), t_max=50.0)
