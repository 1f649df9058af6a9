"""One compiled entry point of a chain kernel (:func:`stickslip.kernels.dense.run_dense`,
:func:`stickslip.kernels.exact.run_exact` or :func:`stickslip.kernels.plate.run_sparse`) per
model: the model's pieces (docs/model.md, "The family the paper stands in"; codes in
:mod:`stickslip.kernels.layout`) are handed on as literal constants, so each composition is its
own machine code, compiled without the other pieces' code (:mod:`stickslip.kernels.pipeline`).
"""

from __future__ import annotations


def specialise(kernel, args, pieces):
    """The compiled entry point of a chain kernel for one model's pieces.

    ``args`` is an example of the kernel's :class:`~stickslip.kernels.layout.ChainArgs` (arrays
    and integers) and ``pieces`` the codes (drive, friction, threshold, ends). Each composition
    is compiled once, with the pieces as literal constants (so branches on them vanish before
    typing), and cached on disk; calling the returned entry point skips the dispatcher's
    type matching.
    """
    from numba import typeof, types

    sig = (typeof(args),) + tuple(types.literal(int(c)) for c in pieces)
    key = (kernel.py_func.__name__, sig)
    entry = _ENTRIES.get(key)
    if entry is None:
        entry = kernel.compile(sig)
        _ENTRIES[key] = entry
    return entry


_ENTRIES: dict = {}
