"""A second Ctrl-C stops a study at once (docs/limits.md, "Signals to whole process groups"): the
driver closes its cluster without being cut short, so it neither waits for the cluster to be
closed again at exit nor leaves its stop request (``points/stop-requested``) behind."""

from __future__ import annotations

import os
import signal
import subprocess
import time

import pytest

from chain_helpers import cli_env, stickslip_cmd


def _double_sigint(out, gap, to_group):
    proc = subprocess.Popen(
        stickslip_cmd() + ["study", "transition", "--quick", "--workers", "1", "--out", str(out), "--no-progress"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=cli_env(),
        start_new_session=True,
        # Ctrl-C's default action even where pytest was started in the background (a shell's
        # background jobs inherit SIGINT ignored, and so would the study)
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    send = (lambda s: os.killpg(proc.pid, s)) if to_group else proc.send_signal
    try:
        deadline = time.monotonic() + 180
        while not list(out.glob("runs/*/points/*/point.json")):
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() < deadline, "no ladder started"
            time.sleep(0.05)
        time.sleep(2.0)  # into the first ladder
        send(signal.SIGINT)
        time.sleep(gap)
        if proc.poll() is None:
            send(signal.SIGINT)
        stdout, stderr = proc.communicate(timeout=120)
        return proc.returncode, stdout, stderr
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate()


# (second Ctrl-C this long after the first, to the driver alone or to the whole group); before,
# a second one while the driver stopped its points took 11 s and left ladders/stop-requested
CASES = [(0.05, False), (0.4, False), (1.0, False), (0.4, True)]


@pytest.mark.parametrize("gap, to_group", CASES, ids=[f"{g:g}s-{'group' if t else 'driver'}" for g, t in CASES])
def test_a_second_ctrl_c_stops_at_once(gap, to_group, tmp_path):
    out = tmp_path / "studies"
    status, stdout, stderr = _double_sigint(out, gap, to_group)
    # 130, or killed by the second SIGINT after the line was written (a shell shows 130 for both)
    assert status in (130, -signal.SIGINT), stderr
    assert stdout == "" and "Traceback" not in stderr, stderr
    assert stderr.count("\n") == 1 and "interrupted" in stderr, stderr
    assert not list(out.glob("runs/*/points/stop-requested")), "the stop request is left behind"
    # at once: the first ladder (minutes of work) was stopped, not waited for
    assert not list(out.glob("runs/*/points/*/done.json")), "a point ran to its end after Ctrl-C"
