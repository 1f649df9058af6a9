"""Numba kernels: the single block (:mod:`~stickslip.kernels.block`) and the chain, whose kernels
span several modules (:mod:`~stickslip.kernels.common` shared pieces, :mod:`~stickslip.kernels.chain`
reference and exact integrators and entry points, :mod:`~stickslip.kernels.plate` sparse exact steps
of the plate drive).

numba's on-disk cache (``cache=True``) stamps a kernel with its own module only, and would load
a kernel compiled from an older version of a module it calls. :mod:`~stickslip.kernels._cache`
caches every kernel in a directory named after a digest of all the kernel modules, so an edit to
any of them recompiles them all, and says on stderr when kernels are being compiled.
"""

from stickslip.kernels import _cache

# numba picks a function's cache directory when the function is decorated, that is when its kernel
# module is imported, always after this package.
_cache.install()
