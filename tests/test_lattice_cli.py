"""`stickslip chain --lattice square` and `chain_params(..., lattice=..., shape=...)`
(docs/lattice.md): a run's outputs, and one-line refusals of bad shapes and of pieces that do
not compose, exit status 2."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from chain_helpers import one_line_error, run_cli
from stickslip.models.lattice.params import LatticeParams
from stickslip.models.params import ChainParams, ParameterError
from stickslip.models.presets import chain_params


def test_chain_params_on_a_square():
    p = chain_params("carlson-langer", lattice="square", shape=(4, 6), edges="top=free,bottom=free")
    assert isinstance(p, LatticeParams)
    assert p.lattice.shape == (4, 6) and p.lattice.edges == ("free", "free", "periodic", "periodic")
    assert p.N == 24 and p.K == 100.0
    assert p.to_dict()["shape"] == "4x6" and "N" not in p.to_dict()
    import pickle

    assert pickle.loads(pickle.dumps(p)) == p
    chain = chain_params(lattice="chain", shape=9)
    assert isinstance(chain, ChainParams) and chain.N == 9


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(lattice="square", shape="64"), "shape must be ROWSxCOLS"),
        (dict(lattice="square"), "lattice square needs shape"),
        (dict(shape=(3, 3)), "shape and edges go with lattice"),
        (dict(lattice="square", shape=(3, 3), N=9), "N goes with"),
        (dict(lattice="square", shape=(3, 3), edges="left=fixed,right=fixed"), "exactly one side"),
        (dict(lattice="hex", shape=(3, 3)), "lattice must be one of"),
    ],
)
def test_chain_params_refusals(kwargs, message):
    with pytest.raises(ParameterError, match=message):
        chain_params(**kwargs)


def test_command_runs_and_writes(tmp_path, capsys):
    out = tmp_path / "run"
    code, stdout, _ = run_cli(
        capsys, "chain", "--model", "carlson-langer", "--lattice", "square", "--shape", "4x5",
        "--t-end", "20", "--snapshot-every", "10", "--sample-interval", "5", "--out", str(out), "--json",
    )  # fmt: skip
    assert code == 0
    summary = json.loads(stdout)
    assert summary["lattice"].startswith("square 4x5") and summary["events"] > 0
    events = pd.read_csv(out / "events.csv")
    assert len(events) == summary["events"]
    assert {"area", "moment", "epicentre_row", "epicentre_col", "row_min", "col_max"} <= set(events.columns)
    assert (events["area"] >= 1).all() and (events["area"] <= 20).all()
    assert ((events["epicentre_row"] >= events["row_min"]) & (events["epicentre_row"] <= events["row_max"])).all()
    ds = xr.open_dataset(out / "state.nc", engine="h5netcdf")
    assert ds["x"].dims == ("row", "col") and ds["x"].shape == (4, 5)
    assert ds["snapshot_x"].dims == ("time", "row", "col")
    np.testing.assert_array_equal(ds["time"].values, [0.0, 10.0, 20.0])
    np.testing.assert_array_equal(ds["snapshot_x"].values[-1], ds["x"].values)
    # the samples at the snapshots' times, from the snapshots: the plate at nu t less x, v, moving
    samples = pd.read_csv(out / "samples.csv").set_index("t")
    assert list(samples.index) == [0.0, 5.0, 10.0, 15.0, 20.0]
    for i, t in enumerate(ds["time"].values):
        x, v = ds["snapshot_x"].values[i], ds["snapshot_v"].values[i]
        assert samples.loc[t, "mean_slip_deficit"] == pytest.approx(np.mean(0.01 * t - x), rel=1e-12, abs=1e-15)
        assert samples.loc[t, "mean_v"] == pytest.approx(np.mean(v), rel=1e-12, abs=1e-15)
        assert samples.loc[t, "moving"] == int((~ds["snapshot_stopped"].values[i]).sum())
    ds.close()


@pytest.mark.parametrize(
    "argv, names",
    [
        (["--lattice", "square", "--shape", "0x4"], ["shape", "rows >= 1"]),
        (["--lattice", "square", "--shape", "4by4"], ["shape", "ROWSxCOLS"]),
        (["--lattice", "square"], ["--shape"]),
        (["--shape", "4x4"], ["--shape", "--lattice square"]),
        (["--lattice", "square", "--shape", "4x4", "--edges", "top=periodic"], ["top and bottom"]),
        (["--lattice", "square", "--shape", "4x4", "--edges", "periodic"], ["periodic"]),
        (["--lattice", "square", "--shape", "4x4", "--N", "16"], ["--N", "--shape"]),
        (["--lattice", "square", "--shape", "4x4", "--model", "carlson-langer", "--edges", "left=driven"], ["driven"]),
        (["--lattice", "square", "--shape", "4x4", "--until-periodic"], ["--until-periodic"]),
    ],
)
def test_command_refusals_are_one_line(argv, names, capsys):
    from stickslip.cli import main

    assert main(["chain", *argv, "--t-end", "1"]) == 2
    one_line_error(capsys, *names)


@pytest.mark.slow  # the bench on the square (about 13 s, measured)
def test_bench_compares_dense_and_exact_on_the_square(capsys):
    code, stdout, _ = run_cli(
        capsys, "bench", "--model", "carlson-langer", "--lattice", "square", "--shape", "6x6",
        "--t-prepare", "0", "--t-end", "10", "--json",
    )  # fmt: skip
    assert code == 0
    result = json.loads(stdout)
    assert result["identical"] is True and result["exact_integrator"] == "exact"
    assert result["t_prepare"] == 0.0 and result["t_timed"] == 10.0
    assert result["exact_block_updates"] < result["dense_block_updates"] == 36 * 2000
    # the slow-loading workload's V unless given; the work of the moving blocks within the exact path's
    assert result["V"] == 0.001 and result["blocks"] == 36 and result["steps"] == 2000
    assert 0 < result["exact_moving_block_updates"] <= result["exact_block_updates"]
    assert result["moving_fraction"] == result["exact_moving_block_updates"] / (36 * 2000)
    code, stdout, _ = run_cli(
        capsys, "bench", "--model", "carlson-langer", "--lattice", "square", "--shape", "4x4",
        "--nu", "0.02", "--t-prepare", "5", "--t-end", "2", "--repeat", "1", "--json",
    )  # fmt: skip
    assert code == 0 and json.loads(stdout)["V"] == 0.02 and json.loads(stdout)["identical"] is True


def test_bench_refusals_are_one_line(capsys):
    from stickslip.cli import main

    assert main(["bench", "--t-prepare", "5"]) == 2
    one_line_error(capsys, "--t-prepare", "--lattice square")
    assert main(["bench", "--lattice", "square", "--shape", "4x4", "--profile"]) == 2
    one_line_error(capsys, "--profile")
