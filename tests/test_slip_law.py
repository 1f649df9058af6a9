"""Ruina's slip law of rate-and-state friction (models/friction/rate_state_slip.py).

Known answers: its linearisation at steady sliding, hence the spring-slider's critical stiffness,
is the aging law's (Ruina 1983); after a step of the sliding velocity its friction relaxes
symmetrically in ln V, the aging law's does not (closed forms of both state laws at constant
velocity, written here). The kernels' step is held to a plain-Python step of the equations.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from stickslip.analysis.dynamics import stability as st
from stickslip.models.friction import rate_state, rate_state_slip
from stickslip.models.params import ChainParams
from stickslip.run.driver import run_chain
from stickslip.run.located import run_located
from test_rate_state import _k_c, _mu, steps_against_the_plain_step

LAW = "rate-state-slip"


def _params(**kw) -> ChainParams:
    return ChainParams(**{"N": 1, "friction": LAW, **kw})


def _slip(p, v, th):
    """The slip law dtheta/dt = -(|v| theta / D_c) ln(|v| theta / D_c), 0 at v = 0."""
    w = abs(v) * th / p.Dc
    return 0.0 if w == 0.0 else -w * math.log(w)


def test_the_law_is_its_own_module_and_a_choice():
    p = _params()
    assert p.friction_piece.module == rate_state_slip.__name__
    assert p.friction_piece.has_state
    assert p.friction_piece.start_theta(p) == pytest.approx(p.Dc / p.V)
    with pytest.raises(ValueError, match="V > 0"):
        _params(V=0.0)


@pytest.mark.parametrize(("V", "N"), [(1e-5, 1), (1e-3, 1), (0.01, 1), (0.002, 4)])
def test_critical_stiffness_equals_the_aging_laws(V, N):
    slip = _params(V=V, N=N)
    aging = slip.replace(friction="rate-state")
    assert st.critical_stiffness(slip) == pytest.approx(st.critical_stiffness(aging), rel=1e-12)
    if N == 1:
        assert st.critical_stiffness(slip) == pytest.approx(_k_c(slip), rel=1e-9)


def _state_after_step(law, p, v0, v1, slips):
    """theta after slipping ``slips`` at velocity v1 from steady state at v0, by RK4 on the law's
    own compiled rate (small steps in slip)."""
    lp = law.PIECE.kernel_params(p)
    th = p.Dc / v0
    out, s, h = [], 0.0, p.Dc / 2000.0
    for target in slips:
        while s < target - 1e-15:
            dt = min(h, target - s) / v1
            k1 = law.rate(0.0, th, 0.0, v1, lp)
            k2 = law.rate(0.0, th + 0.5 * dt * k1, 0.0, v1, lp)
            k3 = law.rate(0.0, th + 0.5 * dt * k2, 0.0, v1, lp)
            k4 = law.rate(0.0, th + dt * k3, 0.0, v1, lp)
            th += dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
            s += dt * v1
        out.append(th)
    return np.array(out)


def test_velocity_steps_symmetric_in_ln_v_for_the_slip_law_only():
    p = _params(V=1e-3)
    r = 10.0
    slips = np.array([0.25, 0.5, 1.0, 2.0, 4.0]) * p.Dc
    ln_up = {}
    ln_down = {}
    for name, law in (("slip", rate_state_slip), ("aging", rate_state)):
        up = _state_after_step(law, p, p.V, r * p.V, slips)
        down = _state_after_step(law, p, p.V, p.V / r, slips)
        # ln Omega = ln(v theta / D_c): the state's part of the friction, b ln Omega, above steady state
        ln_up[name] = np.log(r * p.V * up / p.Dc)
        ln_down[name] = np.log(p.V / r * down / p.Dc)
    decay = np.exp(-slips / p.Dc)
    # slip law: ln Omega = ln(V1 / V0) exp(-slip / D_c), mirror images up and down
    np.testing.assert_allclose(ln_up["slip"], math.log(r) * decay, rtol=1e-8)
    np.testing.assert_allclose(ln_down["slip"], -math.log(r) * decay, rtol=1e-8)
    # aging law: Omega = 1 + (Omega_0 - 1) exp(-slip / D_c), not symmetric
    np.testing.assert_allclose(ln_up["aging"], np.log1p((r - 1.0) * decay), rtol=1e-8)
    np.testing.assert_allclose(ln_down["aging"], np.log1p((1.0 / r - 1.0) * decay), rtol=1e-8)
    assert np.all(np.abs(ln_up["aging"] + ln_down["aging"]) > 0.1 * np.abs(ln_up["aging"]))
    # The friction the kernels see (the law's accel, f = 0): its excess over steady sliding at the
    # new velocity is sigma_n b ln Omega, mirror images up and down for the slip law.
    lp = rate_state_slip.PIECE.kernel_params(p)

    def excess(v, ln_omega):
        theta = p.Dc / v * math.exp(ln_omega)
        friction = -rate_state_slip.accel(0.0, v, theta, lp)
        assert friction == pytest.approx(p.sigma_n * _mu(p, v, theta), rel=1e-12)
        return friction + rate_state_slip.accel(0.0, v, p.Dc / v, lp)

    up = np.array([excess(r * p.V, w) for w in ln_up["slip"]])
    down = np.array([excess(p.V / r, w) for w in ln_down["slip"]])
    np.testing.assert_allclose(up, p.sigma_n * p.rs_b * math.log(r) * decay, rtol=1e-6)
    np.testing.assert_allclose(up, -down, rtol=1e-6)


def test_a_stuck_block_does_not_heal():
    p = _params()
    lp = p.friction_piece.kernel_params(p)
    assert rate_state_slip.rate(0.0, 5.0, 0.0, 0.0, lp) == 0.0
    assert rate_state.rate(0.0, 5.0, 0.0, 0.0, rate_state.PIECE.kernel_params(p)) == 1.0


@pytest.mark.parametrize("integrator", ["dense", "exact"])
def test_one_kernel_step_against_the_plain_step(integrator):
    b = steps_against_the_plain_step(_params(N=4, K=12.0, Fs=2.9), integrator, g=_slip)
    assert b["theta"][1] == 3.0  # the stuck block keeps its state


def test_dense_and_exact_identical():
    p = ChainParams(N=5, K=5.0, friction=LAW)
    runs = [run_chain(p, 400.0, integrator=i, start="steady", perturbation=1e-4) for i in ("dense", "exact")]
    assert runs[0].summary["state_sha256"] == runs[1].summary["state_sha256"]
    assert len(runs[0].events) > 0


@pytest.mark.slow  # the located kernels of this law alone (the aging law's run by default: test_rate_state.py)
def test_located_switches_run():
    # with no switch on the way, located switches and the grid integrate the same equations
    spring_slider = _params(V=0.01, K=10.0)
    located = run_located(spring_slider, 300.0, start="steady", perturbation=1e-3)
    grid = run_chain(spring_slider, 300.0, start="steady", perturbation=1e-3)
    assert len(located.events) == len(grid.events) == 0
    assert located.state.th[1] == pytest.approx(grid.state.theta[0], rel=1e-9)
    assert located.state.th[1] != pytest.approx(spring_slider.Dc / spring_slider.V, rel=1e-3)
