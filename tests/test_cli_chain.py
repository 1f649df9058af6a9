"""`stickslip chain` and `stickslip bench`: JSON output, files, bad input, errors."""

from __future__ import annotations

import json
import warnings

import pandas as pd
import pytest

from chain_helpers import error_lines, run_cli, run_cli_subprocess
from stickslip.models.params import ChainParams
from stickslip.run.driver import run_chain


def test_chain_json_is_one_document_with_the_summary(capsys):
    status, out, err = run_cli(capsys, "chain", "--N", "5", "--t-end", "1500", "--beta", "0.5", "--json",
                               "--no-progress")  # fmt: skip
    assert status == 0
    data = json.loads(out)  # one document: json.loads rejects anything after it
    for key in ("events", "L_final", "L_mean", "t_end", "steps", "wall_seconds", "state_sha256"):
        assert key in data, key
    ref = run_chain(ChainParams(N=5, beta=0.5), 1500.0)
    assert data["state_sha256"] == ref.summary["state_sha256"]
    assert data["events"] == len(ref.events) > 0
    assert data["L_final"] == ref.summary["L_final"] and data["L_mean"] == ref.summary["L_mean"]
    assert data["t_end"] == 1500.0 and data["steps"] == 300000
    assert data["wall_seconds"] >= 0


def test_chain_text_output_and_out_dir(capsys, tmp_path):
    out_dir = tmp_path / "run"
    status, out, _ = run_cli(capsys, "chain", "--N", "4", "--t-end", "800", "--V", "0.01", "--integrator", "dense",
                             "--snapshot", "100", "--profile-window", "0.5", "--out", str(out_dir),
                             "--keep-checkpoint", "--no-progress")  # fmt: skip
    assert status == 0
    ref = run_chain(ChainParams(N=4, V=0.01), 800.0, snapshot_times=(100.0,), profile_window=0.5)
    assert ref.summary["state_sha256"] in out and "events" in out
    for name in ("run.json", "state.nc", "events.parquet", "first_move.parquet", "checkpoint/state.npz"):
        assert (out_dir / name).is_file(), name
    assert pd.read_parquet(out_dir / "events.parquet").equals(ref.events)
    meta = json.loads((out_dir / "run.json").read_text())
    assert meta["integrator"] == "dense" and meta["params"]["V"] == 0.01
    # a second run into the same directory is refused, leaving it as it is
    before = (out_dir / "run.json").read_bytes()
    status, out, err = run_cli(capsys, "chain", "--N", "4", "--t-end", "10", "--out", str(out_dir), "--no-progress")
    assert status == 2 and "--resume" in err and err.count("\n") == 1
    assert (out_dir / "run.json").read_bytes() == before


def test_chain_entry_point_prints_one_json_document(tmp_path):
    proc = run_cli_subprocess("chain", "--N", "3", "--t-end", "400", "--json", "--no-progress")
    assert proc.returncode == 0, proc.stderr
    data = json.loads(proc.stdout)
    assert data["steps"] == 80000 and data["events"] >= 1


BAD = [
    (["--N", "0"], "N"),
    (["--N", "2.5"], "N"),
    (["--K", "0"], "K"),
    (["--K=-1"], "K"),
    (["--K", "inf"], "K"),
    (["--dt", "0"], "dt"),
    (["--dt=-0.005"], "dt"),
    (["--V", "nan"], "V"),
    (["--beta=-0.1"], "beta"),
    (["--Fs", "0"], "Fs"),
    (["--D", "200"], "D"),
    (["--t-end=-1"], "t-end"),
    (["--t-end", "nan"], "t-end"),
    (["--checkpoint-interval", "0"], "checkpoint-interval"),
    (["--sample-interval", "0"], "--sample-interval"),
    (["--perturbation=-0.1", "--start", "steady"], "perturbation"),
    (["--snapshot", "1e9"], "snapshot"),
    (["--start", "flat"], "start"),
    (["--integrator", "rk4"], "integrator"),
    (["--foo", "1"], "--foo"),
]


@pytest.mark.parametrize("argv, name", BAD, ids=[" ".join(a) for a, _ in BAD])
def test_chain_bad_input(capsys, tmp_path, argv, name):
    out_dir = tmp_path / "never"
    status, out, err = run_cli(capsys, "chain", "--N", "3", "--t-end", "10", *argv, "--out", str(out_dir), "--json")
    assert status == 2
    assert out == ""
    assert len(error_lines(err)) == 1 and err.endswith("\n"), err
    assert name in err
    assert not out_dir.exists(), "nothing may be written for bad input"


def test_blow_up_in_the_cli(capsys, tmp_path):
    status, out, err = run_cli(capsys, "chain", "--N", "5", "--K", "1e6", "--t-end", "10", "--no-progress")
    assert status != 0
    assert "non-finite" in err and "t =" in err and "block" in err


def test_blow_up_in_the_entry_point():
    proc = run_cli_subprocess("chain", "--N", "5", "--K", "1e6", "--t-end", "10", "--json", "--no-progress")
    assert proc.returncode != 0
    assert "non-finite" in proc.stderr and "t =" in proc.stderr and "block" in proc.stderr


def test_bench_json(capsys):
    status, out, _ = run_cli(capsys, "bench", "--N", "20", "--t-end", "200", "--json")
    assert status == 0
    data = json.loads(out)
    assert data["identical"] is True
    assert data["dense_seconds"] > 0 and data["exact_seconds"] > 0
    assert data["speedup"] == pytest.approx(data["dense_seconds"] / data["exact_seconds"])
    ns = data["ns_per_block_step"]
    block_steps = 20 * 40000
    assert data["workload"]["steps"] == 40000 and data["workload"]["block_steps"] == block_steps
    assert ns["dense"] == pytest.approx(1e9 * data["dense_seconds"] / block_steps)
    assert ns["exact"] == pytest.approx(1e9 * data["exact_seconds"] / block_steps)
    assert data["state_sha256"] == run_chain(ChainParams(N=20), 200.0).summary["state_sha256"]


def test_bench_does_not_warn_about_its_own_workload():
    from stickslip.run.bench import compare
    from stickslip.run.driver import ShortRunWarning

    with pytest.warns(ShortRunWarning):  # the workload is short of the loading time ...
        run_chain(ChainParams(N=20), 200.0)
    with warnings.catch_warnings():  # ... but a benchmark times it on purpose
        warnings.simplefilter("error", ShortRunWarning)
        assert compare(ChainParams(N=20), 200.0)["identical"] is True


@pytest.mark.parametrize("argv, name", [(["--N", "0"], "N"), (["--t-end=-5"], "t-end"), (["--repeat", "0"], "repeat")])
def test_bench_bad_input(capsys, argv, name):
    status, out, err = run_cli(capsys, "bench", "--t-end", "10", *argv, "--json")
    assert status == 2 and out == "" and err.count("\n") == 1 and name in err


def test_bench_partly_stuck_json(capsys):
    status, out, _ = run_cli(capsys, "bench", "--workload", "partly-stuck", "--N", "20", "--t-end", "200", "--json")
    assert status == 0
    data = json.loads(out)
    assert data["identical"] is True
    for key in ("ns_per_update_exact", "ns_per_block_step_dense", "ratio", "moving_fraction"):
        assert data[key] >= 0
    assert data["ratio"] == pytest.approx(data["ns_per_update_exact"] / data["ns_per_block_step_dense"])
    assert data["workload"]["steps"] == 40000 and data["workload"]["N"] == 20 and data["workload"]["beta"] == 1.3
    assert 0 < data["exact_block_updates"] <= 20 * 40000
    assert data["repeat"] == 3  # the default of this workload: its exact run is short
    assert data["exact_timings"] == 15  # five of the exact run for each of the dense one
    status, out, _ = run_cli(
        capsys, "bench", "--workload", "partly-stuck", "--N", "20", "--t-end", "200", "--repeat", "1", "--json"
    )
    assert status == 0 and json.loads(out)["repeat"] == 1


def test_bench_partly_stuck_refuses_a_start(capsys):
    status, out, err = run_cli(capsys, "bench", "--workload", "partly-stuck", "--start", "steady", "--json")
    assert status == 2 and out == "" and err.count("\n") == 1 and "partly-stuck" in err
