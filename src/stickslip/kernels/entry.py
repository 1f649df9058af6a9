"""One compiled entry point of a chain kernel (:func:`stickslip.kernels.dense.run_dense`,
:func:`stickslip.kernels.exact.run_exact` or :func:`stickslip.kernels.plate.run_sparse`) per
model: the model's pieces (docs/model.md, "The family the paper stands in"; the modules of
:mod:`stickslip.models`) are handed on as literal import paths, so each composition is its own
machine code, typed with its pieces' functions only (:mod:`stickslip.kernels.laws`).
"""

from __future__ import annotations


def specialise(kernel, args, pieces):
    """The compiled entry point of a chain kernel for one model's pieces.

    ``args`` is an example of the kernel's :class:`~stickslip.kernels.layout.ChainArgs` (arrays,
    integers and the pieces' parameters) and ``pieces`` what the kernel is compiled for (drive,
    friction, threshold, ends: their modules' import paths). Each composition is compiled once,
    with the pieces as literal constants (their functions are resolved from their modules), and
    cached on disk; calling the returned entry point skips the dispatcher's type matching.
    """
    from numba import typeof, types

    sig = (typeof(args),) + tuple(types.literal(c) for c in pieces)
    key = (kernel.py_func.__name__, sig)
    entry = _ENTRIES.get(key)
    if entry is None:
        entry = kernel.compile(sig)
        _ENTRIES[key] = entry
    return entry


def specialised(kernel, args, literal):
    """``kernel`` compiled for the types of ``args``, the positions in ``literal`` (the pieces) as
    literal constants: the located integrator's entry (:mod:`stickslip.kernels.located`), whose
    pieces sit among its arrays. Calling the result with arguments of the same types skips the
    typing of every argument (a few hundred microseconds a call)."""
    from numba import typeof, types

    sig = tuple(types.literal(a) if i in literal else typeof(a) for i, a in enumerate(args))
    key = (kernel.py_func.__name__, sig)
    entry = _ENTRIES.get(key)
    if entry is None:
        entry = kernel.compile(sig)
        _ENTRIES[key] = entry
    return entry


def specialise_call(kernel, args, literal):
    """:func:`specialised` ``kernel``, called with ``args``."""
    return specialised(kernel, args, literal)(*args)


_ENTRIES: dict = {}
