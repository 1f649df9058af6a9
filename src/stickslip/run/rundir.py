"""Run directories of the chain (eq. 4): :func:`write_run` and :func:`load_run`.

A run directory holds run.json (parameters, options, summary, versions), state.nc (final state,
L(t), snapshots and profiles as labelled arrays), events.parquet and first_move.parquet.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import xarray as xr

from stickslip import __version__
from stickslip.kernels import chain as K
from stickslip.models.params import ChainParams
from stickslip.run.outputs import ChainRun, RunOptions
from stickslip.run.state import ChainState


def write_run(run: ChainRun, out_dir: str | Path) -> Path:
    """Write a run directory: run.json, state.nc (labelled arrays), events.parquet, first_move.parquet."""
    from stickslip import io

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    blocks = run.snapshots["block"].values
    b = run.state.blocks()
    ds = xr.Dataset(
        {
            "x": ("block", b["x"]), "v": ("block", b["v"]), "theta": ("block", b["theta"]),
            "stopped": ("block", b["stopped"].astype(np.int8)),
            "L": run.samples["L"].rename({"t": "t_sample"}),
            "snapshot_x": run.snapshots.rename({"time": "snapshot_time"}),
            "profile_dx": run.profiles["dx"].rename({"row": "profile_row"}),
            "profile_event": ("profile_row", run.profiles["event"].values),
            "profile_t": ("profile_row", run.profiles["t"].values),
            "profile_t_next": ("profile_row", run.profiles["t_next"].values),
        },
        coords={"block": blocks},
        attrs={"params": json.dumps(run.params.to_dict()), "integrator": run.integrator,
               "version": __version__, "t": run.summary["t_end"]},
    )
    if "n_moving" in run.samples:
        ds["n_moving"] = ("t_moving", run.samples["n_moving"].values)
        ds = ds.assign_coords(t_moving=run.samples["t_moving"].values)
    ds = ds.drop_vars([c for c in ("event", "t_next") if c in ds.coords], errors="ignore")
    io.write_dataset(out / "state.nc", ds)
    io.write_table(out / "events.parquet", run.events)
    io.write_table(out / "first_move.parquet", run.first_move)
    meta = io.run_metadata(run.params, integrator=run.integrator, options=run.options.to_dict(),
                           start=run.start, summary=run.summary)
    io.write_json(out / "run.json", meta)
    return out


def load_run(run_dir: str | Path) -> ChainRun:
    """Read a run directory written by :func:`write_run` back into a :class:`ChainRun`."""
    from stickslip import io

    run_dir = Path(run_dir)
    meta = io.read_json(run_dir / "run.json")
    ds = io.read_dataset(run_dir / "state.nc")
    params = ChainParams(**meta["params"])
    state = ChainState.from_blocks(ds["x"].values, ds["v"].values, ds["theta"].values,
                                   ds["stopped"].values.astype(bool))
    state.ist[K.STEP] = int(meta["summary"]["steps"])
    samples = xr.Dataset({"L": ("t", ds["L"].values)}, coords={"t": ds["t_sample"].values})
    if "n_moving" in ds:
        samples["n_moving"] = xr.DataArray(ds["n_moving"].values, dims="t_moving")
        samples = samples.assign_coords(t_moving=("t_moving", ds["t_moving"].values))
    snapshots = ds["snapshot_x"].rename({"snapshot_time": "time"}).rename("x")
    profiles = xr.Dataset(
        {"dx": (("row", "block"), ds["profile_dx"].values)},
        coords={"event": ("row", ds["profile_event"].values), "t": ("row", ds["profile_t"].values),
                "t_next": ("row", ds["profile_t_next"].values), "block": ds["block"].values},
    )
    return ChainRun(params, RunOptions.from_dict(meta["options"]), meta["integrator"], meta["start"], state,
                    io.read_table(run_dir / "events.parquet"), io.read_table(run_dir / "first_move.parquet"),
                    samples, snapshots, profiles, meta["summary"])

