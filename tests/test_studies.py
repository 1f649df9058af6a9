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
from stickslip.analysis.stats.order import (
    batch_means,
    classify_final_state,
    integrated_time,
    mean_with_error,
    order_parameter,
    transition_bracket,
)
from stickslip.experiments.studies import Study, study
from stickslip.experiments.study_run import run_study
from stickslip.experiments.sweep_points import point_params


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
    ph = study("phase-diagram", "quick")
    assert {p["start"] for p in ph.points} == {"paper", "steady"} and {p["N"] for p in ph.points} == {99}
    assert {(p["alpha"], p["D"]) for p in ph.points} >= {(0.5, 5.0), (1.5, 5.0), (1.0, 0.5), (1.0, 50.0)}
    assert all(p["t_end"] >= 2.5 * 99 * 98 / (2 * 10 * 0.001) for p in ph.points)
    ex = study("exponents", "quick")
    assert {p["model"] for p in ex.points} == {"sakaguchi", "carlson-langer"}
    # the key ignores the point list, so adding a point keeps the directory
    assert Study("phase-diagram", "quick", ph.common, ph.points[:2]).key() == ph.key()


# --- a tiny study end to end -----------------------------------------------------------------


def _tiny(points=None) -> Study:
    common = dict(study("phase-diagram", "tiny").common)
    common["n_samples"] = 400
    points = points or [
        {"N": 5, "alpha": 1.0, "D": 5.0, "beta": 0.8, "t_end": 3000.0, "start": "paper"},
        {"N": 5, "alpha": 1.0, "D": 5.0, "beta": 1.4, "t_end": 3000.0, "start": "paper"},
    ]
    return Study("phase-diagram", "tiny", common, tuple(points))


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


@pytest.mark.slow  # a study on the module's cluster (about 25 s, measured)
def test_tiny_study_end_to_end(tmp_path, cluster):
    first = run_study(_tiny(), tmp_path, scheduler=cluster, progress=False)
    assert first["failed"] == 0 and first["run"] == 2
    rows = first["rows"]
    for key in ("N", "beta", "order_parameter", "order_parameter_err", "final_state"):
        assert all(key in r for r in rows)
    assert {r["final_state"] for r in rows} <= {"steady", "stick-slip", "undecided"}
    page = Path(first["page"])
    assert page.is_file() and "phase-diagram" in page.read_text().lower()
    table = pd.read_parquet(tmp_path / "phase-diagram" / "table.parquet")
    assert len(table) == 2 and (tmp_path / "phase-diagram" / "phase_alpha_beta.png").is_file()
    json.dumps(first, allow_nan=True)
    # a second call reuses every point and gives the same table
    second = run_study(_tiny(), tmp_path, scheduler=cluster, progress=False)
    assert second["run"] == 0 and second["reused"] == 2
    pd.testing.assert_frame_equal(_science(first["rows"]), _science(second["rows"]))


@pytest.mark.slow  # a second study on the cluster (20 s, measured)
def test_failed_point_is_reported_and_retried_alone(tmp_path, cluster):
    # K = 1e6 passes the checks made up front but makes Heun blow up: the run raises on its worker
    cell = {"N": 5, "alpha": 1.0, "D": 5.0, "t_end": 2000.0, "start": "paper"}
    points = [{**cell, "beta": 0.8}, {**cell, "beta": 1.4, "K": 1e6}]
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


@pytest.mark.slow  # a study in a subprocess (20 s or more, measured)
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
        argv, lambda: bool(list(out.glob("runs/*/points/*/point.json"))), signal.SIGTERM, settle=3.0
    )
    assert status == 130, stderr
    assert stdout == ""
    assert len(stderr.splitlines()) == 1 and "interrupted" in stderr, stderr
    (ladder,) = [p.parent for p in out.glob("runs/*/points/*/point.json")]
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


# --- chaos: flow exponent, decorrelation, delta* and the verdict as a study -----------------


def _delta_star_by_hand(rows, seed):
    """The smallest delta whose twin disagreed in window ``seed`` (None: none did)."""
    hits = [r["delta"] for r in rows if r["seed"] == seed and r["decorrelated"] and r["delta"] > 0]
    return min(hits) if hits else None


@pytest.mark.slow
def test_tiny_chaos_study_end_to_end(tmp_path, cluster):
    from stickslip import io
    from stickslip.analysis.dynamics.decorrelation import VERDICTS

    spec = study("chaos", "tiny")
    first = run_study(spec, tmp_path, scheduler=cluster, progress=False)
    assert first["failed"] == 0 and first["run"] == len(spec.points) == 7
    rows = first["rows"]
    for key in ("verdict", "verdict_text", "lyapunov_dt0", "lyapunov_dt0_err", "flow_slips", "window"):
        assert all(key in r for r in rows)
    assert all(r["verdict"] in VERDICTS for r in rows)
    chain = [r for r in rows if r["model"] == "sakaguchi"]
    assert sorted((r["N"], r["beta"]) for r in chain) == [(n, b) for n in (5, 9) for b in (0.5, 0.9, 1.0)]
    assert all(r["loaded"] is True and r["window"] == 40 for r in chain)
    points = tmp_path / "runs" / spec.dirname / "points"
    for r in rows:
        flow = io.read_json(points / r["point_dir"] / "flow.json")
        kinds = ("state", "Fs", "V") if r["model"] == "sakaguchi" else ("state",)
        assert tuple(flow["decorrelation"]) == kinds
        for kind in kinds:
            dec = flow["decorrelation"][kind]["decorrelation"]
            assert len(dec) == 3 * r["seeds"]
            per_seed = [_delta_star_by_hand(dec, s) for s in range(r["seeds"])]
            got = [r[f"delta_star_{kind}_seed{s}"] for s in range(r["seeds"])]
            assert got == per_seed, (r["point_dir"], kind)
            assert r[f"delta_star_{kind}_censored"] == per_seed.count(None)
        # the verdict by its rule: the exponent within 2 errors, then the state's windows
        lam, err = r["lyapunov_dt0"], r["lyapunov_dt0_err"]
        state = flow["decorrelation"]["state"]["decorrelation"]
        smallest = min(x["delta"] for x in state)
        if lam > 2 * err:
            expected = "chaotic"
        elif not any(x["decorrelated"] for x in state):
            expected = "regular"
        elif any(x["decorrelated"] for x in state if x["delta"] == smallest):
            expected = "undetermined"
        else:
            expected = "stable chaos"
        assert r["verdict"] == expected, r["point_dir"]
        if expected == "regular":
            assert r["verdict_text"].startswith("regular over 40 slips for delta <= 0.1")
        assert len(flow["ladder"]) == 2 and flow["flow_slips"] == min(x["events"] for x in flow["ladder"])
    for name in ("decorrelation", "flow_ladder", "threshold"):
        assert (tmp_path / "chaos" / f"{name}.png").is_file()
    assert len(pd.read_csv(tmp_path / "chaos" / "decorrelation.csv")) == sum(
        3 * r["seeds"] * (3 if r["model"] == "sakaguchi" else 1) for r in rows
    )
    fits = first["findings"]["fits"]
    assert {(f["beta"], f["kind"]) for f in fits} == {(b, k) for b in (0.5, 0.9, 1.0) for k in ("state", "Fs", "V")}
    json.dumps(first, allow_nan=True)
    second = run_study(spec, tmp_path, scheduler=cluster, progress=False)
    assert second["run"] == 0 and second["reused"] == 7
    assert [r["verdict_text"] for r in second["rows"]] == [r["verdict_text"] for r in rows]


@pytest.mark.slow  # a chaos point run in a subprocess and stopped (about 100 s, measured)
def test_an_interrupted_chaos_point_keeps_its_finished_parts(tmp_path):
    """A point whose task stopped after some parts runs only the others again, and gives the same
    row; a study's stop request stops it within a part; a part made with other settings is not
    reused."""
    from stickslip.experiments.studies.chaos import chaos_point
    from stickslip.experiments.sweep import STOP_FILE
    from stickslip.run.errors import Interrupted

    spec = study("chaos", "tiny")
    cfg = {**spec.common, **next(p for p in spec.points if p.get("N") == 5 and p.get("beta") == 0.9)}
    params = point_params("chain", cfg)
    point = tmp_path / "points" / "p"
    first = chaos_point(cfg, params, point)
    parts = sorted((point / "parts").glob("*.json"))
    assert [p.name for p in parts] == [
        "decorrelation-Fs.json",
        "decorrelation-V.json",
        "decorrelation-state.json",
        "flow-rung-0.json",
        "flow-rung-1.json",
    ]
    stamps = {p: p.stat().st_mtime_ns for p in parts}
    (point / "parts" / "flow-rung-1.json").unlink()
    (point / "flow.json").unlink()
    (tmp_path / "points" / STOP_FILE).touch()
    with pytest.raises(Interrupted):
        chaos_point(cfg, params, point)
    assert not (point / "parts" / "flow-rung-1.json").exists()
    (tmp_path / "points" / STOP_FILE).unlink()
    again = chaos_point(cfg, params, point)
    assert {k: v for k, v in again.items() if k != "point_wall_seconds"} == {
        k: v for k, v in first.items() if k != "point_wall_seconds"
    }
    kept = [p for p in parts if p.name != "flow-rung-1.json"]
    assert all(p.stat().st_mtime_ns == stamps[p] for p in kept)
    # an edited part is not reused
    edited = point / "parts" / "decorrelation-V.json"
    record = json.loads(edited.read_text())
    record["result"]["decorrelation"][0]["decorrelated"] = not record["result"]["decorrelation"][0]["decorrelated"]
    edited.write_text(json.dumps(record))
    stamp = edited.stat().st_mtime_ns
    third = chaos_point(cfg, params, point)
    assert {k: v for k, v in third.items() if k != "point_wall_seconds"} == {
        k: v for k, v in first.items() if k != "point_wall_seconds"
    }
    assert edited.stat().st_mtime_ns != stamp
    assert all(p.stat().st_mtime_ns == stamps[p] for p in kept if p != edited)
    other = chaos_point({**cfg, "seeds": 1}, params, point)  # other settings: every part again
    assert all(p.stat().st_mtime_ns != stamps[p] for p in kept)
    assert other["windows"] == 1


def test_chaos_findings_state_verdicts_thresholds_and_fits():
    """The findings from rows alone: the verdict of each point with its text, delta* per kind
    from the per-window columns, and the slope of log10 delta* on log10 N (by hand: the points
    (1, -3), (1, -5), (2, -4), (2, -6) have slope -1 with standard error sqrt(2))."""
    from stickslip.experiments.studies.chaos import conclusions

    nan = float("nan")

    def chain(N, beta, s0, s1, verdict):
        return {
            "model": "sakaguchi",
            "N": N,
            "beta": beta,
            "seeds": 2,
            "loaded": True,
            "lyapunov_dt0": -1e-6,
            "lyapunov_dt0_err": 2e-6,
            "flow_slips": 320,
            "verdict": verdict,
            "verdict_text": f"{verdict}: text",
            "delta_star_state": 1e-4,
            "delta_star_state_err_log10": 1.0,
            "delta_star_state_low": min(s0, s1),
            "delta_star_state_high": max(s0, s1),
            "delta_star_state_censored": 0,
            "delta_star_state_seed0": s0,
            "delta_star_state_seed1": s1,
        }

    rows = [chain(10, 0.5, 1e-3, 1e-5, "stable chaos"), chain(100, 0.5, 1e-4, 1e-6, "regular")]
    rows.append(
        {"model": "two-blocks", "N": 2, "beta": nan, "seeds": 1, "lyapunov_dt0": 0.026, "lyapunov_dt0_err": 4e-4}
        | {"flow_slips": 900, "verdict": "chaotic", "verdict_text": "chaotic: text", "loaded": True}
    )
    out = conclusions(study("chaos", "quick"), pd.DataFrame(rows))
    assert out["verdicts"] == {
        "stable chaos": ["beta = 0.5 (N = 10)"],
        "regular": ["beta = 0.5 (N = 100)"],
        "chaotic": ["two blocks (N = 2)"],
    }
    assert (
        "beta = 0.5 (N = 10): flow exponent -1e-06 +- 2e-06 (each rung counting at least 320 slips)"
        in (out["statements"][0])
    )
    (fit,) = out["fits"]
    assert (fit["beta"], fit["kind"], fit["Ns"], fit["trend"]) == (0.5, "state", [10, 100], "none")
    assert fit["slope"] == pytest.approx(-1.0) and fit["slope_err"] == pytest.approx(math.sqrt(2.0))
    assert [t["per_seed"] for t in out["thresholds"]] == [[1e-3, 1e-5], [1e-4, 1e-6]]
    assert any("beta = 0.5: -1.00 +- 1.41 (no trend)" in line for line in out["statements"])
    assert any(line.startswith("Loading: every chain point") for line in out["statements"])


@pytest.mark.slow
def test_a_quick_chain_point_counts_its_slips():
    """One point of ``--quick`` (N = 49, beta = 1): the flow's ladder rungs count at least 300 slips,
    the windows 1000, and the row has the study's columns (about a minute)."""
    import tempfile

    from stickslip.experiments.studies import design
    from stickslip.experiments.studies.chaos import MIN_FLOW_SLIPS, chaos_point

    spec = study("chaos", "quick")
    cfg = {**spec.common, **next(p for p in spec.points if p.get("N") == 49 and p.get("beta") == 1.0)}
    with tempfile.TemporaryDirectory() as d:
        row = chaos_point(cfg, point_params("chain", cfg), Path(d))
    assert row["flow_slips"] >= MIN_FLOW_SLIPS and row["window"] == 1000 and row["loaded"] is True
    point_keys = set(cfg) | {"model", "N", "beta"}
    assert set(design("chaos").columns) <= set(row) | point_keys
    assert row["verdict_text"].startswith(row["verdict"])


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


# --- per-study help ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "says"),
    [
        ("transition", ["continuation in beta", "N in [49, 99, 199]", "15 ladders", "loops and scaling"]),
        ("phase-diagram", ["(alpha, beta)", "35 cells", "70 runs", "phase_alpha_beta"]),
        ("exponents", ["slip-size exponent tau", "N = 199", "6 runs", "tau_beta"]),
        ("chaos", ["delta*", "N = 49, 99, 199", "11 points", "decorrelation.csv"]),
        ("lifetimes", ["Kaplan-Meier", "N = 3, 5, 7, 9, 11, 13", "279 points", "exponent_vs_N", "two blocks"]),
        # the paper's own two, which `stickslip reproduce` gathers into its report
        ("figs1-4", ["eq. (1)", "13 values of V", "seconds in every mode", "fig1 to fig4"]),
        ("figs5-8", ["Fig. 5b", "N = 99 chains", "12 runs", "13 values of beta", "fig5a"]),
    ],
)
def test_each_study_has_its_own_help(name, says, capsys):
    """`stickslip study NAME --help` is the study's own text: what it measures, its grid and
    size in --quick (35 cells of the phase diagram, two starts each: docs/studies/phase-diagram.md),
    its cost and its outputs; only the transition takes --extra-n."""
    from stickslip.cli import main

    with pytest.raises(SystemExit) as stop:
        main(["study", name, "--help"])
    assert stop.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    assert f"usage: stickslip study {name}" in text
    for words in says:
        assert words in text, words
    assert "index.html" in text and ("minutes on two cores" in text or name == "figs1-4")
    assert ("--extra-n" in text) == (name == "transition")


def test_sizes_summary_fits_the_events_after_the_transient_only():
    """The exponents study's analysis of one run: the events counted are those that start at or
    after t_from (counted here by hand); with fewer than 20 of them there is no fit, and it says why."""
    from stickslip.analysis.stats.chain_runs import sizes_summary
    from stickslip.models.presets import chain_params
    from stickslip.run.driver import run_chain

    run = run_chain(chain_params("sakaguchi", N=12), 6e4)
    starts = np.sort(run.events["t_start"].to_numpy())
    t_from = 2e4
    out = sizes_summary(run, t_from, bootstrap=0)
    assert out["n_events"] == int((starts >= t_from).sum()) >= 20 and out["t_from"] == t_from
    assert 1.0 < out["tau"] < 3.0 and out["n_fit"] <= out["n_events"] and out["spanning"] == "max_block"
    few = sizes_summary(run, float(starts[-5]), bootstrap=0)
    assert few["n_events"] == 5 and math.isnan(few["tau"]) and few["error_note"].startswith("only 5 events")


@pytest.mark.slow
def test_tiny_exponents_study_draws_the_family_beside_fig8(tmp_path, cluster):
    """Carlson-Langer's slip sizes beside eq. (4) at beta = 0.2 (Fig. 8), drawn from the points'
    own runs: each panel's fit is its point's row (the same events after the same transient)."""
    from stickslip.experiments.studies.exponents import _family_panels

    spec = study("exponents", "tiny")
    result = run_study(spec, tmp_path, scheduler=cluster, progress=False)
    assert result["failed"] == 0
    rows = {(r["model"], r["beta"]): r for r in result["rows"]}
    cl, fig8 = rows[("carlson-langer", None)], rows[("sakaguchi", 0.2)]
    assert cl["spanning"] == "n_blocks" and fig8["spanning"] == "max_block"
    table = pd.read_parquet(tmp_path / "exponents" / "table.parquet")
    panels = _family_panels(table, tmp_path / "runs" / spec.dirname / "points")
    titles = [title for title, _, _ in panels]
    assert titles[0].startswith("Carlson-Langer") and titles[1].startswith("eq. (4), beta = 0.2")
    for (_, events, stats), row in zip(panels, (cl, fig8), strict=True):
        assert len(events) == row["n_events"] and (events["t_start"] >= row["t_from"]).all()
        assert stats["fit"].tau == row["tau"] and stats["fit"].n == row["n_fit"]
    names = [f["name"] for f in result["figures"]]
    assert names == ["tau_beta", "family_sizes"]
    assert (tmp_path / "exponents" / "family_sizes.pdf").read_bytes().startswith(b"%PDF")
