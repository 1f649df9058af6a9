"""A load history: the pulling point x_0 = p(t_n) of eq. (4), joined to block 1 by the spring K,
moved along a continuous, piecewise-linear p(t) (velocity steps, holds at V = 0, tables; a
:class:`stickslip.lab.LoadHistory`) instead of V t.

The history is the parameter ``history`` of :class:`~stickslip.models.params.ChainParams`: an
object with ``times`` (increasing breakpoints t_0 < ... < t_m) and ``positions`` (p_0, ..., p_m),
a ``LoadHistory`` or a pair of arrays. The kernels receive it as one table (``Params.table``, a
3 x (m + 1) array: the breakpoints, the positions and the velocities V_k = (p_k+1 - p_k) /
(t_k+1 - t_k) of the intervals), which :func:`stickslip.kernels.laws.at` leaves whole (it gathers
1-D fields only), and read the load point at step n with :func:`pull` (the chain's step loops with
:func:`pull_from`, once a step, on the table as its address, :func:`kernel_view`):

    p(t_n) = min(p_k + V_k (t_n - t_k), p_k+1)   on [t_k, t_k+1), with t_n = n dt,

p_0 before t_0 and p_m from t_m on (held, as ``LoadHistory.position``). The clamp keeps p(t_n)
non-decreasing across a breakpoint whatever the rounding of V_k, so the exact integrator's start
search (:func:`stickslip.kernels.triggers._first_trigger`, a bisection on the step's own force)
is exact for it; a history whose positions decrease (only a pair of arrays can) takes the dense
integrator (:func:`monotone`, :attr:`~stickslip.models.piece.Piece.monotone`). On one interval
from t_0 = 0, p_0 = 0, p(t_n) = V_0 (n dt) is the end drive's V * (n dt) bit for bit while
n dt < t_1 and V_0 rounds to V.

On the located integrator (:mod:`stickslip.kernels.located`) the load point is read at the
located times inside a step too (:func:`load`), and positions are held in the lab's frame
(u = x, the frame velocity 0; :func:`stickslip.run.located.frame_velocity`). No steady sliding.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from stickslip.models.piece import Piece, kernel_params, njit

READS = ("history",)
#: Where :func:`entry`, :func:`columns` and :func:`kernel_view` get their compiled forms, imported
#: when the piece's functions are compiled (numba is not loaded by importing the piece).
NUMBA_EXTENSIONS = "stickslip.models.drive.history_numba"
#: The kernels' parameters: the table of breakpoints, positions and velocities (3 x (m + 1)).
Params = kernel_params(__name__, ("table",))


def entry(table, r, k):
    """Row r, column k of the table: of the array, or of its in-kernel form (address, columns),
    :func:`kernel_view`."""
    return table[r, k] if hasattr(table, "shape") else None


def columns(table):
    """The number of breakpoints m + 1 (the table's columns), of either form (:func:`entry`)."""
    return table.shape[1]


def kernel_view(dp):
    """The parameters as the chain's kernels carry them (:func:`stickslip.kernels.laws.drive_view`):
    the table as (the address of its C-contiguous data, its columns), read by :func:`entry`. The
    same numbers; what changes is that the step loops hold no array of the drive's, so they count
    no references to it (as an array, each inlined stage that reads it adds a pair of atomic
    reference counts a step, more than the lookup costs). The kernel's argument keeps the array
    alive; a table of any other layout stays an array."""
    return dp


@njit(cache=True, inline="always")
def force(xl, xc, xr, K, p, dp):
    """K (x_{i+1} - 2 x_i + x_{i-1}) (eq. 4); block 1 reads the load point as its x_0."""
    return K * ((xl - xc) - (xc - xr))


@njit(cache=True, inline="always")
def force_rate(vl, vc, vr, K, q, dp):
    """d/dt of :func:`force`: K (v_{i+1} - 2 v_i + v_{i-1}), block 1 reading the load point's
    velocity q = dp/dt (:func:`pull_rate_from`) in its ghost cell."""
    return K * ((vl - vc) - (vc - vr))


@njit(cache=True, inline="always")
def force_lap(lap, xc, K, p, dp):
    """K times the Laplacian of x (eq. 4); an edge block reads the load point in its ghost cell.
    ``lap`` is the lattice's Laplacian of x at the block (:mod:`stickslip.models.lattice`);
    :func:`force` in the same order of operations, so the chain's bits stay."""
    return K * lap


@njit(cache=True, inline="always")
def leaf(dp):
    """No spring to the drive but block 1's."""
    return 0.0


@njit(cache=True, inline="always")
def left(p, ghost):
    """x_0 is the load point."""
    return p


@njit(cache=True, inline="always")
def _interval(t, table, k):
    """The interval of t, the k with t_k <= t < t_k+1, for t_0 <= t < t_m (``np.searchsorted(t_b,
    t, side="right") - 1``, the same k): from a guess k (0 <= k < m), the last step's interval,
    checked first, then the next; a bisection over the rest (or over all of them with no guess, k
    < 0, or a guess past t). Reads the table's rows in place (a row as an array of its own costs a
    reference count in the kernels that count them)."""
    m = columns(table) - 1
    lo = 0
    if k >= 0 and t >= entry(table, 0, k):
        if t < entry(table, 0, k + 1):
            return k
        if t < entry(table, 0, k + 2):  # k + 1 < m here, since t_k+1 <= t < t_m
            return k + 1
        lo = k + 2
    hi = m  # t_lo <= t < t_hi
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if entry(table, 0, mid) <= t:
            lo = mid
        else:
            hi = mid
    return lo


@njit(cache=True, inline="always")
def _at(t, table, k):
    """p(t) on the interval k: linear, clamped to the interval's end position."""
    q = entry(table, 1, k) + entry(table, 2, k) * (t - entry(table, 0, k))
    if entry(table, 2, k) >= 0.0:
        return min(q, entry(table, 1, k + 1))
    return max(q, entry(table, 1, k + 1))


@njit(cache=True, inline="always")
def load_from(t, dp, k):
    """The load point p(t) at any time t and the interval k of t, from the interval k of an earlier
    time (:func:`_interval`; k < 0 for none): one or two comparisons when the times go forward,
    as a run's steps do. The same value as :func:`load`; k is left as it is outside the breakpoints."""
    table = dp.table
    m = columns(table) - 1
    if t >= entry(table, 0, m):
        return entry(table, 1, m), k
    if t < entry(table, 0, 0):
        return entry(table, 1, 0), k
    k = _interval(t, table, k)
    return _at(t, table, k), k


@njit(cache=True, inline="always")
def load(t, dp):
    """The load point p(t) at any time t (the located integrator reads it inside a step): linear
    on the interval of t, clamped to the interval's end position, held before the first and after
    the last breakpoint."""
    return load_from(t, dp, -1)[0]


@njit(cache=True, inline="always")
def pull(n, dt, dp):
    """The load point p(t_n), t_n = n dt (module docstring): :func:`load` at t_n."""
    return load(np.float64(n) * dt, dp)


@njit(cache=True, inline="always")
def pull_from(n, dt, dp, k):
    """:func:`pull` and the interval of t_n, from the interval k of an earlier step
    (:func:`load_from`): what the kernels' step loops read, once a step
    (:func:`stickslip.kernels.laws.pull_carried`)."""
    return load_from(np.float64(n) * dt, dp, k)


@njit(cache=True, inline="always")
def pull_rate_from(n, dt, dp, k):
    """The load point's velocity dp/dt at t_n = n dt: V_k of the interval of t_n (the right
    derivative at a breakpoint, the interval the steps read p(t_n) on), 0 before t_0 and from t_m
    on; k the interval of an earlier step (:func:`load_from`). What a law that reads the stress
    rate gets as the load point's velocity (:func:`stickslip.kernels.laws.load_rate`)."""
    t = np.float64(n) * dt
    table = dp.table
    m = columns(table) - 1
    q = 0.0
    if entry(table, 0, 0) <= t and t < entry(table, 0, m):
        q = entry(table, 2, _interval(t, table, k))
    return q


def pull_py(n: int, dt: float, table: np.ndarray) -> float:
    """:func:`pull` in plain Python (the oracle of the tests and of the run's ghost cell)."""
    tb, pb, vb = table
    t = float(n) * dt
    m = len(tb) - 1
    if t >= tb[m]:
        return float(pb[m])
    if t < tb[0]:
        return float(pb[0])
    k = max(i for i in range(m) if tb[i] <= t)
    q = pb[k] + vb[k] * (t - tb[k])
    return float(min(q, pb[k + 1]) if vb[k] >= 0.0 else max(q, pb[k + 1]))


def table(history: Any) -> np.ndarray:
    """The kernels' table of a history (``LoadHistory``, a pair (times, positions) or a dict with
    ``times`` and ``positions``): a C-contiguous 3 x (m + 1) float64 array; a ValueError of one
    line for anything else (:class:`~stickslip.models.params.ChainParams` says it as its
    ParameterError)."""
    if history is None:
        raise ValueError("history must be given for drive history (a LoadHistory or (times, positions))")
    if isinstance(history, dict):
        times, positions = history.get("times"), history.get("positions")
    elif hasattr(history, "times"):
        times, positions = history.times, history.positions
    else:
        times, positions = history
    t = np.asarray(times, dtype=float).ravel()
    p = np.asarray(positions, dtype=float).ravel()
    if t.size < 2 or t.size != p.size or not (np.isfinite(t).all() and np.isfinite(p).all()):
        raise ValueError("history must have at least two finite breakpoints with one finite position each")
    if t[0] < 0.0 or (np.diff(t) <= 0.0).any():
        raise ValueError("history times must be >= 0 and increasing")
    v = np.append(np.diff(p) / np.diff(t), 0.0)
    return np.ascontiguousarray(np.stack([t, p, v]))


def monotone(history: Any) -> bool:
    """Whether the load point never moves back (positions non-decreasing): the exact integrator's
    start searches need it."""
    return bool((np.diff(table(history)[1]) >= 0.0).all())


def record(history: Any) -> dict[str, list[float]]:
    """The history as run.json records it: its breakpoints and positions."""
    tb = table(history)
    return {"times": tb[0].tolist(), "positions": tb[1].tolist()}


def _check(p: Any) -> str | None:
    try:
        table(getattr(p, "history", None))
    except ValueError as exc:
        return str(exc)
    return None


PIECE = Piece(
    "drive",
    "history",
    "pulling point x_0 = p(t) joined to block 1 by the spring K, p(t) a load history (steps, holds, tables)",
    READS,
    check=_check,
    pack=lambda p: Params(table(p.history)),
    monotone=lambda p: monotone(p.history),
    steady_sliding=False,
    module=__name__,
)
