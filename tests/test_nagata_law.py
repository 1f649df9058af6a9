"""The Nagata law of rate-and-state friction (Nagata, Nakatani and Yoshida 2012) on the inertial route
(models/friction/rate_state_nagata.py, docs/models/rate-state.md, "The Nagata law").

Known answers, written here from the equations
    mu = a asinh(v / (2 v0) exp((mu0 + b ln(v0 theta / D_c)) / a)),
    dtheta/dt = 1 - v theta / D_c - (c / b) theta (df/dt) / sigma_n,
    df_i/dt = K (v_{i-1} - 2 v_i + v_{i+1}) [+ Kp (V - v_i)], v_0 = V at the end drive:
a plain-Python Heun step of the chain; steady sliding at theta = D_c / V with
mu_ss = mu0 + (a - b) ln(V / v0) (c drops out); c = 0 is the aging law; the quasi-static
spring-slider of the laboratory (stickslip.lab.quasi_static, an adaptive integrator that shares no
code with the kernels), which the inertial one tends to as M -> 0; and the exact integrator equal
to the dense one bit for bit.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from chain_helpers import N_START, PARTLY_STUCK_BLOCKS, assert_same_run, partly_stuck_start, run_cli
from stickslip.kernels.laws import RateContext
from stickslip.lab import LoadHistory, RateState, quasi_static
from stickslip.lab.inertial import critical_stiffness_inertial, sample
from stickslip.models import pieces
from stickslip.models.friction import rate_state, rate_state_nagata
from stickslip.models.params import ChainParams, ParameterError
from stickslip.models.presets import chain_params
from stickslip.run.driver import run_chain

LAW = "rate-state-nagata"


def _params(**kw) -> ChainParams:
    return ChainParams(**{"N": 1, "friction": LAW, **kw})


def _ctx(stress_rate: float) -> RateContext:
    return RateContext(stress_rate)


def _mu(p, v, th):
    """a asinh(|v| / (2 v0) exp((mu0 + b ln(v0 theta / D_c)) / a)), 0 at v = 0."""
    psi = p.mu0 + p.rs_b * math.log(p.v0 * th / p.Dc)
    return p.rs_a * math.asinh(abs(v) / (2.0 * p.v0) * math.exp(psi / p.rs_a))


def _g(p, v, th, fdot):
    """The Nagata law dtheta/dt = 1 - v theta / D_c - (c / b) theta fdot / sigma_n."""
    return 1.0 - v * th / p.Dc - p.rs_c / p.rs_b * th * fdot / p.sigma_n


def _heun(x, v, th, moving, n, p):
    """One Heun step of the chain (free end, constant threshold Fs, unit mass; end or plate drive),
    from the equations: friction sigma_n mu(|v|, theta) on moving blocks, the Nagata law on every
    block with the elastic force's rate from the velocities (stage 2: the predicted ones), the stop
    rule v <= 0."""
    N, dt, plate = len(x), p.dt, p.drive == "plate"

    def forces(X, t):
        ext = [X[0] if plate else p.V * t, *X, X[-1]]
        return [p.K * (ext[i - 1] - 2 * ext[i] + ext[i + 1]) + (p.Kp * (p.V * t - X[i - 1]) if plate else 0.0)
                for i in range(1, N + 1)]  # fmt: skip

    def rates(U):
        ext = [U[0] if plate else p.V, *U, U[-1]]
        return [p.K * (ext[i - 1] - 2 * ext[i] + ext[i + 1]) + (p.Kp * (p.V - U[i - 1]) if plate else 0.0)
                for i in range(1, N + 1)]  # fmt: skip

    f1, r1 = forces(x, n * dt), rates(v)
    mid = [moving[i] or f1[i] > p.Fs for i in range(N)]
    a1 = [f1[i] - p.sigma_n * _mu(p, v[i], th[i]) if mid[i] else 0.0 for i in range(N)]
    b1 = [_g(p, v[i], th[i], r1[i]) for i in range(N)]
    xs = [x[i] + dt * v[i] for i in range(N)]
    vs = [v[i] + dt * a1[i] for i in range(N)]
    ths = [th[i] + dt * b1[i] for i in range(N)]
    f2, r2 = forces(xs, (n + 1) * dt), rates(vs)
    out = []
    for i in range(N):
        thn = th[i] + dt / 2 * (b1[i] + _g(p, vs[i], ths[i], r2[i]))
        if not mid[i]:
            out.append((x[i], 0.0, thn, False))
            continue
        vn = v[i] + dt / 2 * (a1[i] + f2[i] - p.sigma_n * _mu(p, vs[i], ths[i]))
        out.append((x[i] + dt / 2 * (v[i] + vs[i]), max(vn, 0.0), thn, vn > 0.0))
    return [list(c) for c in zip(*out, strict=True)]


def test_the_law_is_its_own_module_a_choice_and_listed(capsys):
    p = _params()
    assert p.friction_piece.module == rate_state_nagata.__name__ == pieces.code("friction", LAW)
    assert p.friction_piece.has_state and p.friction_piece.rate_and_state
    assert p.friction_piece.context == ("stress_rate",) == rate_state_nagata.CONTEXT
    # every other law reads no context: their kernels build none
    assert [q.name for q in pieces.PIECES["friction"] if q.context] == [LAW]
    assert p.rs_c == 2.0 and "rs_c" in p.used()
    assert p.friction_piece.start_theta(p) == pytest.approx(p.Dc / p.V, rel=1e-15)
    with pytest.raises(ParameterError, match="V > 0"):
        _params(V=0.0)
    with pytest.raises(ParameterError, match="rs_b > 0 where rs_c != 0"):
        _params(rs_b=0.0)
    assert _params(rs_b=0.0, rs_c=0.0).rs_c == 0.0
    with pytest.raises(ParameterError, match="rs_c must be"):
        _params(rs_c=-1.0)
    assert chain_params("sakaguchi", N=1, friction=LAW, threshold="none").threshold == "none"
    rc, out, _ = run_cli(capsys, "models")
    assert rc == 0 and LAW in out


def test_the_kernels_law_against_the_equations():
    p = _params(V=0.004, rs_c=1.5)
    lp = p.friction_piece.kernel_params(p)
    for v, th, fdot in [(1e-3, 1.0, 0.0), (0.05, 0.02, 0.3), (1e-6, 30.0, -0.01), (-0.02, 0.3, 2.0), (0.0, 1.0, 0.1)]:
        assert -rate_state_nagata.accel(0.0, v, th, lp) == pytest.approx(p.sigma_n * _mu(p, v, th), rel=1e-14)
        r = rate_state_nagata.rate(0.0, th, 0.0, v, lp, _ctx(fdot))
        assert r == pytest.approx(_g(p, v, th, fdot), rel=1e-13, abs=1e-15)
    # a stuck block at a rising stress: theta relaxes towards b sigma_n / (c fdot)
    th_star = p.rs_b * p.sigma_n / (p.rs_c * 0.2)
    assert rate_state_nagata.rate(0.0, th_star, 0.0, 0.0, lp, _ctx(0.2)) == pytest.approx(0.0, abs=1e-15)
    # steady sliding: theta_0 = D_c / V and mu_ss = mu0 + (a - b) ln(V / v0), whatever c
    c, theta0 = p.friction_piece.steady(p)
    assert theta0 == pytest.approx(p.Dc / p.V, rel=1e-15)
    assert c == pytest.approx(p.sigma_n * (p.mu0 + (p.rs_a - p.rs_b) * math.log(p.V / p.v0)), rel=1e-13)
    assert rate_state_nagata.rate(0.0, theta0, 0.0, p.V, lp, _ctx(0.0)) == pytest.approx(0.0, abs=1e-15)
    # c = 0: the aging law's rate to the bit, whatever the stress rate
    q = _params(V=0.004, rs_c=0.0)
    lq, la = q.friction_piece.kernel_params(q), rate_state.PIECE.kernel_params(q)
    for v, th, fdot in [(1e-3, 1.0, 5.0), (0.05, 0.02, -3.0), (0.0, 7.0, 1e3)]:
        assert rate_state_nagata.rate(0.0, th, 0.0, v, lq, _ctx(fdot)) == rate_state.rate(0.0, th, 0.0, v, la)


@pytest.mark.parametrize("drive", ["end", pytest.param("plate", marks=pytest.mark.slow)])
def test_kernel_steps_against_the_plain_heun_step(drive):
    p = _params(N=4, K=12.0, Fs=2.9, rs_c=1.5, drive=drive, Kp=0.5 if drive == "plate" else 1.0)
    x, v, th, moving = PARTLY_STUCK_BLOCKS
    n = N_START
    start = partly_stuck_start()
    ref = (x, v, th, moving)
    for steps in (1, 2, 3):
        ref = _heun(*ref, n + steps - 1, p)
        for integrator in ("dense", "exact"):
            b = run_chain(p, (n + steps) * p.dt, integrator=integrator, start=start.copy()).state.blocks()
            np.testing.assert_allclose(b["x"], ref[0], rtol=1e-12, atol=0)
            np.testing.assert_allclose(b["v"], ref[1], rtol=1e-12, atol=1e-17)
            np.testing.assert_allclose(b["theta"], ref[2], rtol=1e-12, atol=0)
            assert (~b["stopped"]).tolist() == ref[3]
    # the stress term acts: the aging law alone would age the stuck block 2 by dt per step
    assert abs(b["theta"][1] - (3.0 + 3 * p.dt)) > 1e-6


def test_with_c_zero_it_is_the_aging_law_bit_for_bit():
    kw = {"N": 5, "K": 5.0, "dt": 0.002}
    aging, nagata = (
        run_chain(ChainParams(**kw, **over), 300.0, start="steady", perturbation=1e-3, sample_interval=1.0)
        for over in ({"friction": "rate-state"}, {"friction": LAW, "rs_c": 0.0})
    )
    assert len(aging.events) > 0
    assert aging.summary["state_sha256"] == nagata.summary["state_sha256"]
    assert aging.events.equals(nagata.events)


def _dense_is_exact(cases):
    for p, t_end in cases:
        start = {} if p.drive == "history" else {"start": "steady", "perturbation": 0.05}
        runs = [run_chain(p, t_end, integrator=i, sample_interval=1.0, **start) for i in ("dense", "exact")]
        assert len(runs[0].events) > 0
        assert_same_run(runs[0], runs[1])


def test_dense_and_exact_bit_for_bit_and_steady_sliding_stays():
    # a chain past a group of eight lanes (the exact path's run stages), in stick-slip with stuck
    # blocks (the other drives and forms: the slow test below)
    _dense_is_exact([(ChainParams(N=12, K=5.0, friction=LAW, dt=0.002), 400.0)])
    # steady sliding of the spring-slider above its critical stiffness: theta stays D_c / V, v
    # stays V, and the spring holds sigma_n mu_ss = sigma_n (mu0 + (a - b) ln(V / v0))
    q = _params(V=0.004, dt=0.001)
    q = q.replace(K=3.0 * rate_state_nagata.critical_stiffness(q))
    t_end = 50.0
    b = run_chain(q, t_end, integrator="exact", start="steady").state.blocks()
    assert b["theta"][0] == pytest.approx(q.Dc / q.V, rel=1e-10)
    assert b["v"][0] == pytest.approx(q.V, rel=1e-10)
    mu_ss = q.mu0 + (q.rs_a - q.rs_b) * math.log(q.V / q.v0)
    assert q.K * (q.V * t_end - b["x"][0]) == pytest.approx(q.sigma_n * mu_ss, rel=1e-9)


@pytest.mark.slow  # three more compositions to compile; the default run has the end drive's above
def test_dense_and_exact_bit_for_bit_with_the_plate_springs_per_bond_and_a_history():
    # the plate drive; springs per bond; a load history with a hold and threshold none
    hist = LoadHistory.steps([1e-3, 0.0, 3e-3], [100.0, 50.0, 150.0])
    cases = [
        (ChainParams(N=9, K=5.0, friction=LAW, dt=0.002, drive="plate", Kp=0.3, rs_c=0.7), 300.0),
        # springs per bond and masses per block (the stress rate reads K_i and K_i+1)
        (ChainParams(N=6, K=np.linspace(4.0, 6.0, 6), M=np.linspace(0.8, 1.2, 6), friction=LAW, dt=0.002), 300.0),
        (chain_params("sakaguchi", N=10, K=5.0, friction=LAW, dt=0.002, drive="history", history=hist,
                      threshold="none", V=3e-3), 300.0),
    ]  # fmt: skip
    _dense_is_exact(cases)


def test_critical_stiffness_from_the_characteristic_cubic():
    """M l^3 + (a s / V + M V / D_c) l^2 + (K (1 + c) + s (a - b) / D_c) l + K V / D_c = 0 (the
    spring-slider linearised by hand, s = sigma_n): its roots cross the imaginary axis at k_c."""
    for M, V in ((1.0, 1e-3), (1.0, 0.01), (0.2, 0.03)):
        p = _params(V=V, M=M, rs_c=2.0)
        s, a, b, c, dc = p.sigma_n, p.rs_a, p.rs_b, p.rs_c, p.Dc
        k_c = rate_state_nagata.critical_stiffness(p)
        for ratio, unstable in ((0.95, True), (1.05, False)):
            K = ratio * k_c
            roots = np.roots([M, a * s / V + M * V / dc, K * (1.0 + c) + s * (a - b) / dc, K * V / dc])
            assert (roots.real.max() > 0.0) == unstable
    # the laboratory's quasi-static k_c = (b - a) / (D_c (1 + c)) at M = 0, and the lab's inertial form
    lab = RateState(a=0.005, b=0.01, Dc=10.0, mu0=0.6, V0=1.0, k=1e-3, law="nagata", c=2.0)
    assert critical_stiffness_inertial(lab, 0.0, 1.0) == pytest.approx(0.005 / 30.0, rel=1e-14)
    assert critical_stiffness_inertial(lab, 50.0, 1.0) == pytest.approx(
        0.005 * (0.05 + 50.0) / (10.0 * (0.05 * 3.0 + 2.0 * 50.0)), rel=1e-14
    )


@pytest.mark.slow  # as the PRZ law's: its own compositions (threshold none, the lab's units)
def test_inertial_spring_slider_tends_to_the_lab_quasi_static_nagata_solution():
    """A velocity step 1 -> 3 (lab units: um, s) on the spring-slider with threshold none: the
    spring's friction k (p - x) of the inertial route (mass M per unit normal stress) against the
    quasi-static Nagata solution, sampled every 0.5 s, differs by an error first order in M, far
    below the transient; and the law's stress term is in it (the aging law's solution differs by
    more than the transient's tenth)."""
    model = RateState(a=0.005, b=0.01, Dc=10.0, mu0=0.6, V0=1.0, k=2e-3, law="nagata", c=2.0, form="asinh")
    history = LoadHistory.steps([1.0, 3.0], [20.0, 30.0])
    t = np.linspace(10.0, 50.0, 81)
    qs = quasi_static(model, history, t=t)
    aging = quasi_static(model.with_values(law="aging", c=0.0), history, t=t)
    errors = []
    for M in (2e-4, 1e-4):
        run = sample(model, M, history, t, dt=M / 4, v_init=1.0)
        errors.append(float(np.max(np.abs(run["mu"] - qs.mu.values))))
    transient = float(np.ptp(qs.mu.values))
    assert transient > 0.004
    assert float(np.max(np.abs(aging.mu.values - qs.mu.values))) > 0.1 * transient
    assert errors[1] < 0.05 * transient
    assert errors[1] == pytest.approx(errors[0] / 2.0, rel=0.15)  # first order in M


def test_located_switches_lattices_and_stability_refuse_the_law(capsys):
    from stickslip.analysis.dynamics import stability as st
    from stickslip.run.located import LocatedStepper

    p = _params(N=3)
    with pytest.raises(ParameterError, match="reads the stress rate, which the located integrator does not build"):
        LocatedStepper(p)
    with pytest.raises(ParameterError, match="reads the stress rate, which lattice square does not build"):
        chain_params("sakaguchi", lattice="square", shape=(4, 4), friction=LAW)
    with pytest.raises(ParameterError, match="has no linearisation here"):
        st.critical_stiffness(p)
    rc, _, err = run_cli(capsys, "chain", "--lattice", "square", "--shape", "4x4", "--friction", LAW, "--t-end", "1")
    assert rc == 2 and "reads the stress rate" in err and len(err.strip().splitlines()) == 1
