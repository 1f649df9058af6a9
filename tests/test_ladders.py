"""The transition study by continuation in beta: transient cut, stop rule, ladders, resume, checks."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.signal import lfilter

from chain_helpers import run_cli_subprocess
from stickslip.analysis.dynamics.adaptive import assess, mser_cut
from stickslip.experiments.ladders import ladder_task
from stickslip.experiments.studies.transition import (
    PER_N_COLUMNS,
    ladder_points,
    per_n_summary,
    transition_loop,
)
from stickslip.experiments.study_run import run_study
from stickslip.models.params import ParameterError
from stickslip.models.presets import chain_params
from stickslip.run.state import ChainState


def _ar1(rng, phi: float, n: int) -> np.ndarray:
    return lfilter([1.0], [1.0, -phi], rng.normal(size=n + 2000))[2000:]


# --- the transient and the stop rule -----------------------------------------------------------


def test_mser_cuts_a_decaying_start_and_nothing_of_a_stationary_series():
    rng = np.random.default_rng(1)
    noise = _ar1(rng, 0.5, 4000)
    drift = np.concatenate([np.linspace(30.0, 0.0, 600), np.zeros(3400)])
    cut = mser_cut(noise + drift)
    assert 400 <= cut <= 900  # the drift (600 samples, 30 sigma at its start) is dropped
    assert mser_cut(noise) < 400  # a stationary series keeps nearly everything
    assert mser_cut(np.full(1000, 2.5)) == 0


def test_stop_rule_needs_sixteen_batches_of_ten_tau_and_the_target():
    rng = np.random.default_rng(2)
    x = 0.01 * _ar1(rng, 0.9, 20000)  # tau_int = 19 samples
    t = np.arange(x.size, dtype=float)
    phi = np.full(x.size, 0.9)
    ok = assess(t, x, phi, target=1e-2)
    assert ok.decided and ok.m.reliable and ok.m.n_batches >= 16 and not ok.sliding
    # about 12 batches of 10 tau_int: reliable (>= 8) but not enough for the stop rule
    twelve = assess(t[:2300], x[:2300], phi[:2300], target=1.0)
    assert twelve.m.reliable and 8 <= twelve.m.n_batches < 16
    assert not twelve.decided and "fewer than 16 batches" in twelve.reason
    assert not assess(t, x, phi, target=1e-6).decided  # error above the target
    short = assess(t[:120], x[:120], phi[:120], target=1.0)  # fewer than 16 batches of 10 tau_int
    assert not short.decided and "fewer than 16 batches" in short.reason
    assert assess(t, x, np.zeros(x.size), target=1e-2).sliding  # no block stuck: phi = 0


def test_perturbed_moves_only_moving_blocks_and_is_seeded():
    p = chain_params("sakaguchi", N=7, beta=1.2)
    s = ChainState.steady(p)
    s.mov[3] = 0.0
    a, b = s.perturbed(1e-5, 4), s.perturbed(1e-5, 4)
    assert a.sha256() == b.sha256() != s.perturbed(1e-5, 5).sha256()
    d = a.x - s.x
    assert d[2] == 0.0 and np.all(np.abs(d) <= 1e-5) and np.count_nonzero(d) == 6
    assert s.perturbed(0.0, 4).sha256() == s.sha256()


def test_perturbed_steady_sliding_draws_x_then_v():
    from stickslip.models.physics import chain_steady_state

    p = chain_params("sakaguchi", N=7, beta=1.2)
    ss = chain_steady_state(p, 0.0)
    u = np.random.default_rng(3).uniform(-1e-3, 1e-3, 2 * p.N)  # N numbers for x, then N for v
    s = ChainState.steady(p, 1e-3, 3)
    assert np.array_equal(s.x, ss["x"] + u[: p.N]) and np.array_equal(s.v, ss["v"] + u[p.N :])


# --- ladders ------------------------------------------------------------------------------------


def _tiny_ladder(direction, betas):
    common, _ = ladder_points("tiny")
    return {**common, "N": 9, "direction": direction, "betas": betas, "cap_loads": 1.0}


def test_up_ladder_hands_states_on_and_bisects(tmp_path):
    """Rung k + 1 of the up ladder starts from rung k's final state; the bisection starts from the
    last stick-slip state; beta_t lies between the last stick-slip and the first sliding beta."""
    cfg = _tiny_ladder("up", [0.8, 2.0, 4.0])
    res = ladder_task(cfg, tmp_path)
    rows = res["rows"]
    assert [r["branch_state"] for r in rows[:2]] == ["stick-slip", "stick-slip"]
    assert rows[2]["beta"] == 4.0 and rows[2]["branch_state"] == "sliding"
    assert rows[1]["start_sha256"] == rows[0]["final_sha256"]
    assert rows[3]["role"] == "bisection" and rows[3]["beta"] == 3.0
    assert rows[3]["start_sha256"] == rows[1]["final_sha256"]
    assert res["inside"] < res["outside"]
    # steady sliding has m = phi = 0 by construction; stick-slip has blocks stuck
    assert rows[2]["order_parameter"] == 0.0 and rows[2]["stuck_fraction"] == 0.0
    assert rows[0]["stuck_fraction"] > 0.5
    # a ladder started again replays its finished rungs (same rows, no new work)
    again = ladder_task(cfg, tmp_path)
    assert again["rows"] == rows


def test_an_interrupted_rung_goes_on_from_its_last_segment(tmp_path, monkeypatch):
    """A rung stopped after a segment keeps its progress (progress.npz) and, run again, goes on
    from there. Stopped after every segment of every rung, the ladder ends with the rows and the
    final states of the ladder run without a stop, bit for bit."""
    import stickslip.experiments.ladders as ladders
    import stickslip.run.driver as driver
    from stickslip.kernels import layout
    from stickslip.run.checkpoint import read_npz
    from stickslip.run.errors import Interrupted

    cfg = _tiny_ladder("up", [0.8, 4.0]) | {"bisections": 0}
    whole = ladder_task(cfg, tmp_path / "whole")["rows"]
    keep, run_chain = ladders._keep_progress, driver.run_chain
    kept, starts = [], []

    def stop_after_keeping(path, spec, progress):
        keep(path, spec, progress)
        kept.append(int(read_npz(path)[0]["ist"][layout.STEP]))
        raise Interrupted(None, math.nan)

    def watch(params, t_end, *, start, **kw):
        starts.append(start.step)
        return run_chain(params, t_end, start=start, **kw)

    monkeypatch.setattr(ladders, "_keep_progress", stop_after_keeping)
    monkeypatch.setattr(driver, "run_chain", watch)
    rows, stops = None, 0
    while rows is None and stops < 100:
        try:
            rows = ladder_task(cfg, tmp_path / "stopped")["rows"]
        except Interrupted:
            stops += 1
    # both rungs were stopped, each time the next call's first segment began where the kept one ended
    assert stops == len(kept) >= 3 and not list(tmp_path.glob("stopped/rungs/*/progress.npz"))
    assert all(step in starts[1:] for step in kept)
    drop = ("wall_seconds",)
    assert [{k: v for k, v in r.items() if k not in drop} for r in rows] == [
        {k: v for k, v in r.items() if k not in drop} for r in whole
    ]
    files = [sorted((tmp_path / d).glob("rungs/*/*.npz")) for d in ("whole", "stopped")]
    assert [p.name for p in files[0]] == [p.name for p in files[1]] == ["samples.npz", "state.npz"] * 2
    assert all(a.read_bytes() == b.read_bytes() for a, b in zip(*files, strict=True))


def test_a_rungs_progress_reads_back_only_for_its_own_spec(tmp_path):
    from stickslip.experiments.ladders import _keep_progress, _progress

    p = chain_params("sakaguchi", N=7, beta=1.2)
    state = ChainState.steady(p, 1e-3, 1)
    kept = {"state": state, "seg": 12.5, "t_start": 0.0, "devs": [math.inf, 0.25, 0.125], "wall_seconds": 3.0}
    kept |= {"t": np.array([1.0, 2.0]), "L": np.array([5.0, 5.5]), "n_moving": np.array([7, 6])}
    path = tmp_path / "rungs" / "00-beta1.2" / "progress.npz"
    _keep_progress(path, {"start_sha256": "a"}, kept)
    back = _progress(path, {"start_sha256": "a"}, p)
    assert back["state"].sha256() == state.sha256() and back["devs"] == kept["devs"]
    assert {k: back[k] for k in ("seg", "t_start", "wall_seconds")} == {
        "seg": 12.5,
        "t_start": 0.0,
        "wall_seconds": 3.0,
    }
    assert all(np.array_equal(back[k], kept[k]) and back[k].dtype == kept[k].dtype for k in ("t", "L", "n_moving"))
    assert _progress(path, {"start_sha256": "b"}, p) is None  # another rung's progress
    assert _progress(path, {"start_sha256": "a"}, chain_params("sakaguchi", N=8, beta=1.2)) is None
    path.write_bytes(path.read_bytes()[:-20])  # a damaged file: the rung starts over
    assert _progress(path, {"start_sha256": "a"}, p) is None


def test_down_ladder_leaves_steady_sliding_below_one(tmp_path):
    """Linear stability of steady sliding: above beta = 1 a small kick decays, below it grows and
    blocks stick. The down ladder brackets that edge."""
    from scipy.optimize import brentq

    from stickslip.analysis.dynamics.stability import chain_finite_eigenvalues

    res = ladder_task(_tiny_ladder("down", [2.0, 1.2, 0.8]), tmp_path)
    states = {r["beta"]: r["branch_state"] for r in res["rows"]}
    assert states[2.0] == states[1.2] == "sliding" and states[0.8] == "stick-slip"
    assert all(r["final_state"] == "steady" for r in res["rows"] if r["branch_state"] == "sliding")
    # the bracket holds the linear threshold of the finite chain (0.8255 at N = 9: the longest
    # wave it holds, k ~ pi / (2N), is stabilised by the springs), found here from its eigenvalues
    cfg = _tiny_ladder("down", [1.0])

    def growth(beta):
        p = chain_params("sakaguchi", N=9, beta=beta, **{k: cfg[k] for k in ("K", "D", "V", "Fs", "alpha", "dt")})
        return float(np.max(chain_finite_eigenvalues(p).real))

    beta_c = brentq(growth, 0.5, 1.5, xtol=1e-9)
    assert beta_c == pytest.approx(0.8255, abs=1e-3)
    assert res["outside"] < beta_c < res["inside"]


def test_per_n_summary_reads_the_loop():
    import pandas as pd

    rows = pd.DataFrame(
        [
            {"N": 9, "beta": 1.0, "branch": "up", "branch_state": "stick-slip", "order_parameter": -0.02,
             "order_parameter_err": 0.01, "stuck_fraction": 0.9, "stuck_fraction_err": 0.01, "err_reliable": True,
             "tau_int_loads": 0.02, "final_state": "stick-slip"},
            {"N": 9, "beta": 1.2, "branch": "up", "branch_state": "stick-slip", "order_parameter": -0.05,
             "order_parameter_err": 0.01, "stuck_fraction": 0.9, "stuck_fraction_err": 0.01, "err_reliable": True,
             "tau_int_loads": 0.02, "final_state": "stick-slip"},
            {"N": 9, "beta": 1.4, "branch": "up", "branch_state": "sliding", "order_parameter": 0.0,
             "order_parameter_err": 0.0, "stuck_fraction": 0.0, "stuck_fraction_err": 0.0, "err_reliable": True,
             "tau_int_loads": math.nan, "final_state": "steady"},
            {"N": 9, "beta": 1.1, "branch": "down", "branch_state": "sliding", "order_parameter": 0.0,
             "order_parameter_err": 0.0, "stuck_fraction": 0.0, "stuck_fraction_err": 0.0, "err_reliable": True,
             "tau_int_loads": math.nan, "final_state": "steady"},
            {"N": 9, "beta": 0.9, "branch": "down", "branch_state": "stick-slip", "order_parameter": 0.01,
             "order_parameter_err": 0.01, "stuck_fraction": 0.5, "stuck_fraction_err": 0.01, "err_reliable": False,
             "tau_int_loads": 0.01, "final_state": "stick-slip"},
        ]
    )  # fmt: skip
    s = per_n_summary(rows).iloc[0]
    assert s["beta_t"] == 1.2 and s["beta_t_err"] == pytest.approx(0.1)
    assert s["lower_edge"] == pytest.approx(1.0) and s["lower_edge_err"] == pytest.approx(0.1)
    assert s["step"] == -0.05 and s["step_err"] == 0.01 and s["step_phi"] == 0.9


def _up(replica, beta, state, m=0.0, m_err=0.0):
    stick = state == "stick-slip"
    # fmt: off
    return {"N": 9, "beta": beta, "branch": "up", "replica": replica, "branch_state": state,
            "order_parameter": m, "order_parameter_err": m_err, "stuck_fraction": 0.9 if stick else 0.0,
            "stuck_fraction_err": 0.01 if stick else 0.0, "err_reliable": True,
            "tau_int_loads": 0.02 if stick else math.nan, "final_state": "stick-slip" if stick else "steady"}
    # fmt: on


def test_per_n_summary_averages_the_replicas_of_the_up_ladder():
    """beta_t is the mean of the replicas' last stick-slip beta, its error the standard error of
    that mean when the replicas scatter more than their brackets; the step likewise."""
    import pandas as pd

    rows = pd.DataFrame(
        [
            _up(0, 1.0, "stick-slip", -0.02, 0.001), _up(0, 1.1, "stick-slip", -0.04, 0.001), _up(0, 1.12, "sliding"),
            _up(1, 1.0, "stick-slip", -0.02, 0.001), _up(1, 1.2, "stick-slip", -0.06, 0.001), _up(1, 1.22, "sliding"),
            _up(2, 1.0, "stick-slip", -0.02, 0.001), _up(2, 1.3, "stick-slip", -0.08, 0.001), _up(2, 1.32, "sliding"),
        ]
    )  # fmt: skip
    s = per_n_summary(rows).iloc[0]
    # beta_t of the replicas 1.1, 1.2, 1.3: mean 1.2, sample std 0.1, standard error 0.1 / sqrt(3)
    assert s["beta_t"] == pytest.approx(1.2) and s["beta_t_err"] == pytest.approx(0.1 / math.sqrt(3))
    assert s["beta_t_spread"] == pytest.approx(0.1) and s["replicas"] == 3
    # m there -0.04, -0.06, -0.08: mean -0.06, sample std 0.02
    assert s["step"] == pytest.approx(-0.06) and s["step_err"] == pytest.approx(0.02 / math.sqrt(3))
    # one replica: its half bracket and its own error are all there is
    one = per_n_summary(rows[rows["replica"] == 0]).iloc[0]
    assert one["beta_t"] == 1.1 and one["beta_t_err"] == pytest.approx(0.01) and one["step_err"] == pytest.approx(0.001)


@pytest.mark.slow  # a transition study or a ladder run to its end (20-45 s, measured)
def test_tiny_transition_study_and_its_json(tmp_path):
    """The CLI end to end: rows and per-N fields in --json; a second call reuses every ladder."""
    out = tmp_path / "studies"
    argv = ("study", "transition", "--tiny", "--workers", "1", "--out", str(out), "--no-progress", "--json")
    first = run_cli_subprocess(*argv, timeout=300)
    assert first.returncode == 0, first.stderr
    data = json.loads(first.stdout)
    assert data["points"] == 3 and data["run"] == 3  # two up replicas, one down
    row_keys = {"N", "beta", "branch", "order_parameter", "order_parameter_err", "stuck_fraction",
                "stuck_fraction_err", "final_state", "t_end", "start"}  # fmt: skip
    assert all(row_keys <= set(r) for r in data["rows"])
    assert {r["branch"] for r in data["rows"]} == {"up", "down"}
    assert set(PER_N_COLUMNS) <= set(data["findings"]["per_N"][0])
    assert all(r["final_reason"] for r in data["rows"] if r["final_state"] == "undecided")
    assert (out / "transition" / "loops.png").is_file() and (out / "transition" / "index.html").is_file()
    assert {r["replica"] for r in data["rows"] if r["branch"] == "up"} == {0, 1}
    assert data["findings"]["per_N"][0]["replicas"] == 2
    assert data["findings"]["rungs"] == len(data["rows"]) and "Per N" in (out / "transition" / "index.html").read_text()
    second = json.loads(run_cli_subprocess(*argv, timeout=300).stdout)
    assert second["reused"] == 3 and second["rows"] == data["rows"]


def test_extra_n_only_for_the_transition_study(tmp_path):
    r = run_cli_subprocess("study", "chaos", "--extra-n", "1599", "--out", str(tmp_path))
    assert r.returncode == 2 and "unrecognized arguments: --extra-n" in r.stderr.strip().splitlines()[-1]
    r = run_cli_subprocess("study", "transition", "--extra-n", "2", "--out", str(tmp_path))
    assert r.returncode == 2 and r.stderr.strip().splitlines() == [
        "stickslip study: error: extra-n must be >= 3 and <= 1e+06 (got 2)"
    ]
    assert not any(tmp_path.iterdir())


@pytest.mark.slow  # a transition study or a ladder run to its end (20-45 s, measured)
def test_the_transition_study_resumes_a_ladder_from_its_finished_rungs(tmp_path):
    """A ladder whose task was interrupted (no done.json) replays its finished rungs: the rows come
    back bit for bit and the rungs are not run again."""
    first = run_study("transition", tmp_path, "tiny", n_workers=1, progress=False)
    ladders = sorted((tmp_path / "runs").glob("*/points/*/done.json"))
    assert len(ladders) == 3
    for done in ladders:
        done.unlink()
    stamps = {p: p.stat().st_mtime_ns for p in tmp_path.glob("runs/*/points/*/rungs/*/rung.json")}
    second = run_study("transition", tmp_path, "tiny", n_workers=1, progress=False)
    assert second["run"] == 3 and second["rows"] == first["rows"]
    assert {p: p.stat().st_mtime_ns for p in stamps} == stamps


def test_transition_loop_runs_the_studys_ladders_in_this_process(tmp_path):
    """transition_loop's rungs are the study's ladders with the study's settings (ladder_task with
    the quick mode's, bit for bit); the up ladder stick-slips below the loop and slides above it;
    a second call reuses every rung; a bad beta is refused before anything runs."""
    kw = {"bisections": 1, "cap_loads": 1.0, "up": [0.8, 2.0, 4.0], "down": [2.0, 1.2, 0.8]}
    rows = transition_loop(9, out_dir=tmp_path / "loop", **kw)
    common, _ = ladder_points("quick")
    for branch in ("up", "down"):
        point = {**common, "N": 9, "direction": branch, "betas": kw[branch], "cap_loads": 1.0, "bisections": 1}
        direct = ladder_task({**point, "seed": 0, "replica": 0}, tmp_path / branch)["rows"]
        mine = rows[rows["branch"] == branch].sort_values("rung")
        assert mine["beta"].tolist() == [r["beta"] for r in direct]
        assert mine["order_parameter"].tolist() == [r["order_parameter"] for r in direct]
        assert mine["final_sha256"].tolist() == [r["final_sha256"] for r in direct]
    up = rows[rows["branch"] == "up"].set_index("beta")["branch_state"]
    assert up[0.8] == "stick-slip" and up[4.0] == "sliding"
    stamps = {q: q.stat().st_mtime_ns for q in (tmp_path / "loop").rglob("rung.json")}
    assert len(stamps) == len(rows)
    again = transition_loop(9, out_dir=tmp_path / "loop", **kw)
    assert again.equals(rows) and {q: q.stat().st_mtime_ns for q in stamps} == stamps
    with pytest.raises(ParameterError, match="beta"):
        transition_loop(9, out_dir=tmp_path / "refused", up=[0.8, -1.0])
    assert not (tmp_path / "refused").exists()


# --- the faster method measures the same thing --------------------------------------------------


@pytest.mark.slow  # a transition study or a ladder run to its end (20-45 s, measured)
def test_up_ladder_agrees_with_paper_start_runs_at_n49(tmp_path):
    """Below beta = 0.95 the up ladder's m at N = 49 agrees with runs of 4 loading times from the
    paper's start (second half) within 3 combined errors."""
    from stickslip.experiments.transition_checks import paper_start_check

    common, _ = ladder_points("quick")
    cfg = {**common, "N": 49, "direction": "up", "betas": [0.8, 0.9, 1.0], "cap_loads": 4.0, "bisections": 0}
    rows = ladder_task(cfg, tmp_path)["rows"]
    checks = paper_start_check(rows)
    assert [c["beta"] for c in checks] == [0.8, 0.9]
    for c in checks:
        assert abs(c["z"]) < 3.0, c


@pytest.mark.slow
def test_chain_from_the_final_state_of_another_run(tmp_path):
    """`stickslip chain --from DIR` starts from a run directory's final state and goes on in time:
    run to 2000 then --from to 4000 ends where one run to 4000 from the same state does."""
    first = tmp_path / "first"
    r = run_cli_subprocess(
        "chain", "--N", "6", "--beta", "0.8", "--t-end", "2000", "--out", str(first), "--json", "--no-progress"
    )
    assert r.returncode == 0, r.stderr
    r2 = run_cli_subprocess("chain", "--N", "6", "--beta", "0.8", "--from", str(first), "--t-end", "4000", "--json")
    assert r2.returncode == 0, r2.stderr
    from stickslip.run.driver import run_chain
    from stickslip.run.rundir import final_state

    state = final_state(first)
    assert state.step == 400_000
    direct = run_chain(chain_params("sakaguchi", N=6, beta=0.8), 4000.0, start=state)
    assert json.loads(r2.stdout)["state_sha256"] == direct.summary["state_sha256"]
    bad = run_cli_subprocess("chain", "--N", "7", "--from", str(first), "--t-end", "4000")
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1
    bad = run_cli_subprocess("chain", "--N", "6", "--from", str(first), "--start", "steady")
    assert bad.returncode == 2


@pytest.mark.slow  # a transition study or a ladder run to its end (20-45 s, measured)
def test_a_longer_run_of_a_rung_restarts_from_the_state_it_started_from(tmp_path):
    """write_checks on a finished tiny study: the longer run of an up-ladder rung starts from the
    state that rung started from (the hash its row records) and runs past the rung's own length."""
    from stickslip.experiments.transition_checks import rung_start_state, write_checks

    result = run_study("transition", tmp_path, "tiny", n_workers=1, progress=False)
    up = [r for r in result["rows"] if r["branch"] == "up" and r["replica"] == 0 and r["role"] == "grid"]
    row = up[1]
    runs = Path(result["runs"])
    checks = write_checks(
        tmp_path / "transition" / "study.json", runs, tmp_path / "checks.json",
        paper_Ns=(), longer=((row["N"], row["beta"]),), factor=2.0, n_workers=1,
    )  # fmt: skip
    (long,) = checks["longer"]
    assert long["beta"] == row["beta"] and long["adaptive_m"] == row["order_parameter"]
    assert long["long_loads"] > row["loads"] and json.loads((tmp_path / "checks.json").read_text())["longer"]
    ladder = next(
        p.parent
        for p in runs.glob("points/*/done.json")
        if "direction=up" in p.parent.name and "replica=0" in p.parent.name
    )
    state, stored = rung_start_state(ladder, int(row["rung"]), {})
    assert state.sha256() == stored["start_sha256"] == up[0]["final_sha256"]
