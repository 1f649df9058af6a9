"""The PRZ law of rate-and-state friction (Perrin, Rice and Zheng 1995) on the inertial route
(models/friction/rate_state_prz.py, docs/models/rate-state.md, "The PRZ law").

Known answers, written here from the equations
    mu = a asinh(v / (2 v0) exp((mu0 + b ln(v0 theta / (2 D_c))) / a)),
    dtheta/dt = 1 - (v theta / (2 D_c))^2:
a plain-Python Heun step of the chain; steady sliding at theta = 2 D_c / V with
mu_ss = mu0 + (a - b) ln(V / v0); the critical stiffness of the spring-slider from its
characteristic cubic; Omega = v theta / (2 D_c) after a velocity step, tanh or coth of the slip;
and the quasi-static spring-slider of the laboratory (stickslip.lab.quasi_static, an adaptive
integrator that shares no code with the kernels), which the inertial one tends to as M -> 0.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from chain_helpers import assert_same_run, run_cli
from stickslip.analysis.dynamics import stability as st
from stickslip.lab import LoadHistory, quasi_static
from stickslip.lab.inertial import sample
from stickslip.lab.laws import RateState
from stickslip.models import pieces
from stickslip.models.friction import rate_state_prz
from stickslip.models.params import ChainParams, ParameterError
from stickslip.models.presets import chain_params
from stickslip.run.driver import ChainState, run_chain

LAW = "rate-state-prz"


def _params(**kw) -> ChainParams:
    return ChainParams(**{"N": 1, "friction": LAW, **kw})


def _mu(p, v, th):
    """a asinh(|v| / (2 v0) exp((mu0 + b ln(v0 theta / (2 D_c))) / a)), 0 at v = 0."""
    psi = p.mu0 + p.rs_b * math.log(p.v0 * th / (2.0 * p.Dc))
    return p.rs_a * math.asinh(abs(v) / (2.0 * p.v0) * math.exp(psi / p.rs_a))


def _g(p, v, th):
    """The PRZ law dtheta/dt = 1 - (v theta / (2 D_c))^2."""
    return 1.0 - (v * th / (2.0 * p.Dc)) ** 2


def _heun(x, v, th, moving, n, p):
    """One Heun step of the end-driven chain (free end, constant threshold Fs, unit mass), from
    the equations: friction sigma_n mu(|v|, theta) on moving blocks, the PRZ law on every block,
    the stop rule v <= 0."""
    N, dt = len(x), p.dt

    def forces(X, t):
        ext = [p.V * t, *X, X[-1]]
        return [p.K * (ext[i - 1] - 2 * ext[i] + ext[i + 1]) for i in range(1, N + 1)]

    f1 = forces(x, n * dt)
    mid = [moving[i] or f1[i] > p.Fs for i in range(N)]
    a1 = [f1[i] - p.sigma_n * _mu(p, v[i], th[i]) if mid[i] else 0.0 for i in range(N)]
    b1 = [_g(p, v[i], th[i]) for i in range(N)]
    xs = [x[i] + dt * v[i] for i in range(N)]
    vs = [v[i] + dt * a1[i] for i in range(N)]
    ths = [th[i] + dt * b1[i] for i in range(N)]
    f2 = forces(xs, (n + 1) * dt)
    out = []
    for i in range(N):
        thn = th[i] + dt / 2 * (b1[i] + _g(p, vs[i], ths[i]))
        if not mid[i]:
            out.append((x[i], 0.0, thn, False))
            continue
        vn = v[i] + dt / 2 * (a1[i] + f2[i] - p.sigma_n * _mu(p, vs[i], ths[i]))
        out.append((x[i] + dt / 2 * (v[i] + vs[i]), max(vn, 0.0), thn, vn > 0.0))
    return [list(c) for c in zip(*out, strict=True)]


def test_the_law_is_its_own_module_a_choice_and_listed(capsys):
    p = _params()
    assert p.friction_piece.module == rate_state_prz.__name__ == pieces.code("friction", LAW)
    assert p.friction_piece.has_state and p.friction_piece.rate_and_state
    assert LAW in pieces.RATE_AND_STATE
    assert p.friction_piece.start_theta(p) == pytest.approx(2.0 * p.Dc / p.V, rel=1e-15)
    with pytest.raises(ParameterError, match="V > 0"):
        _params(V=0.0)
    # threshold none takes it; the state threshold does not
    assert chain_params("sakaguchi", N=1, friction=LAW, threshold="none").threshold == "none"
    with pytest.raises(ParameterError, match="threshold state needs friction state"):
        chain_params("sakaguchi", N=1, friction=LAW, threshold="state")
    rc, out, _ = run_cli(capsys, "models")
    assert rc == 0 and LAW in out and "rate-state-slip, rate-state-prz" in out


def test_the_kernels_law_against_the_equations():
    p = _params(V=0.004)
    lp = p.friction_piece.kernel_params(p)
    for v, th in [(1e-3, 1.0), (0.05, 0.02), (1e-6, 30.0), (-0.02, 0.3), (1e-30, 2.0), (0.0, 1.0)]:
        assert -rate_state_prz.accel(0.0, v, th, lp) == pytest.approx(p.sigma_n * _mu(p, v, th), rel=1e-14, abs=1e-300)
        assert rate_state_prz.rate(0.0, th, 0.0, v, lp) == pytest.approx(_g(p, v, th), rel=1e-14)
    assert rate_state_prz.rate(0.0, 5.0, 0.0, 0.0, lp) == 1.0  # a stuck block ages
    # steady sliding: theta_0 = 2 D_c / V and mu_ss = mu0 + (a - b) ln(V / v0)
    c, theta0 = p.friction_piece.steady(p)
    assert theta0 == pytest.approx(2.0 * p.Dc / p.V, rel=1e-15)
    assert c == pytest.approx(p.sigma_n * (p.mu0 + (p.rs_a - p.rs_b) * math.log(p.V / p.v0)), rel=1e-13)
    assert rate_state_prz.rate(0.0, theta0, 0.0, p.V, lp) == pytest.approx(0.0, abs=1e-15)


@pytest.mark.parametrize("V", [1e-5, 1e-3, 0.01])
def test_critical_stiffness_from_the_characteristic_cubic(V):
    # Unit mass, u = v - V, eta = theta - theta_0: lambda^2 + K + lambda (phi_v + phi_th g_v /
    # (lambda - g_th)) = 0 with, by hand, phi_v = sigma a / V, phi_th = sigma b V / (2 D_c),
    # g_v = -2 / V, g_th = -V / D_c; the Hopf point of the cubic is
    # k_c = sigma (b - a) / D_c (1 + V^2 / (sigma a D_c)), the aging law's (Rice & Ruina 1983).
    p = _params(V=V)
    lin = p.friction_piece.linear(p)
    s, a, b, dc = p.sigma_n, p.rs_a, p.rs_b, p.Dc
    assert (lin.phi_v, lin.phi_theta, lin.g_v, lin.g_theta) == pytest.approx(
        (s * a / V, s * b * V / (2 * dc), -2.0 / V, -V / dc), rel=1e-12
    )
    k_c = s * (b - a) / dc * (1.0 + V**2 / (s * a * dc))
    assert st.critical_stiffness(p) == pytest.approx(k_c, rel=1e-8)
    for ratio, unstable in ((0.9, True), (1.1, False)):
        # the cubic lambda^3 + (phi_v - g_th) lambda^2 + (K - phi_v g_th + phi_th g_v) lambda - K g_th
        K = ratio * k_c
        roots = np.roots([1.0, s * a / V + V / dc, K + s * a / dc - s * b / dc, K * V / dc])
        assert (roots.real.max() > 0.0) == unstable


@pytest.mark.slow  # two velocity steps integrated on the kernels' rate (about 14 s, measured)
def test_velocity_step_omega_is_tanh_or_coth_of_the_slip():
    """Omega = v theta / (2 D_c) at a fixed velocity V1 from steady state at V0: d Omega/d(slip) =
    (1 - Omega^2) / (2 D_c), so Omega = tanh(s / 2 D_c + atanh(V1 / V0)) down, coth up. RK4 on
    the kernels' rate."""
    p = _params(V=1e-3)
    lp = p.friction_piece.kernel_params(p)
    for r in (10.0, 0.1):
        v1, th, s, h = r * p.V, 2.0 * p.Dc / p.V, 0.0, p.Dc / 2000.0
        omega = []
        for target in np.array([0.25, 1.0, 4.0]) * p.Dc:
            while s < target - 1e-15:
                dt = min(h, target - s) / v1
                k1 = rate_state_prz.rate(0.0, th, 0.0, v1, lp)
                k2 = rate_state_prz.rate(0.0, th + 0.5 * dt * k1, 0.0, v1, lp)
                k3 = rate_state_prz.rate(0.0, th + 0.5 * dt * k2, 0.0, v1, lp)
                k4 = rate_state_prz.rate(0.0, th + dt * k3, 0.0, v1, lp)
                th += dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
                s += dt * v1
            omega.append((s, v1 * th / (2.0 * p.Dc)))
        for s, om in omega:
            z = s / (2.0 * p.Dc)
            expected = 1.0 / math.tanh(z + math.atanh(1.0 / r)) if r > 1 else math.tanh(z + math.atanh(r))
            assert om == pytest.approx(expected, rel=1e-9)


def test_kernel_steps_against_the_plain_heun_step():
    p = _params(N=4, K=12.0, Fs=2.9)
    x = [-0.30, -0.46, -0.70, -0.93]
    v = [0.002, 0.0, 0.03, 1e-9]
    th = [0.8, 3.0, 0.05, 40.0]
    moving = [True, False, True, True]
    n = 20_000
    start = ChainState.from_blocks(np.array(x), np.array(v), np.array(th), ~np.array(moving))
    start.ist[0] = n  # the state held is at t_n
    ref = (x, v, th, moving)
    for steps in (1, 2, 3):
        ref = _heun(*ref, n + steps - 1, p)
        b = run_chain(p, (n + steps) * p.dt, integrator="dense", start=start.copy()).state.blocks()
        np.testing.assert_allclose(b["x"], ref[0], rtol=1e-12, atol=0)
        np.testing.assert_allclose(b["v"], ref[1], rtol=1e-12, atol=1e-17)
        np.testing.assert_allclose(b["theta"], ref[2], rtol=1e-12, atol=0)
        assert (~b["stopped"]).tolist() == ref[3]
    assert b["theta"][1] == pytest.approx(3.0 + 3 * p.dt, rel=1e-15)  # the stuck block ages


def test_dense_and_exact_bit_for_bit_and_steady_sliding_stays():
    # dt = 0.001: the PRZ rate is quadratic in v theta / (2 D_c), stiffer in fast slip than the
    # aging law's (the default dt = 0.005 takes theta below 0 in this chain's slips)
    p = ChainParams(N=5, K=5.0, friction=LAW, dt=0.001)
    runs = [
        run_chain(p, 400.0, integrator=i, start="steady", perturbation=1e-4, sample_interval=1.0)
        for i in ("dense", "exact")
    ]
    assert len(runs[0].events) > 0
    assert_same_run(runs[0], runs[1])
    # steady sliding of the spring-slider above its critical stiffness, at V > v0: theta stays
    # 2 D_c / V, v stays V, and the spring holds sigma_n mu_ss = sigma_n (mu0 + (a - b) ln(V / v0))
    q = _params(V=0.004, dt=0.001)
    q = q.replace(K=3.0 * st.critical_stiffness(q))
    t_end = 50.0
    b = run_chain(q, t_end, integrator="dense", start="steady").state.blocks()
    assert b["theta"][0] == pytest.approx(2.0 * q.Dc / q.V, rel=1e-10)  # round-off of 50,000 steps
    assert b["v"][0] == pytest.approx(q.V, rel=1e-10)
    mu_ss = q.mu0 + (q.rs_a - q.rs_b) * math.log(q.V / q.v0)
    assert q.K * (q.V * t_end - b["x"][0]) == pytest.approx(q.sigma_n * mu_ss, rel=1e-9)


@pytest.mark.slow  # the PRZ law on the load history with threshold none: a composition of its own
def test_inertial_spring_slider_tends_to_the_lab_quasi_static_prz_solution():
    """A velocity step 1 -> 3 (lab units: um, s) on the spring-slider with threshold none: the
    spring's friction k (p - x) of the inertial route (mass M per unit normal stress) against the
    quasi-static one, sampled every 0.5 s, differs by an error first order in M (threshold none's
    expansion in M), far below the transient. (At k = 1e-3 the PRZ law's step up reaches 20 V and
    the masses here are not yet in the linear regime.)"""
    model = RateState(a=0.005, b=0.01, Dc=10.0, mu0=0.6, V0=1.0, k=2e-3, law="prz", form="asinh")
    history = LoadHistory.steps([1.0, 3.0], [20.0, 30.0])
    t = np.linspace(10.0, 50.0, 81)
    qs = quasi_static(model, history, t=t)
    errors = []
    for M in (2e-4, 1e-4):
        run = sample(model, M, history, t, dt=M / 4, v_init=1.0)
        errors.append(float(np.max(np.abs(run["mu"] - qs.mu.values))))
    # the transient: mu rises towards a ln 3 above mu_ss(1) and relaxes over 2 D_c of slip
    assert float(np.ptp(qs.mu.values)) > 0.008
    assert errors[1] < 8.0 * 1e-4  # error / M is about 4 here; the transient is 0.01
    assert errors[1] == pytest.approx(errors[0] / 2.0, rel=0.15)  # first order in M
