"""Signals to a whole process group: a batch system's SIGTERM to the driver and its Dask workers
together, and Ctrl-C in a terminal (SIGINT to the foreground group). Finished points stay,
running points stop at a checkpoint, the command ends in one line with status 130 (no traceback,
no wait), and the next start continues to the same bits as an uninterrupted run."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import time

import pytest

from chain_helpers import cli_env, run_cli_subprocess, stickslip_cmd
from stickslip.models.params import ChainParams
from stickslip.run.driver import run_chain

T_END = 6000.0


def _said(stderr: str) -> list[str]:
    """The lines of ``stderr`` but the short-run warning and the notice of a first compilation
    (printed when the kernels were not compiled ahead, as after an edit of a kernel)."""
    return [ln for ln in stderr.splitlines() if ": warning: " not in ln and "compiling the numba kernels" not in ln]


SWEEP = ["sweep", "chain", "--t-end", f"{T_END:g}", "--grid", "N=5,399", "--set", "integrator=dense",
         "--workers", "1", "--no-progress", "--json"]  # fmt: skip


def _points(out):
    return {p.name: p for p in out.iterdir() if (p / "point.json").is_file()}


def _started(out):
    """The long point (N = 399) began after the short one finished."""
    pts = _points(out) if out.is_dir() else {}
    return "N=5" in pts and (pts["N=5"] / "done.json").is_file() and "N=399" in pts


def _launch_in_group(argv, started, sig, *, settle=1.5, timeout=180.0):
    """Start ``stickslip ARGV`` as the leader of a new process group; once ``started()`` holds and
    ``settle`` seconds more have passed, send ``sig`` to the whole group; return (status, stdout,
    stderr). That the running point stopped at once shows in its folder (a checkpoint, no
    ``done.json``), not in seconds, which a loaded machine stretches."""
    proc = subprocess.Popen(
        stickslip_cmd() + argv,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=cli_env(),
        start_new_session=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    try:
        deadline = time.monotonic() + timeout
        while not started():
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() < deadline, "nothing started in time"
            time.sleep(0.05)
        time.sleep(settle)
        assert proc.poll() is None, "the work ended before the signal: make it longer"
        os.killpg(proc.pid, sig)
        stdout, stderr = proc.communicate(timeout=timeout)
        return proc.returncode, stdout, stderr
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate()


@pytest.fixture(scope="module")
def reference():
    return run_chain(ChainParams(N=399), T_END, integrator="exact").summary["state_sha256"]


@pytest.mark.slow  # a sweep of N = 399 chains in a process group (about 50 s, measured)
@pytest.mark.parametrize(
    "sig", [signal.SIGTERM, pytest.param(signal.SIGINT, marks=pytest.mark.slow)], ids=["SIGTERM", "SIGINT"]
)
def test_signal_to_the_process_group_of_a_sweep(sig, tmp_path, reference):
    out = tmp_path / "sweep"
    argv = [*SWEEP, "--out", str(out)]
    status, stdout, stderr = _launch_in_group(argv, lambda: _started(out), sig)
    assert status == 130, stderr
    lines = _said(stderr)
    assert len(lines) == 1 and "interrupted" in lines[0] and "Traceback" not in stderr, stderr
    pts = _points(out)
    assert (pts["N=5"] / "done.json").is_file(), "the finished point stays"
    long = pts["N=399"]
    assert (long / "checkpoint" / "state.npz").is_file() and not (long / "done.json").exists()
    assert not (long / "error.json").exists()
    # the next start reuses the finished point and continues the other to the same bits
    again = run_cli_subprocess(*argv, timeout=300)
    assert again.returncode == 0, again.stderr
    data = json.loads(again.stdout)
    assert data["n_reused"] == 1 and data["n_run"] == 1
    (row,) = [r for r in data["points"] if r["point_dir"] == "N=399"]
    assert row["state_sha256"] == reference


def test_ctrl_c_in_a_terminal_stops_a_sweep(tmp_path):
    """Ctrl-C typed in the terminal the command runs in (a pty here): SIGINT goes to the whole
    foreground group; the command ends at once with its one line, no worker traceback."""
    import pty
    import select

    out = tmp_path / "sweep"
    pid, fd = pty.fork()
    if pid == 0:  # the child: the command in the foreground of the pty
        signal.signal(signal.SIGINT, signal.SIG_DFL)  # as a shell leaves it, even where ours ignores it
        os.environ.update(cli_env())
        cmd = stickslip_cmd() + [*SWEEP, "--out", str(out)]
        os.execvp(cmd[0], cmd)
    text, sent, deadline = b"", None, time.monotonic() + 180
    try:
        while time.monotonic() < deadline:
            ready, _, _ = select.select([fd], [], [], 0.1)
            if ready:
                try:
                    chunk = os.read(fd, 4096)
                except OSError:
                    break
                if not chunk:
                    break
                text += chunk
            if sent is None and _started(out):
                time.sleep(1.5)
                os.write(fd, b"\x03")  # the terminal's interrupt character
                sent = True
        _, status = os.waitpid(pid, 0)
    finally:
        try:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
        except (ProcessLookupError, ChildProcessError):
            pass
        os.close(fd)
    assert sent is not None, "the long point never started"
    assert os.waitstatus_to_exitcode(status) == 130, text.decode(errors="replace")
    shown = text.decode(errors="replace")
    assert "Traceback" not in shown and "interrupted" in shown, shown
    assert (out / "N=399" / "checkpoint" / "state.npz").is_file()


@pytest.mark.slow
def test_sigterm_to_the_process_group_of_a_study(tmp_path):
    """The quick transition study (its first ladder, N = 199, runs for minutes) stopped by SIGTERM
    to every process of it: one line, status 130, the running rung's progress kept; the next
    start continues that rung from it."""
    out = tmp_path / "studies"
    argv = ["study", "transition", "--quick", "--workers", "1", "--out", str(out), "--no-progress"]
    status, stdout, stderr = _launch_in_group(
        argv, lambda: bool(list(out.glob("runs/*/points/*/rungs/*/progress.npz"))), signal.SIGTERM, settle=1.0
    )
    assert status == 130 and stdout == "", stderr
    assert len(_said(stderr)) == 1 and "Traceback" not in stderr, stderr
    (point,) = [p.parent for p in out.glob("runs/*/points/*/point.json")]
    (progress,) = point.glob("rungs/*/progress.npz")
    assert not (point / "done.json").exists() and not (progress.parent / "rung.json").exists()
    from stickslip.kernels import layout
    from stickslip.run.checkpoint import read_npz

    step = int(read_npz(progress)[0]["ist"][layout.STEP])
    assert step > 0, "the kept progress holds the work done"
    # the next start continues from there: stopped again, the rung has moved on (or is written)
    status, _, stderr = _launch_in_group(argv, lambda: True, signal.SIGTERM, settle=15.0)
    assert status == 130, stderr
    written = (progress.parent / "rung.json").is_file()
    assert written or int(read_npz(progress)[0]["ist"][layout.STEP]) > step
