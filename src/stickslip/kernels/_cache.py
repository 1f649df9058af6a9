"""The on-disk cache of the kernels, kept fresh across their modules.

numba stamps a cached function with its own source file only, so a kernel that inlines or
calls functions of another module is loaded stale after that module changes (a documented
numba limitation). The kernels of the chain span several modules, so here every kernel's
stamp is a digest of all of them: an edit to any kernel module recompiles every kernel.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

from numba.core import caching

_DIR = Path(__file__).resolve().parent
_IMPL = getattr(caching, "CacheImpl", None) or getattr(caching, "_CacheImpl", None)


def modules_digest(paths) -> str:
    """SHA-256 over the names and contents of the given source files, in name order."""
    h = hashlib.sha256()
    for p in sorted(Path(p) for p in paths):
        h.update(p.name.encode())
        h.update(b"\0")
        h.update(p.read_bytes())
        h.update(b"\0")
    return h.hexdigest()


_DIGEST = modules_digest(_DIR.glob("*.py"))


class KernelsLocator(caching._CacheLocator):
    """numba's own locator for a function of this package (same cache folder and name), with
    a source stamp that covers every kernel module, its own included."""

    def __init__(self, inner):
        self._inner = inner

    def ensure_cache_path(self):
        self._inner.ensure_cache_path()

    def get_cache_path(self):
        return self._inner.get_cache_path()

    def get_source_stamp(self):
        return _DIGEST

    def get_disambiguator(self):
        return self._inner.get_disambiguator()

    @classmethod
    def from_function(cls, py_func, py_file):
        if Path(py_file).resolve().parent != _DIR:
            return None
        for other in _IMPL._locator_classes:
            if other is not cls:
                inner = other.from_function(py_func, py_file)
                if inner is not None:
                    return cls(inner)
        return None


def install() -> bool:
    """Put :class:`KernelsLocator` first among numba's locators (once); False where this numba
    has no such hook, and its own per-file stamps apply."""
    if _IMPL is None or not hasattr(_IMPL, "_locator_classes"):
        return False
    if KernelsLocator not in _IMPL._locator_classes:
        _IMPL._locator_classes.insert(0, KernelsLocator)
    return True
