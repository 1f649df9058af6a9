"""Inversion of inertial stick-slip records (stickslip.lab.cycles, .inertial, .inversion): the
observables of closed-form signals, the period of the neutral oscillation at the inertial critical
stiffness (Rice and Ruina 1983), parameters recovered from synthetic records made by the forward
model with noise, and the command line's bad input.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from stickslip.cli import main
from stickslip.lab import LoadHistory, RateState
from stickslip.lab.cycles import cycle_table, observables
from stickslip.lab.inertial import critical_stiffness_inertial, sample
from stickslip.lab.inversion import invert_stick_slip, synthetic_stick_slip
from stickslip.models.params import ParameterError

# Stick-slip well below k_c = (b - a) / D_c (1 + M V^2 / (a D_c)) = 0.015: a period of about 35,
# slips of about 6 time units at a peak slip rate of about 7 V.
TRUE = RateState(a=0.005, b=0.01, Dc=1.0, mu0=0.6, V0=1.0, k=2.5e-3, form="asinh")
M = 1e-2
HISTORY = LoadHistory.steps([1.0], [400.0])


@pytest.fixture(scope="module")
def noisy():
    return synthetic_stick_slip(TRUE, M, HISTORY, sample_interval=0.2, noise=5e-5, rng=3)


def test_cycles_of_a_sinusoid_are_its_closed_form_period_drop_and_rates():
    A, w, c, V, k = 0.01, 2.0 * math.pi / 7.0, 0.6, 0.5, 2e-3
    t = np.arange(0.0, 70.0, 0.01)
    table = cycle_table(t, c + A * np.sin(w * t), V=V, k=k)
    assert len(table) == 9  # ten falls through the middle; the last one's trough is not followed by a rise
    mean, _, _ = observables(table)
    np.testing.assert_allclose(mean[[0, 1, 3]], [2.0 * math.pi / w, 2.0 * A, c + A], rtol=1e-6)
    # the five-point Savitzky-Golay slope of a sine is short by (w dt)^2 / 2 = 4e-5 of it
    assert mean[2] == pytest.approx(V + A * w / k, rel=1e-4)
    np.testing.assert_allclose(table.peak_drop_rate.dropna(), A * w, rtol=1e-4)


def test_noise_about_the_middle_makes_no_extra_cycles():
    t = np.arange(0.0, 70.0, 0.01)
    mu = 0.6 + 0.01 * np.sin(t) + np.random.default_rng(0).normal(0.0, 1e-3, t.size)
    table = cycle_table(t, mu, V=1.0, k=1.0)
    assert len(table) == 10
    assert table.period.mean() == pytest.approx(2.0 * math.pi, rel=2e-3)


def test_too_few_cycles_is_an_error_naming_what_to_do():
    t = np.linspace(0.0, 10.0, 200)
    with pytest.raises(ParameterError, match="found 0 slip"):
        cycle_table(t, 0.6 + 0.0 * t, V=1.0, k=1.0)


# each mass a 160-time-unit record at dt = 2e-3 (about 100 s, measured): -m slow
@pytest.mark.parametrize(
    "mass", [pytest.param(1e-2, marks=pytest.mark.slow), pytest.param(5e-2, marks=pytest.mark.slow)]
)
def test_the_neutral_oscillation_at_the_inertial_critical_stiffness_has_the_rice_ruina_period(mass):
    # Linearised about steady sliding, M s^3 + (M V / D_c + a / V) s^2 + (k + (a - b) / D_c) s
    # + k / D_c = 0 has s = +-i w at k = k_c, with w = (V / D_c) sqrt((b - a) / a) whatever M:
    # a small kick oscillates with the period 2 pi / w.
    model = TRUE.with_values(Dc=2.0, k=1.0)
    k_c = (0.01 - 0.005) / 2.0 * (1.0 + mass / (0.005 * 2.0))
    assert critical_stiffness_inertial(model, mass, 1.0) == pytest.approx(k_c, rel=1e-14)
    model = model.with_values(k=k_c)
    t = np.arange(0.0, 160.0, 0.05)
    s = sample(model, mass, LoadHistory.steps([1.0], [160.0]), t, dt=2e-3, kick=1e-3)
    table = cycle_table(s["t"], s["mu"], V=1.0, k=k_c, window=(40.0, 160.0))
    w = 1.0 / 2.0 * math.sqrt((0.01 - 0.005) / 0.005)
    assert table.period.mean() == pytest.approx(2.0 * math.pi / w, rel=2e-3)
    # neutral: the amplitude neither grows nor decays much over ten periods
    drops = table.stress_drop.dropna().values
    assert abs(drops[-1] / drops[0] - 1.0) < 0.05


@pytest.mark.slow  # a second fit of two parameters (20-40 s under load)
def test_noise_free_record_gives_back_its_parameters():
    rec = synthetic_stick_slip(TRUE, M, HISTORY, sample_interval=0.2)
    res = invert_stick_slip(rec, TRUE.with_values(b=0.0105, Dc=0.9), M, ("b", "Dc"))
    np.testing.assert_allclose(res.values, [0.01, 1.0], rtol=2e-3)
    assert res.chi2 < 1e-2
    s = res.summary()
    assert s["kind"] == "stick-slip" and s["cycles"] >= 4
    assert s["observables"]["period"]["observed"] == pytest.approx(35.25, rel=2e-3)


def test_noisy_record_recovers_the_parameters_within_two_standard_errors(noisy):
    res = invert_stick_slip(noisy, TRUE.with_values(b=0.0105, Dc=0.9), M, ("b", "Dc"))
    for name, truth in (("b", 0.01), ("Dc", 1.0)):
        value, err = res[name]
        assert abs(value - truth) < 2.0 * err, (name, value, err)
        assert err < 0.05 * truth  # and the interval says something
    ds = res.to_dataset()
    assert list(ds.parameter.values) == ["b", "Dc"] and ds.model_mu.size == res.series["t"].size


@pytest.mark.slow  # three parameters, a mass among them: about a minute of CPU
def test_three_parameters_with_the_mass_within_two_standard_errors(noisy):
    res = invert_stick_slip(noisy, TRUE.with_values(a=0.0055, b=0.0105), 1.2e-2, ("a", "b", "M"), dt=M / 4)
    for name, truth in (("a", 0.005), ("b", 0.01), ("M", M)):
        value, err = res[name]
        assert abs(value - truth) < 2.0 * err, (name, value, err)


@pytest.mark.slow  # a record made, then a fit (about 20 s under load)
def test_a_table_of_cycles_is_inverted_at_its_velocity():
    rec = synthetic_stick_slip(TRUE, M, HISTORY, sample_interval=0.2)
    table = cycle_table(rec.t, rec.mu, V=1.0, k=TRUE.k, window=(200.0, 400.0))
    res = invert_stick_slip(
        table[["period", "stress_drop"]], TRUE.with_values(Dc=0.9), M, ("Dc",), observables_=("period", "stress_drop"),
        V=1.0, sample_interval=0.2,
    )  # fmt: skip
    assert res["Dc"][0] == pytest.approx(1.0, rel=3e-3)


def _write(path, rec):
    pd.DataFrame({"time": rec.t, "mu": rec.mu, "load_point": rec.history.position(rec.t)}).to_csv(path, index=False)


OPTS = ["--a", "0.005", "--b", "0.0105", "--Dc", "1", "--mu0", "0.6", "--V0", "1", "--k", "2.5e-3"]


def test_cli_invert_json_and_outputs(capsys, tmp_path):
    # a coarse record (a sample every 0.5, a dozen per slip) keeps the fit cheap
    rec = synthetic_stick_slip(TRUE, M, LoadHistory.steps([1.0], [330.0]), sample_interval=0.5, noise=5e-5, rng=4)
    path = tmp_path / "ss.csv"
    _write(path, rec)
    argv = ["lab", "invert", str(path), *OPTS, "--M", "1e-2", "--free", "b", "--observables", "period,stress_drop"]
    assert main([*argv, "--json", "--out", str(tmp_path / "o")]) == 0
    d = json.loads(capsys.readouterr().out)
    value, err = d["parameters"]["b"]["value"], d["parameters"]["b"]["stderr"]
    assert abs(value - 0.01) < 2.0 * err
    assert d["cycles"] >= 3 and set(d["observables"]) == {"period", "stress_drop"}
    assert {"invert.nc", "invert.json", "invert.png"} <= {p.name for p in (tmp_path / "o").iterdir()}


@pytest.mark.parametrize(
    "extra, message",
    [
        ([], "--M is required"),
        (["--M", "0"], "M must be"),
        (["--M", "1e-2", "--free", "a,V0"], "cannot fit 'V0'"),
        (["--M", "1e-2", "--free", "a,b,Dc", "--observables", "period,stress_drop"], "need at least as many"),
        (["--M", "1e-2", "--observables", "period,size"], "observables must be distinct names"),
        (["--M", "1e-2", "--window", "5,1"], "--window must be two times"),
        (["--M", "1e-2", "--cycles", "--free", "Dc"], "needs the load-point velocity V"),
        (["--M", "1e-2", "--free", "a,b2"], "b2: the model has 1 state variable"),
    ],
)
def test_cli_invert_bad_input_one_line_exit_2(capsys, tmp_path, extra, message):
    path = tmp_path / "c.csv"
    pd.DataFrame({"period": [35.2, 35.3], "stress_drop": [0.064, 0.065]}).to_csv(path, index=False)
    argv = ["lab", "invert", str(path), *OPTS, *extra]
    if "--cycles" not in extra:
        rec = tmp_path / "r.csv"
        t = np.linspace(0.0, 100.0, 101)
        pd.DataFrame({"time": t, "mu": 0.6 + 0 * t, "load_point": t}).to_csv(rec, index=False)
        argv[2] = str(rec)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1, err


def test_cli_invert_a_record_without_stick_slip(capsys, tmp_path):
    path = tmp_path / "flat.csv"
    t = np.linspace(0.0, 100.0, 101)
    pd.DataFrame({"time": t, "mu": 0.6 + 0 * t, "load_point": t}).to_csv(path, index=False)
    assert main(["lab", "invert", str(path), *OPTS, "--M", "1e-2"]) == 2
    assert "found 0 slip(s)" in capsys.readouterr().err
