"""A full disk is one line naming the file, exit status 1, and the folder left as it was (or with a
checkpoint that resumes): never a half-written file that a later run trusts.

Two ways: ENOSPC injected where each file is flushed to the disk (every write of the package
goes through ``os.fsync`` before its rename: state, events, checkpoint, figures, tables, page),
and, where this machine lets the tests mount one, a real 24 kB tmpfs.
"""

from __future__ import annotations

import errno
import json
import os
import shlex
import subprocess
from pathlib import Path

import pytest

from chain_helpers import cli_env, stickslip_cmd
from stickslip.cli import main


def _files(path: Path):
    return sorted(str(p.relative_to(path)) for p in path.rglob("*")) if path.exists() else None


@pytest.fixture
def full_at(monkeypatch):
    """``full_at(name)``: from now on the disk is full for the file ``name`` (its temporary
    ``.name.XXXX.tmp`` fails at its flush, as a full disk fails a write), other files are written."""
    real = os.fsync

    def arm(name: str):
        def fsync(fd):
            target = Path(os.readlink(f"/proc/self/fd/{fd}")).name
            if target.startswith(f".{name}.") and target.endswith(".tmp"):
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
            return real(fd)

        monkeypatch.setattr(os, "fsync", fsync)

    return arm


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    run = tmp_path_factory.mktemp("run") / "run"
    assert main(["chain", "--N", "4", "--V", "0.01", "--t-end", "400", "--out", str(run), "--no-progress"]) == 0
    return run


CHAIN = "chain --N 4 --V 0.01 --t-end 400 --no-progress --json --out {out}"
WRITES = [
    (CHAIN, ".lock.json"),
    (CHAIN, ".run_id"),
    (CHAIN, "state.npz"),  # the checkpoint
    (CHAIN, "part-000000.npz"),
    (CHAIN, "state.nc"),
    (CHAIN, "events.parquet"),
    (CHAIN, "first_move.parquet"),
    (CHAIN, "run.json"),
    ("block --t-end 10 --fig3 --json --out {out}", "series.nc"),
    ("block --t-end 10 --fig3 --json --out {out}", "slips.parquet"),
    ("block --t-end 10 --fig3 --json --out {out}", "fig3.png"),
    ("block --t-end 10 --fig3 --json --out {out}", "fig3.parquet"),
    ("block --t-end 10 --fig3 --json --out {out}", "fig3.csv"),
    ("stability block --json --out {out}", "stability_map.nc"),
    ("stability block --json --out {out}", "stability_map.pdf"),
    ("stability block --json --out {out}", "stability_block.json"),
    ("hysteresis --time-per-step 10 --json --out {out}", "hysteresis.png"),
    ("hysteresis --time-per-step 10 --json --out {out}", "hysteresis.nc"),
    ("plot {run} --json --out {out}", "length.png"),
    ("plot {run} --json --out {out}", "length.pdf"),
    ("sweep block --t-end 10 --grid K=8,10 --workers 1 --no-progress --json --out {out}", "summary.parquet"),
    ("sweep block --t-end 10 --grid K=8,10 --workers 1 --no-progress --json --out {out}", "summary.csv"),
    ("study transition --tiny --workers 1 --no-progress --json --out {out}", "table.parquet"),
    ("study transition --tiny --workers 1 --no-progress --json --out {out}", "loops.png"),
    ("study transition --tiny --workers 1 --no-progress --json --out {out}", "index.html"),
    ("study transition --tiny --workers 1 --no-progress --json --out {out}", ".stickslip-study.json"),
]


#: Commands whose run is a sweep or a study (10 s or more, measured): all their files with -m slow.
SLOW_WRITERS = {"study transition", "sweep block"}


def _writes():
    """One file of each command but a sweep and a study in the default run, the others with -m slow
    (each a fresh run)."""
    seen = set()
    for command, name in WRITES:
        first = command not in seen
        seen.add(command)
        marks = () if first and command.split(" --")[0] not in SLOW_WRITERS else pytest.mark.slow
        yield pytest.param(command, name, id=f"{command.split(' --')[0]}:{name}", marks=marks)


@pytest.mark.parametrize("command, name", list(_writes()))
def test_full_disk_is_one_line_and_exit_1(command, name, full_at, small_run, tmp_path, capsys):
    out = tmp_path / "out"
    argv = shlex.split(command.format(out=out, run=small_run))
    full_at(name)
    status = main(argv)
    stdout, err = capsys.readouterr()
    assert status == 1 and stdout == "", err
    line = err.splitlines()[-1]
    assert "Traceback" not in err and "the disk is full" in line and name in line, err
    assert [ln for ln in err.splitlines() if "error" in ln] == [line]
    assert not list(tmp_path.rglob("*.tmp")), "no file of the failed write is left"
    left = _files(out)
    command_name = argv[0]
    if command_name in ("block", "stability", "hysteresis", "plot"):
        assert left is None, f"the folder is left as it was (absent): {left}"
    elif command_name == "chain":
        # as it was, or a checkpoint that `--resume` finishes as one run (next test)
        assert left is None or "checkpoint/state.npz" in left, left
        assert name not in [Path(p).name for p in left or []]
        if left is not None:
            assert "--resume" in line
    else:  # sweep, study: points stay (each reused only when whole), the failed file is absent
        assert name not in [Path(p).name for p in left or []]


@pytest.mark.parametrize("name", ["state.npz", "state.nc", "events.parquet", "run.json"])
def test_chain_after_a_full_disk_resumes_to_the_same_run(name, full_at, tmp_path, monkeypatch, capsys):
    ref, out = tmp_path / "ref", tmp_path / "out"
    argv = ["chain", "--N", "4", "--V", "0.01", "--t-end", "400", "--no-progress", "--json"]
    assert main([*argv, "--out", str(ref)]) == 0
    expected = json.loads(capsys.readouterr().out)["state_sha256"]
    full_at(name)
    assert main([*argv, "--out", str(out)]) == 1
    capsys.readouterr()
    monkeypatch.undo()  # space again
    if out.exists():
        assert main(["chain", "--resume", str(out), "--no-progress", "--json"]) == 0
    else:
        assert main([*argv, "--out", str(out)]) == 0
    assert json.loads(capsys.readouterr().out)["state_sha256"] == expected


CONTINUED = [
    ("summary.parquet", ["sweep", "block", "--t-end", "10", "--grid", "K=8,10"], 2),
    ("phase_alpha_beta.png", ["study", "phase-diagram", "--tiny"], 4),
    ("loops.png", ["study", "transition", "--tiny"], 3),  # its three ladders (two up replicas, one down)
]


@pytest.mark.parametrize(
    "name, argv, n_points",
    [pytest.param(*c, id=c[0], marks=() if k == 0 else pytest.mark.slow) for k, c in enumerate(CONTINUED)],
)
def test_sweep_and_study_after_a_full_disk_continue(name, argv, n_points, full_at, tmp_path, monkeypatch, capsys):
    argv = [*argv, "--workers", "1", "--no-progress", "--json", "--out", str(tmp_path / "out")]
    full_at(name)
    assert main(argv) == 1
    capsys.readouterr()
    monkeypatch.undo()
    assert main(argv) == 0
    data = json.loads(capsys.readouterr().out)
    reused = data.get("n_reused", data.get("reused", data.get("meta", {}).get("ladders_reused")))
    assert reused == n_points, "the points finished before the disk filled are reused"


# ---------------------------------------------------------------------------------------------
# A real full file system


@pytest.fixture
def tiny_fs(tmp_path):
    mnt = tmp_path / "fs"
    mnt.mkdir()
    if os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root")
    proc = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=24k", "tmpfs", str(mnt)], capture_output=True)
    if proc.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {proc.stderr.decode().strip()}")
    try:
        yield mnt
    finally:
        subprocess.run(["umount", str(mnt)], capture_output=True)


REAL = [
    "chain --N 3 --t-end 100 --no-progress",
    "block --t-end 200 --fig3",
    "stability block",
    "hysteresis --time-per-step 10",
    "sweep block --t-end 200 --grid K=8,10 --workers 1 --no-progress",
    "study transition --tiny --workers 1 --no-progress",
]


# the chain by default; the other commands each write through the small file system (10-20 s
# each, measured): -m slow
@pytest.mark.parametrize(
    "command",
    [pytest.param(c, id=c.split(" --")[0], marks=() if k == 0 else pytest.mark.slow) for k, c in enumerate(REAL)],
)
def test_real_24k_file_system(command, tiny_fs):
    out = tiny_fs / "o"
    proc = subprocess.run(
        stickslip_cmd() + shlex.split(command) + ["--out", str(out)],
        capture_output=True,
        text=True,
        env=cli_env(),
        timeout=300,
    )
    assert proc.returncode == 1 and proc.stdout == "", proc.stderr
    assert "Traceback" not in proc.stderr and proc.stderr.splitlines()[-1].count("the disk is full") == 1
    assert not list(tiny_fs.rglob("*.tmp"))
