"""Numba kernels: the single block (:mod:`.block`) and the chain, whose kernels span several
modules (:mod:`.common` shared pieces, :mod:`.chain` reference and exact integrators and entry
points, :mod:`.plate` sparse exact steps of the plate drive).

numba's on-disk cache (``cache=True``) does not notice edits in another module that a cached
kernel calls (a numba limitation): after editing any of these modules, clear the cache
directory (``NUMBA_CACHE_DIR``, or the ``__pycache__`` folders beside them).
"""
