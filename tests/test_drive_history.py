"""The load-history drive (drive history): the pulling point of eq. (4) moved along a load
history p(t), read by the kernels through the drive's compiled ``pull`` at step n.

Known answers: the integrators agree bit for bit (exact = dense); a plain-Python Heun step of
the single block of eq. (4) with the history's load point gives the kernel's trajectory bit for
bit; the kernel's load point agrees with the history's linear interpolation (numpy's); a history
at one constant velocity gives the end drive's bits; a history that moves back says so (a
DenseStepsWarning) and runs dense.
"""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

from stickslip.lab import LoadHistory
from stickslip.models.drive import history as hist
from stickslip.models.params import ParameterError
from stickslip.models.presets import chain_params
from stickslip.run.driver import run_chain
from stickslip.run.errors import DenseStepsWarning

#: velocity steps up and down and a hold at V = 0 (eq. 4's units: V = 0.001 is the paper's)
STEPS = LoadHistory.steps([0.001, 0.01, 0.0, 0.002], [500.0, 300.0, 400.0, 1000.0])


def _params(N, history=STEPS, **kw):
    return chain_params("sakaguchi", N=N, drive="history", history=history, **kw)


@pytest.mark.parametrize("N", [1, 6])
def test_exact_equals_dense_with_a_history(N):
    p = _params(N)
    a = run_chain(p, 2000.0, integrator="dense")
    b = run_chain(p, 2000.0, integrator="exact")
    assert a.state.sha256() == b.state.sha256()
    assert len(a.events) == len(b.events) > 0


def test_load_point_is_the_histories_interpolation():
    tb = hist.table(STEPS)
    dt = 0.005
    n = np.arange(0, 500_000, 997)
    got = np.array([hist.pull(int(k), dt, hist.Params(tb)) for k in n])
    want = STEPS.position(n * dt)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
    # never moves back, across every breakpoint
    dense = np.array([hist.pull(int(k), dt, hist.Params(tb)) for k in range(159_000, 161_000)])
    assert (np.diff(dense) >= 0.0).all()
    assert [hist.pull_py(int(k), dt, tb) for k in n] == got.tolist()


def _plain_load(t, tb):
    """p(t) from the table, written plainly: the interval by a scan, linear, clamped, held outside."""
    times, positions, slopes = (list(map(float, row)) for row in tb)
    m = len(times) - 1
    if t >= times[m]:
        return positions[m], None
    if t < times[0]:
        return positions[0], None
    k = max(i for i in range(m) if times[i] <= t)
    q = positions[k] + slopes[k] * (t - times[k])
    return (min(q, positions[k + 1]) if slopes[k] >= 0.0 else max(q, positions[k + 1])), k


@njit
def _viewed(t, dp, k):
    # the table as the chain's kernels carry it (its address and columns)
    return hist.load_from(t, hist.kernel_view(dp), k)


def test_the_load_point_from_any_interval_guess_is_the_plain_interpolation():
    # Twelve intervals with steps up, holds and a step back; the kernels look the interval up from
    # the last step's (any guess must give the same interval and the same number).
    rng = np.random.default_rng(3)
    tb = hist.table((np.cumsum(rng.uniform(0.1, 2.0, 13)), np.r_[0.0, np.cumsum(rng.choice([0.0, 0.5, -0.2], 12))]))
    m = tb.shape[1] - 1
    ts = np.r_[rng.uniform(tb[0, 0] - 1.0, tb[0, -1] + 1.0, 150), tb[0], np.nextafter(tb[0], -np.inf)]
    dp = hist.Params(tb)
    for t in ts:
        want, k_want = _plain_load(float(t), tb)
        for guess in (-1, 0, m - 1, int(rng.integers(0, m))):
            for p, k in (hist.load_from(float(t), dp, guess), _viewed(float(t), dp, guess)):
                assert p == want
                assert k == (guess if k_want is None else k_want)


def _oracle(N1_params, history, steps):
    """Heun for one block of eq. (4) (free ends: x_2 = x_1, so f = K (p - x)), written plainly:
    start rule f > Fs, friction theta + beta v, theta' = theta (1 - theta) - alpha theta v."""
    p = N1_params
    tb = hist.table(history)
    dt, K, Fs, beta, alpha = p.dt, p.K, p.Fs, p.beta, p.alpha
    x, v, th, moving = 0.0, 0.1, 0.1, True

    def acc(f, v, th, m):
        return m * (f - th - beta * v)

    def rate(th, v):
        return th * (1.0 - th) - alpha * th * v + p.D * ((th - th) - (th - th))

    for n in range(steps):
        p1, p2 = hist.pull_py(n, dt, tb), hist.pull_py(n + 1, dt, tb)
        f = K * ((p1 - x) - (x - x))
        m = 1.0 if (moving or f > Fs) else 0.0
        a1, b1 = acc(f, v, th, m), rate(th, v)
        xs, vs, ths = x + dt * v, v + dt * a1, th + dt * b1
        f2 = K * ((p2 - xs) - (xs - xs))
        a2, b2 = acc(f2, vs, ths, m), rate(ths, vs)
        th = th + 0.5 * dt * (b1 + b2)
        if m != 0.0:
            x = x + 0.5 * dt * (v + vs)
            vn = v + 0.5 * dt * (a1 + a2)
            v, moving = (0.0, False) if vn <= 0.0 else (vn, True)
        else:
            v, moving = 0.0, False
    return x, v, th, moving


def test_single_block_follows_a_plain_python_step():
    p = _params(1)
    steps = 120_000  # t = 600: the step up at t = 500 and the stick-slip after it
    run = run_chain(p, steps * p.dt, integrator="exact")
    b = run.state.blocks()
    x, v, th, moving = _oracle(p, STEPS, steps)
    assert (b["x"][0], b["v"][0], b["theta"][0], bool(b["stopped"][0])) == (x, v, th, not moving)


def test_a_constant_velocity_history_is_the_end_drive():
    # V T a power of two times V: the segment's velocity (p_1 - p_0) / (t_1 - t_0) is V exactly,
    # so the load point V_0 (n dt) is the end drive's V * (n dt) bit for bit.
    h = LoadHistory.steps([0.001], [4096.0])
    assert float(hist.table(h)[2, 0]) == 0.001
    a = run_chain(_params(6, h), 2000.0, integrator="exact")
    b = run_chain(chain_params("sakaguchi", N=6), 2000.0, integrator="exact")
    assert a.state.sha256() == b.state.sha256()
    assert len(a.events) == len(b.events) > 0


def test_a_history_that_moves_back_runs_dense():
    back = (np.array([0.0, 500.0, 900.0, 2000.0]), np.array([0.0, 5.0, 4.0, 8.0]))
    assert not hist.monotone(back)
    p = _params(3, back)
    a = run_chain(p, 1500.0, integrator="dense")
    with pytest.warns(DenseStepsWarning, match="moves back.*dense"):
        b = run_chain(p, 1500.0, integrator="exact")
    assert a.state.sha256() == b.state.sha256()


def test_history_drive_needs_a_history():
    with pytest.raises(ParameterError, match="history"):
        chain_params("sakaguchi", N=3, drive="history")
    with pytest.raises(ParameterError, match="increasing"):
        _params(3, ([0.0, 1.0, 1.0], [0.0, 1.0, 2.0]))
