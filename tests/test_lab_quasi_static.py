"""The quasi-static spring-slider and its laws against closed forms and a plain-Python odeint model."""

import math

import numpy as np
import pytest

from stickslip.lab import LoadHistory, RateState, quasi_static, steady_friction
from stickslip.lab.reference import odeint_spring_slider
from stickslip.lab.stability import critical_stiffness, critical_stiffness_numeric, growth_rate
from stickslip.models.params import ParameterError

LAB = dict(a=0.005, b=0.01, Dc=10.0, mu0=0.6, V0=1.0)
LAWS = ("aging", "slip", "prz", "nagata")


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("form", ["log", "asinh"])
def test_steady_state_friction_after_a_step(law, form):
    """mu_ss = mu0 + (a - b) ln(V / V0), reached long after a step 1 -> 10 (each law)."""
    m = RateState(**LAB, k=1e-2, law=law, c=0.001, form=form)
    ds = quasi_static(m, LoadHistory.steps([1.0, 10.0], [10.0, 300.0]), n=11)
    expected = 0.6 + (0.005 - 0.01) * math.log(10.0)
    assert float(ds.mu[0]) == pytest.approx(0.6, abs=1e-12)
    assert float(ds.mu[-1]) == pytest.approx(expected, abs=1e-10)
    assert steady_friction(m, 10.0) == pytest.approx(expected, abs=1e-12)


def test_steady_state_with_two_state_variables():
    m = RateState(a=0.006, b=(0.004, 0.003), Dc=(5.0, 50.0), mu0=0.6, V0=1.0, k=5e-3, law=("aging", "slip"))
    ds = quasi_static(m, LoadHistory.steps([1.0, 3.0], [10.0, 2000.0]), n=11)
    assert ds.theta.dims == ("t", "state")
    assert float(ds.mu[-1]) == pytest.approx(0.6 + (0.006 - 0.007) * math.log(3.0), abs=1e-10)
    np.testing.assert_allclose(ds.theta[-1], [5.0 / 3.0, 50.0 / 3.0], rtol=1e-8)


def _rigid(law, V, theta0, t_end, n=41):
    """State under an imposed slip rate V (a rigid machine), from theta0."""
    m = RateState(**LAB, k=math.inf, law=law)
    h = LoadHistory.steps([V], [t_end])
    return m, quasi_static(m, h, theta_init=theta0, v_init=V, n=n, rtol=1e-12)


def test_aging_law_closed_form_at_constant_v():
    V, th0 = 3.0, 50.0
    _, ds = _rigid("aging", V, th0, 20.0)
    t = ds.t.values
    expected = 10.0 / V + (th0 - 10.0 / V) * np.exp(-V * t / 10.0)
    np.testing.assert_allclose(ds.theta, expected, rtol=1e-10)


def test_slip_law_closed_form_at_constant_v():
    V, th0 = 3.0, 50.0
    _, ds = _rigid("slip", V, th0, 20.0)
    t = ds.t.values
    expected = np.log(V * th0 / 10.0) * np.exp(-V * t / 10.0)
    np.testing.assert_allclose(np.log(V * ds.theta.values / 10.0), expected, rtol=1e-9, atol=1e-12)


def test_aging_law_heals_as_theta0_plus_t_in_a_true_hold():
    m = RateState(**LAB, k=math.inf, law="aging")
    ds = quasi_static(m, LoadHistory.steps([1.0, 0.0], [5.0, 1000.0]), n=51)
    hold = ds.t.values >= 5.0
    np.testing.assert_allclose(ds.theta.values[hold], 10.0 + (ds.t.values[hold] - 5.0), rtol=1e-12)
    # the slip law does not heal at v = 0
    ds = quasi_static(m.with_values(law="slip"), LoadHistory.steps([1.0, 0.0], [5.0, 1000.0]), n=51)
    np.testing.assert_allclose(ds.theta.values[hold], 10.0, rtol=1e-12)


def test_slip_law_responds_symmetrically_to_steps_up_and_down():
    """mu - mu_ss(new V) after 1 -> e^2 and after e^2 -> 1, as functions of slip: equal and opposite."""
    lam = math.exp(2.0)
    m = RateState(**LAB, k=math.inf, law="slip")
    up = quasi_static(m, LoadHistory.steps([lam], [60.0 / lam]), v_init=lam, theta_init=10.0, n=61)
    down = quasi_static(m, LoadHistory.steps([1.0], [60.0]), v_init=1.0, theta_init=10.0 / lam, n=61)
    np.testing.assert_allclose(up.slip, down.slip, rtol=1e-12)
    d_up = up.mu.values - steady_friction(m, lam)
    d_down = down.mu.values - steady_friction(m, 1.0)
    np.testing.assert_allclose(d_up, -d_down, atol=1e-11)
    np.testing.assert_allclose(d_up, 0.01 * 2.0 * np.exp(-up.slip.values / 10.0), atol=1e-11)
    # the aging law is not symmetric
    m = m.with_values(law="aging")
    up = quasi_static(m, LoadHistory.steps([lam], [60.0 / lam]), v_init=lam, theta_init=10.0, n=61)
    down = quasi_static(m, LoadHistory.steps([1.0], [60.0]), v_init=1.0, theta_init=10.0 / lam, n=61)
    assert np.max(np.abs(up.mu.values - steady_friction(m, lam) + down.mu.values - steady_friction(m, 1.0))) > 1e-3


@pytest.mark.parametrize("law", LAWS)
def test_velocity_step_agrees_with_plain_python_odeint(law):
    m = RateState(**{**LAB, "a": 0.008}, k=1e-3, law=law, c=0.002)
    h = LoadHistory.steps([1.0, 10.0, 3.0], [10.0, 40.0, 50.0])
    ds = quasi_static(m, h, n=401)
    mu, th, v = odeint_spring_slider(0.008, 0.01, 10.0, 0.6, 1.0, 1e-3, law, h, ds.t.values, c=0.002, rtol=1e-11)
    np.testing.assert_allclose(ds.mu, mu, rtol=0, atol=1e-9)
    # the state's global error is some 100 rtol near the peak slip rate, in both integrators
    np.testing.assert_allclose(ds.theta, th, rtol=1e-7)
    np.testing.assert_allclose(ds.v, v, rtol=1e-6)


@pytest.mark.parametrize("law", LAWS)
def test_two_state_velocity_step_of_each_law_agrees_with_plain_python_odeint(law):
    """The standard step 1 -> 10 at t = 10 with two state variables of one law (the two-state
    cases of the lab's usual test suite); at rtol 1e-11 (at 1e-10 this stiffer case's global error
    in mu is some 2e-9 in both integrators)."""
    kw = dict(a=0.011, b=(0.01, 0.005), Dc=(10.0, 50.0), mu0=0.6, V0=1.0, k=1e-2, c=(0.002, 0.002))
    h = LoadHistory.steps([1.0, 10.0], [10.0, 40.0])
    ds = quasi_static(RateState(**kw, law=(law, law)), h, n=401, rtol=1e-11)
    mu, th, v = odeint_spring_slider(
        0.011, (0.01, 0.005), (10.0, 50.0), 0.6, 1.0, 1e-2, (law, law), h, ds.t.values, c=(0.002, 0.002), rtol=1e-11
    )
    assert np.ptp(mu) > 0.02  # a real step: the direct effect and the evolution over both D_c
    np.testing.assert_allclose(ds.mu, mu, rtol=0, atol=1e-9)
    np.testing.assert_allclose(ds.theta, th, rtol=1e-7)
    np.testing.assert_allclose(ds.v, v, rtol=1e-6)


@pytest.mark.parametrize("method", ["LSODA", "Radau"])
def test_solve_ivp_route_agrees(method):
    m = RateState(**LAB, k=1e-3)
    h = LoadHistory.steps([1.0, 10.0], [10.0, 40.0])
    a = quasi_static(m, h, n=51)
    b = quasi_static(m, h, n=51, method=method)
    np.testing.assert_allclose(a.mu, b.mu, atol=1e-8)


def test_radiation_damping_keeps_the_steady_state_and_slows_the_jump():
    h = LoadHistory.steps([1.0, 100.0], [10.0, 10.0])
    plain = quasi_static(RateState(**LAB, k=1e-2), h, n=201)
    damped = quasi_static(RateState(**LAB, k=1e-2, eta=1e-4), h, n=201)
    # tau = mu + eta v: the steady state shifts by eta V
    assert float(damped.mu[0]) == pytest.approx(0.6 + 1e-4, abs=1e-12)
    assert float(damped.v.max()) < float(plain.v.max())


def test_critical_stiffness_one_state_closed_form():
    for law in ("aging", "slip", "prz"):
        m = RateState(**LAB, law=law)
        assert critical_stiffness(m) == pytest.approx((0.01 - 0.005) / 10.0, rel=1e-14)
        assert critical_stiffness_numeric(m) == pytest.approx(5e-4, rel=1e-6)
    m = RateState(**LAB, law="nagata", c=0.002)
    assert critical_stiffness_numeric(m) == pytest.approx(5e-4 / 1.002, rel=1e-6)


@pytest.mark.parametrize(
    ("b", "Dc"), [((0.01, 0.004), (10.0, 100.0)), ((0.01, -0.004), (10.0, 100.0)), ((0.003, 0.004), (1.0, 50.0))]
)
def test_critical_stiffness_two_states_against_the_linearisation(b, Dc):
    m = RateState(a=0.005, b=b, Dc=Dc, mu0=0.6, V0=1.0)
    kc = critical_stiffness_numeric(m)
    if kc > 0.0:
        assert critical_stiffness(m) == pytest.approx(kc, rel=1e-6)
        assert growth_rate(m, 0.99 * kc) > 0.0 > growth_rate(m, 1.01 * kc)
    else:
        assert critical_stiffness(m) <= 0.0
    # a second state variable with b2 = 0 changes nothing
    m0 = RateState(a=0.005, b=(0.01, 0.0), Dc=Dc, mu0=0.6, V0=1.0)
    assert critical_stiffness(m0) == pytest.approx((0.01 - 0.005) / Dc[0], rel=1e-12)


def test_stability_boundary_in_the_nonlinear_spring_slider():
    """A small step grows into oscillations below k_c and dies out above it."""
    kc = 5e-4
    h = LoadHistory.steps([1.0, 1.01], [1.0, 600.0])
    amp = {}
    for f in (0.9, 1.1):
        ds = quasi_static(RateState(**LAB, k=f * kc), h, n=3001)
        late = ds.mu.values[ds.t.values > 400]
        early = ds.mu.values[(ds.t.values > 50) & (ds.t.values < 150)]
        amp[f] = np.ptp(late) / np.ptp(early)
    assert amp[0.9] > 1.0 > amp[1.1]


def test_missing_and_bad_parameters():
    with pytest.raises(ParameterError, match="Dc is required"):
        RateState(a=0.005, b=0.01, mu0=0.6, V0=1.0)
    with pytest.raises(ParameterError, match="k is required"):
        quasi_static(RateState(**LAB), LoadHistory.steps([1.0], [1.0]))
    with pytest.raises(ParameterError, match="a must be > 0"):
        RateState(**{**LAB, "a": -1.0})
    with pytest.raises(ParameterError, match="law must be one of"):
        RateState(**LAB, law="dieterich")
    with pytest.raises(ParameterError, match="one value per state variable"):
        RateState(a=0.005, b=(0.01, 0.01), Dc=(1.0,), mu0=0.6, V0=1.0)
    with pytest.raises(ParameterError, match="singular"):
        quasi_static(RateState(**LAB, k=1e-3), LoadHistory.steps([0.0, 1.0], [1.0, 1.0]))


def test_two_state_variables_and_damping_agree_with_plain_python_odeint():
    """Two state variables of different laws, with radiation damping (v by Newton's method here,
    by Brent's method in the reference)."""
    kw = dict(a=0.008, b=(0.006, 0.004), Dc=(5.0, 50.0), mu0=0.6, V0=1.0, k=2e-3, law=("aging", "slip"))
    h = LoadHistory.steps([1.0, 10.0, 0.0, 10.0], [10.0, 40.0, 30.0, 40.0])
    for eta in (0.0, 2e-4):
        ds = quasi_static(RateState(**kw, eta=eta), h, n=241)
        mu, th, v = odeint_spring_slider(
            0.008, (0.006, 0.004), (5.0, 50.0), 0.6, 1.0, 2e-3, ("aging", "slip"), h, ds.t.values, eta=eta,
            rtol=1e-11,
        )  # fmt: skip
        np.testing.assert_allclose(ds.mu, mu, rtol=0, atol=1e-9)
        np.testing.assert_allclose(ds.theta, th, rtol=1e-7)
        np.testing.assert_allclose(ds.v, v, rtol=1e-6)


def test_asinh_form_matches_the_log_form_away_from_v_0():
    h = LoadHistory.steps([1.0, 10.0], [10.0, 40.0])
    a = quasi_static(RateState(**LAB, k=1e-3), h, n=101)
    b = quasi_static(RateState(**LAB, k=1e-3, form="asinh"), h, n=101)
    # the forms differ by terms of relative size exp(-2 mu / a) ~ 1e-104
    np.testing.assert_allclose(a.mu, b.mu, atol=1e-10)


def test_same_physics_as_the_inertial_models_rate_state_pieces():
    """The lab's aging and slip laws and its asinh friction are those of the package's inertial
    friction pieces (models/friction/rate_state.py, rate_state_slip.py) at the same parameters."""
    from stickslip.lab.laws import friction_of, rhs
    from stickslip.models.friction import rate_state, rate_state_slip

    lp = rate_state.Params(rs_a=0.005, rs_b=0.01, Dc=10.0, v0=1.0, mu0=0.6, sigma_n=1.0)
    for law, piece in (("aging", rate_state), ("slip", rate_state_slip)):
        m = RateState(**LAB, k=math.inf, law=law, form="asinh")
        out = np.empty(2)
        for v, th in ((2.0, 30.0), (0.3, 4.0), (50.0, 0.1)):
            rhs(0.0, np.array([0.0, th]), out, v, *m.arrays())
            assert out[1] == pytest.approx(piece.rate(0.0, th, 0.0, v, lp), rel=1e-14)
            assert friction_of(m, v, th) == pytest.approx(rate_state.mu_lp(v, th, lp), rel=1e-14)


def test_auto_takes_lsoda_for_a_very_stiff_spring():
    h = LoadHistory.steps([1.0, 10.0], [10.0, 30.0])
    stiff = RateState(**LAB, k=1.0)  # k V Dc / a = 20000
    ds = quasi_static(stiff, h, n=61)
    assert ds.attrs["integrator"] == "LSODA"
    np.testing.assert_allclose(ds.mu, quasi_static(stiff, h, n=61, method="Radau").mu, atol=1e-9)
    assert quasi_static(RateState(**LAB, k=1e-3), h, n=61).attrs["integrator"] == "dop853"
