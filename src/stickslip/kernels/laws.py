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
  variable (otherwise the kernels skip theta);
* ``PIECE.context``: what ``rate`` reads besides the block's own values, ``("stress_rate",)``
  for a law that reads the rate of the elastic force on the block (the Nagata law): its ``rate``
  is then ``rate(thl, th, thr, v, lp, ctx)`` with ``ctx`` a :class:`RateContext`, which
  :func:`_dtheta_in` builds from the velocities, their ghost cells (:func:`set_velocity_ghosts`)
  and the drive's velocity (:func:`load_rate`) and the drive's ``force_rate``. For every other
  law these compile to nothing and :func:`_dtheta_in` is :func:`_dtheta`: a compile-time
  specialisation, so their kernels are as before. The dense and exact chain integrators build
  it; the located integrator and the lattices do not, and refuse such a law before compiling.

So a new law needs no edit here or in any integrator.
"""

from __future__ import annotations

import importlib
from collections import namedtuple

import numpy as np
from numba import njit, types
from numba.extending import intrinsic, overload

from stickslip.kernels import lanes


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
    if law.PIECE.context:
        raise TypeError(f"{law.__name__}.rate reads {law.PIECE.context}: a kernel calls it through _dtheta_in")
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


def at(params, i):
    """A piece's parameters (its module's ``Params``) at block ``i``: each field that is an array
    over the blocks (per-block parameters, docs/model.md "Per-block parameters") read at ``i``,
    each float as it is; ``params`` itself when every field is a float (a uniform chain's code
    is then the code without this function). ``i`` is a block index, or ``(i, n)``: blocks
    i..i+n-1 as 8 lanes (:mod:`stickslip.kernels.lanes`)."""
    return params


def _is_array(ty) -> bool:
    return isinstance(ty, types.Array)


def _is_per_block(ty) -> bool:
    """A field over the blocks (1-D); a table (a load history's breakpoints, 2-D) is not gathered."""
    return isinstance(ty, types.Array) and ty.ndim == 1


@overload(at)
def _at(params, i):
    if not isinstance(params, types.BaseNamedTuple):
        return None
    if not any(_is_per_block(t) for t in params.types):
        return lambda params, i: params
    group = isinstance(i, types.BaseTuple)
    fields = []
    for name, ty in zip(params.fields, params.types, strict=True):
        if not _is_per_block(ty):
            fields.append(f"params.{name}")
        elif group:
            fields.append(f"_load(params.{name}.ctypes.data, i[0], i[1])")
        else:
            fields.append(f"params.{name}[i]")
    # The piece's own named tuple, built with the gathered fields (numba builds a named tuple
    # from its class).
    source = f"def impl(params, i):\n    return _cls({', '.join(fields)})\n"
    scope = {"_cls": params.instance_class, "_load": lanes.load}
    exec(source, scope)
    return scope["impl"]


def _springs(xl, xc, xr, K, dp, p, drive, i):
    """The drive's force on block i with the springs K: one K for every spring, or K per bond."""


@overload(_springs, prefer_literal=True)
def _springs_impl(xl, xc, xr, K, dp, p, drive, i):
    if isinstance(K, types.Float):

        def uniform(xl, xc, xr, K, dp, p, drive, i):
            return call(drive, "force", xl, xc, xr, K, p, dp)

        return uniform
    if not _is_array(K):
        return None
    if isinstance(i, types.BaseTuple):

        def bonds8(xl, xc, xr, K, dp, p, drive, i):
            kl = lanes.load(K.ctypes.data, i[0], i[1])
            kr = lanes.load(K.ctypes.data, i[0] + np.uint64(1), i[1])
            return (kl * (xl - xc) - kr * (xc - xr)) + call(drive, "force", xl, xc, xr, 0.0, p, dp)

        return bonds8

    if isinstance(i, types.Integer) and not i.signed:

        def bonds_u(xl, xc, xr, K, dp, p, drive, i):
            return (K[i] * (xl - xc) - K[i + np.uint64(1)] * (xc - xr)) + call(drive, "force", xl, xc, xr, 0.0, p, dp)

        return bonds_u

    def bonds(xl, xc, xr, K, dp, p, drive, i):
        return (K[i] * (xl - xc) - K[i + 1] * (xc - xr)) + call(drive, "force", xl, xc, xr, 0.0, p, dp)

    return bonds


def per_mass(a, M, i):
    """(force - friction) / M_i: ``a`` itself for unit mass (``M`` None), else divided by the
    mass M (a float) or M_i (an array over the blocks)."""
    return a


@overload(per_mass)
def _per_mass(a, M, i):
    if isinstance(M, types.NoneType):
        return lambda a, M, i: a
    if isinstance(M, types.Float):
        return lambda a, M, i: a / M
    if not _is_array(M):
        return None
    if isinstance(i, types.BaseTuple):
        return lambda a, M, i: a / lanes.load(M.ctypes.data, i[0], i[1])
    return lambda a, M, i: a / M[i]


@njit(cache=True, inline="always")
def _force(xl, xc, xr, K, dp, p, drive, i):
    """Spring force on block i: the drive's ``force``, K (x_{i+1} - 2 x_i + x_{i-1}) (eq. 4), plus
    Kp (V t - x_i) from the plate at p = V t with the plate drive (Burridge-Knopoff,
    Carlson-Langer); ``dp`` the drive's parameters. With springs per bond (K an array, K[i] the
    spring between blocks i-1 and i): K_i (x_{i-1} - x_i) - K_{i+1} (x_i - x_{i+1}) plus the
    drive's force with K = 0 (docs/model.md, "Per-block parameters")."""
    return _springs(xl, xc, xr, K, at(dp, i), p, drive, i)


@njit(cache=True, inline="always")
def _accel(f, th, v, m, mp, friction, i):
    """dv/dt of block i times the moving mask m (1.0 moving, 0.0 stopped): m (f - friction) with
    the law's own ``accel``, divided by the block's mass where the chain has one; ``mp`` = (K, the
    drive's, the threshold's and the law's parameters, the masses)."""
    return m * per_mass(law_accel(friction, f, v, th, at(mp[3], i)), mp[4], i)


@njit(cache=True, inline="always")
def _dtheta(thl, th, thr, v, mp, friction, i):
    """dtheta/dt of the law (its ``rate``) at block i, for moving and stopped blocks alike; 0 for
    laws without a state variable."""
    return law_rate(friction, thl, th, thr, v, at(mp[3], i))


#: What the kernels pass a law whose ``PIECE.context`` asks for it, as ``rate``'s last argument:
#: ``stress_rate``, the rate of the elastic force on the block (:func:`_dtheta_in`).
RateContext = namedtuple("RateContext", ["stress_rate"])


def reads_context(friction) -> bool | None:
    """Whether the law ``friction`` (a literal module path) reads a :class:`RateContext`; None
    while it is not a literal."""
    law = _module(friction)
    return None if law is None else bool(law.PIECE.context)


def _springs_rate(vl, vc, vr, K, dp, q, drive, i):
    """d/dt of :func:`_springs` at the velocities vl, vc, vr and the drive's velocity q: the
    drive's ``force_rate``, with one K or K per bond as :func:`_springs` reads them."""


@overload(_springs_rate, prefer_literal=True)
def _springs_rate_impl(vl, vc, vr, K, dp, q, drive, i):
    if isinstance(K, types.Float):
        return lambda vl, vc, vr, K, dp, q, drive, i: call(drive, "force_rate", vl, vc, vr, K, q, dp)
    if not _is_array(K) or not isinstance(i, types.Integer):
        return None
    one = np.uint64(1) if not i.signed else 1

    def bonds(vl, vc, vr, K, dp, q, drive, i):
        return (K[i] * (vl - vc) - K[i + one] * (vc - vr)) + call(drive, "force_rate", vl, vc, vr, 0.0, q, dp)

    return bonds


def _dtheta_in(thl, th, thr, v, vel, q, mp, drive, friction, i):
    """dtheta/dt of the law at block i (its ``rate``) with the context it reads: for a law whose
    ``PIECE.context`` is empty, :func:`_dtheta` on the block's velocity v, and ``vel`` and ``q``
    unread (the code of :func:`_dtheta`, so those laws keep their bits and instructions); for a
    law that reads the stress rate, the rate of the elastic force on block i,

        K (vel_{i-1} - 2 vel_i + vel_{i+1}) [+ Kp (q - vel_i) with the plate, + r with a ramp],

    the drive's ``force_rate`` at the velocities ``vel`` (v or the predictor vs, ghost cells from
    :func:`set_velocity_ghosts`) and the drive's velocity q (:func:`load_rate`), passed as a
    :class:`RateContext`. ``i`` is a block index (signed or not; no lanes)."""


@overload(_dtheta_in, prefer_literal=True)
def _dtheta_in_impl(thl, th, thr, v, vel, q, mp, drive, friction, i):
    ctx = reads_context(friction)
    if ctx is None:
        return None
    if not ctx:
        return lambda thl, th, thr, v, vel, q, mp, drive, friction, i: _dtheta(thl, th, thr, v, mp, friction, i)
    if not isinstance(i, types.Integer):
        return None
    fn = _module(friction).rate
    one = np.uint64(1) if not i.signed else 1

    def with_context(thl, th, thr, v, vel, q, mp, drive, friction, i):
        sr = _springs_rate(vel[i - one], vel[i], vel[i + one], mp[0], at(mp[1], i), q, drive, i)
        return fn(thl, th, thr, v, at(mp[3], i), RateContext(sr))

    return with_context


def load_rate(V, n, dt, dp, drive, carry, friction):
    """The drive's velocity at step n, where the law ``friction`` reads the stress rate: the
    drive's ``pull_rate_from`` where it has one (a load history's dp/dt, from the carry's interval,
    :func:`pull_carried`), else the kernels' V; 0.0 for every other law (compiled away)."""
    return 0.0


@overload(load_rate, prefer_literal=True)
def _load_rate(V, n, dt, dp, drive, carry, friction):
    ctx, mod = reads_context(friction), _module(drive)
    if ctx is None or mod is None:
        return None
    if not ctx:
        return lambda V, n, dt, dp, drive, carry, friction: 0.0
    if hasattr(mod, "pull_rate_from"):
        if hasattr(mod, "NUMBA_EXTENSIONS"):
            importlib.import_module(mod.NUMBA_EXTENSIONS)
        fn = mod.pull_rate_from
        return lambda V, n, dt, dp, drive, carry, friction: fn(n, dt, dp, carry[2])
    return lambda V, n, dt, dp, drive, carry, friction: V


def set_velocity_ghosts(v, N, q, drive, ends, friction):
    """Ghost cells 0 and N + 1 of the velocities ``v`` (v or its predictor) as :func:`_set_ghosts`
    sets x's, at the drive's velocity q and a wall at rest, where the law ``friction`` reads the
    stress rate (:func:`_dtheta_in`); nothing for every other law (compiled away)."""


@overload(set_velocity_ghosts, prefer_literal=True)
def _set_velocity_ghosts(v, N, q, drive, ends, friction):
    ctx = reads_context(friction)
    if ctx is None:
        return None
    if not ctx:
        return lambda v, N, q, drive, ends, friction: None

    def ghosts(v, N, q, drive, ends, friction):
        v[0] = call(drive, "left", q, call(ends, "ghost", v[1], v[N], 0.0))
        v[N + 1] = call(ends, "ghost", v[N], v[1], 0.0)

    return ghosts


@njit(cache=True, inline="always")
def _threshold(th, tp, threshold, i):
    """Static threshold of the start rule at block i: the threshold piece's ``value`` (Fs, or
    theta_i), its parameters ``tp``."""
    return call(threshold, "value", th, at(tp, i))


def pull_point(V, n, dt, dp, drive):
    """The drive's load point at step n: its module's ``pull(n, dt, dp)`` where it has one (a load
    history), else V t_n = V * (n dt)."""
    mod = importlib.import_module(drive)
    if hasattr(mod, "pull"):
        return mod.pull(n, dt, dp)
    return V * (np.float64(n) * dt)


@overload(pull_point, prefer_literal=True)
def _pull_point(V, n, dt, dp, drive):
    mod = _module(drive)
    if mod is None:
        return None
    if hasattr(mod, "pull"):
        fn = mod.pull
        return lambda V, n, dt, dp, drive: fn(n, dt, dp)
    # Every constant-velocity drive: today's expression, so their runs keep their bits.
    return lambda V, n, dt, dp, drive: V * (np.float64(n) * dt)


@njit(cache=True, inline="always")
def _pull(V, n, dt, dp, drive):
    """Pulling point (or plate) at t_n = n dt from the integer step count (docs/model.md): V t_n
    = V * (n dt) for the drives at a constant velocity, the drive's own ``pull`` for a load
    history (:mod:`stickslip.models.drive.history`), chosen when the kernel is compiled."""
    return pull_point(V, n, dt, dp, drive)


def drive_view(dp, drive):
    """The drive's parameters as a kernel's step loop carries them: the drive's own
    ``kernel_view(dp)`` where it has one (a load history's table as an address, so that the loop
    counts no references to an array: :func:`stickslip.models.drive.history.kernel_view`), else
    ``dp`` itself (compiled away)."""
    mod = importlib.import_module(drive)
    return mod.kernel_view(dp) if hasattr(mod, "kernel_view") else dp


@overload(drive_view, prefer_literal=True)
def _drive_view(dp, drive):
    mod = _module(drive)
    if mod is None:
        return None
    if hasattr(mod, "kernel_view"):
        if hasattr(mod, "NUMBA_EXTENSIONS"):  # kernel_view's compiled form (stickslip.models.piece)
            importlib.import_module(mod.NUMBA_EXTENSIONS)
        fn = mod.kernel_view
        return lambda dp, drive: fn(dp)
    return lambda dp, drive: dp


#: The carry of :func:`pull_carried` before a kernel's first step: no step read, no interval.
NO_CARRY = (np.int64(-1), 0.0, np.int64(-1))


def pull_carried(V, n, dt, dp, drive, carry):
    """(the load point at step n as :func:`_pull` gives it, the carry): for a load history, the
    value of the step the carry holds if it is n (a step's end is the next step's start), else the
    drive's ``pull_from`` from the carry's interval, O(1) as the steps go forward; the carry is
    (step, value, interval), :data:`NO_CARRY` at first. For the drives at a constant velocity V *
    (n dt) and the carry as it was (compiled away): today's code."""
    mod = importlib.import_module(drive)
    if hasattr(mod, "pull_from"):
        if n == carry[0]:
            return carry[1], carry
        p, k = mod.pull_from(n, dt, dp, carry[2])
        return p, (n, p, k)
    return V * (np.float64(n) * dt), carry


@overload(pull_carried, prefer_literal=True)
def _pull_carried(V, n, dt, dp, drive, carry):
    mod = _module(drive)
    if mod is None:
        return None
    if hasattr(mod, "pull_from"):
        fn = mod.pull_from

        def carried(V, n, dt, dp, drive, carry):
            if n == carry[0]:
                return carry[1], carry
            p, k = fn(n, dt, dp, carry[2])
            return p, (np.int64(n), p, k)

        return carried
    return lambda V, n, dt, dp, drive, carry: (V * (np.float64(n) * dt), carry)


def pull_peek(V, n, dt, dp, drive, carry):
    """The load point at step n as :func:`pull_carried` gives it, the carry left as it is (a read
    outside the step's own two)."""
    return pull_carried(V, n, dt, dp, drive, carry)[0]


@overload(pull_peek, prefer_literal=True)
def _pull_peek(V, n, dt, dp, drive, carry):
    mod = _module(drive)
    if mod is None:
        return None
    if hasattr(mod, "pull_from"):
        fn = mod.pull_from

        def peek(V, n, dt, dp, drive, carry):
            if n == carry[0]:
                return carry[1]
            return fn(n, dt, dp, carry[2])[0]

        return peek
    return lambda V, n, dt, dp, drive, carry: V * (np.float64(n) * dt)


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


def load_point(t, dp, drive):
    """The load point in the located integrator's frame at any time t (:mod:`stickslip.kernels.located`):
    the drive's own ``load(t, dp)`` where it has one (a load history, whose frame is the lab's,
    :mod:`stickslip.models.drive.history`), else 0 (the drive's own frame, u = x - V t)."""
    mod = importlib.import_module(drive)
    if hasattr(mod, "load"):
        return mod.load(t, dp)
    return 0.0


@overload(load_point, prefer_literal=True)
def _load_point(t, dp, drive):
    mod = _module(drive)
    if mod is None:
        return None
    if hasattr(mod, "load"):
        fn = mod.load
        return lambda t, dp, drive: fn(t, dp)
    # Every constant-velocity drive: the constant 0.0 of today's ghost cell, so its bits stay.
    return lambda t, dp, drive: 0.0
