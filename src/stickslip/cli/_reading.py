"""Run directories a command reads and writes beside (``catalog``, ``plot``): the run's lock held
while it reads, and the command's files written whole or not at all."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable, Iterator
from pathlib import Path

from stickslip.cli._common import CommandError


@contextlib.contextmanager
def reading_run_dir(run_dir: str | Path) -> Iterator[None]:
    """Hold a run directory's lock while a command reads it and writes beside it (``catalog``,
    ``plot``), so that a run writing into it (``chain --resume``) and the reader exclude each
    other: the second one is refused at once, naming the holder. A folder that is not there is
    left to the command's own check; a read-only one, where no run can write, is read unlocked."""
    import errno

    from stickslip.run.rundir import RunDirBusy, owned_run_dir

    run_dir = Path(run_dir)
    if not run_dir.is_dir():
        yield
        return
    with contextlib.ExitStack() as stack:
        try:
            stack.enter_context(owned_run_dir(run_dir, run_id=False))
        except RunDirBusy as exc:
            raise CommandError(f"{exc} (it is being written: read it when the run has finished)") from None
        except OSError as exc:
            if exc.errno not in (errno.EACCES, errno.EPERM, errno.EROFS):
                raise
        yield


@contextlib.contextmanager
def staged_writes(out: Path, own: Callable[[str], bool]) -> Iterator[Path]:
    """A staging folder inside ``out`` (``.staging.XXXX.tmp``) for a command's files: when the
    block ends they replace ``out``'s (and the command's files that the new set lacks are
    removed), with SIGINT and SIGTERM held for those few renames, so that a stop leaves ``out``
    as it was or whole, never half written. A block that fails leaves ``out`` as it was; a
    staging folder left by a kill is removed when ``out`` is next locked."""
    import shutil
    import signal
    import tempfile

    stage = Path(tempfile.mkdtemp(prefix=".staging.", suffix=".tmp", dir=out))
    try:
        yield stage
        held = {signal.SIGINT, signal.SIGTERM}
        old = signal.pthread_sigmask(signal.SIG_BLOCK, held)
        try:
            new = {p.name for p in stage.iterdir()}
            for name in sorted(new):
                os.replace(stage / name, out / name)
            for path in out.iterdir():
                if path.is_file() and own(path.name) and path.name not in new:
                    path.unlink()
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)
    finally:
        shutil.rmtree(stage, ignore_errors=True)
