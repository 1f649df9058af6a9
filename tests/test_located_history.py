"""The located integrator with a load history (drive history, :mod:`stickslip.models.drive.history`).

Known answers: a history at one constant velocity gives the constant-V run's events and state
to round-off (the two run in different frames, u = x and u = x - V t); a stuck block's start
time equals the root of K (p(t) - x) = Fs found by a plain-Python bisection, to the float; with
a velocity step and a hold the located run and the grid's dense run approach each other as dt
goes to 0 (the grid switches late by up to dt, the located run converges at second order).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from stickslip.lab import LoadHistory
from stickslip.models.params import ParameterError
from stickslip.models.presets import chain_params
from stickslip.run.driver import run_chain
from stickslip.run.located import LocatedState, run_located

#: a step up at t = 400, a hold at V = 0 from t = 600, a step to 0.002 at t = 800
STEPS = LoadHistory.steps([0.001, 0.01, 0.0, 0.002], [400.0, 200.0, 200.0, 300.0])


def _history(N, history=STEPS, **kw):
    return chain_params("sakaguchi", N=N, drive="history", history=history, **kw)


@pytest.mark.slow  # the located kernels with a history compile a composition of their own (about 60 s, measured)
@pytest.mark.parametrize("N", [1, 5])
def test_a_constant_velocity_history_is_the_constant_v_run(N):
    V = 0.001
    h = _history(N, LoadHistory.steps([V], [4000.0]))
    c = chain_params("sakaguchi", N=N, V=V)
    a, b = run_located(h, 2000.0), run_located(c, 2000.0)
    assert len(a.events) == len(b.events) > 2
    cols = ["t_start", "t_end", "size"]
    np.testing.assert_allclose(a.events[cols].to_numpy(), b.events[cols].to_numpy(), rtol=1e-10, atol=1e-9)
    assert (a.events[["start_block", "n_blocks"]].to_numpy() == b.events[["start_block", "n_blocks"]].to_numpy()).all()
    xa, xb = a.state.blocks(h), b.state.blocks(c)
    np.testing.assert_allclose(xa["x"], xb["x"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(xa["theta"], xb["theta"], rtol=0, atol=1e-9)
    assert (xa["stopped"] == xb["stopped"]).all()


def _position(t, times, positions):
    """p(t) of a piecewise-linear history, written plainly (held outside the breakpoints)."""
    if t >= times[-1]:
        return positions[-1]
    if t < times[0]:
        return positions[0]
    k = max(i for i in range(len(times) - 1) if times[i] <= t)
    slope = (positions[k + 1] - positions[k]) / (times[k + 1] - times[k])
    return min(positions[k] + slope * (t - times[k]), positions[k + 1])


@pytest.mark.slow  # the located kernels with a history compile a composition of their own (about 60 s, measured)
def test_a_start_after_a_hold_is_located_to_the_float():
    # One stuck block of eq. (4) (free ends: f = K (p(t) - x)); the load point is held at 0 until
    # t = 10.3, then moves at 0.01: the block starts where K (p(t) - x0) reaches Fs, inside a step.
    hist = LoadHistory.steps([0.0, 0.01], [10.3, 1000.0])
    p = _history(1, hist)
    x0 = -0.2876543
    run = run_located(p, 14.0, start=LocatedState.from_blocks([x0], [0.0], [0.5], [True]))
    t_start = float(run.events["t_start"].iloc[0])
    times, positions = list(hist.times), list(hist.positions)

    def g(t):
        return p.K * ((_position(t, times, positions) - x0) - (x0 - x0)) - p.Fs

    a, b = 0.0, 14.0
    while math.nextafter(a, b) < b:
        m = 0.5 * (a + b)
        if m in (a, b):
            break
        a, b = (a, m) if g(m) > 0.0 else (m, b)
    assert g(b) > 0.0 >= g(a)
    assert abs(t_start - b) <= 2 * math.ulp(b)
    assert abs(t_start - 11.53457) < 1e-9  # the closed form: 10.3 + (x0 + Fs / K) / 0.01
    assert t_start / p.dt != round(t_start / p.dt)  # off the grid


def _after_zero(events):
    """The events that start after t = 0 (the grid's table leaves out the event open at the start)."""
    return events[events["t_start"] > 0.0].reset_index(drop=True)


@pytest.mark.slow  # the located kernels with a history compile a composition of their own (about 60 s, measured)
@pytest.mark.parametrize("N", [1, 4])
def test_a_velocity_step_and_a_hold_converge_to_the_grid_run(N):
    # A start time moves by dx / V for a position error dx, so the grid's O(dt) errors in x show
    # up magnified 1 / V in the later events' times; the first start after t = 0 shows the order.
    firsts, selves = [], []
    previous = None
    for dt in (0.01, 0.005, 0.0025):
        p = _history(N, dt=dt)
        a = _after_zero(run_located(p, 1000.0).events)
        g = run_chain(p, 1000.0, integrator="dense").events
        assert len(a) == len(g) > 5
        assert (a["start_block"].to_numpy() == g["start_block"].to_numpy()).all()
        assert (a["n_blocks"].to_numpy() == g["n_blocks"].to_numpy()).all()
        gap = np.abs(a["t_start"].to_numpy() - g["t_start"].to_numpy())
        firsts.append(gap[0])
        assert gap.max() < 100 * dt  # O(dt) in x over V = 0.002: O(dt / V) in t
        np.testing.assert_allclose(a["size"].to_numpy(), g["S"].to_numpy(), rtol=0, atol=5e-3)
        if previous is not None:
            selves.append(np.abs(a[["t_start", "t_end"]].to_numpy() - previous).max())
        previous = a[["t_start", "t_end"]].to_numpy()
        # nothing starts in the hold (600 < t < 800) once the step's last slip has ended
        for starts in (a["t_start"].to_numpy(), g["t_start"].to_numpy()):
            assert not ((starts > 610.0) & (starts < 800.0)).any()
    # the grid switches late by up to dt: its first start draws to the located one as dt halves
    assert firsts[2] < 2 * 0.0025
    assert firsts[2] < 0.5 * firsts[0]
    # the located run converges at second order
    assert selves[1] < 0.35 * selves[0]


def test_a_history_refuses_restarting_the_clock():
    p = _history(3)
    state = run_chain(p, 10.0).state
    with pytest.raises(ParameterError, match="history"):
        LocatedState.from_chain_state(state, p, restart_clock=True)
