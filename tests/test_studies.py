"""Studies (`stickslip study`): the order parameter's error bar, final states, a tiny study end to end."""

from __future__ import annotations

import json
import math
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.signal import lfilter

from chain_helpers import error_lines
from stickslip.analysis.order import (
    batch_means,
    classify_final_state,
    integrated_time,
    mean_with_error,
    order_parameter,
    transition_bracket,
)
from stickslip.experiments.studies import Study, study
from stickslip.experiments.study_run import run_study


def _ar1(rng, phi: float, n: int) -> np.ndarray:
    e = rng.normal(size=n + 2000)
    return lfilter([1.0], [1.0, -phi], e)[2000:]


# --- the error bar against an AR(1) series with a known variance of the mean ---------------------


def test_ar1_error_bar_matches_known_variance_of_the_mean():
    """x_t = phi x_{t-1} + e_t: tau_int = (1 + phi) / (2 (1 - phi)) and
    Var(mean) -> sigma^2 (1 + phi) / ((1 - phi) n), sigma^2 = 1 / (1 - phi^2)."""
    rng = np.random.default_rng(7)
    phi, n, reps = 0.9, 20000, 120
    true_sd = math.sqrt((1.0 / (1 - phi**2)) * (1 + phi) / (1 - phi) / n)
    ests = [mean_with_error(_ar1(rng, phi, n)) for _ in range(reps)]
    rms_err = math.sqrt(np.mean([e.err**2 for e in ests]))
    assert 0.85 < rms_err / true_sd < 1.1
    spread = np.std([e.mean for e in ests])
    assert 0.8 < spread / true_sd < 1.2  # the replicas themselves confirm the formula
    assert np.mean([e.tau_int for e in ests]) == pytest.approx((1 + phi) / (2 * (1 - phi)), rel=0.1)
    assert all(e.reliable for e in ests)
    covered = np.mean([abs(e.mean) <= e.err for e in ests])
    assert 0.55 < covered < 0.8  # about 68 % of one-sigma intervals hold the true mean 0
    naive = np.mean([np.std(_ar1(rng, phi, n)) / math.sqrt(n) for _ in range(5)])
    assert naive < 0.3 * true_sd  # the naive error would be far too small


def test_integrated_time_and_batches_of_white_noise():
    x = np.random.default_rng(1).normal(size=50000)
    assert integrated_time(x) == pytest.approx(0.5, abs=0.05)
    err, k = batch_means(x, 100)
    assert k == 500 and err == pytest.approx(1 / math.sqrt(50000), rel=0.1)
    assert integrated_time(np.ones(100)) == 0.5


def test_short_series_is_flagged_unreliable():
    est = mean_with_error(_ar1(np.random.default_rng(2), 0.99, 2000))
    assert not est.reliable and est.n_batches == 8


def test_order_parameter_of_steady_sliding_is_zero():
    est = order_parameter(np.full(100, 7940.1), 7940.1)
    assert est.mean == 0.0 and est.err == 0.0


# --- final states ----------------------------------------------------------------------------


def _classify(**kw):
    base = dict(reached_steady=False, stuck_q3=0.9, stuck_q4=0.9, m_q3=0.1, m_err_q3=0.01, m_q4=0.1, m_err_q4=0.01)
    return classify_final_state(**{**base, **kw})[0]


def test_final_state_classification():
    assert _classify(reached_steady=True) == "steady"
    assert _classify() == "stick-slip"
    assert _classify(stuck_q4=0.0) == "undecided"  # sliding, not yet steady
    assert _classify(stuck_q3=0.8, stuck_q4=0.2) == "undecided"  # stick-slip dying out
    assert _classify(m_q3=0.1, m_q4=0.2) == "undecided"  # m drifting by 7 errors
    assert _classify(m_q3=0.1, m_q4=0.12) == "stick-slip"  # 1.4 errors: fluctuation
    assert _classify(stuck_q4=float("nan")) == "undecided"


def test_transition_bracket():
    b = [0.8, 0.9, 1.0, 1.1, 1.2]
    br = transition_bracket(b, ["stick-slip", "stick-slip", "stick-slip", "undecided", "steady"])
    assert (br["lo"], br["hi"], br["undecided"]) == (1.0, 1.2, [1.1])
    assert br["estimate"] == pytest.approx(1.1) and br["uncertainty"] == pytest.approx(0.1)
    assert math.isnan(transition_bracket(b, ["steady"] * 5)["estimate"])


# --- specs -----------------------------------------------------------------------------------


def test_quick_specs_cover_the_brief():
    t = study("transition", "quick")
    assert sorted({p["N"] for p in t.points}) == [49, 99, 199]
    betas = sorted({p["beta"] for p in t.points})
    assert betas[0] <= 0.6 and betas[-1] >= 1.4 and max(np.diff([b for b in betas if 0.9 <= b <= 1.1])) <= 0.05 + 1e-9
    assert all(p["t_end"] >= 2.5 * p["N"] * (p["N"] - 1) / (2 * 10 * 0.001) for p in t.points)
    f = study("transition", "full")
    assert sorted({p["N"] for p in f.points}) == [49, 99, 199, 399, 799]
    ph = study("phase-diagram", "quick")
    assert {p["start"] for p in ph.points} == {"paper", "steady"} and {p["N"] for p in ph.points} == {99}
    ex = study("exponents", "quick")
    assert {p["model"] for p in ex.points} == {"sakaguchi", "carlson-langer"}
    # the key ignores the point list, so adding a point keeps the directory
    assert Study("transition", "tiny", t.common, t.points[:2]).key() == Study("transition", "tiny", t.common).key()


# --- a tiny study end to end -----------------------------------------------------------------


def _tiny(points=None) -> Study:
    common = dict(study("transition", "tiny").common)
    common["n_samples"] = 400
    points = points or [{"N": 5, "beta": 0.8, "t_end": 3000.0}, {"N": 5, "beta": 1.4, "t_end": 3000.0}]
    return Study("transition", "tiny", common, tuple(points))


def _science(rows) -> pd.DataFrame:
    cols = [
        "N",
        "beta",
        "order_parameter",
        "order_parameter_err",
        "final_state",
        "stuck_fraction",
        "event_rate",
        "S_max",
        "t_steady",
    ]
    return pd.DataFrame(rows)[cols].sort_values(["N", "beta"]).reset_index(drop=True)


@pytest.fixture(scope="module")
def cluster():
    """One local Dask cluster for the module: workers import the package and load kernels once."""
    from dask.distributed import LocalCluster

    lc = LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0")
    yield lc.scheduler_address
    lc.close()


def test_tiny_study_end_to_end(tmp_path, cluster):
    first = run_study(_tiny(), tmp_path, scheduler=cluster, progress=False)
    assert first["failed"] == 0 and first["run"] == 2
    rows = first["rows"]
    for key in ("N", "beta", "order_parameter", "order_parameter_err", "final_state"):
        assert all(key in r for r in rows)
    assert {r["final_state"] for r in rows} <= {"steady", "stick-slip", "undecided"}
    page = Path(first["page"])
    assert page.is_file() and "order parameter" in page.read_text().lower()
    table = pd.read_parquet(tmp_path / "transition" / "table.parquet")
    assert len(table) == 2 and (tmp_path / "transition" / "order_parameter.png").is_file()
    json.dumps(first, allow_nan=True)
    # a second call reuses every point and gives the same table
    second = run_study(_tiny(), tmp_path, scheduler=cluster, progress=False)
    assert second["run"] == 0 and second["reused"] == 2
    pd.testing.assert_frame_equal(_science(first["rows"]), _science(second["rows"]))


def test_failed_point_is_reported_and_retried_alone(tmp_path, cluster):
    # K = 1e6 passes the checks made up front but makes Heun blow up: the run raises on its worker
    points = [{"N": 5, "beta": 0.8, "t_end": 2000.0}, {"N": 5, "beta": 1.4, "t_end": 2000.0, "K": 1e6}]
    first = run_study(_tiny(points), tmp_path, scheduler=cluster, progress=False)
    assert first["failed"] == 1 and first["run"] == 2
    assert "non-finite" in first["failed_points"][0]["error"]
    states = {r["beta"]: r["final_state"] for r in first["rows"]}
    assert states[1.4] == "failed" and states[0.8] in ("stick-slip", "undecided", "steady")
    second = run_study(_tiny(points), tmp_path, scheduler=cluster, progress=False)
    assert second["run"] == 1 and second["reused"] == 1  # only the failed point runs again


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.slow
def test_existing_scheduler_gives_the_local_result(tmp_path):
    """`dask scheduler` and `dask worker` processes on 127.0.0.1 give the local cluster's table."""
    dask = str(Path(sys.executable).with_name("dask"))
    port = _free_port()
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(Path(__file__).parents[1] / "src"), os.environ.get("PYTHONPATH", "")]),
    }
    sched = subprocess.Popen(
        [dask, "scheduler", "--host", "127.0.0.1", "--port", str(port), "--dashboard-address", ":0"],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    worker = None
    try:
        time.sleep(3)
        worker = subprocess.Popen(
            [dask, "worker", f"tcp://127.0.0.1:{port}", "--nthreads", "1", "--nworkers", "2"],
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        time.sleep(5)
        remote = run_study(_tiny(), tmp_path / "remote", scheduler=f"tcp://127.0.0.1:{port}", progress=False)
        local = run_study(_tiny(), tmp_path / "local", n_workers=2, progress=False)
        pd.testing.assert_frame_equal(_science(remote["rows"]), _science(local["rows"]))
    finally:
        for proc in (worker, sched):
            if proc is not None:
                proc.terminate()
                proc.wait(timeout=30)


def test_an_interrupted_study_stops_its_running_ladder(tmp_path):
    """SIGTERM to `stickslip study` (as a batch system's stop or `kill` sends it) while its worker
    runs a ladder of the transition study: the command ends (exit 130, one line), the ladder is
    left unfinished (no done.json, no error.json) and the next call continues it from its
    finished rungs (tests/test_ladders.py)."""
    import signal

    from chain_helpers import signal_when_running
    from stickslip.experiments.sweep import STOP_FILE

    out = tmp_path / "studies"
    # the quick transition starts with its dearest ladder, N = 199 up: minutes of work
    argv = ["study", "transition", "--quick", "--workers", "1", "--out", str(out), "--no-progress"]
    status, stdout, stderr = signal_when_running(
        argv, lambda: bool(list(out.glob("runs/*/ladders/*/point.json"))), signal.SIGTERM, settle=3.0
    )
    assert status == 130, stderr
    assert stdout == ""
    assert len(stderr.splitlines()) == 1 and "interrupted" in stderr, stderr
    (ladder,) = [p.parent for p in out.glob("runs/*/ladders/*/point.json")]
    assert "direction=up_N=199" in ladder.name
    assert not (ladder / "error.json").exists() and not (ladder / "done.json").exists()
    assert not (ladder.parent / STOP_FILE).exists()


def test_sample_moving_leaves_the_run_unchanged(tmp_path):
    from stickslip.models.presets import chain_params
    from stickslip.run.driver import load_run, run_chain

    p = chain_params("sakaguchi", N=5, beta=0.8)
    plain = run_chain(p, 2000.0, sample_interval=10.0)
    run = run_chain(p, 2000.0, sample_interval=10.0, sample_moving=True, out_dir=tmp_path)
    assert run.summary["state_sha256"] == plain.summary["state_sha256"]
    n = run.samples["n_moving"].values
    assert len(n) == 201 and n.min() >= 0 and n.max() <= 5 and n[-1] == run.summary["n_moving"]
    assert np.array_equal(run.samples["t_moving"].values, np.arange(201) * 10.0)
    back = load_run(tmp_path)
    assert np.array_equal(back.samples["n_moving"].values, n)


# --- chaos: the largest Lyapunov exponent as a study ----------------------------------------


def test_tiny_chaos_study_end_to_end(tmp_path, cluster):
    from stickslip.analysis.decorrelation import VERDICTS
    from stickslip.analysis.stability import chain_finite_eigenvalues
    from stickslip.models.params import ChainParams

    spec = study("chaos", "tiny")
    first = run_study(spec, tmp_path, scheduler=cluster, progress=False)
    assert first["failed"] == 0 and first["run"] == len(spec.points) == 5
    rows = first["rows"]
    for key in ("model", "N", "beta", "lyapunov", "lyapunov_err", "t_end", "renormalisations"):
        assert all(key in r for r in rows)
    # steady sliding of N = 4 at beta = 1.5, V = 0.5: separations decay at the least stable
    # eigenvalue of the linearised chain (eq. 5), a negative number
    steady = next(r for r in rows if r["model"] == "sakaguchi" and r["N"] == 4)
    expected = float(chain_finite_eigenvalues(ChainParams(N=4, beta=1.5, V=0.5))[0].real)
    assert expected < 0 and steady["lyapunov"] < 0
    assert abs(steady["lyapunov"] - expected) <= 0.03 * abs(expected)
    # the flow (located switches, dt -> 0) has the same eigenvalue; it contracts: regular
    assert abs(steady["lyapunov_dt0"] - expected) <= 0.05 * abs(expected)
    assert steady["verdict"] == "regular"
    assert all(r["verdict"] in VERDICTS for r in rows)
    assert all(math.isfinite(r["lyapunov_dt0_err"]) for r in rows)
    # (400 - 0.1 * 400) / 5 = 72 counted renormalisations
    assert steady["renormalisations"] == 72
    family = {r["model"]: r for r in rows if r["model"] != "sakaguchi"}
    assert set(family) == {"two-blocks", "carlson-langer"}
    assert family["two-blocks"]["N"] == 2 and family["carlson-langer"]["N"] == 16
    assert all(r["beta"] is None for r in family.values())
    assert all(math.isfinite(r["lyapunov"]) for r in rows)
    assert (tmp_path / "chaos" / "lyapunov_beta.png").is_file()
    point = tmp_path / "runs" / spec.dirname / "points"
    assert len(list(point.glob("*/renormalisations.parquet"))) == 5
    json.dumps(first, allow_nan=True)
    second = run_study(spec, tmp_path, scheduler=cluster, progress=False)
    assert second["run"] == 0 and second["reused"] == 5
    assert [r["lyapunov"] for r in second["rows"]] == [r["lyapunov"] for r in rows]


def test_bad_study_input_is_one_line_and_exit_2(tmp_path):
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).parents[1] / "src")}
    cases = [
        ["study", "bogus"],
        ["study", "chaos", "--workers", "0"],
        ["study", "chaos", "--quick", "--full"],
        ["study", "transition", "--scheduler", " "],
        ["study", "chaos", "--workers", "two"],
        ["study", "exponents", "--bogus"],
    ]
    for argv in cases:
        proc = subprocess.run(
            [sys.executable, "-m", "stickslip.cli", *argv, "--out", str(tmp_path / "o")],
            env=env,
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert proc.returncode == 2, (argv, proc.stderr)
        assert len(error_lines(proc.stderr)) == 1, (argv, proc.stderr)
        assert proc.stdout == ""
    assert not (tmp_path / "o").exists()  # refused before the output folder is made


def test_chaos_findings_judge_the_relatives_on_the_exponents_they_have():
    """A value of d0 at which the twin fell onto the reference has no exponent (-inf, stored as
    empty): the relative is judged on the others and the lost one is named with its merges."""
    from stickslip.experiments.study_findings import conclusions

    rows = [
        {"model": "two-blocks", "N": 2, "beta": None, "d0": d0, "lyapunov": lam, "lyapunov_err": err, "merges": m}
        for d0, lam, err, m in ((1e-11, None, None, 6), (1e-10, 0.0443, 0.00066, 0), (1e-8, 0.0474, 0.00077, 0))
    ]
    out = conclusions(study("chaos", "quick"), pd.DataFrame(rows))
    (line,) = out["statements"]
    assert out["family"]["two-blocks"]["positive_3sigma"] is True
    assert "chaotic (positive beyond 3 errors) at d0 = 1e-10, 1e-08" in line
    assert "no exponent at d0 = 1e-11 (the twin fell onto the reference 6 times" in line
    assert "spread over d0 0.0031" in line


def test_chaos_findings_name_the_verdict_of_each_point():
    from stickslip.experiments.study_findings import conclusions

    rows = [
        {"model": "sakaguchi", "N": 99, "beta": b, "lyapunov": 0.0, "lyapunov_err": 1e-5, "lyapunov_per_event": 0.0}
        | {"verdict": v}
        for b, v in ((0.5, "regular"), (1.0, "stable chaos"))
    ]
    rows.append(
        {"model": "two-blocks", "N": 2, "beta": None, "d0": 1e-10, "lyapunov": 0.044, "lyapunov_err": 0.001}
        | {"verdict": "chaotic", "merges": 0}
    )
    out = conclusions(study("chaos", "quick"), pd.DataFrame(rows))
    assert out["verdicts"] == {
        "regular": ["beta = 0.5 (N = 99)"],
        "stable chaos": ["beta = 1 (N = 99)"],
        "chaotic": ["two blocks (N = 2)"],
    }
    assert (
        "regular at beta = 0.5 (N = 99); stable chaos at beta = 1 (N = 99); chaotic at two blocks (N = 2)"
        in (out["statements"][-1])
    )


def test_chaos_findings_summarise_the_finite_size_exponents():
    from stickslip.experiments.study_findings import conclusions

    nan = float("nan")
    rows = [
        {"model": "sakaguchi", "N": 99, "beta": 1.0, "lyapunov": 0.0, "lyapunov_err": 1e-5, "verdict": "regular"}
        | {"lyapunov_per_event": 0.0}
        | {"fsle_pooled": nan, "fsle_pooled_err": nan, "fsle_peak": nan, "fsle_peak_delta": nan, "fsle_unfinished": 4},
        {"model": "two-blocks", "N": 2, "beta": nan, "d0": 1e-10, "lyapunov": 0.044, "lyapunov_err": 0.001}
        | {"verdict": "chaotic", "merges": 0, "fsle_pooled": 0.0143, "fsle_pooled_err": 0.002}
        | {"fsle_peak": 9.47, "fsle_peak_delta": 0.0512, "fsle_unfinished": 0},
    ]
    out = conclusions(study("chaos", "quick"), pd.DataFrame(rows))
    (line,) = [s for s in out["statements"] if s.startswith("Finite-size exponent")]
    assert "beta = 1 (N = 99): no doubling below 1e-6, none, 4 cycles unfinished" in line
    assert "two-blocks: 0.014, largest 9.5 at delta = 0.051" in line
