"""Run directories of the chain (eq. 4): :func:`write_run` and :func:`load_run`.

A run directory holds run.json (parameters, options, summary, versions), state.nc (final state,
L(t), snapshots and profiles as labelled arrays), events.parquet and first_move.parquet, the
checkpoint folder while the run goes on (removed when the run finishes, unless kept), and
``.run_id``, the id its checkpoints carry too. A run holds the directory's lock (``.lock``, with
the holder's pid and host in ``.lock.json``) for its whole life (:func:`owned_run_dir`); every
command that writes into an output directory takes the same lock.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import socket
import time
import uuid
from collections.abc import Callable, Collection, Iterator
from pathlib import Path

import numpy as np
import xarray as xr

from stickslip import __version__
from stickslip.kernels import layout
from stickslip.models.params import ChainParams
from stickslip.run.outputs import ChainRun, RunOptions
from stickslip.run.state import ChainState

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
    "t_sample": _model("sampling time of L"),
    "L": _model("chain length L = x_1 - x_N (Fig. 5b)"),
    "snapshot_time": _model("time of the snapshot"),
    "snapshot_x": _model("block positions x_i at the snapshot time (Fig. 5a)"),
    "profile_dx": _model("displacement Delta x_i = x_i(t_next) - x_i(t) over one window (Fig. 6)"),
    "profile_event": {"long_name": "slip event of the profile row (events.parquet column event)", "units": "1"},
    "profile_t": _model("start of the profile window"),
    "profile_t_next": _model("end of the profile window"),
    "t": _model("start of the profile window"),
}

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


def _param_attrs(params: ChainParams) -> dict[str, object]:
    """The parameters as individual attributes ``param_<name>`` (bools as 0/1)."""
    return {
        f"param_{k}": (int(v) if isinstance(v, bool) else v)
        for k, v in params.to_dict().items()
        if isinstance(v, (int, float, str, bool))
    }


def write_run(run: ChainRun, out_dir: str | Path) -> Path:
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
            "L": run.samples["L"].rename({"t": "t_sample"}),
            "snapshot_x": run.snapshots.rename({"time": "snapshot_time"}),
            "profile_dx": run.profiles["dx"].rename({"row": "profile_row"}),
            "profile_event": ("profile_row", run.profiles["event"].values),
            "profile_t": ("profile_row", run.profiles["t"].values),
            "profile_t_next": ("profile_row", run.profiles["t_next"].values),
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
            "t": run.summary["t_end"],
        },
    )
    if "n_moving" in run.samples:
        ds["n_moving"] = ("t_moving", run.samples["n_moving"].values)
        ds = ds.assign_coords(t_moving=run.samples["t_moving"].values)
    ds = ds.drop_vars([c for c in ("event", "t_next") if c in ds.coords], errors="ignore")
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


class RunDirDamaged(ValueError):
    """A file of a run directory is missing, truncated or not what :func:`write_run` writes."""


def _read(path: Path, reader):
    """``reader(path)``, any failure of it a :class:`RunDirDamaged` naming the file."""
    try:
        return reader(path)
    except FileNotFoundError:
        raise RunDirDamaged(f"{path} is missing") from None
    except Exception as exc:  # truncated, overwritten, another format: all the same to a reader
        why = str(exc).strip().splitlines()[0][:120] if str(exc).strip() else type(exc).__name__
        raise RunDirDamaged(f"{path} is damaged or not a file of this package ({why})") from None


def load_run(run_dir: str | Path) -> ChainRun:
    """Read a run directory written by :func:`write_run` back into a :class:`ChainRun`; a
    missing or damaged file raises :class:`RunDirDamaged` naming it."""
    run_dir = Path(run_dir)
    try:
        return _load_run(run_dir)
    except RunDirDamaged:
        raise
    except (KeyError, TypeError, ValueError, IndexError, AttributeError, OverflowError) as exc:
        raise RunDirDamaged(
            f"{run_dir} does not hold a whole chain run ({type(exc).__name__}: {str(exc)[:80]})"
        ) from None


def _load_run(run_dir: Path) -> ChainRun:
    from stickslip import io

    meta = _read(run_dir / "run.json", io.read_json)
    ds = _read(run_dir / "state.nc", io.read_dataset)
    params = ChainParams(**meta["params"])
    state = ChainState.from_blocks(
        ds["x"].values, ds["v"].values, ds["theta"].values, ds["stopped"].values.astype(bool)
    )
    state.ist[layout.STEP] = int(meta["summary"]["steps"])
    if state.N != params.N:
        raise RunDirDamaged(f"{run_dir / 'state.nc'} holds {state.N} blocks, its run.json N = {params.N}")
    state.of(params)
    samples = xr.Dataset({"L": ("t", ds["L"].values)}, coords={"t": ds["t_sample"].values})
    if "n_moving" in ds:
        samples["n_moving"] = xr.DataArray(ds["n_moving"].values, dims="t_moving")
        samples = samples.assign_coords(t_moving=("t_moving", ds["t_moving"].values))
    snapshots = ds["snapshot_x"].rename({"snapshot_time": "time"}).rename("x")
    profiles = xr.Dataset(
        {"dx": (("row", "block"), ds["profile_dx"].values)},
        coords={
            "event": ("row", ds["profile_event"].values),
            "t": ("row", ds["profile_t"].values),
            "t_next": ("row", ds["profile_t_next"].values),
            "block": ds["block"].values,
        },
    )
    return ChainRun(
        params,
        RunOptions.from_dict(meta["options"]),
        meta["integrator"],
        meta["start"],
        state,
        _read(run_dir / "events.parquet", io.read_table),
        _read(run_dir / "first_move.parquet", io.read_table),
        samples,
        snapshots,
        profiles,
        meta["summary"],
    )


#: The lock of a directory and its holder's record.
LOCK_FILES = frozenset({".lock", ".lock.json"})
RUN_ID_FILE = ".run_id"
#: The files and folders a chain run writes into its run directory.
#: The results of a finished chain run, as :func:`write_run` writes them.
RUN_FILES = ("run.json", "state.nc", "events.parquet", "events.csv", "first_move.parquet", "first_move.csv")
OWN_FILES = frozenset({*RUN_FILES, "checkpoint", RUN_ID_FILE, *LOCK_FILES})


#: The file of a state handed on (a rung of the transition study): every array of the state and its model.
STATE_FILE = "state.npz"


def write_state_file(path: str | Path, state: ChainState) -> Path:
    """Write ``state`` (every array, and its model as JSON under ``__model__``) to ``path`` as
    an npz file, built in memory and written atomically (a full disk leaves no half file)."""
    from io import BytesIO

    from stickslip import io

    arrays = {k: getattr(state, k) for k in ChainState.ARRAYS}
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
    return ChainState(**{k: arrays[k].copy() for k in ChainState.ARRAYS}, model=model)


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


def is_temporary(name: str) -> bool:
    """A file name of :func:`stickslip.io.atomic_path` (``.NAME.XXXX.tmp``), left only by a killed write."""
    return name.startswith(".") and name.endswith(".tmp")


class RunDirBusy(RuntimeError):
    """Another run holds the run directory's lock; the message names the holder."""


#: Run directories held in this process (:func:`owned_run_dir`), or owned by the caller of a run
#: (:func:`owned_by_caller`): a run writing into one of them neither locks nor checks it again.
_HELD: set[str] = set()


@contextlib.contextmanager
def owned_by_caller(run_dir: str | Path) -> Iterator[None]:
    """Mark ``run_dir`` as owned by the caller for the block (a sweep's point folder, which the
    sweep owns), so that :func:`run_dir_for_run` takes it as it is."""
    key = os.path.realpath(run_dir)
    new = key not in _HELD
    _HELD.add(key)
    try:
        yield
    finally:
        if new:
            _HELD.discard(key)


@contextlib.contextmanager
def run_dir_for_resume(run_dir: str | Path) -> Iterator[None]:
    """The run directory of ``resume_chain(run_dir)``, locked for the run as ``chain --resume``
    locks it (a second writer gets :class:`RunDirBusy`); one this process already holds or its
    caller owns (:func:`owned_by_caller`) is taken as it is."""
    if os.path.realpath(run_dir) in _HELD:
        yield
        return
    with owned_run_dir(run_dir, new_id=False):
        yield


@contextlib.contextmanager
def run_dir_for_run(out_dir: str | Path | None, run_id: str | None = None) -> Iterator[str | None]:
    """The run directory of ``run_chain(out_dir=...)``, owned as ``stickslip chain --out`` owns it:
    a folder holding files a chain run does not write, or a run already (finished, or with a
    checkpoint to resume), is refused with ParameterError before anything is written; the folder
    is locked for the run (a second writer gets :class:`RunDirBusy`, naming the holder) and gets
    a run id, which is yielded. A folder this process already holds (the command's) or that its
    caller owns (:func:`owned_by_caller`) is taken as it is, with ``run_id``."""
    if out_dir is None or os.path.realpath(out_dir) in _HELD:
        yield run_id
        return
    from stickslip.models.params import ParameterError

    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise ParameterError(f"out_dir {out} is not a directory")
    if out.is_dir():
        foreign = sorted(n for n in os.listdir(out) if n not in OWN_FILES and not is_temporary(n))
        if foreign:
            shown = ", ".join(foreign[:3]) + (", ..." if len(foreign) > 3 else "")
            raise ParameterError(
                f"out_dir {out} holds files that a chain run does not write ({shown}); choose an empty directory"
            )
        if (out / "checkpoint" / "state.npz").exists():
            raise ParameterError(
                f"{out} already holds a run; continue it with resume_chain({str(out)!r}) or choose another out_dir"
            )
        if (out / "run.json").exists():
            raise ParameterError(f"{out} already holds a finished run; choose another out_dir")
    with owned_run_dir(out) as rid:
        yield rid


def read_run_id(run_dir: str | Path) -> str | None:
    """The run id of a run directory (None for one written before run ids)."""
    path = Path(run_dir) / RUN_ID_FILE
    try:
        return path.read_text().strip() or None
    except OSError:
        return None


@contextlib.contextmanager
def owned_run_dir(
    run_dir: str | Path | None, *, run_id: bool = True, new_id: bool = True, keep: Collection[str] = ()
) -> Iterator[str | None]:
    """Hold the lock of ``run_dir`` for the life of a run and yield its run id (a new one for a
    directory without, unless ``new_id`` is false; None with ``run_id=False``, for outputs without
    checkpoints). A second holder is refused at once with :class:`RunDirBusy`; files left by a
    killed write are removed. On a full disk (:func:`stickslip.io.disk_full`) what the block
    added is removed again (:func:`_undo_on_full_disk`; the names in ``keep`` stay): the
    directory is left as it was, or with a resumable checkpoint."""
    if run_dir is None:
        yield None
        return
    from filelock import FileLock, Timeout

    run_dir = Path(run_dir)
    created = not run_dir.exists()
    run_dir.mkdir(parents=True, exist_ok=True)
    before = {p.name for p in run_dir.iterdir()}
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
        raise RunDirBusy(
            f"{run_dir} is in use by another run ({who}); wait for it or choose another directory"
        ) from None
    except OSError:
        _remove_if_empty(run_dir, created)
        raise
    key = os.path.realpath(run_dir)
    _HELD.add(key)
    try:
        from stickslip.io import write_bytes

        record = {"pid": os.getpid(), "host": socket.gethostname(), "since": time.strftime("%Y-%m-%dT%H:%M:%S")}
        write_bytes(info, json.dumps(record).encode())
        for stale in run_dir.glob(".*.tmp"):  # left by a write that was killed
            with contextlib.suppress(OSError):
                stale.unlink()
        if not run_id:
            yield None
            return
        rid = read_run_id(run_dir)
        if rid is None and new_id and not (run_dir / "checkpoint").exists():
            rid = uuid.uuid4().hex
            write_bytes(run_dir / RUN_ID_FILE, (rid + "\n").encode())
        yield rid
    except BaseException as exc:
        from stickslip.io import disk_full

        if disk_full(exc) is not None:
            _undo_on_full_disk(run_dir, before | set(keep))
        raise
    finally:
        _HELD.discard(key)
        # Unlinked while held, so a directory left behind is as it was (the check above
        # keeps a waiter from holding the unlinked file).
        for path in (info, run_dir / ".lock"):
            with contextlib.suppress(OSError):
                path.unlink()
        lock.release()
        _remove_if_empty(run_dir, created)


def _remove_if_empty(run_dir: Path, created: bool) -> None:
    """Remove ``run_dir`` again if this run created it and left nothing in it."""
    if created:
        with contextlib.suppress(OSError):
            run_dir.rmdir()


def _undo_on_full_disk(run_dir: Path, before: set[str]) -> None:
    """Remove what a run that met a full disk added to ``run_dir``: new files, a new checkpoint
    without its state file (with the new run id) and new empty folders. Kept: a checkpoint that
    can be resumed (and its run id), and new folders with content (a sweep's points, each reused
    only when its done.json is whole)."""
    from stickslip.run.checkpoint import Checkpointer

    resumable = (Checkpointer(run_dir).dir / "state.npz").is_file()
    for path in run_dir.iterdir():
        name = path.name
        if name in before or name in LOCK_FILES:
            continue
        if name == RUN_ID_FILE and resumable:
            continue
        with contextlib.suppress(OSError):
            if path.is_dir():
                if name == "checkpoint" and not resumable:
                    shutil.rmtree(path)
                elif not any(path.iterdir()):
                    path.rmdir()
            else:
                path.unlink()


def _same_file(lock, path: Path) -> bool:
    """The lock held is on the file now at ``path``."""
    fd = getattr(getattr(lock, "_context", None), "lock_file_fd", None)
    try:
        return fd is None or os.fstat(fd).st_ino == os.stat(path).st_ino
    except OSError:
        return False


def remove_own_files(run_dir: str | Path, own: Callable[[str], bool] | None = None) -> None:
    """Remove what a run wrote into ``run_dir``: the entries whose name ``own`` accepts (default:
    a chain run's files) and files of killed writes; not the lock nor the run id. Other files stay."""
    for path in Path(run_dir).iterdir():
        name = path.name
        if name in LOCK_FILES or name == RUN_ID_FILE:
            continue
        if (own(name) if own is not None else name in OWN_FILES) or is_temporary(name):
            if path.is_dir():
                shutil.rmtree(path)
            else:
                path.unlink()
