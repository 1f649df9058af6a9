"""Labelled outputs: CF attributes of state.nc, Parquet column descriptions, sweep tables' fixed settings."""

import pyarrow.parquet as pq
import pytest
import xarray as xr

from stickslip.experiments.sweep import _row, _table
from stickslip.models.params import ChainParams
from stickslip.run.rundir import EVENT_DOCS, load_run


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    from stickslip.run.driver import run_chain

    out = tmp_path_factory.mktemp("labelled")
    run_chain(ChainParams(N=8, beta=0.8), 3e3, snapshot_times=[1e3], profile_window=20.0, out_dir=out)
    return out


def test_state_variables_carry_long_name_and_units(run_dir):
    with xr.open_dataset(run_dir / "state.nc") as ds:
        for name in ("x", "v", "theta", "stopped", "L", "snapshot_x", "profile_dx", "t"):
            assert ds[name].attrs.get("long_name"), name
            assert "units" in ds[name].attrs, name
        assert ds["x"].attrs["units"] == "1" and "M = sigma = 1" in ds["x"].attrs["comment"]
        assert list(ds["stopped"].attrs["flag_values"]) == [0, 1]
        assert ds["stopped"].attrs["flag_meanings"] == "moving stopped"
        assert ds.attrs["Conventions"].startswith("CF-")
        assert ds.attrs["param_N"] == 8 and ds.attrs["param_beta"] == 0.8
        assert ds.attrs["param_model"] == "sakaguchi"
    assert load_run(run_dir).params == ChainParams(N=8, beta=0.8)  # still reads back


def test_parquet_columns_are_described(run_dir):
    schema = pq.read_schema(run_dir / "events.parquet")
    for name in EVENT_DOCS:
        assert schema.field(name).metadata[b"description"].decode() == EVENT_DOCS[name]
    fm = pq.read_schema(run_dir / "first_move.parquet")
    assert b"first moved" in fm.field("t_first").metadata[b"description"]


def test_sweep_table_holds_the_fixed_settings():
    common = {"N": 49, "t_end": 3e5}
    record = {"status": "ok", "summary": {"L_mean": 1.0, "t_end": 2e5}}
    rows = [_row({"beta": b}, f"beta={b}", record, False, common) for b in (0.6, 1.0)]
    table = _table(rows, [{"beta": 0.6}, common])
    assert list(table.columns[:3]) == ["beta", "N", "t_end"]
    assert table["N"].tolist() == [49, 49] and table["result_t_end"].tolist() == [2e5, 2e5]


def _cf_units_of(path):
    """Every ``units`` attribute (variables and coordinates) of a NetCDF file."""
    with xr.open_dataset(path, decode_times=False) as ds:
        return {name: ds[name].attrs["units"] for name in [*ds.variables] if "units" in ds[name].attrs}


@pytest.mark.slow  # three commands run for their NetCDF files (about 14 s, measured)
def test_every_units_string_is_cf(run_dir, tmp_path):
    """The CF conventions' own parser (cf-units) reads every units string the package writes."""
    cf_units = pytest.importorskip("cf_units")
    from stickslip.cli import main

    for argv in (
        ["block", "--t-end", "300", "--out", str(tmp_path / "block")],
        ["stability", "block", "--out", str(tmp_path / "stab")],
        ["stability", "chain", "--out", str(tmp_path / "modes")],
    ):
        assert main(argv) == 0, argv
    files = [run_dir / "state.nc", *sorted(tmp_path.rglob("*.nc"))]
    assert len(files) >= 4
    seen = 0
    for path in files:
        for name, units in _cf_units_of(path).items():
            unit = cf_units.Unit(units)  # raises on a string CF tools cannot read
            assert not unit.is_unknown(), (path.name, name, units)
            seen += 1
    assert seen >= 10
    assert _cf_units_of(run_dir / "state.nc")["L"] == "1"
