"""The expressions of one Heun step of the chain (eq. 4 and its relatives, docs/model.md):
spring force, acceleration under each friction, the state variable's rate, the start
threshold, the drive's position and the ghost cells.

One Heun step from t_n = n dt to t_{n+1} (docs/model.md):

1. start rule: a stopped block with f_i > threshold moves (with v = 0) for this step; ``mm``
   is this mid-step mask;
2. stage 1 at t_n: f_i = K ((x_{i-1} - x_i) - (x_i - x_{i+1})) [+ Kp (V t_n - x_i)],
   a_i = mm (f_i - friction), b_i = dtheta_i/dt; predictor xs = x + dt v, vs = v + dt a,
   ths = th + dt b;
3. stage 2 at t_{n+1} on the predictor, with the same mask; corrector
   x += dt/2 (v + vs), v += dt/2 (a + a2), th += dt/2 (b + b2);
4. stop rule: a moving block whose new v <= 0 gets v = 0 and stops.

Every integrator (:mod:`~stickslip.kernels.dense`, :mod:`~stickslip.kernels.exact`,
:mod:`~stickslip.kernels.plate`, :mod:`~stickslip.kernels.located`) evaluates each quantity
through these functions, inlined, so they agree bit for bit. Pieces and layout:
:mod:`stickslip.kernels.layout`.

A friction law is its own module (:mod:`stickslip.models.friction`), and a kernel is compiled for
one law: it receives the import path of the law's module as a literal string (``friction``) and
the law's parameters as the module's ``Params`` named tuple (``lp``). :func:`law_accel`,
:func:`law_rate` resolve, when the kernel is compiled, to the module's compiled functions (numba's
:func:`~numba.extending.overload` on the literal), inlined there:

* ``accel(f, v, th, lp)``: the force f on a moving block less the law's friction, in the law's
  own order of operations (it fixes the bits);
* ``rate(thl, th, thr, v, lp)``: dtheta/dt of the block between thl and thr, moving or stopped
  (0.0 for a law without a state variable);
* ``PIECE.has_state``, read as ``has(friction, "has_state")``: whether the law has a state
  variable (otherwise the kernels skip theta).

So a new law needs no edit here or in any integrator.
"""

from __future__ import annotations

import importlib

import numpy as np
from numba import njit, types
from numba.extending import intrinsic, overload


def _module(piece):
    """The module of a piece, from the literal a kernel is compiled for (None otherwise)."""
    if isinstance(piece, types.StringLiteral):
        return importlib.import_module(piece.literal_value)
    if isinstance(piece, str):
        return importlib.import_module(piece)
    return None


def law_accel(friction, f, v, th, lp):
    """The force f on a moving block less the friction of the law ``friction`` (its module's
    ``accel``)."""
    return _module(friction).accel(f, v, th, lp)


def law_rate(friction, thl, th, thr, v, lp):
    """dtheta/dt of the law ``friction`` (its module's ``rate``)."""
    return _module(friction).rate(thl, th, thr, v, lp)


@overload(law_accel, prefer_literal=True)
def _law_accel(friction, f, v, th, lp):
    law = _module(friction)
    if law is None:
        return None
    fn = law.accel

    def impl(friction, f, v, th, lp):
        return fn(f, v, th, lp)

    return impl


@overload(law_rate, prefer_literal=True)
def _law_rate(friction, thl, th, thr, v, lp):
    law = _module(friction)
    if law is None:
        return None
    fn = law.rate

    def impl(friction, thl, th, thr, v, lp):
        return fn(thl, th, thr, v, lp)

    return impl


def call(piece, name, *args):
    """The compiled function ``name`` of the piece whose module is ``piece`` (a literal import
    path), called with ``args``: resolved when the kernel is compiled, so no other piece's code
    is typed."""
    return getattr(importlib.import_module(piece), name)(*args)


# ``call``'s compiled form per number of arguments (numba inlines the pieces' functions, which
# it cannot do for a call with ``*args``).
_CALLS = {
    1: lambda fn: lambda piece, name, *args: fn(args[0]),
    2: lambda fn: lambda piece, name, *args: fn(args[0], args[1]),
    3: lambda fn: lambda piece, name, *args: fn(args[0], args[1], args[2]),
    4: lambda fn: lambda piece, name, *args: fn(args[0], args[1], args[2], args[3]),
    5: lambda fn: lambda piece, name, *args: fn(args[0], args[1], args[2], args[3], args[4]),
    6: lambda fn: lambda piece, name, *args: fn(args[0], args[1], args[2], args[3], args[4], args[5]),
    7: lambda fn: lambda piece, name, *args: fn(args[0], args[1], args[2], args[3], args[4], args[5], args[6]),
    8: lambda fn: lambda piece, name, *args: fn(args[0], args[1], args[2], args[3], args[4], args[5], args[6], args[7]),
}


@overload(call, prefer_literal=True)
def _call(piece, name, *args):
    mod = _module(piece)
    if mod is None or not isinstance(name, types.StringLiteral):
        return None
    return _CALLS[len(args)](getattr(mod, name.literal_value))


def piece_attr(piece, name):
    """The attribute ``name`` of the piece whose module is the literal ``piece``, when a kernel is
    typed (None for a piece that is not a literal): what an ``overload`` dispatches on."""
    mod = _module(piece)
    return None if mod is None else bool(getattr(mod.PIECE, name))


@intrinsic(prefer_literal=True)
def has(typingctx, piece, name):
    """The attribute ``name`` of the piece whose module is ``piece`` (``PIECE.has_state``,
    ``PIECE.ring``, ...), a constant in the compiled kernel (no function of its own to compile)."""
    value = piece_attr(piece, name.literal_value) if isinstance(name, types.StringLiteral) else None
    if value is None:
        return None

    def codegen(context, builder, signature, args):
        return context.get_constant(types.boolean, value)

    return types.boolean(piece, name), codegen


@njit(cache=True, inline="always")
def _force(xl, xc, xr, K, dp, p, drive):
    """Spring force on a block: the drive's ``force``, K (x_{i+1} - 2 x_i + x_{i-1}) (eq. 4), plus
    Kp (V t - x_i) from the plate at p = V t with the plate drive (Burridge-Knopoff,
    Carlson-Langer); ``dp`` the drive's parameters."""
    return call(drive, "force", xl, xc, xr, K, p, dp)


@njit(cache=True, inline="always")
def _accel(f, th, v, m, mp, friction):
    """dv/dt of a block times the moving mask m (1.0 moving, 0.0 stopped): m (f - friction) with
    the law's own ``accel``; ``mp`` = (K, the drive's, the threshold's and the law's parameters)."""
    return m * law_accel(friction, f, v, th, mp[3])


@njit(cache=True, inline="always")
def _dtheta(thl, th, thr, v, mp, friction):
    """dtheta/dt of the law (its ``rate``), for moving and stopped blocks alike; 0 for laws
    without a state variable."""
    return law_rate(friction, thl, th, thr, v, mp[3])


@njit(cache=True, inline="always")
def _threshold(th, tp, threshold):
    """Static threshold of the start rule: the threshold piece's ``value`` (Fs, or theta_i), its
    parameters ``tp``."""
    return call(threshold, "value", th, tp)


@njit(cache=True, inline="always")
def _pull(V, n, dt):
    """Pulling point (or plate) V t_n with t_n = n dt from the integer step count (docs/model.md)."""
    return V * (np.float64(n) * dt)


@njit(cache=True, inline="always")
def _set_ghosts(x, th, N, p, drive, ends):
    """Ghost cells 0 and N + 1 from the drive and the ends' ``ghost`` (a wall at x = 0; theta
    without flux)."""
    x[0] = call(drive, "left", p, call(ends, "ghost", x[1], x[N], 0.0))
    x[N + 1] = call(ends, "ghost", x[N], x[1], 0.0)
    th[0] = call(ends, "ghost", th[1], th[N], th[1])
    th[N + 1] = call(ends, "ghost", th[N], th[1], th[N])


@njit(cache=True, inline="always")
def _right_of_first(x, N, ends):
    """x_2 as block 1's force reads it (the ghost cell when N = 1; end drive)."""
    if N > 1:
        return x[2]
    return call(ends, "ghost", x[1], x[1], 0.0)
