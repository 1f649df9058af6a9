"""Eight blocks at once: a numba type of 8 float64 lanes, so that the pieces' own compiled functions
(a friction law's ``accel`` and ``rate``, a drive's ``force``) run on 8 blocks in one call.

A piece whose functions use only ``+``, ``-``, ``*`` and ``/`` on their arguments and float
parameters says so (``PIECE.lanes``, :mod:`stickslip.models.piece`); the run stages of
:mod:`stickslip.kernels.stages` then load 8 neighbouring blocks into one value of
:data:`f64x8`, call the same functions on it and store the 8 results. Each lane is the IEEE
operation of the scalar expression, in the same order, so the bits are those of the scalar loop
(no contraction into fused multiply-adds: the operations carry no fast-math flags). The last
group of a run is loaded and stored under a mask of its n < 8 blocks (``llvm.masked.load``,
``llvm.masked.store``): nothing past the run is read or written, and no block is left to a
scalar remainder. Why not leave it to the compiler: on the development machine (AVX-512) its cost
model picks 256-bit vectors for the auto-vectorised loops, 8 blocks per iteration in two
vectors when the loop carries a reduction, and the rest one block at a time; the explicit
lanes compile to 512-bit vectors there and to two 256-bit ones on AVX2 (docs/performance.md,
"Eight blocks at once").
"""

from __future__ import annotations

import operator

from llvmlite import ir
from numba import types
from numba.extending import intrinsic, lower_builtin, models, register_model, type_callable

#: lanes per value
WIDTH = 8
_VT = ir.VectorType(ir.DoubleType(), WIDTH)
_MASK = ir.VectorType(ir.IntType(1), WIDTH)
_I64 = ir.IntType(64)
_I32 = ir.IntType(32)


class F64x8(types.Type):
    """8 float64 lanes (the numba type)."""

    def __init__(self) -> None:
        super().__init__(name="f64x8")


#: the type of 8 float64 lanes
f64x8 = F64x8()


@register_model(F64x8)
class _F64x8Model(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, _VT)


def _broadcast(builder, value, vector_type):
    undef = ir.Constant(vector_type, ir.Undefined)
    one = builder.insert_element(undef, value, ir.Constant(_I32, 0))
    return builder.shuffle_vector(one, undef, ir.Constant(ir.VectorType(_I32, WIDTH), [0] * WIDTH))


def _operand(builder, ty, value):
    return value if isinstance(ty, F64x8) else _broadcast(builder, value, _VT)


def _arithmetic(a, b) -> bool:
    """Lanes with lanes or with a float64 (a scalar is used in every lane)."""
    return (isinstance(a, F64x8) or isinstance(b, F64x8)) and all(
        isinstance(t, F64x8) or t == types.float64 for t in (a, b)
    )


def _register(op, instruction):
    """Type and lower ``op`` on lanes (with lanes or a float64) as the LLVM ``instruction`` on
    <8 x double>: no function of its own to compile per operator and operand types."""

    @type_callable(op)
    def _typing(context):
        def typer(a, b):
            return f64x8 if _arithmetic(a, b) else None

        return typer

    def _lower(context, builder, sig, args):
        x = _operand(builder, sig.args[0], args[0])
        y = _operand(builder, sig.args[1], args[1])
        return getattr(builder, instruction)(x, y)

    for a, b in ((F64x8, F64x8), (F64x8, types.float64), (types.float64, F64x8)):
        lower_builtin(op, a, b)(_lower)


for _op, _instruction in (
    (operator.add, "fadd"),
    (operator.sub, "fsub"),
    (operator.mul, "fmul"),
    (operator.truediv, "fdiv"),
):
    _register(_op, _instruction)


def _first(builder, n):
    """The mask of lanes 0..n-1."""
    index = ir.Constant(ir.VectorType(_I64, WIDTH), list(range(WIDTH)))
    return builder.icmp_unsigned("<", index, _broadcast(builder, n, ir.VectorType(_I64, WIDTH)))


def _address(context, builder, sig, args):
    """Pointer to element i of the float64 array at address ``base`` (both uint64)."""
    base = context.cast(builder, args[0], sig.args[0], types.uint64)
    i = context.cast(builder, args[1], sig.args[1], types.uint64)
    return builder.inttoptr(builder.add(base, builder.mul(i, ir.Constant(_I64, 8))), _VT.as_pointer())


def _declare(module, name, fnty):
    try:
        return module.get_global(name)
    except KeyError:
        return ir.Function(module, fnty, name)


@intrinsic
def load(typingctx, base, i, n):
    """Elements i..i+n-1 (n <= 8) of the float64 array whose data start at address ``base``
    (``a.ctypes.data``), as lanes 0..n-1; the other lanes are 0 and read nothing."""
    if not all(isinstance(t, types.Integer) for t in (base, i, n)):
        return None

    def codegen(context, builder, sig, args):
        ptr = _address(context, builder, sig, args)
        n_ = context.cast(builder, args[2], sig.args[2], types.uint64)
        fn = _declare(builder.module, "llvm.masked.load.v8f64.p0", ir.FunctionType(_VT, [ptr.type, _I32, _MASK, _VT]))
        return builder.call(fn, [ptr, ir.Constant(_I32, 8), _first(builder, n_), ir.Constant(_VT, [0.0] * WIDTH)])

    return f64x8(base, i, n), codegen


@intrinsic
def store(typingctx, base, i, n, value):
    """Lanes 0..n-1 of ``value`` into elements i..i+n-1 of the array at ``base`` (nothing else
    written); a float64 ``value`` goes to each of them."""
    if not all(isinstance(t, types.Integer) for t in (base, i, n)) or not (
        isinstance(value, F64x8) or value == types.float64
    ):
        return None

    def codegen(context, builder, sig, args):
        ptr = _address(context, builder, sig, args)
        n_ = context.cast(builder, args[2], sig.args[2], types.uint64)
        fn = _declare(
            builder.module, "llvm.masked.store.v8f64.p0", ir.FunctionType(ir.VoidType(), [_VT, ptr.type, _I32, _MASK])
        )
        lanes = _operand(builder, sig.args[3], args[3])
        builder.call(fn, [lanes, ptr, ir.Constant(_I32, 8), _first(builder, n_)])
        return context.get_dummy_value()

    return types.none(base, i, n, value), codegen


@intrinsic
def any_not_positive(typingctx, value, n):
    """Whether one of lanes 0..n-1 is not > 0 (<= 0 or NaN): the stop rule's test."""
    if not isinstance(value, F64x8) or not isinstance(n, types.Integer):
        return None

    def codegen(context, builder, sig, args):
        n_ = context.cast(builder, args[1], sig.args[1], types.uint64)
        test = builder.fcmp_unordered("<=", args[0], ir.Constant(_VT, [0.0] * WIDTH))
        bits = builder.bitcast(builder.and_(test, _first(builder, n_)), ir.IntType(WIDTH))
        return builder.icmp_unsigned("!=", bits, ir.Constant(ir.IntType(WIDTH), 0))

    return types.boolean(value, n), codegen


@intrinsic
def changed(typingctx, new, old, n):
    """Bit k set where lane k < n of ``new`` differs from ``old`` (!=, so NaN counts as changed):
    the change tracking of the state-variable stages."""
    if not (isinstance(new, F64x8) and isinstance(old, F64x8) and isinstance(n, types.Integer)):
        return None

    def codegen(context, builder, sig, args):
        n_ = context.cast(builder, args[2], sig.args[2], types.uint64)
        test = builder.fcmp_unordered("!=", args[0], args[1])
        bits = builder.bitcast(builder.and_(test, _first(builder, n_)), ir.IntType(WIDTH))
        return builder.zext(bits, _I64)

    return types.int64(new, old, n), codegen


def _count_zeros(name):
    @intrinsic
    def count(typingctx, bits):
        if not isinstance(bits, types.Integer):
            return None

        def codegen(context, builder, sig, args):
            value = context.cast(builder, args[0], sig.args[0], types.int64)
            fn = _declare(builder.module, f"llvm.{name}.i64", ir.FunctionType(_I64, [_I64, ir.IntType(1)]))
            return builder.call(fn, [value, ir.Constant(ir.IntType(1), 0)])

        return types.int64(bits), codegen

    return count


#: trailing zeros of a non-zero int64 (the lowest lane in a mask of :func:`changed`)
lowest = _count_zeros("cttz")
#: leading zeros of a non-zero int64 (63 less the highest lane)
leading_zeros = _count_zeros("ctlz")
