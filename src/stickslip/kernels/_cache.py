"""The on-disk cache of the kernels, kept fresh across their modules, and a word when they compile.

numba stamps a cached function with its own source file only, so a kernel that inlines or
calls functions of another module is loaded stale after that module changes (a documented
numba limitation). The kernels of the chain span several modules (and inline the friction laws
of :mod:`stickslip.models.friction`), so every kernel is cached in a directory named after a
digest of all of them and of the model modules, given to numba through its documented cache
setting (``NUMBA_CACHE_DIR``, :data:`numba.config.CACHE_DIR`), set when this package is imported:
an edit to any kernel module leads to a new directory, and every kernel is compiled afresh. A
user's ``NUMBA_CACHE_DIR`` is kept as the place of these directories. (Other numba functions with
``cache=True`` decorated later in the same process are cached under the same directory, each with
numba's own stamp of its source file.)

numba announces each compilation (not a load from the cache) through its event API
(:mod:`numba.core.event`, ``"numba:compile"``); the first one of a kernel in a process writes one
line on stderr, so that the first run of a model does not sit silent for half a minute.
"""

from __future__ import annotations

import hashlib
import os
import sys
import threading
from pathlib import Path

import numba
from numba.core import event

_DIR = Path(__file__).resolve().parent

#: What the first compilation in a process says (stderr).
COMPILE_NOTICE = (
    "stickslip: compiling the numba kernels of this model (once per model and version of the "
    "kernels; usually 10-40 s, a few minutes on a busy machine; `stickslip compile` does it ahead of time)"
)


def modules_digest(paths) -> str:
    """SHA-256 over the names and contents of the given source files, in name order."""
    h = hashlib.sha256()
    for p in sorted(Path(p) for p in paths):
        h.update(p.name.encode())
        h.update(b"\0")
        h.update(p.read_bytes())
        h.update(b"\0")
    return h.hexdigest()


#: The kernels inline the friction laws' compiled functions from their own modules
#: (:mod:`stickslip.models.friction`), so those modules are part of the digest too.
DIGEST = modules_digest([*_DIR.glob("*.py"), *(_DIR.parent / "models").rglob("*.py")])


def _writable(path: Path) -> bool:
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError:
        return False
    return os.access(path, os.W_OK | os.X_OK)


def cache_dir() -> Path:
    """The directory of this version of the kernels: ``stickslip-<digest>`` under the user's
    ``NUMBA_CACHE_DIR`` if set, else under the kernels' own ``__pycache__`` (or, where that is
    read-only, under ``~/.cache/stickslip-numba``)."""
    name = f"stickslip-{DIGEST[:20]}"
    user = os.environ.get("NUMBA_CACHE_DIR", "").strip()
    if user:
        return Path(user).expanduser() / name
    for base in (_DIR / "__pycache__", Path.home() / ".cache" / "stickslip-numba"):
        if _writable(base):
            return base / name
    return _DIR / "__pycache__" / name  # nothing writable: numba then caches nothing and says so


def use_cache_dir() -> Path:
    """Point numba's cache setting at :func:`cache_dir`, so that the kernels decorated from now on
    (``cache=True``) are cached there; numba picks a function's cache directory when it is
    decorated."""
    path = cache_dir()
    numba.config.CACHE_DIR = str(path)
    return path


class _CompileNotice(event.Listener):
    """Writes :data:`COMPILE_NOTICE` once, at the first compilation of a kernel of this package."""

    def __init__(self):
        self.said = False
        self.lock = threading.Lock()

    def on_start(self, ev):
        if self.said:
            return
        dispatcher = (ev.data or {}).get("dispatcher")
        module = getattr(getattr(dispatcher, "py_func", None), "__module__", "") or ""
        if not module.startswith(__name__.rpartition(".")[0]):
            return
        with self.lock:
            if not self.said:
                self.said = True
                sys.stderr.write(COMPILE_NOTICE + "\n")
                sys.stderr.flush()

    def on_end(self, ev):
        pass


NOTICE = _CompileNotice()


def install() -> None:
    """Cache the kernels in :func:`cache_dir` and listen for their compilations (once per process)."""
    if not getattr(install, "done", False):
        use_cache_dir()
        event.register("numba:compile", NOTICE)
        install.done = True
