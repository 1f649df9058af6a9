"""The compiled forms of :func:`~stickslip.models.drive.history.entry`,
:func:`~stickslip.models.drive.history.columns` and
:func:`~stickslip.models.drive.history.kernel_view` (the load history's table read in place as an
address in the chain's kernels), registered with numba when the history's functions or a kernel
that reads them are compiled (:data:`stickslip.models.drive.history.NUMBA_EXTENSIONS`), so that
importing the piece does not load numba."""

from __future__ import annotations

import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic, overload

from stickslip.models.drive.history import Params, columns, entry, kernel_view


@intrinsic
def _read(typingctx, address, i):
    """The float64 at ``address`` + 8 i (the table's memory, which the caller keeps alive)."""
    if not (isinstance(address, types.Integer) and isinstance(i, types.Integer)):
        return None

    def codegen(context, builder, signature, args):
        ptr = builder.inttoptr(args[0], ir.DoubleType().as_pointer())
        return builder.load(builder.gep(ptr, [args[1]]))

    return types.float64(address, i), codegen


@overload(entry, inline="always")
def _entry(table, r, k):
    if isinstance(table, types.Array):
        return lambda table, r, k: table[r, k]
    if isinstance(table, types.BaseTuple):
        return lambda table, r, k: _read(table[0], r * table[1] + k)
    return None


@overload(columns, inline="always")
def _columns(table):
    if isinstance(table, types.Array):
        return lambda table: table.shape[1]
    if isinstance(table, types.BaseTuple):
        return lambda table: table[1]
    return None


@overload(kernel_view, inline="always")
def _kernel_view(dp):
    table = dp.types[0] if isinstance(dp, types.BaseNamedTuple) else None
    if isinstance(table, types.Array) and table.ndim == 2 and table.layout == "C" and table.dtype == types.float64:
        return lambda dp: Params((dp.table.ctypes.data, np.int64(dp.table.shape[1])))
    return lambda dp: dp
