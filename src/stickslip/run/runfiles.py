"""The files of a chain run directory (eq. 4): what :func:`write_run` writes, with their labels.

state.nc (final state, L(t), snapshots and profiles as labelled arrays, CF attributes from
:data:`VARIABLE_ATTRS`; every array under the name it has in ``ChainRun.samples``,
``.snapshots`` and ``.profiles``, the time of the final state in the attribute ``t_end``; files
written before L's time took the name ``t`` had ``t_sample``, and
:func:`~stickslip.run.rundir.load_run` reads both), events and first_move (each as .parquet and
.csv, the columns described by :data:`EVENT_DOCS` and :data:`FIRST_MOVE_DOCS`) and run.json.
Reading them back is :func:`stickslip.run.rundir.load_run`; owning and locking the directory is
:mod:`stickslip.run.ownership`.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from stickslip import __version__

#: The results of a finished chain run, as :func:`write_run` writes them.
RUN_FILES = ("run.json", "state.nc", "events.parquet", "events.csv", "first_move.parquet", "first_move.csv")

UNITS = "model units"  # eq. (4) scaled to M = sigma = 1 (the Parquet column descriptions say so)

#: Every quantity of the model is dimensionless (eq. 4 scaled to M = sigma = 1, docs/model.md,
#: "Units"): CF units "1", with the scale said in the comment.
SCALE = "dimensionless model units: eq. (4) scaled to M = sigma = 1 (docs/model.md, Units)"


def _model(long_name: str, **extra) -> dict:
    """CF attributes of a dimensionless model quantity."""
    return {"long_name": long_name, "units": "1", "comment": SCALE, **extra}


#: long_name, units and comment of the variables of state.nc (CF attributes).
VARIABLE_ATTRS = {
    "block": {"long_name": "block index i (1 = pulled end, N = free end)", "units": "1"},
    "x": _model("block position x_i at the end of the run"),
    "v": _model("block velocity v_i at the end of the run"),
    "theta": _model("state variable theta_i of the friction at the end of the run"),
    "stopped": {
        "long_name": "block stuck (start and stop rules of eq. 4) at the end of the run",
        "units": "1",
        "flag_values": np.array([0, 1], dtype=np.int8),
        "flag_meanings": "moving stopped",
    },
    "t": _model("sampling time t of L"),
    "L": _model("chain length L = x_1 - x_N (Fig. 5b)"),
    "snapshot_time": _model("time of the snapshot"),
    "snapshot_x": _model("block positions x_i at the snapshot time (Fig. 5a)"),
    "profile_dx": _model("displacement Delta x_i = x_i(profile_t_next) - x_i(profile_t) over one window (Fig. 6)"),
    "profile_event": {"long_name": "slip event of the profile row (events.parquet column event)", "units": "1"},
    "profile_t": _model("start of the profile window"),
    "profile_t_next": _model("end of the profile window"),
}

#: The per-row quantities of ChainRun.profiles (coordinates in memory, variables in state.nc).
PROFILE_COORDS = ("profile_event", "profile_t", "profile_t_next")

#: Descriptions of the columns of events.parquet and first_move.parquet (Parquet field metadata).
EVENT_DOCS = {
    "event": "event number, 0-based, in order of start",
    "step_start": "first step n in which a block moved (t = n dt)",
    "step_end": "first step that ended with every block stopped again",
    "t_start": f"start time step_start * dt, {UNITS}",
    "t_end": f"end time step_end * dt, {UNITS}",
    "duration": f"t_end - t_start, {UNITS}",
    "S": f"slip size S = sum_i (x_i(end) - x_i(start)), {UNITS} (Figs. 7, 8)",
    "start_block": "block that moved first (1..N)",
    "max_block": "farthest block that moved (1..N)",
    "n_blocks": "number of blocks that moved",
}
FIRST_MOVE_DOCS = {
    "event": "event number (events.parquet column event)",
    "block": "block index i (1..N)",
    "t_first": f"time at which block i first moved in the event, {UNITS} (Fig. 6)",
    "step": "step at which block i first moved in the event",
}


def _param_attrs(params: Any) -> dict[str, object]:
    """The parameters as individual attributes ``param_<name>`` (bools as 0/1)."""
    return {
        f"param_{k}": (int(v) if isinstance(v, bool) else v)
        for k, v in params.to_dict().items()
        if isinstance(v, (int, float, str, bool))
    }


def write_run(run: Any, out_dir: str | Path) -> Path:
    """Write a run directory: run.json, state.nc (labelled arrays), the tables events and
    first_move (each as .parquet and .csv, :data:`RUN_FILES`)."""
    from stickslip import io

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    blocks = run.snapshots["block"].values
    b = run.state.blocks()
    ds = xr.Dataset(
        {
            "x": ("block", b["x"]),
            "v": ("block", b["v"]),
            "theta": ("block", b["theta"]),
            "stopped": ("block", b["stopped"].astype(np.int8)),
            "L": run.samples["L"],
            "snapshot_x": run.snapshots,
            "profile_dx": run.profiles["profile_dx"].reset_coords(drop=True),
            **{name: ("profile_row", run.profiles[name].values) for name in PROFILE_COORDS},
        },
        coords={"block": blocks},
        attrs={
            "Conventions": "CF-1.10",
            "title": "chain of eq. (4): final state, L(t), snapshots, profiles",
            "source": f"stickslip {__version__}, {run.integrator} integrator",
            "units_note": "model units: eq. (4) scaled to M = sigma = 1 (docs/model.md)",
            "params": json.dumps(run.params.to_dict()),
            **_param_attrs(run.params),
            "integrator": run.integrator,
            "version": __version__,
            "t_end": run.summary["t_end"],
        },
    )
    for name, pb in run.params.per_block().items():
        # Per-block parameters over the blocks, with their provenance (docs/model.md).
        attrs = {k: v for k, v in pb.describe().items() if v is not None}
        ds[f"param_{name}"] = ("block", pb.values, {"long_name": f"{name} at each block", **attrs})
    if "n_moving" in run.samples:
        ds["n_moving"] = ("t_moving", run.samples["n_moving"].values)
        ds = ds.assign_coords(t_moving=run.samples["t_moving"].values)
    for name, attrs in VARIABLE_ATTRS.items():
        if name in ds.variables:
            ds[name].attrs.update(attrs)
    io.write_dataset(out / "state.nc", ds)
    # The model, its pieces and every parameter travel with each table too.
    model = {"params": run.params.to_dict(), "integrator": run.integrator}
    io.write_table_files(out / "events", run.events, EVENT_DOCS, metadata=model)
    io.write_table_files(out / "first_move", run.first_move, FIRST_MOVE_DOCS, metadata=model)
    meta = io.run_metadata(
        run.params, integrator=run.integrator, options=run.options.to_dict(), start=run.start, summary=run.summary
    )
    io.write_json(out / "run.json", meta)
    return out
