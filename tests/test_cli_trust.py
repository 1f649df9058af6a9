"""Bad input is refused in one line (exit 2, nothing on stdout, nothing written); run directories
are owned by one run; checkpoints are validated before a kernel sees them; blow-ups exit 1."""

from __future__ import annotations

import os
import shlex
import subprocess
import time

import numpy as np
import pytest
from chain_helpers import cli_env, run_cli_subprocess, stickslip_cmd

from stickslip.cli import main

BAD = [
    ("block --every 1e300", "every"), ("block --t-end 1e300", "t_end"), ("block --K abc", "K must be a number > 0"),
    ("block --out afile/x", "--out"), ("block --M -1", "M"),
    ("slip-limit --rtol 10", "rtol"), ("slip-limit --K 1e12", "dt"), ("slip-limit --dt 1e3", "dt"),
    ("slip-limit --Fs 1e9", "Fs"),
    ("stability block --out afile/x", "--out"), ("stability chain --K -1", "K"),
    ("stability block --K 1e300 --out sbk", "K"),
    ("chain --model carlson-langer --D 3", "--D"), ("chain --ends periodic", "periodic"),
    ("chain --model train --threshold state", "threshold"), ("chain --model nosuch", "--model"),
    ("chain --model carlson-langer --amplitude -1", "amplitude"), ("block --model carlson-langer", "--model"),
    ("bench --model carlson-langer --l 0", "l"), ("lyapunov --model two-blocks --d0 1", "d0"),
    ("hysteresis --time-per-step 1e12", "time_per_step"),
    ("chain --sample-interval 1e300", "sample_interval"), ("chain --sample-interval 1e30", "sample_interval"),
    ("chain --profile-window 1e300", "profile_window"), ("chain --start steady --perturbation 0.1 --seed -1", "seed"),
    ("chain --out afile/x --t-end 10", "--out"), ("chain --N 10000000 --t-end 100", "N"),
    ("chain --t-end 1e300", "t-end"), ("chain --t-end 1e17", "t-end"), ("chain --dt 1e-12", "t-end"),
    ("chain --D 100", "D*dt"), ("chain --D 99.9", "D*dt"), ("chain --checkpoint-interval 5 --t-end 10", "--checkpoint-interval"),
    ("chain --seed 3 --t-end 10", "--seed"), ("chain --average-from 100 --t-end 10", "average_from"),
    ("chain --overwrite --t-end 10", "--overwrite"),
    ("bench --N 9 --t-end 0", "t-end"), ("bench --N 10000000 --t-end 100", "N"), ("bench --t-end 1e300", "t-end"),
    ("sweep chain --t-end 10 --out o --scheduler garbage", "--scheduler"),
    ("sweep chain --t-end 10 --out o --scheduler ''", "--scheduler"),
    ("sweep chain --t-end 10 --out afile/x", "--out"), ("sweep chain --t-end 1e300 --out o", "t_end"),
    ("sweep chain --t-end 10 --out o --set integrator=foo", "integrator"),
    ("sweep chain --t-end 10 --out o --set start=foo", "start"),
    ("sweep chain --t-end 10 --out o --set sample_interval=0", "sample_interval"),
    ("sweep chain --t-end 10 --out o --set average_from=-1", "average_from"),
    ("sweep chain --t-end 10 --out o --set profile_window=0", "profile_window"),
    ("sweep chain --t-end 10 --out o --set profile_min_blocks=-1", "profile_min_blocks"),
    ("sweep block --t-end 10 --out o --set every=0", "every"),
    ("sweep chain --t-end 10 --out o --set K=inf", "K"),
    ("models --bogus", "--bogus"), ("lyapunov --N 0", "N"), ("reproduce --bogus", "--bogus"), ("--bogus", "--bogus"),
]


def _tree(path):
    return sorted(str(p.relative_to(path)) for p in path.rglob("*"))


@pytest.mark.parametrize("argv,name", BAD, ids=[c for c, _ in BAD])
def test_bad_input_one_line_exit_2(argv, name, tmp_path, monkeypatch, capsys):
    (tmp_path / "afile").write_text("")
    monkeypatch.chdir(tmp_path)
    before = _tree(tmp_path)
    try:
        status = main(shlex.split(argv))
    except SystemExit as exc:
        status = exc.code
    out, err = capsys.readouterr()
    assert status == 2, err
    assert out == ""
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert name in err, err
    assert _tree(tmp_path) == before


@pytest.mark.parametrize("argv", ["--bogus", "chain --t-end 1e300", "block --K abc"])
def test_bad_input_subprocess(argv, tmp_path):
    proc = subprocess.run(stickslip_cmd() + shlex.split(argv), capture_output=True, text=True, cwd=tmp_path,
                          env=cli_env(), timeout=120)
    assert proc.returncode == 2 and proc.stdout == "" and proc.stderr.count("\n") == 1, proc.stderr
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
    assert main(["chain", "--N", "4", "--V", "0.01", "--t-end", "400", "--out", str(path), "--no-progress"]) == 0
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
    from stickslip.kernels import chain as K
    from stickslip.run.checkpoint import _read_npz, _write_npz

    run = _finished_run(tmp_path / "r")
    path = run / "checkpoint" / "state.npz"
    arrays, header, _ = _read_npz(path)
    ist = arrays["ist"]
    if craft == "step":
        ist[K.STEP] = -5
    elif craft == "act":
        ist[K.ACT_LO], ist[K.ACT_HI] = 1, 10**9
    elif craft == "count":
        ist[K.EV_COUNT] = 7
    elif craft == "parts":
        header["parts"] = []
        ist[K.N_EVENTS] = max(1, int(ist[K.N_EVENTS]))
    elif craft == "integrator":
        header["integrator"] = "bogus"
    else:
        header["options"]["sample_interval"] = 0
    _write_npz(path, arrays, header)
    capsys.readouterr()
    assert main(["chain", "--resume", str(run), "--t-end", "800", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "checkpoint" in err, err


def test_second_writer_refused_while_first_runs(tmp_path):
    out = tmp_path / "run"
    first = subprocess.Popen(stickslip_cmd() + ["chain", "--N", "99", "--t-end", "20000", "--out", str(out),
                                                "--integrator", "dense", "--no-progress", "--json"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=cli_env())
    deadline = time.time() + 60
    while not (out / ".lock.json").exists() and time.time() < deadline:
        time.sleep(0.1)
    second = run_cli_subprocess("chain", "--resume", str(out), "--no-progress")
    assert second.returncode == 2 and "in use by another run" in second.stderr
    assert f"pid {first.pid}" in second.stderr
    stdout, _ = first.communicate(timeout=300)
    assert first.returncode == 0 and (out / "run.json").exists() and not (out / ".lock").exists()
    assert '"events"' in stdout
