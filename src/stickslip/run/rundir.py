"""Run directories of the chain (eq. 4): :func:`write_run` and :func:`load_run`.

A run directory holds run.json (parameters, options, summary, versions), state.nc (final state,
L(t), snapshots and profiles as labelled arrays), events.parquet and first_move.parquet, the
checkpoint folder while the run goes on, and ``.run_id``, the id its checkpoints carry too. A run
holds the directory's lock (``.lock``, with the holder's pid and host in ``.lock.json``) for its
whole life (:func:`owned_run_dir`).
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import socket
import time
import uuid
from pathlib import Path
from typing import Iterator

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
    snapshots = ds["snapshot_x"].rename({"snapshot_time": "time"}).rename("x")
    profiles = xr.Dataset(
        {"dx": (("row", "block"), ds["profile_dx"].values)},
        coords={"event": ("row", ds["profile_event"].values), "t": ("row", ds["profile_t"].values),
                "t_next": ("row", ds["profile_t_next"].values), "block": ds["block"].values},
    )
    return ChainRun(params, RunOptions.from_dict(meta["options"]), meta["integrator"], meta["start"], state,
                    io.read_table(run_dir / "events.parquet"), io.read_table(run_dir / "first_move.parquet"),
                    samples, snapshots, profiles, meta["summary"])



#: The files and folders a chain run writes into its run directory.
OWN_FILES = frozenset({"run.json", "state.nc", "events.parquet", "first_move.parquet", "checkpoint",
                       ".run_id", ".lock", ".lock.json"})
RUN_ID_FILE = ".run_id"


class RunDirBusy(RuntimeError):
    """Another run holds the run directory's lock; the message names the holder."""


def read_run_id(run_dir: str | Path) -> str | None:
    """The run id of a run directory (None for one written before run ids)."""
    path = Path(run_dir) / RUN_ID_FILE
    try:
        return path.read_text().strip() or None
    except OSError:
        return None


@contextlib.contextmanager
def owned_run_dir(run_dir: str | Path | None) -> Iterator[str | None]:
    """Hold the lock of ``run_dir`` for the life of a run and yield its run id (a new one for a
    directory without). A second holder is refused at once with :class:`RunDirBusy`."""
    if run_dir is None:
        yield None
        return
    from filelock import FileLock, Timeout

    run_dir = Path(run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    lock = FileLock(str(run_dir / ".lock"))
    info = run_dir / ".lock.json"
    try:
        lock.acquire(timeout=0)
        if not _same_file(lock, run_dir / ".lock"):  # removed by a holder finishing meanwhile
            lock.release()
            raise Timeout(str(run_dir / ".lock"))
    except Timeout:
        try:
            holder = json.loads(info.read_text())
            who = f"pid {holder['pid']} on {holder['host']} since {holder['since']}"
        except (OSError, ValueError, KeyError, TypeError):
            who = "another process"
        raise RunDirBusy(f"{run_dir} is in use by another run ({who}); wait for it or choose another "
                         "directory") from None
    try:
        info.write_text(json.dumps({"pid": os.getpid(), "host": socket.gethostname(),
                                    "since": time.strftime("%Y-%m-%dT%H:%M:%S")}))
        for stale in run_dir.glob(".*.tmp"):  # left by a write that was killed
            with contextlib.suppress(OSError):
                stale.unlink()
        run_id = read_run_id(run_dir)
        if run_id is None and not (run_dir / "checkpoint").exists():
            run_id = uuid.uuid4().hex
            (run_dir / RUN_ID_FILE).write_text(run_id + "\n")
        yield run_id
    finally:
        # Unlinked while held, so a directory left behind is as it was (the check above
        # keeps a waiter from holding the unlinked file).
        for path in (info, run_dir / ".lock"):
            with contextlib.suppress(OSError):
                path.unlink()
        lock.release()


def _same_file(lock, path: Path) -> bool:
    """The lock held is on the file now at ``path``."""
    fd = getattr(getattr(lock, "_context", None), "lock_file_fd", None)
    try:
        return fd is None or os.fstat(fd).st_ino == os.stat(path).st_ino
    except OSError:
        return False


def remove_own_files(run_dir: str | Path) -> None:
    """Remove what a chain run wrote into ``run_dir`` (not the lock nor the run id); other files stay."""
    for path in Path(run_dir).iterdir():
        name = path.name
        if name in (".lock", ".lock.json", RUN_ID_FILE):
            continue
        if name in OWN_FILES or (name.startswith(".") and name.endswith(".tmp")):
            if path.is_dir():
                shutil.rmtree(path)
            else:
                path.unlink()
