"""Model equations that have closed forms: steady sliding of the block and of the chain.

Conventions (docs/model.md): blocks are numbered i = 1..N in the paper and in every output of this
package; arrays hold block i at index i - 1. The pulling point is x_0 = V t.
"""

from __future__ import annotations

import numpy as np

from stickslip.models.params import BlockParams, ChainParams

#: Tolerance of steady sliding (largest deviation of v, theta and the springs from it) where the
#: studies and the reproduction stop a chain run or call its final state steady.
UNTIL_STEADY = 1e-6


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


def steady_friction(p: ChainParams) -> tuple[float, float]:
    """Friction c of a block sliding steadily at v = V, and its state variable theta_0.

    The friction law says (:attr:`~stickslip.models.piece.Piece.steady`): state (eq. 4):
    theta_0 = 1 - alpha V, c = theta_0 + beta V; weakening (Carlson-Langer):
    c = phi(V) = (1 - sigma) / (1 + 2 alpha V / (1 - sigma)); strengthening: c = F0 + beta V.
    Models without a state variable report theta_0 = 0 (the value their runs carry).
    """
    return p.friction_piece.steady(p)


def has_steady_state(p: ChainParams) -> bool:
    """Whether the chain can slide steadily with every block at v = V.

    The end drive with a free end (eq. 4) and the plate drive with free or periodic ends can;
    a fixed end holds a spring that stretches for ever, so those compositions cannot.
    """
    return p.ends != "fixed"


def chain_steady_state(p: ChainParams, t: float = 0.0) -> dict[str, np.ndarray]:
    """Exact discrete steady sliding of the chain, eq. (4) with the ends of docs/model.md.

    End drive: v_i = V, theta_i = 1 - alpha V (= 1 - V for alpha = 1), friction
    c = theta_0 + beta V; every block is pulled by the spring behind it with the friction of all
    blocks ahead, so x_{i-1} - x_i = (c / K) (N - i + 1), with x_0 = V t.
    Plate drive (free or periodic ends): every block lags the plate by c / Kp, springs K unstretched.
    Returns x (length N), v, theta and the extensions ``ext`` (x_{i-1} - x_i, i = 1..N).
    """
    if not has_steady_state(p):
        raise ValueError(f"the chain with ends {p.ends} has no steady sliding state")
    c, theta0 = steady_friction(p)
    if p.drive == "plate":
        x = np.full(p.N, p.V * t - c / p.Kp)
        ext = np.zeros(p.N)
    else:
        i = np.arange(1, p.N + 1, dtype=np.float64)
        ext = (c / p.K) * (p.N - i + 1.0)
        x = p.V * t - np.cumsum(ext)
    return {
        "x": x,
        "v": np.full(p.N, p.V),
        "theta": np.full(p.N, theta0),
        "ext": ext,
        "friction": c,
    }


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
        the plate equally); NaN where there is no steady sliding.

    Examples
    --------
    >>> from stickslip import chain_params
    >>> from stickslip.models.physics import chain_steady_length
    >>> round(chain_steady_length(chain_params(N=49)), 5)  # c = 1, K = 10: 49 * 48 / 20
    117.6
    """
    if not has_steady_state(p):
        return float("nan")
    if p.drive == "plate":
        return 0.0
    c = (1.0 - p.alpha * p.V) + p.beta * p.V if p.friction == "state" else steady_friction(p)[0]
    return c / p.K * p.N * (p.N - 1) / 2.0


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
    if p.drive != "end" or not p.V > 0 or not has_steady_state(p):
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
