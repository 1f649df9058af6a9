"""Rate-and-state friction (models/friction/rate_state.py, docs/models/rate-state.md).

The expected values come from the equations written out here: the law and the aging law in
plain Python, the spring-slider's characteristic cubic
    D_c l^3 + (V + sigma a D_c / V) l^2 + (k D_c + sigma (a - b)) l + k V = 0
(unit mass, linearised about steady sliding at V, theta_0 = D_c / V), and its Hopf point
k_c = sigma (b - a) / D_c (1 + V^2 / (sigma a D_c)) (Rice & Ruina 1983), which tends to
sigma (b - a) / D_c as V -> 0.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from chain_helpers import N_START, PARTLY_STUCK_BLOCKS, assert_same_run, partly_stuck_start, run_cli
from stickslip.analysis.dynamics import stability as st
from stickslip.models.friction.rate_state import mu_lp
from stickslip.models.params import ChainParams, ParameterError
from stickslip.models.pieces import CompositionError, check_composition
from stickslip.run.driver import ChainState, run_chain
from stickslip.run.located import LocatedState, run_located
from stickslip.run.located import rates as located_rates


def _params(**kw) -> ChainParams:
    return ChainParams(**{"N": 1, "friction": "rate-state", **kw})


def _mu(p, v, theta):
    """a asinh(v / (2 v0) exp((mu0 + b ln(v0 theta / D_c)) / a)) at |v| (Rice & Ben-Zion 1996)."""
    psi = p.mu0 + p.rs_b * math.log(p.v0 * theta / p.Dc)
    return p.rs_a * math.asinh(abs(v) / (2.0 * p.v0) * math.exp(psi / p.rs_a))


def _mu_log(p, v, theta):
    """The unregularised law mu0 + a ln(v / v0) + b ln(v0 theta / D_c)."""
    return p.mu0 + p.rs_a * math.log(v / p.v0) + p.rs_b * math.log(p.v0 * theta / p.Dc)


def _k_c(p):
    return p.sigma_n * (p.rs_b - p.rs_a) / p.Dc * (1.0 + p.V**2 / (p.sigma_n * p.rs_a * p.Dc))


def test_law_and_its_regularisation():
    p = _params()
    law = p.friction_piece
    for v, theta in [(1e-3, 1.0), (0.05, 0.02), (1e-6, 30.0)]:
        assert _mu(p, v, theta) == pytest.approx(_mu_log(p, v, theta), rel=1e-14)
    assert _mu(p, 0.0, 1.0) == 0.0
    # the kernel's expression, on both sides of its switch to ln(2 z) at z = e^20
    lp = law.kernel_params(p)
    for v, theta in [(1e-30, 1.0), (3e-35, 0.5), (-1e-30, 2.0), (1e-3, 1.0), (-0.02, 0.3), (0.0, 1.0)]:
        assert mu_lp(v, theta, lp) == pytest.approx(_mu(p, v, theta), rel=1e-14, abs=1e-300)
    assert 0.0 < _mu(p, 1e-30, 1.0) < 0.5 * p.mu0  # regularised: far below mu0 near v = 0
    # steady sliding: theta_0 = D_c / V, friction sigma_n (mu0 + (a - b) ln(V / v0))
    q = p.replace(V=0.004)
    c, theta0 = law.steady(q)
    assert theta0 == pytest.approx(q.Dc / q.V, rel=1e-15)
    assert c == pytest.approx(q.sigma_n * (q.mu0 + (q.rs_a - q.rs_b) * math.log(q.V / q.v0)), rel=1e-13)
    assert law.start_theta(q) == pytest.approx(0.25, rel=1e-15)


@pytest.mark.parametrize("V", [1e-4, 1e-3, 0.02])
def test_linearisation_against_the_law(V):
    p = _params(V=V)
    lin = p.friction_piece.linear(p)
    theta0 = p.Dc / V
    h = 1e-7

    def phi(v, th):
        return p.sigma_n * _mu_log(p, v, th)

    def g(v, th):
        return 1.0 - v * th / p.Dc

    assert lin.theta0 == pytest.approx(theta0, rel=1e-15)
    assert lin.phi_v == pytest.approx((phi(V * (1 + h), theta0) - phi(V * (1 - h), theta0)) / (2 * h * V), rel=1e-6)
    d = theta0 * h
    assert lin.phi_theta == pytest.approx((phi(V, theta0 + d) - phi(V, theta0 - d)) / (2 * d), rel=1e-6)
    assert lin.g_v == pytest.approx(-theta0 / p.Dc, rel=1e-14)
    assert lin.g_theta == pytest.approx(-V / p.Dc, rel=1e-14)
    assert lin.diffusion == 0.0


@pytest.mark.parametrize(("K", "V"), [(10.0, 1e-3), (25.5, 1e-3), (40.0, 0.01)])
def test_spring_slider_eigenvalues_are_the_roots_of_the_cubic(K, V):
    p = _params(K=K, V=V)
    s, a, b, Dc = p.sigma_n, p.rs_a, p.rs_b, p.Dc
    roots = np.roots([Dc, V + s * a * Dc / V, K * Dc + s * (a - b), K * V])
    eig = st.chain_finite_eigenvalues(p)
    np.testing.assert_allclose(np.sort_complex(eig), np.sort_complex(roots), rtol=1e-9, atol=1e-9)


def test_critical_stiffness_quasi_static_and_inertial():
    # small V: the quasi-static k_c = sigma (b - a) / D_c within 1%
    slow = _params(V=1e-5)
    quasi = slow.sigma_n * (slow.rs_b - slow.rs_a) / slow.Dc
    assert st.critical_stiffness(slow) == pytest.approx(quasi, rel=1e-2)
    # moderate V: the inertial correction triples k_c here; the package follows the closed form
    for V in (1e-3, 0.01):
        p = _params(V=V)
        assert st.critical_stiffness(p) == pytest.approx(_k_c(p), rel=1e-9)
    fast = _params(V=0.01)
    assert _k_c(fast) / quasi == pytest.approx(3.0, rel=1e-12)
    assert p.friction_piece.stability_extras(fast)["k_c_spring_slider"] == pytest.approx(75.0, rel=1e-12)


@pytest.mark.parametrize("N", [2, 7])
def test_critical_stiffness_of_the_chain(N):
    # No diffusion: the sine modes k_m = (2m - 1) pi / (2N + 1) of the end-driven chain decouple,
    # mode m has stiffness K q_m, q_m = 2 (1 - cos k_m); the lowest goes first: K_c = k_c / q_1.
    p = _params(N=N, V=0.002)
    q1 = 2.0 * (1.0 - math.cos(math.pi / (2 * N + 1)))
    assert st.critical_stiffness(p) == pytest.approx(_k_c(p) / q1, rel=1e-8)


def test_velocity_strengthening_is_stable_at_every_K():
    p = _params(rs_a=0.02, rs_b=0.015)
    for K in np.geomspace(1e-3, 1e4, 15):
        assert st.chain_finite_eigenvalues(p.replace(K=float(K)))[0].real < 0.0
    assert math.isnan(st.critical_stiffness(p))


def _aging(p, v, th):
    """The aging law dtheta/dt = 1 - v theta / D_c."""
    return 1.0 - v * th / p.Dc


def _plain_step(x, v, th, moving, n, p, g=_aging):
    """One Heun step of the end-driven chain with free end, constant threshold Fs and rate-state
    friction, written from the equations (docs/model.md's step; friction sigma_n mu(|v|, theta);
    dtheta/dt = g(v, theta) on every block, by default the aging law)."""
    N, dt = len(x), p.dt

    def forces(X, t):
        ext = [p.V * t] + list(X) + [X[-1]]
        return [p.K * (ext[i - 1] - 2 * ext[i] + ext[i + 1]) for i in range(1, N + 1)]

    f1 = forces(x, n * dt)
    mid = [moving[i] or f1[i] > p.Fs for i in range(N)]
    a1 = [f1[i] - p.sigma_n * _mu(p, v[i], th[i]) if mid[i] else 0.0 for i in range(N)]
    b1 = [g(p, v[i], th[i]) for i in range(N)]
    xs = [x[i] + dt * v[i] for i in range(N)]
    vs = [v[i] + dt * a1[i] for i in range(N)]
    ths = [th[i] + dt * b1[i] for i in range(N)]
    f2 = forces(xs, (n + 1) * dt)
    out = []
    for i in range(N):
        b2 = g(p, vs[i], ths[i])
        thn = th[i] + dt / 2 * (b1[i] + b2)
        if not mid[i]:
            out.append((x[i], 0.0, thn, False))
            continue
        a2 = f2[i] - p.sigma_n * _mu(p, vs[i], ths[i])
        vn = v[i] + dt / 2 * (a1[i] + a2)
        out.append((x[i] + dt / 2 * (v[i] + vs[i]), max(vn, 0.0), thn, vn > 0.0))
    return [list(c) for c in zip(*out, strict=True)]


def steps_against_the_plain_step(p, integrator, g=_aging):
    """One and three kernel steps from a partly stuck state of four blocks against
    :func:`_plain_step` with the state law ``g``; returns the blocks after three steps."""
    x, v, th, moving = PARTLY_STUCK_BLOCKS
    n = N_START
    start = partly_stuck_start()
    for steps in (1, 3):
        ref = (x, v, th, moving)
        for k in range(steps):
            ref = _plain_step(*ref, n + k, p, g=g)
        b = run_chain(p, (n + steps) * p.dt, integrator=integrator, start=start.copy()).state.blocks()
        np.testing.assert_allclose(b["x"], ref[0], rtol=1e-14, atol=0)
        np.testing.assert_allclose(b["v"], ref[1], rtol=1e-11, atol=1e-17)
        np.testing.assert_allclose(b["theta"], ref[2], rtol=1e-13, atol=0)
        assert (~b["stopped"]).tolist() == ref[3]
    return b


@pytest.mark.parametrize("integrator", ["dense", "exact"])
def test_one_kernel_step_against_the_plain_step(integrator):
    p = _params(N=4, K=12.0, Fs=2.9)
    b = steps_against_the_plain_step(p, integrator)
    # the stuck block ages: dtheta/dt = 1
    assert b["theta"][1] == pytest.approx(3.0 + 3 * p.dt, rel=1e-15)


def _v_swing(p, t0, t1, start):
    """max |v - V| of block 1 over [t0, t1] sampled every 0.25, and the state at t1."""
    state, swing, t = start, 0.0, t0
    while t < t1:
        t += 0.25
        state = run_chain(p, t, start=state).state
        swing = max(swing, abs(float(state.blocks()["v"][0]) - p.V))
    return swing, state


@pytest.mark.parametrize(("ratio", "grows"), [(0.85, True), (1.15, False)])
def test_spring_slider_near_k_c(ratio, grows):
    base = _params()
    p = base.replace(K=ratio * _k_c(base))
    s = ChainState.steady(p)
    b = s.blocks()
    start = ChainState.from_blocks(b["x"], b["v"] * 1.001, b["theta"], b["stopped"])
    early, state = _v_swing(p, 0.0, 20.0, start)
    state = run_chain(p, 180.0, start=state).state
    late, _ = _v_swing(p, 180.0, 200.0, state)
    assert (late > 10.0 * early) if grows else (late < 0.1 * early)


def test_below_k_c_the_spring_slider_sticks_and_slips():
    p = _params(K=20.0)
    run = run_chain(p, 600.0, start="steady", perturbation=1e-6)
    assert len(run.events) >= 5  # stops and restarts at Fs
    assert np.isfinite(run.state.blocks()["theta"]).all()


def test_dense_and_exact_agree_bit_for_bit_on_a_chain():
    p = ChainParams(N=5, K=5.0, friction="rate-state")
    runs = [
        run_chain(p, 400.0, integrator=i, start="steady", perturbation=1e-4, sample_interval=1.0)
        for i in ("dense", "exact")
    ]
    assert len(runs[0].events) > 10 and runs[0].events["n_blocks"].max() > 1
    assert_same_run(runs[0], runs[1])


def test_parameters_and_composition():
    with pytest.raises(ParameterError, match="V > 0"):
        _params(V=0.0)
    with pytest.raises(ParameterError, match="rs_a"):
        _params(rs_a=0.0)
    with pytest.raises(CompositionError, match="threshold state needs friction state"):
        check_composition("end", "rate-state", "state", "free")
    # eq. (4)'s explicit-step check on D is its own law's, not this one's
    assert _params(D=1000.0).D == 1000.0
    assert "rs_a" not in ChainParams().to_dict() and "rs_a" in _params().to_dict()


@pytest.mark.slow
def test_located_switches_run_the_law():
    """The located integrator's right-hand side is the law's, checked against the plain formulas
    above (friction sigma_n mu(|v|, theta); the aging law on stuck blocks too)."""
    p = _params(N=3, K=10.0, V=0.01)
    st_ = LocatedState.from_blocks([0.3, -0.2, 0.1], [0.004, 0.0, 0.011], [0.05, 0.2, 0.1], [False, True, False])
    du, dv, dth = located_rates(st_, p)
    u = st_.u
    for i in range(1, 4):
        ur = u[i + 1] if i < 3 else u[i]
        ul = u[i - 1] if i > 1 else 0.0
        f = p.K * ((ul - u[i]) - (u[i] - ur))
        moving = st_.mov[i] != 0.0
        assert dv[i] == pytest.approx(f - p.sigma_n * _mu(p, st_.v[i], st_.th[i]) if moving else 0.0, rel=1e-12)
        assert dth[i] == pytest.approx(1.0 - st_.v[i] * st_.th[i] / p.Dc, rel=1e-12)
        assert du[i] == st_.v[i] - p.V
    # and it runs: the spring-slider below k_c stick-slips with located switches
    run = run_located(_params(V=0.01), 300.0, start="paper")
    assert len(run.events) >= 2 and (run.events["size"] > 0).all()


@pytest.mark.slow  # stability and lyapunov on a rate-and-state block (about 60 s, measured)
def test_command_line(capsys):
    status, out, _ = run_cli(capsys, "stability", "chain", "--friction", "rate-state", "--V", "0.01", "--json")
    assert status == 0
    d = json.loads(out)
    assert d["params"]["N"] == 1 and d["critical_K"] == pytest.approx(75.0, rel=1e-9)
    assert d["finite_chain"]["unstable"]  # K = 10 < k_c
    status, out, err = run_cli(
        capsys,
        "lyapunov",
        "--friction",
        "rate-state",
        "--N",
        "1",
        "--V",
        "0.01",
        "--switches",
        "located",
        "--t-end",
        "200",
        "--json",
    )
    assert status == 0, err
    assert math.isfinite(json.loads(out)["lyapunov_dt0"])


def test_the_spring_sliders_tiny_slips_as_documented():
    """docs/models/rate-state.md, "The spring-slider's tiny slips": at K = 20 (below k_c = 25.5)
    each large slip (S = 0.0164, one every 16.7) follows two tiny ones (S ~ 1.4e-4)."""
    import warnings

    from stickslip import chain_params, run_chain

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = run_chain(chain_params(N=1, friction="rate-state", K=20), 2000.0)
    S = run.events["S"].to_numpy()
    t = run.events["t_start"].to_numpy()
    large = np.flatnonzero(S > 1e-3)
    assert (len(S), len(large)) == (362, 110) and large[0] == 32
    assert np.all(np.diff(large) == 3), "two tiny slips before each large one"
    assert S[large].mean() == pytest.approx(0.0164, rel=0.01)
    assert np.median(np.diff(t[large])) == pytest.approx(16.7, rel=0.01)
    tiny = np.delete(S, large)
    assert 7e-5 < tiny.min() and tiny.max() < 1.6e-4 and np.median(tiny) == pytest.approx(1.4e-4, rel=0.05)
