"""Velocity steps and slide-hold-slide tests, and `stickslip lab step|shs|fit|bench`."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from stickslip.cli import main
from stickslip.lab import LoadHistory, RateState
from stickslip.lab.protocols import slide_hold_slide, velocity_step
from stickslip.lab.records import synthetic

LAB = dict(a=0.005, b=0.01, Dc=10.0, mu0=0.6, V0=1.0)
OPTS = ["--a", "0.005", "--b", "0.01", "--Dc", "10", "--mu0", "0.6", "--V0", "1", "--k", "1e-3"]


def test_velocity_step_reads_a_minus_b_and_the_direct_effect():
    ds, s = velocity_step(RateState(**LAB, k=1e-3), (1.0, 10.0, 1.0), displacement=600.0)
    up, down = s["steps"]
    assert up["a_minus_b_from_run"] == pytest.approx(-0.005, rel=1e-6)
    assert down["a_minus_b_from_run"] == pytest.approx(-0.005, rel=1e-6)
    assert up["mu_peak"] > up["mu_before"] and down["mu_peak"] < down["mu_before"]
    # the peak is short of the direct effect a ln 10 (the spring lets the block slip on the way)
    assert 0.0 < up["mu_peak"] - up["mu_before"] < 0.005 * math.log(10.0)
    assert s["k_c"] == pytest.approx(5e-4)


def test_aging_law_heals_at_b_ln10_per_decade_in_a_stiff_machine():
    """theta = theta_0 + t_h in a hold, so Delta mu -> b ln(10) per decade for t_h >> theta_0."""
    model = RateState(**LAB, k=1.0)
    _, s = slide_hold_slide(model, 10.0, (100.0, 1000.0, 10000.0))
    assert s["aging_long_hold_rate"] == pytest.approx(0.01 * math.log(10.0))
    assert s["healing_rate"] == pytest.approx(0.01 * math.log(10.0), rel=0.05)
    # the slip law heals only by the slip of the relaxation in the hold: far less
    _, slip = slide_hold_slide(model.with_values(law="slip"), 10.0, (100.0, 1000.0, 10000.0))
    assert slip["healing_rate"] < 0.5 * s["healing_rate"]
    # peaks grow with hold time
    peaks = [r["mu_peak"] for r in s["holds"]]
    assert np.all(np.diff(peaks) > 0.0)


def _json(capsys, *argv):
    status = main(list(argv) + ["--json"])
    out = capsys.readouterr().out
    assert status == 0
    return json.loads(out)


def test_cli_step_shs_and_outputs(capsys, tmp_path):
    d = _json(capsys, "lab", "step", *OPTS, "--V", "1,10", "--out", str(tmp_path / "step"))
    assert d["steps"][0]["mu_ss_closed_form"] == pytest.approx(0.6 - 0.005 * math.log(10.0), abs=1e-12)
    assert sorted(p.name for p in (tmp_path / "step").iterdir() if not p.name.startswith(".")) == [
        "index.html", "step.json", "step.nc", "step.pdf", "step.png",
    ]  # fmt: skip
    d = _json(capsys, "lab", "shs", *OPTS[:-2], "--k", "1e-2", "--V", "10", "--holds", "10,100,1000")
    assert len(d["holds"]) == 3 and d["healing_rate"] > 0.0


@pytest.mark.slow  # a fit from the command line (25 s, measured)
def test_cli_fit_of_a_csv_record(capsys, tmp_path):
    true = RateState(**LAB, k=1e-3)
    h = LoadHistory.steps([1.0, 10.0], [50.0, 100.0])
    rec = synthetic(true, h, n=300)
    path = tmp_path / "step.csv"
    lines = [
        f"{float(t)!r},{float(m)!r},{float(p)!r}" for t, m, p in zip(rec.t, rec.mu, h.position(rec.t), strict=True)
    ]
    path.write_text("time,mu,load_point\n" + "\n".join(lines) + "\n")
    start = ["--a", "0.007", "--b", "0.008", "--Dc", "5", "--mu0", "0.6", "--V0", "1", "--k", "1e-3"]
    d = _json(capsys, "lab", "fit", str(path), *start, "--free", "a,b,Dc", "--out", str(tmp_path / "fit"))
    # the record samples the step once every 0.5: the fit sees the step smeared over one sample
    assert d["parameters"]["a"]["value"] == pytest.approx(0.005, rel=2e-3)
    assert d["parameters"]["Dc"]["value"] == pytest.approx(10.0, rel=2e-3)
    assert (tmp_path / "fit" / "fit.nc").is_file() and (tmp_path / "fit" / "fit.png").is_file()
    page = (tmp_path / "fit" / "index.html").read_text(encoding="utf-8")
    for name in ("a", "b", "Dc"):  # the page's parameter table: value and standard error
        p = d["parameters"][name]
        assert f"<td>{name}</td><td>{p['value']:.4g}</td><td>{p['stderr']:.4g}</td>" in page


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["lab", "step", "--a", "0.005", "--b", "0.01", "--mu0", "0.6", "--V0", "1", "--k", "1e-3"], "Dc is required"),
        (["lab", "step", *OPTS[:-2]], "k is required"),
        (["lab", "step", *OPTS, "--V", "1,-10"], "V must be > 0"),
        (["lab", "step", *OPTS, "--V", "-1,10"], "V must be > 0"),
        (["lab", "step", *OPTS[2:], "--a", "-5e-3"], "a must be > 0"),
        (["lab", "shs", *OPTS, "--holds", "0,10"], "hold must be > 0"),
        (["lab", "step", *OPTS, "--law", "dieterich"], "law must be one of"),
        (["lab", "fit", "missing.csv", *OPTS], "no such file"),
    ],
)
def test_cli_bad_input_one_line_exit_2(capsys, argv, message):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1


def test_cli_fit_bad_csv(capsys, tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("time,mu\n0,0.6\n1,0.6\n")
    assert main(["lab", "fit", str(path), *OPTS]) == 2
    assert "no load-point column" in capsys.readouterr().err


@pytest.mark.slow  # a benchmark: both routes timed on the full workload (about a minute)
def test_bench_measures_both_routes_and_they_agree(capsys):
    d = _json(capsys, "lab", "bench", "--repeats", "1")
    assert d["max_abs_mu_difference"] < 1e-9
    assert d["speed_ratio"] > 0.0 and d["fit_cpu_s"] > 0.0
    inertial = d["inertial_history"]
    assert inertial["steps"] == 276_000 and inertial["ratio"] == inertial["history_s"] / inertial["constant_s"]
    # a fair comparison: the same steps, and the history at one V is the constant V's run bit for bit
    assert inertial["same_steps"] and inertial["flat_same_state"]
    for name in ("a", "b", "Dc", "mu0"):
        v, e = d["fit"][name]["value"], d["fit"][name]["stderr"]
        assert abs(v - d["fit_truth"][name]) < 5.0 * e


def test_cli_fit_with_window_and_detrend(capsys, tmp_path):
    true = RateState(**LAB, k=1e-3)
    h = LoadHistory.steps([1.0, 10.0], [50.0, 100.0])
    rec = synthetic(true, h, n=301)
    p = h.position(rec.t)
    mu = rec.mu + 3e-5 * p  # a slip-hardening trend
    mu[rec.t > 140.0] -= 0.02  # a spoilt end the window leaves out
    path = tmp_path / "trend.csv"
    rows = [f"{float(t)!r},{float(m)!r},{float(x)!r}" for t, m, x in zip(rec.t, mu, p, strict=True)]
    path.write_text("time,friction,lp_disp\n" + "\n".join(rows) + "\n")
    start = ["--a", "0.007", "--b", "0.008", "--Dc", "5", "--mu0", "0.6", "--V0", "1", "--k", "1e-3"]
    d = _json(capsys, "lab", "fit", str(path), *start, "--detrend", "0,49", "--window", "0,140")
    assert d["parameters"]["b"]["value"] == pytest.approx(0.01, rel=5e-3)
    assert main(["lab", "fit", str(path), *start, "--window", "5,1"]) == 2
    assert "--window must be two times T0,T1 with T0 < T1" in capsys.readouterr().err


def test_velocity_step_with_damping_and_two_state_variables():
    model = RateState(
        a=0.008, b=(0.006, 0.004), Dc=(5.0, 50.0), law=("aging", "slip"), mu0=0.6, V0=1.0, k=2e-3, eta=1e-4
    )
    _, s = velocity_step(model, (1.0, 10.0), displacement=2000.0)
    st = s["steps"][0]
    assert st["mu_before"] == pytest.approx(0.6 + 1e-4, abs=1e-12)  # the spring carries mu + eta V
    assert st["mu_end"] == pytest.approx(st["mu_ss_closed_form"], abs=1e-9)
    assert st["a_minus_b_from_run"] == pytest.approx(0.008 - 0.010, rel=1e-6)


def test_cli_fit_posterior_writes_the_corner_figure(capsys, tmp_path):
    """`lab fit --posterior`: emcee's samples about the known truth, the corner figure and the
    posterior's NetCDF beside the fit's."""
    pytest.importorskip("emcee")
    true = RateState(**LAB, k=1e-3)
    h = LoadHistory.steps([1.0, 10.0], [20.0, 80.0])
    rec = synthetic(true, h, n=200, noise=2e-4, rng=11)
    path = tmp_path / "noisy.csv"
    rows = [f"{float(t)!r},{float(m)!r},{float(p)!r}" for t, m, p in zip(rec.t, rec.mu, h.position(rec.t), strict=True)]
    path.write_text("time,mu,load_point\n" + "\n".join(rows) + "\n")
    # a and b free from 20% and 10% off; D_c, mu0 and k at their true values
    start = ["--a", "0.006", "--b", "0.009", "--Dc", "10", "--mu0", "0.6", "--V0", "1", "--k", "1e-3"]
    out = tmp_path / "fit"
    d = _json(capsys, "lab", "fit", str(path), *start, "--free", "a,b", "--posterior", "200", "--out", str(out))
    post = d["posterior"]["parameters"]
    for name, truth in (("a", 0.005), ("b", 0.01)):
        # the CSV carries no weights: the errors are the residuals' scatter, the noise 2e-4
        assert abs(post[name]["mean"] - truth) < 5.0 * post[name]["std"]
        lo, hi = post[name]["interval_95"]
        assert lo < post[name]["mean"] < hi
        assert 0.5 < post[name]["std"] / d["parameters"][name]["stderr"] < 2.0
    assert {"fit.json", "fit.nc", "fit.png", "posterior.nc", "posterior.png"} <= {p.name for p in out.iterdir()}


def test_cli_a_run_that_fails_writes_nothing(capsys, tmp_path):
    """The slip law runs away after a step 1 -> 10 at k = 2 k_c: one line, exit 2, no --out left."""
    out = tmp_path / "step"
    assert main(["lab", "step", *OPTS, "--law", "slip", "--V", "1,10", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "the slip rate runs away" in err and err.count("\n") == 1
    assert not out.exists()
    # bad input found before the run leaves nothing either
    assert main(["lab", "shs", *OPTS, "--V", "0", "--out", str(out)]) == 2
    assert "V must be > 0" in capsys.readouterr().err and not out.exists()


def test_cli_shs_writes_its_figure_and_data(capsys, tmp_path):
    d = _json(capsys, "lab", "shs", *OPTS[:-2], "--k", "1e-2", "--holds", "10,100", "--out", str(tmp_path / "shs"))
    assert {"shs.json", "shs.nc", "shs.png", "shs.pdf"} <= {p.name for p in (tmp_path / "shs").iterdir()}
    # two holds give the rate as the difference quotient of their healing
    rate = (d["holds"][1]["delta_mu"] - d["holds"][0]["delta_mu"]) / 1.0
    assert d["healing_rate"] == pytest.approx(rate, rel=1e-12)
