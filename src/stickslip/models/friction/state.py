"""eq. (4)'s friction: theta_i + beta v_i while moving, with the state law of eq. (4); the single
block's sigma theta + beta v of eq. (1) with its optional parameter sigma.

dtheta_i/dt = theta_i (1 - theta_i) - alpha theta_i v_i + D (theta_{i+1} - 2 theta_i + theta_{i-1}).
Its compiled functions :func:`accel` and :func:`rate` are what every integrator evaluates
(contract in :mod:`stickslip.kernels.laws`).
"""

from __future__ import annotations

from typing import Any

from stickslip.models.piece import Linearisation, Piece, kernel_params, njit

READS = ("beta", "alpha", "D")
#: ``sigma``: eq. (1)'s scale of the state term, sigma theta + beta v; None (eq. 4) reads theta.
Params = kernel_params(__name__, READS, optional=("sigma",))


@njit(cache=True)
def scaled(sigma, th):
    """sigma theta (eq. 1), or theta itself where sigma is None (eq. 4): chosen when compiled, so
    the chain's expression is untouched. Not inlined by numba, so that it can prune the branch
    on its argument's type; LLVM inlines it."""
    if sigma is None:
        return th
    return sigma * th


@njit(cache=True, inline="always")
def accel(f, v, th, lp):
    """f - sigma theta - beta v: the force on a moving block less the friction sigma theta + beta v
    of eq. (1) (eq. 4: sigma None, theta + beta v)."""
    return f - scaled(lp.sigma, th) - lp.beta * v


@njit(cache=True, inline="always")
def rate(thl, th, thr, v, lp):
    """dtheta/dt of eq. (4): theta (1 - theta) - alpha theta v + D (theta_{i-1} - 2 theta + theta_{i+1}),
    for moving and stopped blocks alike (a stopped block has v = 0)."""
    return th * (1.0 - th) - lp.alpha * th * v + lp.D * ((thl - th) - (th - thr))


@njit(cache=True, inline="always")
def rate_lap(lap, th, v, lp):
    """eq. (4)'s dtheta/dt with the lattice's Laplacian of theta ``lap`` (:mod:`stickslip.models.lattice`):
    theta (1 - theta) - alpha theta v + D lap, :func:`rate` in the same order of operations."""
    return th * (1.0 - th) - lp.alpha * th * v + lp.D * lap


def _steady(p: Any) -> tuple[float, float]:
    """theta_0 = 1 - alpha V and c = theta_0 + beta V (sections 2, 3)."""
    theta0 = 1.0 - p.alpha * p.V
    return theta0 + p.beta * p.V, theta0


def _linear(p: Any) -> Linearisation:
    """eq. (4)'s law linearised about steady sliding at v = V (eq. 2, eq. 5).

    Friction theta + beta v: dphi/dv = beta, dphi/dtheta = 1. State law
    g = theta (1 - theta) - alpha theta v at the stable steady state theta_0 = max(1 - alpha V, 0):
    dg/dv = -alpha theta_0 and dg/dtheta = 1 - 2 theta_0 - alpha V; diffusion D.
    """
    theta0 = max(1.0 - p.alpha * p.V, 0.0)
    return Linearisation(theta0, p.beta, 1.0, -p.alpha * theta0, 1.0 - 2.0 * theta0 - p.alpha * p.V, p.D)


def _check(p: Any) -> str | None:
    """Heun keeps every theta_i in [0, 1] if (2 D + 1) dt <= 1 (docs/limits.md)."""
    if (2.0 * p.D + 1.0) * p.dt > 1.0:
        return (
            f"D*dt must be <= (1 - dt)/2 = {(1.0 - p.dt) / 2:g} so that theta stays in [0, 1] "
            f"(got D={p.D:g}, dt={p.dt:g})"
        )
    return None


PIECE = Piece(
    "friction",
    "state",
    "theta_i + beta v_i while moving; dtheta_i/dt = theta_i (1 - theta_i) "
    "- alpha theta_i v_i + D (theta_{i+1} - 2 theta_i + theta_{i-1}) (eq. 4)",
    READS,
    check=_check,
    has_state=True,
    theta0=0.1,
    theta_range=(0.0, 1.0, False),  # Heun keeps theta_i in [0, 1] (docs/limits.md)
    steady=_steady,
    linear=_linear,
    eq5=True,
    module=__name__,
    lanes=True,
    label=r"$\theta + \beta v$",
)
