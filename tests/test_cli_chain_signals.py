"""`stickslip chain` killed or interrupted mid-run, then resumed, ends where an
uninterrupted run ends: same final state hash, same event and first-move tables, same L.

The workload is the paper's chain (N = 399, beta = 1) with the dense integrator for 4000
time units: a few seconds, with a dozen slips. The uninterrupted reference is computed
in-process with the exact integrator, which gives the same result bit for bit.
"""

from __future__ import annotations

import json
import signal
import subprocess
import time

import numpy as np
import pandas as pd
import pytest

from chain_helpers import assert_bits_equal, assert_same_run, cli_env, run_cli_subprocess, stickslip_cmd
from stickslip import io
from stickslip.kernels import layout
from stickslip.models.params import ChainParams, steps_for
from stickslip.run import driver as C

T_END = 4000.0
P = ChainParams()  # the paper's chain: N = 399, beta = 1


@pytest.fixture(scope="module")
def reference():
    run = C.run_chain(P, T_END, integrator="exact")
    assert run.summary["n_events"] >= 5
    return run


def _launch_and_signal(out_dir, sig, delay):
    """Start a run, wait for its first checkpoint, wait ``delay`` more seconds, send ``sig``."""
    cmd = stickslip_cmd() + ["chain", "--out", str(out_dir), "--t-end", f"{T_END:g}", "--integrator", "dense",
                             "--checkpoint-interval", "0.2", "--no-progress", "--json"]  # fmt: skip
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=cli_env())
    state = out_dir / "checkpoint" / "state.npz"
    deadline = time.monotonic() + 120
    try:
        while not state.exists():
            assert proc.poll() is None, f"the run ended before its first checkpoint: {proc.communicate()}"
            assert time.monotonic() < deadline, "no checkpoint within 120 s"
            time.sleep(0.02)
        time.sleep(delay)
        assert proc.poll() is None, "the workload finished before the signal: make it longer"
        proc.send_signal(sig)
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    return proc.returncode, out, err


def _checkpoint_step(out_dir) -> int:
    arrays, _, _ = C.read_npz(out_dir / "checkpoint" / "state.npz")
    return int(arrays["ist"][layout.STEP])


def _assert_outputs_match(out_dir, reference, sha):
    assert sha == reference.summary["state_sha256"]
    assert io.read_table(out_dir / "events.parquet").equals(reference.events)
    assert io.read_table(out_dir / "first_move.parquet").equals(reference.first_move)
    ds = io.read_dataset(out_dir / "state.nc")
    assert_bits_equal(ds["L"].values, reference.samples["L"].values, "L samples")
    assert_bits_equal(ds["t"].values, reference.samples["t"].values, "sample times")


@pytest.mark.slow  # a chain killed and resumed in subprocesses (about 25 s, measured)
@pytest.mark.parametrize("delay", [0.37, pytest.param(0.0, marks=pytest.mark.slow),
                                   pytest.param(0.8, marks=pytest.mark.slow)])  # fmt: skip
def test_sigkill_then_resume_from_the_command_line(tmp_path, reference, delay):
    out_dir = tmp_path / "run"
    status, _, _ = _launch_and_signal(out_dir, signal.SIGKILL, delay=delay)
    assert status == -signal.SIGKILL
    n_ckpt = _checkpoint_step(out_dir)
    assert 0 < n_ckpt < steps_for(T_END, P.dt, "t_end"), "the kill must land in the middle of the run"
    assert not (out_dir / "run.json").exists()
    proc = run_cli_subprocess("chain", "--resume", str(out_dir), "--json", "--no-progress", timeout=300)
    assert proc.returncode == 0, proc.stderr
    data = json.loads(proc.stdout)
    assert data["steps"] == reference.steps and data["events"] == reference.summary["n_events"]
    assert data["L_mean"] == reference.summary["L_mean"]
    _assert_outputs_match(out_dir, reference, data["state_sha256"])


@pytest.mark.parametrize(
    "sig", [pytest.param(signal.SIGTERM, marks=pytest.mark.slow), signal.SIGINT], ids=["SIGTERM", "SIGINT"]
)  # SIGTERM repeats SIGINT's path (14 s, measured)
def test_sigterm_sigint_write_a_checkpoint_and_exit_130(tmp_path, reference, sig):
    out_dir = tmp_path / "run"
    status, out, err = _launch_and_signal(out_dir, sig, delay=0.25 if sig == signal.SIGTERM else 0.6)
    assert status == 130, err
    data = json.loads(out)
    assert data["interrupted"] is True
    assert "--resume" in err
    n_ckpt = _checkpoint_step(out_dir)
    assert 0 < n_ckpt < steps_for(T_END, P.dt, "t_end")
    assert data["t"] == pytest.approx(n_ckpt * P.dt), "the checkpoint is written at the reported time"
    run = C.resume_chain(out_dir)
    assert_same_run(run, reference)
    _assert_outputs_match(out_dir, reference, run.summary["state_sha256"])
    # the resumed run's outputs are those of one run: no event counted twice
    events = pd.read_parquet(out_dir / "events.parquet")
    assert np.array_equal(events["event"].to_numpy(), np.arange(len(events)))


# Every model of the family: killed mid-run, resumed from the command line, identical.
FAMILY = [
    ("carlson-langer", 15000.0),
    ("train", 4000.0),
    pytest.param("two-blocks", 6e5, marks=pytest.mark.slow),
    pytest.param("batista-carlson", 1e6, marks=pytest.mark.slow),
]


@pytest.mark.slow  # a run per model killed and resumed (20-25 s each, measured)
@pytest.mark.parametrize("model, t_end", FAMILY)
def test_sigkill_then_resume_every_model(tmp_path, model, t_end):
    from stickslip.models.presets import PRESETS, chain_params

    p = chain_params(model)
    pr = PRESETS[model]
    ref = C.run_chain(
        p,
        t_end,
        start=pr.start,
        perturbation=pr.start_options.get("amplitude", 0.0),
        seed=pr.start_options.get("seed", 0),
    )
    out_dir = tmp_path / "run"
    cmd = stickslip_cmd() + [
        "chain",
        "--model",
        model,
        "--out",
        str(out_dir),
        "--t-end",
        f"{t_end:g}",
        "--integrator",
        "dense",
        "--checkpoint-interval",
        "0.2",
        "--no-progress",
        "--json",
    ]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=cli_env())
    state = out_dir / "checkpoint" / "state.npz"
    deadline = time.monotonic() + 120
    try:
        while not state.exists():
            assert proc.poll() is None, f"the run ended before its first checkpoint: {proc.communicate()}"
            assert time.monotonic() < deadline
            time.sleep(0.02)
        time.sleep(0.3)
        assert proc.poll() is None, "the workload finished before the signal: make it longer"
        proc.send_signal(signal.SIGKILL)
        proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert 0 < _checkpoint_step(out_dir) < steps_for(t_end, p.dt, "t_end")
    done = run_cli_subprocess("chain", "--resume", str(out_dir), "--json", "--no-progress", timeout=300)
    assert done.returncode == 0, done.stderr
    data = json.loads(done.stdout)
    assert data["model"] == model and data["events"] == ref.summary["n_events"] > 0
    _assert_outputs_match(out_dir, ref, data["state_sha256"])
