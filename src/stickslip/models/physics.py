"""Model equations that have closed forms: steady sliding of the block and of the chain.

Conventions (docs/model.md): blocks are numbered i = 1..N in the paper and in every output of this
package; arrays hold block i at index i - 1. The pulling point is x_0 = V t.
"""

from __future__ import annotations

import functools
import importlib
from typing import Any

import numpy as np

from stickslip.models.params import BlockParams, ChainParams

#: Tolerance of steady sliding (largest deviation of v, theta and the springs from it) where the
#: studies and the reproduction stop a chain run or call its final state steady.
UNTIL_STEADY = 1e-6


class NoClosedForm(ValueError):
    """The chain's steady sliding has no closed form here (per-block theta_0 coupled by diffusion,
    or no velocity at which the frictions balance the applied force); the message is one line."""


def sliding_friction(V: float, beta: float) -> float:
    """Friction of steady sliding, c = theta_0 + beta v_0 = 1 - (1 - beta) V (sections 2, 3)."""
    return 1.0 - (1.0 - beta) * V


def block_steady_state(p: BlockParams) -> dict[str, float]:
    """Steady sliding of the single block, section 2 (with general M, sigma, alpha).

    v_0 = V; theta_0 solves theta (1 - theta) = alpha theta V, so theta_0 = 1 - alpha V;
    the spring carries the friction: K (V t - x_0) = sigma theta_0 + beta V.
    For M = sigma = alpha = 1 this is the paper's x_0 = V t - {1 - (1 - beta) V} / K.
    Returns v, theta and the spring extension ``lag`` = V t - x_0.
    """
    theta0 = 1.0 - p.alpha * p.V
    force = p.sigma * theta0 + p.beta * p.V
    return {"v": p.V, "theta": theta0, "force": force, "lag": force / p.K}


def _block_values(value: Any) -> np.ndarray | None:
    """The N values of a per-block parameter (an array, or the values of a
    :class:`~stickslip.models.disorder.PerBlock`), None for a number."""
    if isinstance(value, np.ndarray):
        return value
    values = getattr(value, "values", None)
    return values if isinstance(values, np.ndarray) else None


def per_block(p: Any, name: str) -> np.ndarray:
    """The parameter ``name`` of ``p`` at every block, i = 1..N at index i - 1.

    A parameter is a float (the same at every block) or an array of N values (quenched
    disorder, one value per block); either way this returns N values (read-only for a float).
    """
    value = getattr(p, name)
    values = _block_values(value)
    return np.broadcast_to(np.asarray(value if values is None else values, dtype=float), (p.N,))


def is_uniform(p: Any) -> bool:
    """Whether every block has the same parameters: no field of ``p`` is an array of N values
    with two different entries (a uniform chain given as arrays counts as uniform)."""
    for value in _arrays(p):
        if value.ndim == 1 and value.size > 1 and np.any(value != value[0]):
            return False
    return True


def _arrays(p: Any) -> list[np.ndarray]:
    """The fields of ``p`` that are arrays (none for a chain of floats)."""
    return [a for a in (_block_values(v) for v in vars(p).values()) if a is not None]


class BlockView:
    """The parameters ``p`` as block ``i`` (0-based) sees them: a field that is an array of N values
    reads its i-th value, every other field as it is, and ``overrides`` replace fields (the
    steady velocity of a force drive in place of V).

    What a piece's closed forms (:attr:`~stickslip.models.piece.Piece.steady`, ``linear``,
    ``slope``) read, so that a piece never learns about per-block arrays.
    """

    def __init__(self, p: Any, i: int, **overrides: float):
        self._p = p
        self._i = i
        self._overrides = overrides

    def __getattr__(self, name: str) -> Any:
        if name in self._overrides:
            return self._overrides[name]
        value = getattr(self._p, name)
        values = _block_values(value)
        if values is not None and values.ndim == 1:
            return float(values[self._i])
        return value


def uniform_view(p: Any, **overrides: float) -> Any:
    """``p`` itself for a chain of floats, else block 1's view (for a uniform chain given as arrays)."""
    return p if not _arrays(p) and not overrides else BlockView(p, 0, **overrides)


def steady_friction(p: ChainParams) -> tuple[float, float]:
    """Friction c of a block sliding steadily at v = V, and its state variable theta_0.

    The friction law says (:attr:`~stickslip.models.piece.Piece.steady`): state (eq. 4):
    theta_0 = 1 - alpha V, c = theta_0 + beta V; weakening (Carlson-Langer):
    c = phi(V) = (1 - sigma) / (1 + 2 alpha V / (1 - sigma)); strengthening: c = F0 + beta V.
    Models without a state variable report theta_0 = 0 (the value their runs carry).
    """
    return p.friction_piece.steady(p)


def block_frictions(p: Any, v: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Each block's friction c_i and state variable theta_i of steady sliding at velocity ``v``
    (default V): the friction piece's :attr:`~stickslip.models.piece.Piece.steady` read at each
    block's own parameters (:class:`BlockView`), computed once where every block is alike."""
    over = {} if v is None else {"V": float(v)}
    steady = p.friction_piece.steady
    if is_uniform(p):
        c, theta0 = steady(uniform_view(p, **over))
        return np.full(p.N, c), np.full(p.N, theta0)
    pairs = [steady(BlockView(p, i, **over)) for i in range(p.N)]
    return np.array([c for c, _ in pairs]), np.array([th for _, th in pairs])


def applied_forces(p: Any) -> np.ndarray | None:
    """The constant force of a force drive on each block (:attr:`~stickslip.models.piece.Piece.applied`),
    or None for a drive that sets the velocity V (end, plate)."""
    applied = p.drive_piece.applied
    if applied is None:
        return None
    if is_uniform(p):
        return np.full(p.N, float(applied(BlockView(p, 0))))
    return np.array([applied(BlockView(p, i)) for i in range(p.N)])


def _cached(fn):
    """``fn(p)`` remembered for parameters that hash (floats; a chain with arrays is computed each
    time), its arrays read-only: the steady stop asks at every sample."""
    remembered = functools.lru_cache(maxsize=64)(fn)

    @functools.wraps(fn)
    def wrapper(p):
        try:
            out = remembered(p)
        except TypeError:  # an array among the parameters
            return fn(p)
        for a in out.values() if isinstance(out, dict) else (out,):
            if isinstance(a, np.ndarray):
                a.flags.writeable = False
        return out

    return wrapper


@_cached
def drive_stiffness(p: Any) -> np.ndarray:
    """The stiffness of the spring joining each block to the drive: the drive's compiled ``leaf``
    (Kp for the plate, 0 for the end drive and the force drives) at each block's parameters."""
    leaf = _python(p.drive_piece.module, "leaf")
    if is_uniform(p):
        return np.full(p.N, float(leaf(block_kernel_params(p.drive_piece, p, 0))))
    return np.array([float(leaf(block_kernel_params(p.drive_piece, p, i))) for i in range(p.N)])


def _python(module: str, name: str) -> Any:
    """A piece's compiled function ``name`` as plain Python (its ``py_func``), without compiling it
    (a function still waiting for numba, :func:`stickslip.models.piece.njit`, is read as it is)."""
    fn = vars(importlib.import_module(module))[name]
    return getattr(fn, "py_func", None) or fn.__wrapped__


def block_kernel_params(piece: Any, p: Any, i: int) -> tuple:
    """The ``Params`` named tuple of a piece's compiled functions at block ``i`` (0-based)."""
    view = BlockView(p, i)
    return importlib.import_module(piece.module).Params(*(float(getattr(view, r)) for r in piece.reads))


@_cached
def ghost_rows(p: Any) -> dict[str, tuple[float, float]]:
    """The ghost cells of the chain as linear functions of the end blocks, from the pieces' own
    compiled ``left`` and ``ghost`` (the rows the kernels' :func:`stickslip.kernels.laws._set_ghosts`
    evaluates), about a state that moves with the drive.

    ``x0``, ``xN1``: the weights (on x_1, on x_N) of x_0 and x_{N+1}; ``th0``, ``thN1`` those of
    theta_0 and theta_{N+1} (no flux). x_0 of the end drive is the pulling point, which moves with
    steady sliding, so its weights are 0. The ghost functions are selections, so the weights are exact.
    """
    ends = _python(p.ends_piece.module, "ghost")
    left = _python(p.drive_piece.module, "left")
    on_ghost = left(0.0, 1.0)  # 1 where x_0 is the ends' ghost cell, 0 where it is the pulling point
    x_edge, x_other = ends(1.0, 0.0, 0.0), ends(0.0, 1.0, 0.0)
    th_edge, th_other = ends(1.0, 0.0, 1.0), ends(0.0, 1.0, 0.0)
    return {
        "x0": (on_ghost * x_edge, on_ghost * x_other),
        "xN1": (x_other, x_edge),
        "th0": (th_edge, th_other),
        "thN1": (th_other, th_edge),
    }


def left_ghost(p: Any, pull: float, x1: float, xN: float) -> float:
    """x_0 as the kernels set it (:func:`stickslip.kernels.laws._set_ghosts`): the drive's compiled
    ``left`` of the pull point ``pull`` and the ends' ``ghost`` of x_1 and x_N (a wall at 0)."""
    ends = _python(p.ends_piece.module, "ghost")
    left = _python(p.drive_piece.module, "left")
    return left(pull, ends(x1, xN, 0.0))


def laplacian(N: int, rows: tuple[tuple[float, float], tuple[float, float]]) -> np.ndarray:
    """The N x N discrete Laplacian (x_{i-1} - 2 x_i + x_{i+1}) with the ghost cells x_0 and
    x_{N+1} given as weights on (x_1, x_N) and (x_1, x_N) (:func:`ghost_rows`)."""
    L = -2.0 * np.eye(N) + np.eye(N, k=1) + np.eye(N, k=-1)
    (a1, aN), (b1, bN) = rows
    L[0, 0] += a1
    L[0, -1] += aN
    L[-1, 0] += b1
    L[-1, -1] += bN
    return L


def has_steady_state(p: ChainParams) -> bool:
    """Whether the chain can slide steadily with every block at one velocity.

    The end drive with a free end (eq. 4), the plate drive with free or periodic ends and a
    constant force can; a fixed end holds a spring that stretches for ever, and a force ramp
    never lets the velocity settle (the pieces' ``steady_sliding``).
    """
    return p.ends_piece.steady_sliding and p.drive_piece.steady_sliding


def steady_velocity(p: Any) -> float:
    """The velocity of steady sliding: V where the drive moves at V; under a force drive the v
    at which the frictions balance the applied forces, sum_i c_i(v) = sum_i F_i (Brent's method;
    for the strengthening law F0 + beta v it is (sum F_i - sum F0_i) / sum beta_i).

    The first root above v = 0 found by doubling a bracket (a weakening law below its friction at
    rest balances on its falling branch). Raises ValueError where no v >= 0 balances them.
    """
    forces = applied_forces(p)
    if forces is None:
        return float(p.V)
    from scipy.optimize import brentq  # here: the command line's help loads no scipy

    total = float(np.sum(forces))

    def excess(v: float) -> float:
        return float(np.sum(block_frictions(p, v)[0])) - total

    at_rest = excess(0.0)
    if at_rest == 0.0:
        return 0.0
    hi = 1.0
    for _ in range(200):
        if (excess(hi) > 0.0) != (at_rest > 0.0):
            break
        hi *= 2.0
    else:
        raise NoClosedForm(
            f"the friction does not balance the applied force at any velocity (drive {p.drive}, friction {p.friction})"
        )
    return float(brentq(excess, 0.0, hi, xtol=1e-15, rtol=4.0 * np.finfo(float).eps))


def chain_steady_state(p: ChainParams, t: float = 0.0) -> dict[str, np.ndarray]:
    """Exact discrete steady sliding of the chain, eq. (4) with the ends of docs/model.md, for
    uniform and per-block parameters (:func:`per_block`).

    Every block slides at one velocity v (:func:`steady_velocity`: V, or where the frictions
    balance a force drive), with its own friction c_i and theta_i at v (:func:`block_frictions`).
    End drive: the spring behind block i carries the friction of every block from i to the free
    end, so x_{i-1} - x_i = (1/K) sum_{j >= i} c_j, (c / K) (N - i + 1) for a uniform chain,
    with x_0 = V t. Force drive (free ends): the same sum of c_j - F_j, which vanishes at block 1;
    block 1 at v t. Plate drive: every block lags the plate by c / Kp (springs K unstretched) for a
    uniform chain; otherwise the force balance K (x_{i-1} - 2 x_i + x_{i+1}) + Kp_i (V t - x_i)
    = c_i, a linear system. Returns x (length N), v, theta, the extensions ``ext``
    (x_{i-1} - x_i, i = 1..N, x_0 the drive's or the ends' ghost) and ``friction`` (c, or c_i).
    """
    if not has_steady_state(p):
        raise ValueError(f"the chain with drive {p.drive} and ends {p.ends} has no steady sliding state")
    N = p.N
    uniform = is_uniform(p)
    if uniform and p.drive_piece.applied is None:
        c, theta0 = steady_friction(uniform_view(p))
        friction: Any = c
        v = p.V
        theta = np.full(N, theta0)
    else:
        v = steady_velocity(p)
        cs, theta = block_frictions(p, v)
        friction = cs if not uniform else float(cs[0])
        _check_theta_decoupled(p, theta, v)
    stiff = drive_stiffness(p)
    rows = ghost_rows(p)
    if np.any(stiff > 0.0):
        if uniform:
            x = np.full(N, p.V * t - friction / float(stiff[0]))
            ext = np.zeros(N)
        else:
            # K L u - Kp u = c with u = x - V t (the springs' rows from the ends).
            A = p.K * laplacian(N, (rows["x0"], rows["xN1"])) - np.diag(stiff)
            x = p.V * t + np.linalg.solve(A, cs)
            ext = _extensions(x, rows)
    elif applied_forces(p) is None:
        if uniform:
            i = np.arange(1, N + 1, dtype=np.float64)
            ext = (friction / p.K) * (N - i + 1.0)
        else:
            ext = np.cumsum(cs[::-1])[::-1] / p.K
        x = p.V * t - np.cumsum(ext)
    else:
        if uniform:
            ext = np.zeros(N)  # every block carries its own force: the springs stay unstretched
        elif not p.ends_piece.ring:
            ext = np.cumsum((cs - applied_forces(p))[::-1])[::-1] / p.K
            ext[0] = 0.0  # x_0 is block 1's own ghost: the sum vanishes there at the steady v
        else:
            # On a ring the springs' force balance fixes the extensions up to a translation.
            A = p.K * laplacian(N, (rows["x0"], rows["xN1"]))
            u = np.linalg.lstsq(A, cs - applied_forces(p), rcond=None)[0]
            ext = _extensions(u, rows)
        x = v * t - np.concatenate(([0.0], np.cumsum(ext[1:])))
    return {"x": x, "v": np.full(N, v), "theta": theta, "ext": ext, "friction": friction}


def _check_theta_decoupled(p: Any, theta: np.ndarray, v: float) -> None:
    """Each block's theta_0 is steady only where diffusion does not couple unequal values: refuse
    per-block theta_0 with D > 0 (the steady theta then solves a nonlinear system, no closed form)."""
    linear = p.friction_piece.linear
    if linear is None or np.all(theta == theta[0]):
        return
    over = {} if v == p.V else {"V": float(v)}
    if any(linear(BlockView(p, i, **over)).diffusion != 0.0 for i in range(p.N)):
        raise NoClosedForm(
            "blocks with different steady theta_0 coupled by diffusion D > 0 have no closed-form steady state"
        )


@_cached
def steady_reference(p: Any) -> dict[str, Any]:
    """:func:`chain_steady_state` at t = 0 and whether the drive holds every block's position (a
    leaf spring, so steady sliding is compared in the plate's frame): what the steady stop compares
    a state with at every sample, computed once per parameters."""
    return {**chain_steady_state(p, 0.0), "pinned": bool(np.any(drive_stiffness(p) > 0.0))}


def _extensions(x: np.ndarray, rows: dict[str, tuple[float, float]]) -> np.ndarray:
    """x_{i-1} - x_i, i = 1..N, with x_0 the ends' ghost cell (weights ``rows['x0']``)."""
    a1, aN = rows["x0"]
    return np.concatenate(([a1 * x[0] + aN * x[-1]], x[:-1])) - x


def chain_steady_length(p: ChainParams) -> float:
    """Total length L = x_1 - x_N of steady sliding, exact discrete form (docs/model.md).

    L_ss = (c / K) N (N - 1) / 2 with c = theta_0 + beta V, the steady friction.

    Parameters
    ----------
    p : ChainParams
        The chain.

    Returns
    -------
    float
        L_ss: 7940.1 for the paper's chain (N = 399); zero for the plate drive (every block lags
        the plate equally) and under a uniform constant force; NaN where there is no steady
        sliding. With per-block parameters, x_1 - x_N of :func:`chain_steady_state`.

    Examples
    --------
    >>> from stickslip import chain_params
    >>> from stickslip.models.physics import chain_steady_length
    >>> round(chain_steady_length(chain_params(N=49)), 5)  # c = 1, K = 10: 49 * 48 / 20
    117.6
    """
    if not has_steady_state(p):
        return float("nan")
    if not is_uniform(p):
        x = chain_steady_state(p)["x"]
        return float(x[0] - x[-1])
    if p.drive_piece.leaf_spring:
        return 0.0
    q = uniform_view(p)
    c = steady_friction(q)[0]
    return c / q.K * p.N * (p.N - 1) / 2.0


def chain_steady_profile_paper(p: ChainParams, t: float = 0.0) -> np.ndarray:
    """The paper's continuum form x_i = V t - c/K {N^2 - (i - N)^2} / 2 (section 3, Fig. 5a).

    An approximation of :func:`chain_steady_state`; shown beside it where a figure compares.
    """
    c = sliding_friction(p.V, p.beta)
    i = np.arange(1, p.N + 1, dtype=np.float64)
    return p.V * t - c / p.K * (p.N**2 - (i - p.N) ** 2) / 2.0


def loading_time(p: ChainParams) -> float:
    """Time the end drive takes to stretch the chain to its steady length from x_i = 0: L_ss / V.

    From the paper's start (x_i(0) = 0, section 3) the pulling point x_0 = V t has to move by about
    L_ss (:func:`chain_steady_length`) before the far blocks load and the chain reaches its
    stick-slip state; 4.85e5 for N = 99, 1.18e5 for N = 49 and 7.9e6 for the paper's N = 399.
    NaN for the plate drive (it loads every block at once), for V = 0 and where there is no steady
    sliding.
    """
    if p.drive_piece.leaf_spring or not p.V > 0 or not has_steady_state(p):
        return float("nan")
    return chain_steady_length(p) / p.V


#: Blocks of the first-look chain (``stickslip chain`` without ``--t-end``): long enough for
#: avalanches of many sizes, short enough to load in t ~ 1.2e5 (loading_time).
FIRST_LOOK_N = 49
#: How many loading times a first look runs: the second half, where <L> is averaged, lies past
#: the loading with room to spare.
FIRST_LOOK_LOADINGS = 4.0


def first_look_t_end(p: ChainParams) -> float:
    """End time of a first look at a chain: :data:`FIRST_LOOK_LOADINGS` loading times
    (:func:`loading_time`, L_ss / V from the paper's start x_i = 0), rounded up to one significant
    digit (5e5 for N = 49 with the paper's parameters); NaN where the chain does not load from one
    end (plate drive, no steady sliding)."""
    t = FIRST_LOOK_LOADINGS * loading_time(p)
    if not np.isfinite(t) or t <= 0:
        return float("nan")
    scale = 10.0 ** np.floor(np.log10(t))
    return float(np.ceil(t / scale) * scale)
