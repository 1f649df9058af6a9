"""Bad input is refused in one line (exit 2, nothing on stdout, nothing written); run directories
are owned by one run; checkpoints are validated before a kernel sees them; blow-ups exit 1."""

from __future__ import annotations

import json
import shlex
import subprocess
import time

import pytest

from chain_helpers import cli_env, error_lines, run_cli_subprocess, stickslip_cmd
from stickslip.cli import main

BAD = [
    ("block --every 1e300", "every"),
    ("block --t-end 1e300", "t_end"),
    ("block --K abc", "K must be a number > 0"),
    ("block --out afile/x", "--out"),
    ("block --M -1", "M"),
    ("slip-limit --rtol 10", "rtol"),
    ("slip-limit --K 1e12", "dt"),
    ("slip-limit --dt 1e3", "dt"),
    ("slip-limit --Fs 1e9", "Fs"),
    ("stability block --out afile/x", "--out"),
    ("stability chain --K -1", "K"),
    ("stability block --K 1e300 --out sbk", "K"),
    ("chain --model carlson-langer --D 3", "--D"),
    ("chain --ends periodic", "periodic"),
    ("chain --model train --threshold state", "threshold"),
    ("chain --model nosuch", "--model"),
    ("chain --model carlson-langer --perturbation -1", "perturbation"),
    ("block --model carlson-langer", "--model"),
    ("bench --model carlson-langer --l 0", "l"),
    ("lyapunov --model two-blocks --d0 1", "d0"),
    ("hysteresis --time-per-step 1e12", "time_per_step"),
    ("chain --sample-interval 1e300", "--sample-interval"),
    ("chain --sample-interval 1e30", "--sample-interval"),
    ("chain --profile-window 1e300", "--profile-window"),
    ("chain --start steady --perturbation 0.1 --seed -1", "seed"),
    ("chain --out afile/x --t-end 10", "--out"),
    ("chain --N 10000000 --t-end 100", "N"),
    ("chain --t-end 1e300", "t-end"),
    ("chain --t-end 1e17", "t-end"),
    ("chain --dt 1e-12", "t-end"),
    ("chain --D 100", "D*dt"),
    ("chain --D 99.9", "D*dt"),
    ("chain --checkpoint-interval 5 --t-end 10", "--checkpoint-interval"),
    ("chain --seed 3 --t-end 10", "--seed"),
    ("chain --average-from 100 --t-end 10", "--average-from"),
    ("chain --overwrite --t-end 10", "--overwrite"),
    ("bench --N 9 --t-end 0", "t-end"),
    ("bench --N 10000000 --t-end 100", "N"),
    ("bench --t-end 1e300", "t-end"),
    ("sweep chain --t-end 10 --out o --scheduler garbage", "--scheduler"),
    ("sweep chain --t-end 10 --out o --scheduler ''", "--scheduler"),
    ("sweep chain --t-end 10 --out afile/x", "--out"),
    ("sweep chain --t-end 1e300 --out o", "t_end"),
    ("sweep chain --t-end 10 --out o --set integrator=foo", "integrator"),
    ("sweep chain --t-end 10 --out o --set start=foo", "start"),
    ("sweep chain --t-end 10 --out o --set sample_interval=0", "sample_interval"),
    ("sweep chain --t-end 10 --out o --set average_from=-1", "average_from"),
    ("sweep chain --t-end 10 --out o --set profile_window=0", "profile_window"),
    ("sweep chain --t-end 10 --out o --set profile_min_blocks=-1", "profile_min_blocks"),
    ("sweep block --t-end 10 --out o --set every=0", "every"),
    ("sweep chain --t-end 10 --out o --set K=inf", "K must be a finite number > 0"),
    ("sweep chain --t-end 10 --out o --set K=nan", "K must be a finite number > 0"),
    ("sweep chain --t-end 10 --out o --set N=inf", "N must be an integer >= 1"),
    ("sweep chain --t-end 10 --out o --grid beta=1,nan", "beta must be a finite number >= 0"),
    ("sweep chain --t-end 10 --out o --set sample_interval=inf", "sample_interval must be a finite number > 0"),
    ("sweep chain --t-end 10 --out o --set average_from=-inf", "average_from must be a finite number >= 0"),
    ("sweep block --t-end 10 --out o --set every=inf", "every must be an integer >= 1"),
    ("sweep block --t-end 10 --out o --set K=-inf", "K must be a finite number > 0"),
    # --out holding somebody else's files; --overwrite or --keep-checkpoint without --out
    ("block --t-end 10 --out foreign", "notes.txt"),
    ("stability block --out foreign", "notes.txt"),
    ("stability chain --out foreign", "notes.txt"),
    ("stability chain --model train --out foreign", "notes.txt"),
    ("hysteresis --time-per-step 10 --out foreign", "notes.txt"),
    ("sweep block --t-end 10 --out foreign", "notes.txt"),
    ("reproduce --tiny --out foreign", "notes.txt"),
    ("chain --t-end 10 --out foreign", "notes.txt"),
    ("block --t-end 10 --overwrite", "--overwrite"),
    ("stability block --overwrite", "--overwrite"),
    ("stability chain --overwrite", "--overwrite"),
    ("hysteresis --time-per-step 10 --overwrite", "--overwrite"),
    ("chain --keep-checkpoint --t-end 10", "--keep-checkpoint"),
    ("models --bogus", "--bogus"),
    ("chain --t-end 0", "t-end"),
    ("chain --t-end 0 --out o", "t-end"),
    ("block --t-end 0", "t_end"),
    ("chain --resume ''", "--resume"),
    ("chain --resume nope", "no such run directory"),
    ("chain --resume afile", "no such run directory"),
    ("lyapunov --direction-seed -1", "direction-seed"),
    ("lyapunov --seed 3", "--seed"),
    ("lyapunov --betas ''", "betas"),
    ("lyapunov --betas , --plot p.png", "betas"),
    ("sweep block --t-end 10 --out o --scheduler 127.0.0.1:65536", "port"),
    ("sweep block --t-end 10 --out o --scheduler tcp://127.0.0.1:1", "no scheduler answers"),
    ("study chaos --tiny --out o --scheduler tcp://127.0.0.1:1", "no scheduler answers"),
    ("study chaos --tiny --out foreign", "notes.txt"),
    ("reproduce --smoke --out o --scheduler 127.0.0.1:99999", "port"),
    ("lyapunov --N 0", "N"),
    ("reproduce --bogus", "--bogus"),
    ("--bogus", "--bogus"),
]


def _tree(path):
    return sorted(str(p.relative_to(path)) for p in path.rglob("*"))


@pytest.mark.parametrize("argv,name", BAD, ids=[c for c, _ in BAD])
def test_bad_input_one_line_exit_2(argv, name, tmp_path, monkeypatch, capsys):
    (tmp_path / "afile").write_text("")
    (tmp_path / "foreign").mkdir()
    (tmp_path / "foreign" / "notes.txt").write_text("mine")
    monkeypatch.chdir(tmp_path)
    before = _tree(tmp_path)
    try:
        status = main(shlex.split(argv))
    except SystemExit as exc:
        status = exc.code
    out, err = capsys.readouterr()
    assert status == 2, err
    assert out == ""
    assert len(error_lines(err)) == 1 and err.endswith("\n") and "Traceback" not in err, err
    assert name in err, err
    assert _tree(tmp_path) == before


@pytest.mark.parametrize("argv", ["--bogus", "chain --t-end 1e300", "block --K abc"])
def test_bad_input_subprocess(argv, tmp_path):
    proc = subprocess.run(
        stickslip_cmd() + shlex.split(argv), capture_output=True, text=True, cwd=tmp_path, env=cli_env(), timeout=120
    )
    assert proc.returncode == 2 and proc.stdout == "" and len(error_lines(proc.stderr)) == 1, proc.stderr
    assert list(tmp_path.iterdir()) == []


def test_block_blow_up_exits_1(capsys):
    assert main(["block", "--K", "1e6", "--t-end", "20"]) == 1
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and "non-finite by t = " in err


def test_foreign_folders_refused(tmp_path, capsys):
    (tmp_path / "notes.txt").write_text("mine")
    assert main(["chain", "--N", "3", "--t-end", "10", "--out", str(tmp_path), "--no-progress"]) == 2
    assert "notes.txt" in capsys.readouterr().err
    run = tmp_path / "run"
    assert main(["chain", "--N", "3", "--t-end", "10", "--out", str(run), "--no-progress"]) == 0
    meta = (run / "run.json").read_bytes()
    assert main(["block", "--t-end", "10", "--out", str(run)]) == 2
    assert (run / "run.json").read_bytes() == meta
    capsys.readouterr()
    assert main(["chain", "--N", "3", "--t-end", "20", "--out", str(run), "--overwrite", "--no-progress"]) == 0


def _finished_run(path):
    assert (
        main(
            [
                "chain",
                "--N",
                "4",
                "--V",
                "0.01",
                "--t-end",
                "400",
                "--out",
                str(path),
                "--keep-checkpoint",
                "--no-progress",
            ]
        )
        == 0
    )
    return path


def test_swapped_checkpoint_refused(tmp_path, capsys):
    import shutil

    a, b = _finished_run(tmp_path / "a"), _finished_run(tmp_path / "b")
    shutil.rmtree(b / "checkpoint")
    shutil.copytree(a / "checkpoint", b / "checkpoint")
    capsys.readouterr()
    assert main(["chain", "--resume", str(b), "--t-end", "800", "--no-progress"]) == 2
    assert "another run" in capsys.readouterr().err


@pytest.mark.parametrize("craft", ["step", "act", "count", "parts", "integrator", "sample"])
def test_crafted_checkpoint_refused(craft, tmp_path, capsys):
    from stickslip.kernels import layout
    from stickslip.run.checkpoint import read_npz, write_npz

    run = _finished_run(tmp_path / "r")
    path = run / "checkpoint" / "state.npz"
    arrays, header, _ = read_npz(path)
    ist = arrays["ist"]
    if craft == "step":
        ist[layout.STEP] = -5
    elif craft == "act":
        ist[layout.ACT_LO], ist[layout.ACT_HI] = 1, 10**9
    elif craft == "count":
        ist[layout.EV_COUNT] = 7
    elif craft == "parts":
        header["parts"] = []
        ist[layout.N_EVENTS] = max(1, int(ist[layout.N_EVENTS]))
    elif craft == "integrator":
        header["integrator"] = "bogus"
    else:
        header["options"]["sample_interval"] = 0
    write_npz(path, arrays, header)
    capsys.readouterr()
    assert main(["chain", "--resume", str(run), "--t-end", "800", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "checkpoint" in err, err


@pytest.mark.slow
def test_second_writer_refused_while_first_runs(tmp_path):
    out = tmp_path / "run"
    first = subprocess.Popen(
        stickslip_cmd()
        + [
            "chain",
            "--N",
            "99",
            "--t-end",
            "20000",
            "--out",
            str(out),
            "--integrator",
            "dense",
            "--no-progress",
            "--json",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=cli_env(),
    )
    deadline = time.time() + 60
    while not (out / ".lock.json").exists() and time.time() < deadline:
        time.sleep(0.1)
    second = run_cli_subprocess("chain", "--resume", str(out), "--no-progress")
    assert second.returncode == 2 and "in use by another run" in second.stderr
    assert f"pid {first.pid}" in second.stderr
    stdout, _ = first.communicate(timeout=300)
    assert first.returncode == 0 and (out / "run.json").exists() and not (out / ".lock").exists()
    assert '"events"' in stdout


# Every command that writes into --out owns it as a chain run does: one writer at a time, no
# foreign files, --overwrite removes only this package's files.

WRITERS = [
    "block --t-end 10 --out {out}",
    "stability block --out {out}",
    "stability chain --out {out}",
    "stability chain --model train --out {out}",
    "hysteresis --time-per-step 10 --out {out}",
    "sweep block --t-end 10 --out {out}",
    "plot {run} --out {out}",
    "reproduce --tiny --out {out}",
    "chain --N 3 --t-end 10 --no-progress --out {out}",
]


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    run = tmp_path_factory.mktemp("small") / "run"
    assert main(["chain", "--N", "3", "--t-end", "10", "--out", str(run), "--no-progress"]) == 0
    return run


@pytest.fixture(scope="module")
def held(tmp_path_factory):
    """A directory whose lock another process holds; yields it and the holder's pid."""
    import sys

    d = tmp_path_factory.mktemp("held")
    code = (
        "import sys, time\nfrom stickslip.run.rundir import owned_run_dir\n"
        "with owned_run_dir(sys.argv[1], run_id=False):\n"
        "    print('held', flush=True)\n    time.sleep(600)\n"
    )
    proc = subprocess.Popen([sys.executable, "-c", code, str(d)], stdout=subprocess.PIPE, text=True, env=cli_env())
    try:
        assert proc.stdout.readline().strip() == "held"
        yield d, proc.pid
    finally:
        proc.kill()
        proc.wait()


@pytest.mark.parametrize("command", WRITERS, ids=[c.split(" --out")[0] for c in WRITERS])
def test_second_writer_refused_at_once_naming_the_holder(command, held, small_run, capsys, monkeypatch):
    from chain_helpers import record_lock_tries

    tries = record_lock_tries(monkeypatch)
    out, pid = held
    before = _tree(out)
    capsys.readouterr()
    status = main(shlex.split(command.format(out=out, run=small_run)))
    stdout, err = capsys.readouterr()
    assert status == 2 and stdout == "", err
    assert err.count("\n") == 1 and "in use by another run" in err and f"pid {pid}" in err, err
    assert tries and set(tries) == {0}, "refused at once: the lock is tried, never waited for"
    assert _tree(out) == before


@pytest.mark.parametrize("command", ["block --t-end 10", "stability block", "hysteresis --time-per-step 10"])
def test_finished_chain_run_is_not_overwritten(command, tmp_path, capsys):
    """The issue's example: `block --out` on a finished chain run overwrote its run.json."""
    run = tmp_path / "run"
    assert main(["chain", "--N", "3", "--t-end", "10", "--out", str(run), "--no-progress"]) == 0
    meta = (run / "run.json").read_bytes()
    before = _tree(run)
    capsys.readouterr()
    assert main(shlex.split(command) + ["--out", str(run)]) == 2
    stdout, err = capsys.readouterr()
    assert stdout == "" and err.count("\n") == 1 and "events.parquet" in err and "--overwrite" in err, err
    assert (run / "run.json").read_bytes() == meta and _tree(run) == before


def test_overwrite_removes_only_this_packages_files(tmp_path, capsys):
    run = tmp_path / "run"
    assert main(["chain", "--N", "3", "--t-end", "10", "--out", str(run), "--no-progress"]) == 0
    (run / "notes.txt").write_text("mine")
    (run / "mine").mkdir()
    capsys.readouterr()
    assert main(["block", "--t-end", "10", "--out", str(run), "--overwrite", "--json"]) == 0
    assert (run / "notes.txt").read_text() == "mine" and (run / "mine").is_dir()
    for name in ("state.nc", "events.parquet", "first_move.parquet"):
        assert not (run / name).exists(), f"the chain run's {name} was left beside the block's files"
    assert (run / "series.nc").is_file() and json.loads((run / "run.json").read_text())["command"] == "block"
    assert not (run / ".lock").exists() and not (run / ".lock.json").exists()


@pytest.mark.slow  # a sweep run twice (about 12 s, measured)
def test_sweep_reuses_its_own_folder_and_refuses_others(tmp_path, capsys):
    out = tmp_path / "sweep"
    argv = [
        "sweep",
        "block",
        "--t-end",
        "10",
        "--grid",
        "K=8,10",
        "--out",
        str(out),
        "--workers",
        "1",
        "--no-progress",
        "--json",
    ]
    assert main(argv) == 0
    capsys.readouterr()
    assert main(argv) == 0, "a sweep run again into its own folder reuses its points"
    assert json.loads(capsys.readouterr().out)["n_reused"] == 2
    (out / "K=8" / "point.json").unlink()  # a folder that is no longer the sweep's point
    before = _tree(out)
    assert main(argv) == 2
    assert "K=8" in capsys.readouterr().err and _tree(out) == before


# A finished chain run keeps only what it needs.


def test_finished_run_drops_its_checkpoint_and_still_loads(tmp_path, capsys):
    from stickslip.run.rundir import load_run

    run = tmp_path / "run"
    assert (
        main(["chain", "--N", "4", "--V", "0.01", "--t-end", "400", "--out", str(run), "--no-progress", "--json"]) == 0
    )
    printed = json.loads(capsys.readouterr().out)
    assert not (run / "checkpoint").exists()
    assert sorted(p.name for p in run.iterdir()) == [
        ".run_id",
        "events.csv",
        "events.parquet",
        "first_move.csv",
        "first_move.parquet",
        "run.json",
        "state.nc",
    ]
    loaded = load_run(run)
    assert loaded.summary["state_sha256"] == printed["state_sha256"]
    assert len(loaded.events) == printed["events"]
    assert main(["plot", str(run), "--json"]) == 0
    assert (run / "figures" / "length.png").is_file()
    capsys.readouterr()
    before = _tree(run)
    assert main(["chain", "--resume", str(run), "--t-end", "800", "--no-progress"]) == 2
    stdout, err = capsys.readouterr()
    assert stdout == "" and err.count("\n") == 1 and "--keep-checkpoint" in err, err
    assert _tree(run) == before


def test_kept_checkpoint_stays_through_a_resume(tmp_path, capsys):
    run = tmp_path / "run"
    assert (
        main(
            [
                "chain",
                "--N",
                "4",
                "--V",
                "0.01",
                "--t-end",
                "400",
                "--out",
                str(run),
                "--no-progress",
                "--keep-checkpoint",
            ]
        )
        == 0
    )
    assert (run / "checkpoint" / "state.npz").is_file()
    capsys.readouterr()
    assert main(["chain", "--resume", str(run), "--t-end", "800", "--no-progress", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["t_end"] == 800
    assert (run / "checkpoint" / "state.npz").is_file(), "a run started with --keep-checkpoint keeps it"


def test_results_killed_while_written_are_finished_by_resume(tmp_path, capsys):
    """A kill during the final write of state.nc leaves the checkpoint and a .state.nc.*.tmp;
    --resume removes the file of the killed write and finishes the run as one run."""
    from stickslip.run.rundir import load_run

    ref, run = tmp_path / "ref", tmp_path / "run"
    for d in (ref, run):
        assert (
            main(
                [
                    "chain",
                    "--N",
                    "4",
                    "--V",
                    "0.01",
                    "--t-end",
                    "400",
                    "--out",
                    str(d),
                    "--no-progress",
                    "--keep-checkpoint",
                ]
            )
            == 0
        )
    for name in ("state.nc", "run.json"):
        (run / name).unlink()
    stale = run / ".state.nc.k1ll3d.tmp"
    stale.write_bytes(b"half a netCDF file")
    capsys.readouterr()
    assert main(["chain", "--resume", str(run), "--no-progress"]) == 0
    assert not stale.exists() and not list(run.glob(".*.tmp"))
    assert load_run(run).summary["state_sha256"] == load_run(ref).summary["state_sha256"]


def test_start_removes_files_of_a_killed_write(tmp_path):
    out = tmp_path / "run"
    out.mkdir()
    (out / ".state.nc.k1ll3d.tmp").write_bytes(b"half a netCDF file")
    assert main(["chain", "--N", "3", "--t-end", "10", "--out", str(out), "--no-progress"]) == 0
    assert not list(out.glob(".*.tmp")) and (out / "state.nc").is_file()


# A damaged run directory given to `plot`: one line naming the file, exit 2, nothing written.


def _damage_truncate(name):
    def damage(run):
        data = (run / name).read_bytes()
        (run / name).write_bytes(data[: len(data) // 3])

    return damage


def _damage_garbage(name):
    return lambda run: (run / name).write_bytes(b"not what stickslip writes\n" * 40)


PLOT_DAMAGE = [
    ("state.nc truncated", _damage_truncate("state.nc"), "state.nc"),
    ("state.nc garbage", _damage_garbage("state.nc"), "state.nc"),
    ("events.parquet truncated", _damage_truncate("events.parquet"), "events.parquet"),
    ("events.parquet missing", lambda run: (run / "events.parquet").unlink(), "events.parquet"),
    ("first_move.parquet garbage", _damage_garbage("first_move.parquet"), "first_move.parquet"),
    ("run.json truncated", _damage_truncate("run.json"), "run.json"),
    ("run.json without its summary", lambda run: (run / "run.json").write_text('{"params": {}}'), "whole chain run"),
]


@pytest.mark.parametrize("what, damage, named", PLOT_DAMAGE, ids=[d[0] for d in PLOT_DAMAGE])
def test_plot_of_a_damaged_run_is_one_line(what, damage, named, small_run, tmp_path, capsys):
    import shutil

    run = tmp_path / "run"
    shutil.copytree(small_run, run)
    shutil.rmtree(run / "figures", ignore_errors=True)
    damage(run)
    before = _tree(tmp_path)
    capsys.readouterr()
    assert main(["plot", str(run)]) == 2
    stdout, err = capsys.readouterr()
    assert stdout == "" and err.count("\n") == 1 and "Traceback" not in err and named in err, err
    assert _tree(tmp_path) == before


def test_resume_of_a_missing_directory_creates_nothing(tmp_path, capsys):
    assert main(["chain", "--resume", str(tmp_path / "nope"), "--no-progress"]) == 2
    assert not (tmp_path / "nope").exists()
    empty = tmp_path / "empty"
    empty.mkdir()
    assert main(["chain", "--resume", str(empty), "--no-progress"]) == 2
    assert list(empty.iterdir()) == [], "no .run_id left in a directory that holds no run"
