"""Heun with located switches (stickslip.run.located): the equations, the closed form, the order.

Independent sources:
- a plain-Python Heun step of the family's equations written here from docs/model.md;
- the closed form of a single block with constant kinetic friction F0 (the train model's law at
  beta = 0): stuck until K V t = Fs, then the harmonic slip v(t) = V (1 - cos wt) + A sin wt
  (w = sqrt K, A = (Fs - F0) / w) until v = 0 at wt = 2 (pi - atan(A / V)), then stuck again;
- convergence against a run at dt / 16, at the order of Heun's method (two).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from stickslip.models.params import ChainParams
from stickslip.models.presets import chain_params
from stickslip.run.located import LocatedState, run_located


def _plain_rates(x, v, th, t, p):
    """dx/dt, dv/dt, dtheta/dt of docs/model.md for every block moving (plain Python)."""
    N = len(x)
    out_x, out_v, out_th = [], [], []
    for i in range(N):
        if p.drive == "end":
            left = p.V * t if i == 0 else x[i - 1]
        elif p.ends == "periodic":
            left = x[i - 1] if i > 0 else x[N - 1]
        else:
            left = x[i - 1] if i > 0 else x[0]
        if p.ends == "periodic":
            right = x[i + 1] if i < N - 1 else x[0]
        else:
            right = x[i + 1] if i < N - 1 else x[N - 1]
        f = p.K * (left - 2 * x[i] + right)
        if p.drive == "plate":
            f += p.Kp * (p.V * t - x[i])
        if p.friction == "state":
            fr = th[i] + p.beta * v[i]
        elif p.friction == "weakening":
            fr = (1 - p.sigma) / (1 + 2 * p.alpha * max(v[i], 0.0) / (1 - p.sigma))
        else:
            fr = p.F0 + p.beta * v[i]
        out_x.append(v[i])
        out_v.append(f - fr)
        if p.friction == "state":
            if p.ends == "periodic":
                tl, tr = th[i - 1], th[(i + 1) % N]
            else:
                tl, tr = th[max(i - 1, 0)], th[min(i + 1, N - 1)]
            out_th.append(th[i] * (1 - th[i]) - p.alpha * th[i] * v[i] + p.D * (tl - 2 * th[i] + tr))
        else:
            out_th.append(0.0)
    return out_x, out_v, out_th


def _plain_heun(x, v, th, p, n_steps):
    """Heun's method (explicit trapezoid) on the equations above, t_n = n dt."""
    for n in range(n_steps):
        t = n * p.dt
        kx, kv, kth = _plain_rates(x, v, th, t, p)
        xs = [a + p.dt * b for a, b in zip(x, kx, strict=True)]
        vs = [a + p.dt * b for a, b in zip(v, kv, strict=True)]
        ts = [a + p.dt * b for a, b in zip(th, kth, strict=True)]
        lx, lv, lth = _plain_rates(xs, vs, ts, t + p.dt, p)
        x = [a + 0.5 * p.dt * (b + c) for a, b, c in zip(x, kx, lx, strict=True)]
        v = [a + 0.5 * p.dt * (b + c) for a, b, c in zip(v, kv, lv, strict=True)]
        th = [a + 0.5 * p.dt * (b + c) for a, b, c in zip(th, kth, lth, strict=True)]
    return np.array(x), np.array(v), np.array(th)


@pytest.mark.parametrize(
    "params",
    [
        chain_params("sakaguchi", N=3, V=0.5),
        pytest.param(chain_params("carlson-langer", N=4, V=0.5), marks=pytest.mark.slow),
        pytest.param(chain_params("train", N=3, V=0.5), marks=pytest.mark.slow),
    ],
    ids=["sakaguchi", "carlson-langer", "train"],
)
def test_without_switches_it_is_heun_on_the_equations(params):
    rng = np.random.default_rng(3)
    x = list(0.01 * rng.standard_normal(params.N))
    v = list(3.0 + 0.1 * rng.random(params.N))  # fast enough that no block stops
    th = list(0.5 + 0.1 * rng.random(params.N))
    n = 100
    px, pv, pth = _plain_heun(x, v, th, params, n)
    start = LocatedState.from_blocks(x, v, th, np.zeros(params.N, bool))
    run = run_located(params, n * params.dt, start=start)
    b = run.state.blocks(params)
    assert not b["stopped"].any()
    assert np.allclose(b["x"], px, rtol=0, atol=1e-12)
    assert np.allclose(b["v"], pv, rtol=0, atol=1e-12)
    if params.friction_piece.has_state:
        assert np.allclose(b["theta"], pth, rtol=0, atol=1e-12)


def _closed_form_events(p: ChainParams, n: int) -> np.ndarray:
    """(start, end, size) of the first n slips of one block from rest at x = 0 (module docstring)."""
    w = math.sqrt(p.K)
    A = (p.Fs - p.F0) / w
    t_slip = 2.0 * (math.pi - math.atan(A / p.V)) / w
    x_slip = p.V * t_slip - p.V * math.sin(w * t_slip) / w + A * (1.0 - math.cos(w * t_slip)) / w
    f_end = p.Fs + p.K * (p.V * t_slip - x_slip)
    period = t_slip + (p.Fs - f_end) / (p.K * p.V)
    starts = p.Fs / (p.K * p.V) + period * np.arange(n)
    return np.column_stack((starts, starts + t_slip, np.full(n, x_slip)))


SPRING_SLIDER = ChainParams(model="train", N=1, friction="strengthening", K=10.0, V=0.1, beta=0.0, F0=1.0, Fs=3.0)


@pytest.mark.slow  # the located kernels compiled here first; three runs down to dt = 0.0025 (about 60 s, measured)
def test_single_block_matches_the_closed_form_at_second_order():
    n = 10
    exact = _closed_form_events(SPRING_SLIDER, n)
    errors = []
    for dt in (0.01, 0.005, 0.0025):
        run = run_located(SPRING_SLIDER.replace(dt=dt), exact[-1, 1] + 1.0, start="rest")
        ev = run.events[["t_start", "t_end", "size"]].to_numpy()
        assert len(ev) == n
        errors.append(float(np.max(np.abs(ev - exact))))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all((orders > 1.8) & (orders < 2.3)), (errors, orders)
    assert errors[-1] < 2e-4


ORDER_CASES = {
    "sakaguchi": (chain_params("sakaguchi", N=5, V=0.1), 60.0, "paper", 0.0, (0.02, 0.01, 0.005)),
    "train": (chain_params("train", N=5, V=0.1), 60.0, "paper", 0.0, (0.02, 0.01, 0.005)),
    "batista-carlson": (chain_params("batista-carlson"), 100.0, "rest", 0.0, (0.02, 0.01, 0.005)),
    "two-blocks": (chain_params("two-blocks"), 160.0, "rest", 0.01, (0.02, 0.01, 0.005)),
    "carlson-langer": (chain_params("carlson-langer", N=8), 80.0, "rest", 0.01, (0.005, 0.0025, 0.00125)),
}


@pytest.mark.parametrize(
    "name",
    # Carlson-Langer's ring compiles the located kernels for its composition alone (the plate and
    # the weakening law are in the default run through two-blocks).
    [pytest.param(n, marks=pytest.mark.slow) if n in ("batista-carlson", "carlson-langer") else n for n in ORDER_CASES],
)
def test_second_order_against_a_run_at_dt_over_16(name):
    params, t_end, start, amplitude, dts = ORDER_CASES[name]
    ref = run_located(params.replace(dt=dts[0] / 16), t_end, start=start, perturbation=amplitude)
    rb = ref.state.blocks(ref.params)
    assert len(ref.events) >= 1
    errors = []
    for dt in dts:
        run = run_located(params.replace(dt=dt), t_end, start=start, perturbation=amplitude)
        b = run.state.blocks(run.params)
        errors.append(max(float(np.max(np.abs(b[k] - rb[k]))) for k in ("u", "v", "theta")))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all((orders > 1.7) & (orders < 2.5)), (errors, orders)


def test_events_and_state_bookkeeping():
    run = run_located(SPRING_SLIDER, 30.0, start="rest")
    assert run.state.step == round(30.0 / SPRING_SLIDER.dt)
    assert run.t_end == pytest.approx(30.0)
    ev = run.events
    assert list(ev["start_block"]) == [1] * len(ev) and list(ev["n_blocks"]) == [1] * len(ev)
    assert np.all(np.diff(ev["t_start"]) > 0) and np.all(ev["t_end"] > ev["t_start"])


def test_restarting_the_clock_changes_nothing_in_the_frame_of_the_drive():
    from stickslip.models.params import ParameterError
    from stickslip.run.driver import run_chain

    p = chain_params("sakaguchi", N=6, V=0.1)
    engine = run_chain(p, 200.0).state
    kept = LocatedState.from_chain_state(engine, p)
    restarted = LocatedState.from_chain_state(engine, p, restart_clock=True)
    assert kept.step == engine.step and restarted.step == 0
    a = run_located(p, 300.0, start=kept).state.blocks(p)
    b = run_located(p, 100.0, start=restarted).state.blocks(p)
    for k in ("u", "v", "theta", "stopped"):
        assert np.array_equal(a[k], b[k])
    with pytest.raises(ParameterError, match="fixed ends"):
        LocatedState.from_chain_state(engine, p.replace(ends="fixed"), restart_clock=True)
