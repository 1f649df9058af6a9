"""A run directory's state.nc is checked against the state_sha256 its run.json records: load_run,
chain --from and catalog refuse a state.nc changed after the run (a rung's state.npz already was)."""

from __future__ import annotations

import shutil

import numpy as np
import pytest
import xarray as xr

import stickslip
from stickslip.cli import main
from stickslip.models.presets import chain_params
from stickslip.run.rundir import RunDirDamaged, load_run


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("runs")
    p = chain_params(N=6)
    stickslip.run_chain(p, 5000.0, out_dir=root / "a", progress=False)
    stickslip.run_chain(p, 8000.0, out_dir=root / "b", progress=False)
    return root


def _rewrite(path, change):
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        ds = ds.load()
    change(ds)
    path.unlink()
    ds.to_netcdf(path, engine="h5netcdf")


def _nudge_x(ds):
    x = ds["x"].values.copy()
    x[2] = np.nextafter(x[2], np.inf)  # one bit of one block
    ds["x"] = ("block", x)


def _flip_stopped(ds):
    ds["stopped"] = ("block", 1 - ds["stopped"].values)


TAMPER = [
    ("one bit of x", lambda run, other: _rewrite(run / "state.nc", _nudge_x)),
    ("stopped flags", lambda run, other: _rewrite(run / "state.nc", _flip_stopped)),
    ("another run's state.nc", lambda run, other: shutil.copy(other / "state.nc", run / "state.nc")),
]


@pytest.mark.parametrize("what, tamper", TAMPER, ids=[t[0] for t in TAMPER])
def test_load_run_refuses_a_state_nc_changed_after_the_run(what, tamper, two_runs, tmp_path):
    run = tmp_path / "run"
    shutil.copytree(two_runs / "a", run)
    load_run(run)  # untouched, it loads
    tamper(run, two_runs / "b")
    with pytest.raises(RunDirDamaged, match=r"state\.nc does not hold the final state its run\.json records"):
        load_run(run)


@pytest.mark.parametrize("what, tamper", TAMPER[:1] + TAMPER[2:], ids=[TAMPER[0][0], TAMPER[2][0]])
def test_chain_from_and_catalog_refuse_a_tampered_state_nc_in_one_line(what, tamper, two_runs, tmp_path, capsys):
    run = tmp_path / "run"
    shutil.copytree(two_runs / "a", run)
    tamper(run, two_runs / "b")
    capsys.readouterr()
    code = main(["chain", "--N", "6", "--from", str(run), "--t-end", "9000", "--no-progress"])
    out, err = capsys.readouterr()
    assert code == 2 and out == "" and err.count("\n") == 1 and "does not hold the final state" in err, err
    assert main(["catalog", str(run)]) == 2
    out, err = capsys.readouterr()
    assert err.count("\n") == 1 and "does not hold the final state" in err, err
    assert not (run / "catalog").exists()
