"""Run directories of the chain (eq. 4): :func:`write_run` and :func:`load_run`.

A run directory holds run.json (parameters, options, summary, versions), state.nc (final state,
L(t), snapshots and profiles as labelled arrays), events.parquet and first_move.parquet, the
checkpoint folder while the run goes on (removed when the run finishes, unless kept), and
``.run_id``, the id its checkpoints carry too. The files and their labels are
:mod:`stickslip.run.runfiles`; the lock a run holds on its directory for its whole life, and which
files it may replace, :mod:`stickslip.run.ownership`. Both are named here too.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import xarray as xr

from stickslip.kernels import layout
from stickslip.models.params import ChainParams
from stickslip.run.options import RunOptions
from stickslip.run.outputs import ChainRun

# The directory's files and its ownership, named here as before they had modules of their own.
from stickslip.run.ownership import (  # noqa: F401
    _HELD,
    LOCK_FILES,
    OWN_FILES,
    RUN_ID_FILE,
    RunDirBusy,
    is_temporary,
    owned_by_caller,
    owned_run_dir,
    read_run_id,
    remove_own_files,
    run_dir_for_resume,
    run_dir_for_run,
)
from stickslip.run.runfiles import (  # noqa: F401
    EVENT_DOCS,
    FIRST_MOVE_DOCS,
    PROFILE_COORDS,
    RUN_FILES,
    SCALE,
    UNITS,
    VARIABLE_ATTRS,
    write_run,
)
from stickslip.run.state import ChainState


class RunDirDamaged(ValueError):
    """A file of a run directory is missing, truncated or not what :func:`write_run` writes."""


class RunDirMissing(RunDirDamaged, FileNotFoundError):
    """A run directory, or a file it must hold, is not there: a :class:`FileNotFoundError` as
    Python code expects of a missing path (and a :class:`RunDirDamaged` as before)."""

    def __init__(self, message: str, path: Path):
        super().__init__(message)
        self.filename = str(path)

    def __str__(self) -> str:  # the message, not OSError's "[Errno None] None: path"
        return str(self.args[0])


class LatticeRunDir(RunDirDamaged):
    """A run directory that holds a run on a lattice (docs/lattice.md), which the chain's readers
    (:func:`load_run`, the catalogue, the period, the plots, ``--from``) do not yet take."""


def lattice_run(run_dir: str | Path) -> str | None:
    """The lattice and shape of the run in ``run_dir`` (``"square 4x5"``), None for a chain run or
    a folder without a readable run.json."""
    import json

    try:
        params = json.loads((Path(run_dir) / "run.json").read_text()).get("params", {})
    except (OSError, ValueError, AttributeError):
        return None
    if not isinstance(params, dict) or params.get("lattice") in (None, "chain"):
        return None
    return f"{params['lattice']} {params.get('shape', '')}".strip()


def refuse_lattice_run(run_dir: str | Path, what: str) -> None:
    """Raise :class:`LatticeRunDir` in one line where ``run_dir`` holds a run on a lattice, which
    ``what`` does not yet read."""
    lat = lattice_run(run_dir)
    if lat is not None:
        raise LatticeRunDir(
            f"{run_dir} holds a run on lattice {lat}: {what} does not yet read lattice runs "
            "(their events.csv and state.nc are read with pandas and xarray; docs/lattice.md)"
        )


def _read(path: Path, reader):
    """``reader(path)``, any failure of it a :class:`RunDirDamaged` naming the file."""
    try:
        return reader(path)
    except FileNotFoundError:
        raise RunDirMissing(f"{path} is missing", path) from None
    except Exception as exc:  # truncated, overwritten, another format: all the same to a reader
        why = str(exc).strip().splitlines()[0][:120] if str(exc).strip() else type(exc).__name__
        raise RunDirDamaged(f"{path} is damaged or not a file of this package ({why})") from None


def load_run(run_dir: str | Path) -> ChainRun:
    """Read a run directory written by :func:`write_run` back into a :class:`ChainRun`; a
    missing or damaged file raises :class:`RunDirDamaged` naming it (a missing folder or file
    :class:`RunDirMissing`, which is also a :class:`FileNotFoundError`), and so does a state.nc
    whose final state no longer has the SHA-256 (``state_sha256``) its run.json records.

    Parameters
    ----------
    run_dir : str or Path
        A folder written by ``stickslip chain --out``, by ``run_chain(out_dir=...)`` or by
        :meth:`ChainRun.save`.

    Returns
    -------
    ChainRun
        The run as :func:`~stickslip.run.driver.run_chain` returned it (state, tables, summary).

    Examples
    --------
    >>> import stickslip, tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp()) / "run"
    >>> run = stickslip.run_chain(stickslip.chain_params(N=10), 2e4, out_dir=folder)
    >>> back = stickslip.load_run(folder)
    >>> back.events.equals(run.events), back.summary["state_sha256"] == run.summary["state_sha256"]
    (True, True)
    """
    run_dir = Path(run_dir)
    if run_dir.exists() and not run_dir.is_dir():
        raise RunDirDamaged(f"{run_dir} is not a directory (a run directory holds run.json, state.nc, ...)")
    if not run_dir.exists():
        raise RunDirMissing(f"{run_dir}: no such run directory", run_dir)
    refuse_lattice_run(run_dir, "the chain's readers (load_run, --from)")
    try:
        return _load_run(run_dir)
    except RunDirDamaged:
        raise
    except (KeyError, TypeError, ValueError, IndexError, AttributeError, OverflowError) as exc:
        raise RunDirDamaged(
            f"{run_dir} does not hold a whole chain run ({type(exc).__name__}: {str(exc)[:80]})"
        ) from None


def _state_file_sha256(ds: xr.Dataset) -> str:
    """SHA-256 of a state.nc's final state, over its arrays as stored and in the order of
    :meth:`~stickslip.run.state.ChainState.sha256` (x, v, theta as float64 little-endian, then
    stopped one byte each), so that it equals the ``state_sha256`` its run.json records."""
    h = hashlib.sha256()
    for name in ("x", "v", "theta"):
        h.update(np.ascontiguousarray(ds[name].values, dtype="<f8").tobytes())
    h.update((np.asarray(ds["stopped"].values) != 0).astype(np.uint8).tobytes())
    return h.hexdigest()


#: The columns of events.parquet every reader of a run uses (:data:`EVENT_DOCS`).
EVENT_COLUMNS = ("event", "t_start", "duration", "S", "start_block", "max_block", "n_blocks")


def _check_events(events, path: Path):
    """``events`` (a run's events.parquet) as :func:`write_run` writes it, else a
    :class:`RunDirDamaged` naming the file and what is wrong: every column of
    :data:`EVENT_COLUMNS`, numbers only, finite, and each event once, in order."""
    import pandas as pd

    missing = [c for c in EVENT_COLUMNS if c not in events.columns]
    if missing:
        raise RunDirDamaged(f"{path} is not a table of events: it lacks the column(s) {', '.join(missing)}")
    for c in EVENT_COLUMNS:
        column = events[c]
        if len(column) and not (pd.api.types.is_numeric_dtype(column) and not pd.api.types.is_bool_dtype(column)):
            raise RunDirDamaged(f"{path}: column {c} holds {column.dtype} values, not numbers")
        values = column.to_numpy(dtype=np.float64) if len(column) else np.empty(0)
        bad = ~np.isfinite(values)
        if bad.any():
            raise RunDirDamaged(f"{path}: column {c} holds {int(bad.sum())} non-finite value(s) (NaN or inf)")
    numbers = events["event"].to_numpy(dtype=np.float64)
    if numbers.size > 1 and not np.all(np.diff(numbers) > 0):
        raise RunDirDamaged(f"{path}: events repeated or out of order (column event is not increasing)")
    return events


def _load_run(run_dir: Path) -> ChainRun:
    from stickslip import io

    meta = _read(run_dir / "run.json", io.read_json)
    ds = _read(run_dir / "state.nc", io.read_dataset)
    params = ChainParams(**meta["params"])
    recorded = meta["summary"].get("state_sha256")
    if isinstance(recorded, str) and _state_file_sha256(ds) != recorded:
        # state.nc replaced or edited after the run: its state is not the one the run ended on
        raise RunDirDamaged(
            f"{run_dir / 'state.nc'} does not hold the final state its run.json records "
            f"(state_sha256 {recorded[:16]}...): the file was changed after the run"
        )
    state = ChainState.from_blocks(
        ds["x"].values, ds["v"].values, ds["theta"].values, ds["stopped"].values.astype(bool)
    )
    state.ist[layout.STEP] = int(meta["summary"]["steps"])
    if state.N != params.N:
        raise RunDirDamaged(f"{run_dir / 'state.nc'} holds {state.N} blocks, its run.json N = {params.N}")
    for name, pb in params.per_block().items():
        held = ds[f"param_{name}"].values
        if held.shape != pb.values.shape or held.tobytes() != pb.values.tobytes():
            raise RunDirDamaged(f"{run_dir / 'state.nc'} holds other per-block values of {name} than its run.json")
    state.of(params)
    # L's time axis was called t_sample before it took the name it has in ChainRun.samples
    t_sample = ds["t_sample"] if "t_sample" in ds.variables else ds["t"]
    samples = xr.Dataset({"L": ("t", ds["L"].values)}, coords={"t": t_sample.values})
    if "n_moving" in ds:
        samples["n_moving"] = xr.DataArray(ds["n_moving"].values, dims="t_moving")
        samples = samples.assign_coords(t_moving=("t_moving", ds["t_moving"].values))
    snapshots = ds["snapshot_x"]
    profiles = xr.Dataset(
        {"profile_dx": (("profile_row", "block"), ds["profile_dx"].values)},
        coords={
            **{name: ("profile_row", ds[name].values) for name in PROFILE_COORDS},
            "block": ds["block"].values,
        },
    )
    return ChainRun(
        params,
        RunOptions.from_dict(meta["options"], meta["integrator"]),
        meta["integrator"],
        meta["start"],
        state,
        _check_events(_read(run_dir / "events.parquet", io.read_table), run_dir / "events.parquet"),
        _read(run_dir / "first_move.parquet", io.read_table),
        samples,
        snapshots,
        profiles,
        meta["summary"],
    )


#: The file of a state handed on (a rung of the transition study): every array of the state and its model.
STATE_FILE = "state.npz"


def write_state_file(path: str | Path, state: ChainState) -> Path:
    """Write ``state`` (every array, and its model as JSON under ``__model__``) to ``path`` as
    an npz file, built in memory and written atomically (a full disk leaves no half file)."""
    from io import BytesIO

    from stickslip import io

    arrays = state.arrays()
    if state.model is not None:
        arrays["__model__"] = np.frombuffer(json.dumps(state.model, sort_keys=True).encode(), dtype=np.uint8)
    buf = BytesIO()
    np.savez(buf, **arrays)
    return io.write_bytes(path, buf.getvalue())


def read_state_file(path: str | Path) -> ChainState:
    """The state in an npz file of :func:`write_state_file`; raises ValueError (one line naming the
    file) if it is missing, damaged or lacks an array. A file without ``__model__`` (written before
    states recorded it: a rung of the transition study) holds a state of eq. (4)."""
    from stickslip.run.state import model_of

    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except FileNotFoundError:
        raise ValueError(f"{path} is missing") from None
    except Exception as exc:  # truncated, empty, not npz, pickled objects: all refused alike
        raise ValueError(f"{path} is damaged or not a state file ({type(exc).__name__})") from None
    missing = [k for k in ChainState.ARRAYS if k not in arrays]
    if missing:
        raise ValueError(f"{path} is not a state file: it lacks {', '.join(missing)}")
    model = model_of(ChainParams())
    if "__model__" in arrays:
        try:
            model = json.loads(arrays["__model__"].tobytes().decode())
        except (ValueError, UnicodeDecodeError):
            model = None
        if not isinstance(model, dict) or not all(isinstance(v, str) for v in model.values()):
            raise ValueError(f"{path} is damaged: its model record is unreadable")
    return ChainState.from_arrays(arrays, model=model)


def final_state(path: str | Path) -> ChainState:
    """The final state of another run, as a start: a run directory (its ``state.nc``: x, v, theta,
    stopped and the step count, so the time goes on) or a rung of the transition study (its
    ``state.npz``, every array of the state, checked against the SHA-256 its ``rung.json``
    recorded). Raises ValueError (one line) if there is neither, or it is damaged; the state
    itself is checked by :func:`stickslip.run.validate.check_start_state` before a run."""
    path = Path(path)
    if (path / STATE_FILE).is_file():
        state = read_state_file(path / STATE_FILE)
        recorded = _recorded_sha256(path / "rung.json")
        if recorded is not None and (_safe_sha256(state) != recorded):
            raise ValueError(f"{path / STATE_FILE} does not match the final state its rung.json records")
        return state
    if (path / "run.json").is_file() and (path / "state.nc").is_file():
        return load_run(path).state
    raise ValueError(f"{path} holds no finished run (run.json and state.nc) and no study rung (state.npz)")


def _recorded_sha256(path: Path) -> str | None:
    """The final state's SHA-256 a rung's record names, or None where there is no readable one."""
    try:
        row = json.loads(path.read_text()).get("row", {})
    except (OSError, ValueError, AttributeError):
        return None
    digest = row.get("final_sha256") if isinstance(row, dict) else None
    return digest if isinstance(digest, str) else None


def _safe_sha256(state: ChainState) -> str | None:
    """:meth:`ChainState.sha256`, or None for arrays it cannot hash (the start check names them)."""
    try:
        return state.sha256()
    except (TypeError, ValueError, IndexError):
        return None
