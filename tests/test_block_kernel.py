"""eq. (1) on the chain's engine at N = 1 equals a plain-Python Heun step bit for bit (short runs):
the series, the slips, the counts and the range of v, with the mass M, sigma and either threshold."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from stickslip.models.params import BlockParams
from stickslip.run.block import BlockState, simulate_block


def plain_heun_step(x, v, theta, moving, n, p: BlockParams):
    """One step of eq. (1), written from docs/model.md independently of the kernels.

    Returns the new state and whether the step started / stopped the block.
    """
    dt = p.dt

    def rates(y, t, moving):
        x, v, th = y
        if moving:
            return [v, (p.K * (p.V * t - x) - p.sigma * th - p.beta * v) / p.M, th * (1.0 - th) - p.alpha * th * v]
        return [0.0, 0.0, th * (1.0 - th)]

    threshold = p.Fs if p.threshold == "constant" else p.sigma * theta
    started = stopped_now = False
    if not moving and p.K * (p.V * (n * dt) - x) > threshold:
        moving, started = True, True
    y = [x, v, theta]
    k1 = rates(y, n * dt, moving)
    pred = [y[i] + dt * k1[i] for i in range(3)]
    k2 = rates(pred, (n + 1) * dt, moving)
    x, v, theta = (y[i] + 0.5 * dt * (k1[i] + k2[i]) for i in range(3))
    if moving and v <= 0.0:
        v, moving, stopped_now = 0.0, False, True
    return x, v, theta, moving, started, stopped_now


def plain_run(p: BlockParams, state: BlockState, n_steps: int):
    """Every state of a plain run, its slips (start step, end step, x then) and counts."""
    x, v, th, moving = state.x, state.v, state.theta, not state.stopped
    xs, vs, ths, stop_flags = [x], [v], [th], [not moving]
    starts = stops = 0
    slips, current = [], None
    for n in range(n_steps):
        x0 = x
        x, v, th, moving, started, stopped_now = plain_heun_step(x, v, th, moving, n, p)
        if started:
            current = (n, x0)
        if stopped_now and current is not None:
            slips.append((current[0], n + 1, current[1], x))
            current = None
        starts += started
        stops += stopped_now
        xs.append(x)
        vs.append(v)
        ths.append(th)
        stop_flags.append(not moving)
    return np.array(xs), np.array(vs), np.array(ths), np.array(stop_flags), slips, starts, stops


def _check(p: BlockParams, state: BlockState, n_steps: int, every: int = 1):
    run = simulate_block(p, n_steps * p.dt, initial=state, every=every)
    xs, vs, ths, stop_flags, slips, starts, stops = plain_run(p, state, n_steps)
    keep = np.unique(np.r_[np.arange(0, n_steps + 1, every), n_steps])
    s = run.series
    assert np.array_equal(s["x"].values, xs[keep])
    assert np.array_equal(s["v"].values, vs[keep])
    assert np.array_equal(s["theta"].values, ths[keep])
    assert np.array_equal(s["stopped"].values, stop_flags[keep])
    assert np.array_equal(s["t"].values, keep * p.dt)
    assert (run.n_starts, run.n_stops) == (starts, stops)
    assert (run.v_min, run.v_max) == (vs.min(), vs.max())
    assert len(run.slips) == len(slips)
    for row, (n_c, n_e, x_c, x_e) in zip(run.slips.itertuples(), slips, strict=True):
        assert (row.t_c, row.t_e) == (n_c * p.dt, n_e * p.dt)
        assert row.slip == x_e - x_c
        assert row.force_at_stop == p.K * (p.V * (n_e * p.dt) - x_e)
    assert run.final == BlockState(x=xs[-1], v=vs[-1], theta=ths[-1], stopped=bool(stop_flags[-1]))
    return starts, stops


params_st = st.builds(
    BlockParams,
    K=st.floats(2.0, 20.0),
    V=st.floats(0.02, 0.3),
    beta=st.floats(0.1, 2.0),
    alpha=st.floats(0.2, 2.0),
    Fs=st.floats(1.2, 4.0),
    M=st.floats(0.5, 2.0),
    sigma=st.floats(0.5, 1.0),
    dt=st.sampled_from([0.005, 0.01, 0.0025]),
    threshold=st.sampled_from(["constant", "state"]),
)


@settings(max_examples=6, deadline=None)
@given(p=params_st, lag=st.floats(0.0, 0.05), theta=st.floats(0.1, 1.0), every=st.integers(1, 7))
def test_engine_equals_plain_step(p, lag, theta, every):
    # Start just short of the threshold so that the short run sees starts and stops.
    s = BlockState(x=-p.Fs / p.K + lag, theta=theta)
    starts, _ = _check(p, s, 1500, every)
    assert starts >= 1


@pytest.mark.parametrize(
    "p, state",
    [
        (BlockParams(V=0.05), BlockState(x=-0.29, theta=0.9)),
        (BlockParams(K=5.0, V=0.2, beta=0.3, alpha=1.5, Fs=2.0, M=1.3, sigma=0.8), BlockState()),
        (BlockParams(V=0.01), BlockState(x=0.0, v=0.2, theta=0.5, stopped=False)),
        (BlockParams(V=0.05, sigma=0.7, threshold="state"), BlockState(x=-0.05, theta=0.8)),
    ],
)
def test_engine_equals_independent_step(p, state):
    starts, stops = _check(p, state, 2000)
    assert starts + stops > 0
