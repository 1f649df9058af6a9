"""The compiled Heun step of eq. (1) equals plain Python bit for bit (short runs)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from stickslip.kernels.block import heun_block
from stickslip.kernels.entry import specialise_call
from stickslip.models.params import BlockParams
from stickslip.run.block import LAW_ARG, BlockState, n_samples, simulate_block


def _buffers(n_steps, every, capacity=64):
    n = n_samples(n_steps, every)
    return (
        np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n, dtype=np.bool_),
        np.empty(capacity, dtype=np.int64), np.empty(capacity, dtype=np.int64),
        np.empty(capacity), np.empty(capacity),
    )  # fmt: skip


def _call(fn, p: BlockParams, s: BlockState, n_steps: int, every: int):
    bufs = _buffers(n_steps, every)
    law, thr = p.friction_piece, p.threshold_piece
    args = (s.x, s.v, s.theta, s.stopped, n_steps, every, p.K, p.V, law.module, law.kernel_params(p),
            thr.module, thr.kernel_params(p), p.M, p.sigma, p.dt, *bufs)  # fmt: skip
    ret = specialise_call(fn, args, LAW_ARG) if fn is heun_block else fn(*args)
    return ret, bufs


def _assert_same(a, b):
    (ret_a, bufs_a), (ret_b, bufs_b) = a, b
    assert tuple(ret_a) == tuple(ret_b)
    n_slips = ret_a[4]
    for i, (xa, xb) in enumerate(zip(bufs_a, bufs_b, strict=False)):
        if i >= 5:  # slip buffers: only the filled part is defined
            xa, xb = xa[:n_slips], xb[:n_slips]
        assert np.array_equal(xa, xb), f"output array {i} differs"


def plain_heun_step(x, v, theta, moving, n, p: BlockParams):
    """One step of eq. (1), written from docs/model.md independently of the kernel.

    Returns the new state and whether the step started / stopped the block.
    """
    dt = p.dt

    def rates(y, t, moving):
        x, v, th = y
        if moving:
            return [v, (p.K * (p.V * t - x) - p.sigma * th - p.beta * v) / p.M, th * (1.0 - th) - p.alpha * th * v]
        return [0.0, 0.0, th * (1.0 - th)]

    started = stopped_now = False
    if not moving and p.K * (p.V * (n * dt) - x) > p.Fs:
        moving, started = True, True
    y = [x, v, theta]
    k1 = rates(y, n * dt, moving)
    pred = [y[i] + dt * k1[i] for i in range(3)]
    k2 = rates(pred, (n + 1) * dt, moving)
    x, v, theta = (y[i] + 0.5 * dt * (k1[i] + k2[i]) for i in range(3))
    if moving and v <= 0.0:
        v, moving, stopped_now = 0.0, False, True
    return x, v, theta, moving, started, stopped_now


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
)


@settings(max_examples=6, deadline=None)
@given(p=params_st, lag=st.floats(0.0, 0.05), theta=st.floats(0.1, 1.0), every=st.integers(1, 7))
def test_kernel_equals_py_func(p, lag, theta, every):
    # Start just short of the threshold so that the short run sees starts and stops.
    s = BlockState(x=-p.Fs / p.K + lag, theta=theta)
    n_steps = 1500
    compiled = _call(heun_block, p, s, n_steps, every)
    assert compiled[0][5] >= 1  # the start rule fired at least once
    _assert_same(compiled, _call(heun_block.py_func, p, s, n_steps, every))


@pytest.mark.parametrize(
    "p, state",
    [
        (BlockParams(V=0.05), BlockState(x=-0.29, theta=0.9)),
        (BlockParams(K=5.0, V=0.2, beta=0.3, alpha=1.5, Fs=2.0, M=1.3, sigma=0.8), BlockState()),
        (BlockParams(V=0.01), BlockState(x=0.0, v=0.2, theta=0.5, stopped=False)),
    ],
)
def test_kernel_equals_independent_step(p, state):
    n_steps = 2000
    run = simulate_block(p, n_steps * p.dt, initial=state)
    x, v, th, moving = state.x, state.v, state.theta, not state.stopped
    xs, vs, ths, stop_flags = [x], [v], [th], [not moving]
    starts = stops = 0
    for n in range(n_steps):
        x, v, th, moving, started, stopped_now = plain_heun_step(x, v, th, moving, n, p)
        starts += started
        stops += stopped_now
        xs.append(x)
        vs.append(v)
        ths.append(th)
        stop_flags.append(not moving)
    s = run.series
    assert np.array_equal(s["x"].values, np.array(xs))
    assert np.array_equal(s["v"].values, np.array(vs))
    assert np.array_equal(s["theta"].values, np.array(ths))
    assert np.array_equal(s["stopped"].values, np.array(stop_flags))
    assert np.array_equal(s["t"].values, np.arange(n_steps + 1) * p.dt)
    assert (run.n_starts, run.n_stops) == (starts, stops)
    assert starts + stops > 0
