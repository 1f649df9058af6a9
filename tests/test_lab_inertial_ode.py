"""The inertial spring-slider with any number of state variables (stickslip.lab.inertial_slider)
against three independent answers: a plain-Python right-hand side written here from the equations
and integrated by scipy, the chain's single block (N = 1, threshold none: the kernels' own fixed-step
integrator, which shares no code with the lab's), and the quasi-static spring-slider, which it must
approach linearly in the mass.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from stickslip.lab import LoadHistory, RateState, inertial_slider, quasi_static, slide_hold_slide, velocity_step
from stickslip.lab.laws import friction_of
from stickslip.models.params import ParameterError
from stickslip.models.presets import chain_params
from stickslip.run.driver import ChainState, run_chain

LAB = dict(a=0.005, mu0=0.6, V0=1.0)


def _written_rhs(t, y, *, a, b, dc, k, M, eta, V):
    """M dv/dt = tau - mu0 - a ln(v / V0) - sum b_k ln(V0 theta_k / D_c,k) - eta v, dtau/dt = k (V - v),
    theta_1 by the aging law 1 - v theta / D_c and theta_2 by the slip law -x ln x (log form)."""
    tau, v, th1, th2 = y
    mu = 0.6 + a * math.log(v) + b[0] * math.log(th1 / dc[0]) + b[1] * math.log(th2 / dc[1])
    x2 = v * th2 / dc[1]
    return [k * (V - v), (tau - mu - eta * v) / M, 1.0 - v * th1 / dc[0], -x2 * math.log(x2)]


def test_two_state_variables_agree_with_a_plain_python_right_hand_side_to_1e_9():
    b, dc, k, M, eta = (0.006, 0.004), (5.0, 50.0), 2e-3, 1e-3, 1e-4
    model = RateState(**LAB, b=b, Dc=dc, law=("aging", "slip"), k=k, eta=eta)
    t = np.linspace(0.0, 60.0, 121)
    ds = inertial_slider(model, LoadHistory.steps([1.0, 3.0], [20.0, 40.0]), M, t=t, rtol=1e-12, atol=1e-14)
    # the same start: steady sliding at V = 1 (theta_k = D_c,k), the spring at mu_ss + eta
    y = [0.6 + eta, 1.0, dc[0], dc[1]]
    pieces = []
    for t0, t1, V in ((0.0, 20.0, 1.0), (20.0, 60.0, 3.0)):
        inside = t[(t >= t0) & (t <= t1)]
        sol = solve_ivp(
            lambda tt, yy, V=V: _written_rhs(tt, yy, a=0.005, b=b, dc=dc, k=k, M=M, eta=eta, V=V),
            (t0, t1), y, method="DOP853", t_eval=inside, rtol=1e-13, atol=1e-14,
        )  # fmt: skip
        assert sol.status == 0
        pieces.append(sol.y[:, : -1 if t1 < 60.0 else None])
        y = sol.y[:, -1]
    ref = np.concatenate(pieces, axis=1)
    np.testing.assert_allclose(ds.mu.values, ref[0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(ds.v.values, ref[1], rtol=1e-8)
    np.testing.assert_allclose(ds.theta.values, ref[2:].T, rtol=1e-8)
    assert ds.theta.dims == ("t", "state") and ds.attrs["M"] == M
    # the step did something the test can see: the slip rate rings about its new value
    assert ds.v.values.max() > 3.2


def test_one_state_variable_agrees_with_the_chains_single_block():
    # the slide-hold-slide of the threshold-none tests: the chain's N = 1 with a mass, Heun at dt = M / 4
    A, B, DC, K, M = 0.005, 0.01, 10.0, 1e-3, 5e-4
    shs = LoadHistory.steps([1.0, 0.0, 1.0], [20.0, 10.0, 40.0])
    model = RateState(**LAB, b=B, Dc=DC, k=K, form="asinh")
    T = np.array([10.0, 25.0, 30.0, 35.0, 40.0, 50.0, 69.0])
    x0 = -friction_of(model, 1.0, np.array([DC])) / K
    p = chain_params(
        "sakaguchi", N=1, drive="history", history=shs, friction="rate-state", threshold="none",
        rs_a=A, rs_b=B, Dc=DC, v0=1.0, mu0=0.6, sigma_n=1.0, K=K, M=M, dt=M / 4, V=1.0,
    )  # fmt: skip
    run = run_chain(p, 69.0, integrator="exact", start=ChainState.from_blocks([x0], [1.0], [DC], [False]),
                    snapshot_times=T[:-1])  # fmt: skip
    chain_slip = run.snapshots.values[:, 0] - x0
    for method in ("LSODA", "dop853"):
        ds = inertial_slider(model, shs, M, t=T, method=method, rtol=1e-11, atol=1e-13)
        # a slip of 60 to 1e-8; the quasi-static run differs by 0.07 at this mass
        np.testing.assert_allclose(ds.slip.values, chain_slip, rtol=0, atol=1e-7)
    assert np.max(np.abs(quasi_static(model, shs, t=T).slip.values - chain_slip)) > 0.05


@pytest.mark.parametrize("laws", [("aging", "slip"), ("prz", "nagata")])
def test_it_tends_to_the_quasi_static_spring_slider_linearly_in_the_mass(laws):
    model = RateState(**LAB, b=(0.006, 0.004), Dc=(5.0, 50.0), law=laws, c=(0.0, 1.0) if "nagata" in laws else 0.0,
                      k=2e-3, form="asinh", eta=1e-4)  # fmt: skip
    history = LoadHistory.steps([1.0, 3.0, 0.0, 1.0], [20.0, 60.0, 20.0, 60.0])  # a step and a hold
    t = np.linspace(0.0, 160.0, 161)
    qs = quasi_static(model, history, t=t)
    masses = np.array([4e-4, 2e-4, 1e-4])
    errors = np.array([np.max(np.abs(inertial_slider(model, history, M, t=t).slip - qs.slip)) for M in masses])
    slope = np.polyfit(np.log(masses), np.log(errors), 1)[0]
    assert 0.9 < slope < 1.15, (slope, errors)
    assert errors[-1] < 0.1  # of a slip of 160


def test_steady_sliding_stays_steady_and_a_kick_rings_down_to_it():
    model = RateState(**LAB, b=(0.006, 0.004), Dc=(5.0, 50.0), law=("aging", "prz"), k=2e-3)
    flat = LoadHistory.steps([2.0], [100.0])
    ds = inertial_slider(model, flat, 1e-3, n=51)
    mu_ss = 0.6 + (0.005 - 0.01) * math.log(2.0)
    np.testing.assert_allclose(ds.mu.values, mu_ss, rtol=0, atol=1e-12)
    np.testing.assert_allclose(ds.v.values, 2.0, rtol=1e-11)
    np.testing.assert_allclose(
        ds.theta.values, np.broadcast_to([2.5, 50.0], (51, 2)), rtol=1e-11
    )  # s_k D_c,k / V, s = 2 for PRZ
    kicked = inertial_slider(model, LoadHistory.steps([2.0], [2000.0]), 1e-3, n=51, kick=0.2)
    assert kicked.v.values[0] == pytest.approx(2.4)
    assert abs(kicked.v.values[-1] - 2.0) < 1e-6  # k > k_c: the kick dies out


def test_protocols_and_the_command_line_take_a_mass(tmp_path, capsys):
    from stickslip.cli import main

    model = RateState(**LAB, b=(0.006, 0.004), Dc=(5.0, 50.0), law=("aging", "slip"), k=2e-3)
    ds, summary = velocity_step(model, (1.0, 3.0), M=1e-4)
    assert summary["M"] == 1e-4 and ds.attrs["M"] == 1e-4
    assert summary["steps"][0]["a_minus_b_from_run"] == pytest.approx(0.005 - 0.01, rel=1e-6)
    _, shs = slide_hold_slide(RateState(**LAB, b=0.01, Dc=10.0, k=1e-3, form="asinh"), 1.0, (1.0, 10.0), M=1e-3)
    assert shs["M"] == 1e-3 and shs["holds"][1]["delta_mu"] > shs["holds"][0]["delta_mu"] > 0.0
    args = "lab step --a 0.005 --b 0.006,0.004 --Dc 5,50 --law aging,slip --mu0 0.6 --V0 1 --k 2e-3 --V 1,3"
    assert main([*args.split(), "--M", "1e-4"]) == 0
    assert "inertial, M = 0.0001" in capsys.readouterr().out


def test_bad_input_is_refused_in_one_line():
    model = RateState(**LAB, b=0.01, Dc=10.0, k=1e-3)
    history = LoadHistory.steps([1.0], [10.0])
    for M, match in ((0.0, "M must be > 0"), (-1.0, "M must be > 0"), (math.nan, "M")):
        with pytest.raises(ParameterError, match=match):
            inertial_slider(model, history, M)
    with pytest.raises(ParameterError, match="finite k"):
        inertial_slider(RateState(**LAB, b=0.01, Dc=10.0, k=math.inf), history, 1e-3)
    with pytest.raises(ParameterError, match="kick"):
        inertial_slider(model, history, 1e-3, kick=-1.0)
    with pytest.raises(ParameterError, match="history starts at V = 0"):
        inertial_slider(model, LoadHistory.steps([0.0, 1.0], [5.0, 5.0]), 1e-3)


def test_a_two_state_stick_slip_record_is_inverted_with_honest_errors():
    from stickslip.lab.inertial import chain_params_of, on_chain
    from stickslip.lab.inversion import invert_stick_slip, synthetic_stick_slip

    truth = RateState(**LAB, b=(0.008, 0.003), Dc=(1.0, 5.0), law=("aging", "slip"), k=2.5e-3, form="asinh")
    assert not on_chain(truth)
    with pytest.raises(ParameterError, match="inertial_slider has the rest"):
        chain_params_of(truth, 1e-2, 2.5e-3, LoadHistory.steps([1.0], [10.0]))
    M, history = 1e-2, LoadHistory.steps([1.0], [400.0])
    record = synthetic_stick_slip(truth, M, history, sample_interval=0.2, noise=5e-5, rng=3)
    assert record.mu.max() - record.mu.min() > 0.03  # stick-slip, not steady sliding
    res = invert_stick_slip(record, truth.with_values(b1=0.0085, Dc1=0.9), M, ("b1", "Dc1"))
    for name, value in (("b1", 0.008), ("Dc1", 1.0)):
        fitted, err = res[name]
        assert abs(fitted - value) < 2.0 * err, (name, fitted, err)
        assert err < 0.05 * value


def test_critical_stiffness_with_a_mass_is_rice_and_ruinas_and_the_runs_obey_it():
    from stickslip.lab.stability import critical_stiffness, critical_stiffness_numeric

    one = RateState(**LAB, b=0.01, Dc=10.0, k=1e-3)
    for M, V in ((1e-3, 1.0), (1.0, 1.0), (10.0, 2.0)):
        # Rice and Ruina 1983: k_c = (b - a) / D_c (1 + M V^2 / (a D_c))
        closed = (0.01 - 0.005) / 10.0 * (1.0 + M * V * V / (0.005 * 10.0))
        assert critical_stiffness_numeric(one, V, M=M) == pytest.approx(closed, rel=1e-6)
    two = RateState(**LAB, b=(0.006, 0.004), Dc=(5.0, 50.0), law=("aging", "slip"), k=1e-3)
    kcs = [critical_stiffness_numeric(two, 1.0, M=M) for M in (1e-6, 1e-4, 1e-2)]
    # as M -> 0 the two-state quasi-static closed form (Gu, Rice, Ruina and Tse 1984); inertia destabilises
    assert kcs[0] == pytest.approx(critical_stiffness(two, 1.0), rel=1e-4)
    assert kcs[0] < kcs[1] < kcs[2]
    history = LoadHistory.steps([1.0], [3000.0])
    for factor, grows in ((0.8, True), (1.25, False)):
        ds = inertial_slider(two.with_values(k=factor * kcs[2]), history, 1e-2, n=3001, kick=0.01)
        swing = np.abs(ds.v.values - 1.0)
        late = swing[ds.t.values > 2500.0].max()
        assert (late > 10.0 * swing[0]) if grows else (late < 1e-6 * swing[0]), (factor, late)


@pytest.mark.parametrize("method", ["LSODA", "Radau"])
def test_the_solve_ivp_routes_count_their_steps_not_their_outputs(method):
    model = RateState(**LAB, b=(0.006, 0.004), Dc=(5.0, 50.0), law=("aging", "slip"), k=1e-3, form="asinh")
    history = LoadHistory.steps([1.0, 10.0, 0.0, 1.0], [10.0, 40.0, 30.0, 40.0])
    for run in (quasi_static, lambda m, h, **kw: inertial_slider(m, h, 1e-3, **kw)):
        few, many = (run(model, history, n=n, method=method) for n in (11, 301))
        # the step sequence does not depend on where the outputs are read
        assert few.attrs["steps"] == many.attrs["steps"] > 0
        assert few.attrs["evaluations"] > few.attrs["steps"]


def test_auto_crosses_a_short_hold_explicitly_and_a_long_one_with_lsoda():
    from stickslip.lab.integrate import HOLD_BUDGET

    model = RateState(**LAB, b=0.012, Dc=10.0, k=5e-3, form="asinh").with_values(a=0.01)
    short = inertial_slider(model, LoadHistory.steps([1.0, 0.0, 1.0], [20.0, 10.0, 40.0]), 1e-3, n=71)
    assert short.attrs["integrator"] == "dop853" and short.attrs["steps"] < HOLD_BUDGET
    history = LoadHistory.slide_hold_slide(10.0, 20.0, [300.0])
    t = np.linspace(0.0, history.t_end, 201)
    long = inertial_slider(model, history, 1e-5, t=t)
    assert long.attrs["integrator"] == "LSODA"
    np.testing.assert_array_equal(long.mu.values, inertial_slider(model, history, 1e-5, t=t, method="LSODA").mu.values)
