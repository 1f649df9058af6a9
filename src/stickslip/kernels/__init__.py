"""Numba kernels of the chain (the single block of eq. (1) is its N = 1), whose kernels show their
parts: :mod:`~stickslip.kernels.layout` (arrays, pieces' codes, status codes),
:mod:`~stickslip.kernels.laws` (the step's expressions), :mod:`~stickslip.kernels.events`
(outputs and events), :mod:`~stickslip.kernels.triggers` (the drive's starts),
:mod:`~stickslip.kernels.dense` (the reference), :mod:`~stickslip.kernels.active` (which blocks
get which stage in a step, and the rules the fast paths share), :mod:`~stickslip.kernels.stages`
and :mod:`~stickslip.kernels.exact` (the fast interval path), :mod:`~stickslip.kernels.plate` (the
fast sparse path of the plate drive), :mod:`~stickslip.kernels.located` (Heun with switches
located inside the step, the flow's reference) with its fast form
:mod:`~stickslip.kernels.located_fast` and :mod:`~stickslip.kernels.located_lazy` (the same
bits), and :mod:`~stickslip.kernels.entry` (a compiled entry point per model).

numba's on-disk cache (``cache=True``) stamps a kernel with its own module only, and would load
a kernel compiled from an older version of a module it calls. :mod:`~stickslip.kernels._cache`
caches every kernel in a directory named after a digest of all the kernel modules, so an edit to
any of them recompiles them all, and says on stderr when kernels are being compiled.
"""

from stickslip.kernels import _cache

# numba picks a function's cache directory when the function is decorated, that is when its kernel
# module is imported, always after this package.
_cache.install()
