"""Owning a run directory: its lock, its run id, and which of its files a run may replace.

A run holds the directory's lock (``.lock``, with the holder's pid and host in ``.lock.json``) for
its whole life (:func:`owned_run_dir`); every command that writes into an output directory takes
the same lock. :func:`run_dir_for_run` owns a folder as ``stickslip chain --out`` does (foreign
files and an earlier run refused), :func:`run_dir_for_resume` as ``chain --resume`` does.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import shutil
import socket
import time
import uuid
from collections.abc import Callable, Collection, Iterator
from pathlib import Path

from stickslip.run.runfiles import RUN_FILES

#: The lock of a directory and its holder's record.
LOCK_FILES = frozenset({".lock", ".lock.json"})
RUN_ID_FILE = ".run_id"
#: Where ``stickslip plot`` draws a run's figures by default (RUN_DIR/figures), and their names
#: (:func:`stickslip.plotting.run.run_figures`): the run owns that folder while it holds only these.
PLOT_FOLDER = "figures"
PLOT_FILE = re.compile(
    r"(length|snapshot_final|snapshot_t[^/]*|sizes|fronts|slip_map_e\d+|rupture_e\d+)\.(png|pdf|svg)"
)
#: Where ``stickslip catalog`` writes a run's catalogue by default (RUN_DIR/catalog), its figures
#: and every file it may write there: the run owns that folder while it holds only these.
CATALOG_FOLDER = "catalog"
CATALOG_FIGURES = ("frequency_magnitude", "ccdf", "recurrence", "moment_rate")
CATALOG_FILES = frozenset(
    {"catalog.parquet", "catalog.csv", "moment_rate.parquet", "moment_rate.csv", "catalog.json", "index.html"}
    | {f"{stem}.{fmt}" for stem in CATALOG_FIGURES for fmt in ("png", "pdf", "svg")}
)


def only_plot_files(folder: str | Path) -> bool:
    """Whether ``folder`` is a directory holding nothing but figures ``stickslip plot`` draws
    (:data:`PLOT_FILE`; and files of a killed write)."""
    folder = Path(folder)
    if not folder.is_dir():
        return False
    return all(PLOT_FILE.fullmatch(p.name) or is_temporary(p.name) for p in folder.iterdir())


def only_catalog_files(folder: str | Path) -> bool:
    """Whether ``folder`` is a directory holding nothing but what ``stickslip catalog`` writes
    (:data:`CATALOG_FILES`; and files of a killed write, the lock of one writing it)."""
    folder = Path(folder)
    if not folder.is_dir():
        return False
    return all(p.name in CATALOG_FILES or p.name in LOCK_FILES or is_temporary(p.name) for p in folder.iterdir())


#: The files and folders a chain run writes into its run directory.
OWN_FILES = frozenset({*RUN_FILES, "checkpoint", RUN_ID_FILE, *LOCK_FILES})


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
def run_dir_for_run(
    out_dir: str | Path | None, run_id: str | None = None, *, overwrite: bool = False
) -> Iterator[str | None]:
    """The run directory of ``run_chain(out_dir=...)``, owned as ``stickslip chain --out`` owns it:
    a folder holding files a chain run does not write, or a run already (finished, or with a
    checkpoint to resume), is refused with ParameterError before anything is written; the folder
    is locked for the run (a second writer gets :class:`RunDirBusy`, naming the holder) and gets
    a run id, which is yielded. A folder this process already holds (the command's) or that its
    caller owns (:func:`owned_by_caller`) is taken as it is, with ``run_id``. With ``overwrite``
    (``--overwrite``), a run's own files there are removed first and other files stay."""
    from stickslip.models.params import ParameterError

    if out_dir is not None and not str(out_dir).strip():
        raise ParameterError("out_dir must name a directory (got '')")
    if out_dir is None or os.path.realpath(out_dir) in _HELD:
        yield run_id
        return
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise ParameterError(f"out_dir {out} is not a directory")
    if out.is_dir() and not overwrite:
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
            raise ParameterError(f"{out} already holds a finished run; choose another out_dir or overwrite=True")
    with owned_run_dir(out, new_id=not overwrite) as rid:
        if overwrite:
            from stickslip.io import write_bytes

            remove_own_files(out)
            rid = uuid.uuid4().hex
            write_bytes(out / RUN_ID_FILE, (rid + "\n").encode())
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
        for stale in run_dir.glob(".*.tmp"):  # left by a write that was killed (a file, or a staging folder)
            with contextlib.suppress(OSError):
                if stale.is_dir() and not stale.is_symlink():
                    shutil.rmtree(stale)
                else:
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
    resumable = (run_dir / "checkpoint" / "state.npz").is_file()  # the Checkpointer's state file
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
