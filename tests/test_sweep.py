"""Parameter sweeps on a real dask.distributed LocalCluster with two worker processes."""

from __future__ import annotations

import json
import os
import sys
import types
from pathlib import Path

import pandas as pd
import pytest

from stickslip.cli import main
from stickslip.experiments.sweep import chain_task, demo_task, point_name, run_sweep
from stickslip.io import read_json


def sum_of_squares(n: int) -> float:
    return n * (n + 1) * (2 * n + 1) / 6


@pytest.fixture(scope="module")
def cluster():
    from dask.distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as lc:
        with Client(lc) as client:
            pids = set(client.run(os.getpid).values())
        yield lc, pids


def test_point_names_are_stable_and_safe():
    assert point_name({"N": 399, "beta": 0.9}) == "beta=0.9_N=399"
    assert point_name({"beta": 0.9, "N": 399}) == "beta=0.9_N=399"
    assert point_name({"N": 399.0, "beta": 1.0}) == "beta=1_N=399"
    assert point_name({"V": 1e-3}) == "V=0.001"
    assert point_name({"mode": "a/b c"}) == "mode=a-b-c"


def test_sweep_on_two_worker_processes_skips_done_points_and_survives_a_failure(cluster, tmp_path):
    lc, worker_pids = cluster
    assert len(worker_pids) == 2 and os.getpid() not in worker_pids
    points = [{"x": 1.0}, {"x": 2.0}, {"x": 3.0, "fail": True}, {"x": 4.0}]
    common = {"n": 5, "sleep": 0.2}

    first = run_sweep(demo_task, points, tmp_path, common=common, scheduler=lc.scheduler_address, progress=False)
    table = first.table.set_index("point_dir")
    assert sorted(p.name for p in tmp_path.iterdir() if p.is_dir()) == sorted(["x=1", "x=2", "x=4", "fail=True_x=3"])
    assert first.n_run == 4 and first.n_reused == 0 and first.n_failed == 1
    for x in (1.0, 2.0, 4.0):
        name = point_name({"x": x})
        assert table.loc[name, "status"] == "ok"
        assert table.loc[name, "value"] == sum_of_squares(5) * x
        assert float((tmp_path / name / "value.txt").read_text()) == sum_of_squares(5) * x
        assert (tmp_path / name / "done.json").is_file()
        assert int(table.loc[name, "pid"]) in worker_pids  # ran in a worker process
    failed = table.loc["fail=True_x=3"]
    assert failed["status"] == "failed"
    assert "demo point asked to fail" in failed["error"]
    error = read_json(tmp_path / "fail=True_x=3" / "error.json")
    assert "ValueError" in error["traceback"] and "demo_task" in error["traceback"]
    assert not (tmp_path / "fail=True_x=3" / "done.json").exists()

    # the summary table on disk, Parquet and CSV
    stored = pd.read_parquet(tmp_path / "summary.parquet")
    assert stored["point_dir"].tolist() == ["x=1", "x=2", "fail=True_x=3", "x=4"]
    assert list(stored.columns[:2]) == ["x", "fail"]
    assert pd.read_csv(tmp_path / "summary.csv")["status"].tolist() == ["ok", "ok", "failed", "ok"]

    # a second call runs only the failed point again
    stamp = (tmp_path / "x=1" / "done.json").stat().st_mtime_ns
    second = run_sweep(demo_task, points, tmp_path, common=common, scheduler=lc.scheduler_address, progress=False)
    assert second.n_run == 1 and second.n_reused == 3 and second.n_failed == 1
    assert second.table.set_index("point_dir")["reused"].to_dict() == {
        "x=1": True,
        "x=2": True,
        "fail=True_x=3": False,
        "x=4": True,
    }
    assert (tmp_path / "x=1" / "done.json").stat().st_mtime_ns == stamp

    # a changed common setting makes the stored results stale: they are run again
    third = run_sweep(demo_task, points[:2], tmp_path, common={"n": 6}, scheduler=lc.scheduler_address, progress=False)
    assert third.n_run == 2 and third.n_reused == 0
    assert third.table["value"].tolist() == [sum_of_squares(6) * 1.0, sum_of_squares(6) * 2.0]


def test_sweep_starts_its_own_local_cluster(tmp_path, capfd, monkeypatch):
    from stickslip.experiments import sweep as sweep_module

    monkeypatch.setattr(sweep_module, "_on_terminal", lambda: True)  # the bar is drawn on a terminal only
    points = [{"x": 1.0}, {"x": 2.0}]
    result = run_sweep(demo_task, points, tmp_path, common={"n": 3}, n_workers=2, progress=True)
    assert result.n_run == 2 and result.n_failed == 0
    assert result.table["value"].tolist() == [14.0, 28.0]
    assert os.getpid() not in set(result.table["pid"].astype(int))
    err = capfd.readouterr().err
    assert "2/2" in err  # progress: points done / total
    # all points done: nothing to compute, no cluster needed
    again = run_sweep(demo_task, points, tmp_path, common={"n": 3}, n_workers=2, progress=False)
    assert again.n_run == 0 and again.n_reused == 2


def test_sweep_draws_no_bar_into_a_log(tmp_path, capfd, monkeypatch):
    from stickslip.experiments import sweep as sweep_module

    monkeypatch.setattr(sweep_module, "_on_terminal", lambda: False)
    result = run_sweep(demo_task, [{"x": 1.0}], tmp_path, common={"n": 3}, n_workers=1, progress=True)
    assert result.n_run == 1
    assert "1/1" not in capfd.readouterr().err


def test_sweep_rejects_repeated_points(tmp_path):
    with pytest.raises(ValueError, match="repeat"):
        run_sweep(demo_task, [{"x": 1.0}, {"x": 1}], tmp_path, progress=False)


def test_chain_task_calls_the_simulator_with_the_point(tmp_path, monkeypatch):
    from stickslip.experiments.sweep import STOP_FILE

    calls = {}

    def continue_or_run(params, t_end, run_dir, **kwargs):
        calls.update(params=params, t_end=t_end, run_dir=run_dir, **kwargs)
        return types.SimpleNamespace(summary={"n_events": 3, "L_mean": 12.5})

    def write_run(run, out_dir):
        calls["written"] = Path(out_dir)

    fake = types.ModuleType("stickslip.run.driver")
    fake.continue_or_run, fake.write_run = continue_or_run, write_run
    monkeypatch.setitem(sys.modules, "stickslip.run.driver", fake)
    monkeypatch.setattr("stickslip.run.driver", fake, raising=False)
    point_dir = tmp_path / "beta=0.9"
    summary = chain_task({"beta": 0.9, "N": 19, "t_end": 100.0, "average_from": 50.0}, point_dir)
    assert summary == {"n_events": 3, "L_mean": 12.5}
    assert calls["params"].beta == 0.9 and calls["params"].N == 19 and calls["params"].K == 10.0
    assert calls["t_end"] == 100.0 and calls["average_from"] == 50.0 and calls["run_dir"] == point_dir
    assert calls["checkpoint_interval"] == 120.0
    assert calls["stop_requested"]() is False
    (tmp_path / STOP_FILE).touch()
    assert calls["stop_requested"]() is True
    with pytest.raises(ValueError, match="unknown"):
        chain_task({"gamma": 1.0, "t_end": 1.0}, tmp_path)


# --- command line ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "args, message",
    [
        (["--grid", "beta"], "--grid expects NAME=VALUE"),
        (["--grid", "gamma=1,2"], "unknown parameter 'gamma'"),
        (["--grid", "beta=0.5,x"], "beta must be"),
        (["--grid", "beta=-1,1"], "beta must be >= 0"),
        (["--grid", "N=10.5"], "N must be an integer"),
        (["--grid", "beta=1,1"], "repeated value"),
        (["--grid", "beta=1", "--set", "beta=2"], "more than once"),
        (["--set", "D=200"], "D*dt"),
    ],
)
def test_cli_bad_grid_is_one_line_exit_2_and_writes_nothing(tmp_path, capsys, args, message):
    out = tmp_path / "sweep"
    status = main(["sweep", "chain", "--t-end", "10", "--out", str(out), *args])
    err = capsys.readouterr().err
    assert status == 2
    assert message in err and err.count("\n") == 1
    assert not out.exists()


def test_cli_bad_t_end_and_workers(tmp_path, capsys):
    out = tmp_path / "sweep"
    assert main(["sweep", "block", "--grid", "V=0.01", "--t-end", "-5", "--out", str(out)]) == 2
    assert main(["sweep", "block", "--grid", "V=0.01", "--t-end", "5", "--workers", "0", "--out", str(out)]) == 2
    assert not out.exists()


@pytest.mark.slow  # a sweep of blocks from the command line (19 s, measured)
def test_cli_block_sweep_json(tmp_path, capsys):
    out = tmp_path / "sweep"
    argv = [
        "sweep",
        "block",
        "--grid",
        "V=0.01,0.02",
        "--set",
        "Fs=3",
        "--t-end",
        "150",
        "--out",
        str(out),
        "--workers",
        "2",
        "--no-progress",
        "--json",
    ]
    assert main(argv) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["n_points"] == 2 and data["n_failed"] == 0
    rows = {row["point_dir"]: row for row in data["points"]}
    assert set(rows) == {"V=0.01", "V=0.02"}
    for name, V in (("V=0.01", 0.01), ("V=0.02", 0.02)):
        assert rows[name]["status"] == "ok" and rows[name]["V"] == V
        assert (out / name / "series.nc").is_file() and (out / name / "slips.parquet").is_file()
        # stick interval ~ (Fs - f_end)/(K V): the period halves when V doubles (Fig. 3)
    assert rows["V=0.01"]["period"] / rows["V=0.02"]["period"] == pytest.approx(2.0, rel=0.1)
    assert main(argv) == 0
    assert json.loads(capsys.readouterr().out)["n_reused"] == 2


@pytest.mark.slow  # a worker killed and its cluster restarted (13 s, measured)
def test_a_point_that_kills_its_worker_is_recorded_and_the_others_finish(tmp_path):
    import dask

    # the crashing point waits, so the others are done before it takes its worker down
    points = [{"x": 1.0}, {"x": 2.0, "crash": True, "sleep": 1.0}, {"x": 3.0}]
    crashed = point_name(points[1])
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        result = run_sweep(demo_task, points, tmp_path, common={"n": 2}, n_workers=2, progress=False)
    table = result.table.set_index("point_dir")
    assert table.loc[crashed, "status"] == "failed"
    assert "KilledWorker" in table.loc[crashed, "error"]
    assert (tmp_path / crashed / "error.json").is_file()
    assert table.loc[["x=1", "x=3"], "status"].tolist() == ["ok", "ok"]
    assert table.loc[["x=1", "x=3"], "value"].tolist() == [5.0, 15.0]


# both end in the same except clause; each a sweep stopped and resumed in subprocesses (about
# 20 s, measured): -m slow (tests/test_signals_group.py stops a sweep in the default run)
@pytest.mark.slow
@pytest.mark.parametrize("signame", ["SIGINT", "SIGTERM"])
def test_an_interrupted_sweep_says_so_in_one_line_and_resumes(tmp_path, signame):
    """SIGINT or SIGTERM to the command alone (as ``timeout`` or ``kill`` send them) while its worker
    runs a chain: exit 130, one line on stderr, the directory left to the next call."""
    import signal

    from chain_helpers import signal_when_running

    out = tmp_path / "sweep"
    # a sliding N = 199 chain to t = 1e7 runs for hours: the worker is busy when the signal comes
    argv = ["sweep", "chain", "--grid", "beta=1.5", "--set", "N=199", "--t-end", "1e7",
            "--workers", "1", "--out", str(out), "--no-progress"]  # fmt: skip
    status, stdout, stderr = signal_when_running(
        argv, (out / "beta=1.5" / "point.json").is_file, getattr(signal, signame)
    )
    assert status == 130, stderr
    assert stdout == ""
    assert stderr.splitlines() == [
        "stickslip sweep: interrupted; run the same command again to continue "
        f"(finished points in {out} are kept, chain runs continue from their checkpoints)"
    ], stderr
    assert not (out / "summary.parquet").exists()
    assert (out / "beta=1.5" / "point.json").is_file()  # the point's spec stays for the next call
    assert (out / "beta=1.5" / "checkpoint" / "state.npz").is_file()  # written on the way out
    assert not (out / "stop-requested").exists()


def test_a_point_stopped_on_request_is_left_for_the_next_sweep(tmp_path):
    """A task that stops because its sweep was interrupted (Interrupted, after its checkpoint)
    gets neither done.json nor error.json; with the stop file present a point does not start."""
    from stickslip.experiments.sweep import STOP_FILE, _run_point, stop_requested
    from stickslip.run.errors import Interrupted

    seen = []

    def task(point: dict, point_dir: Path) -> dict:
        seen.append(stop_requested(point_dir)())
        (tmp_path / STOP_FILE).touch()  # the sweep is interrupted while the point runs
        assert stop_requested(point_dir)()
        raise Interrupted(point_dir / "checkpoint" / "state.npz", 12.5)

    record = _run_point(task, {"x": 1}, {}, str(tmp_path / "x=1"), {"x": 1})
    assert record["status"] == "interrupted"
    assert seen == [False]
    assert not (tmp_path / "x=1" / "done.json").exists()
    assert not (tmp_path / "x=1" / "error.json").exists()
    assert _run_point(task, {"x": 2}, {}, str(tmp_path / "x=2"), {"x": 2})["status"] == "interrupted"
    assert seen == [False]  # the second point never started
    assert not (tmp_path / "x=2").exists()


def test_a_chain_point_stopped_on_request_continues_to_the_uninterrupted_result(tmp_path):
    """A sweep's chain point stopped through the stop file checkpoints; run again it continues
    from there and ends with the bits of one uninterrupted run."""
    from stickslip.experiments.sweep import STOP_FILE
    from stickslip.models.params import ChainParams
    from stickslip.run.driver import run_chain
    from stickslip.run.errors import Interrupted

    point = {"beta": 0.9, "N": 9, "t_end": 3000.0}  # 6e5 steps: stopped after the first call's 2e5
    ref = run_chain(ChainParams(beta=0.9, N=9), 3000.0)
    (tmp_path / STOP_FILE).touch()
    with pytest.raises(Interrupted) as stopped:
        chain_task(point, tmp_path / "beta=0.9")
    assert 0 < stopped.value.t < 3000.0
    assert (tmp_path / "beta=0.9" / "checkpoint" / "state.npz").is_file()
    (tmp_path / STOP_FILE).unlink()
    summary = chain_task(point, tmp_path / "beta=0.9")
    assert summary["state_sha256"] == ref.summary["state_sha256"]
    assert summary["n_events"] == ref.summary["n_events"] > 0
    assert not (tmp_path / "beta=0.9" / "checkpoint").exists()


def test_a_checkpoint_of_other_settings_is_not_continued(tmp_path):
    """A point whose point.json holds another spec (say another --t-end) loses its checkpoint
    before the task runs; with the same spec the checkpoint stays for the task to continue."""
    from stickslip.experiments.sweep import _run_point

    seen = []

    def task(point: dict, point_dir: Path) -> dict:
        seen.append((point_dir / "checkpoint" / "state.npz").is_file())
        return {}

    def old_checkpoint(spec):
        (tmp_path / "x=1" / "checkpoint").mkdir(parents=True, exist_ok=True)
        (tmp_path / "x=1" / "checkpoint" / "state.npz").write_bytes(b"state")
        (tmp_path / "x=1" / "point.json").write_text(json.dumps({"spec": spec}))

    old_checkpoint({"x": 1, "t_end": 10.0})
    assert _run_point(task, {"x": 1}, {}, str(tmp_path / "x=1"), {"x": 1, "t_end": 10.0})["status"] == "ok"
    old_checkpoint({"x": 1, "t_end": 10.0})
    assert _run_point(task, {"x": 1}, {}, str(tmp_path / "x=1"), {"x": 1, "t_end": 20.0})["status"] == "ok"
    assert seen == [True, False]


def log_an_error_on_the_worker(point: dict, point_dir: Path) -> dict:
    """Logs as a worker does when its scheduler is gone (at every Ctrl-C during a point)."""
    import logging

    logging.getLogger("distributed.worker").error("failed to communicate with scheduler (test)")
    return {"value": 1.0}


def test_the_local_clusters_log_stays_off_the_terminal(tmp_path, capfd):
    result = run_sweep(log_an_error_on_the_worker, [{"x": 1.0}], tmp_path, n_workers=1, progress=False)
    assert result.table["status"].tolist() == ["ok"]  # the task ran on the worker ...
    err = capfd.readouterr().err
    assert "failed to communicate" not in err  # ... and its log did not reach the terminal
