"""Linear stability of steady sliding on a lattice (eq. 5 and Fig. 4 in two dimensions;
docs/lattice.md).

Steady sliding (every block at v = V, theta = theta_0; :func:`stickslip.run.lattice.steady_fields`)
is perturbed by the lattice's normal modes: each eigenvector of minus the lattice's Laplacian,
eigenvalue q (4 sin^2(kx/2) + 4 sin^2(ky/2) on the periodic square;
:meth:`~stickslip.models.lattice.square.Square.eigenvalues`), gives the 3 x 3 matrix of eq. (5)
with the chain's 2 (1 - cos k) replaced by q (and a plate's leaf spring Kp added to K q). As for
the chain, the long waves (q -> 0) are unstable for beta < alpha and every mode is stable for
beta >= alpha (alpha V < 1): the threshold beta_c = alpha does not depend on the dimension.
"""

from __future__ import annotations

from typing import Any

import numpy as np


def _leaf(p: Any) -> float:
    """The plate's leaf spring Kp (0 for an edge drive); the modes of eq. (5) take one number
    per parameter, so per-block values are refused in one line."""
    if p.per_block():
        from stickslip.models.params import ParameterError

        raise ParameterError(
            f"the linear stability on a lattice takes one number per parameter (per block: {', '.join(p.per_block())})"
        )
    return p.leaf()


def lattice_mode_matrix(p: Any, q: np.ndarray | float) -> np.ndarray:
    """eq. (5)'s matrix for a mode of Laplacian eigenvalue -q, shape (..., 3, 3).

    Variables (dx, dv, dtheta): dx' = dv, dv' = -(K q + Kp) dx - phi_v dv - phi_theta dtheta,
    dtheta' = g_v dv + (g_theta - D q) dtheta, with the friction law linearised at steady sliding
    (:class:`~stickslip.models.piece.Linearisation`); Kp the plate's leaf spring (0 for an edge drive).
    """
    lin = p.friction_piece.linear
    if lin is None:
        raise ValueError(f"friction {p.friction} has no state variable: its modes are not eq. (5)'s")
    lin = lin(p.chain)
    q = np.asarray(q, dtype=float)
    kp = _leaf(p)
    A = np.zeros(q.shape + (3, 3))
    A[..., 0, 1] = 1.0
    A[..., 1, 0] = -(p.K * q + kp)
    A[..., 1, 1] = -lin.phi_v
    A[..., 1, 2] = -lin.phi_theta
    A[..., 2, 1] = lin.g_v
    A[..., 2, 2] = lin.g_theta - lin.diffusion * q
    return A


def lattice_growth_rates(p: Any) -> np.ndarray:
    """The largest real part of eq. (5)'s eigenvalues for each normal mode of the lattice (in the
    order of its eigenvalues q), leaving out a rigid translation (q = 0 without a leaf spring)."""
    q = p.lattice.eigenvalues()
    if _leaf(p) == 0.0:
        q = q[q > 1e-12]
    return np.linalg.eigvals(lattice_mode_matrix(p, q)).real.max(axis=-1)


def lattice_stability(p: Any) -> dict[str, float | bool]:
    """Steady sliding on the lattice against its normal modes (module docstring): the largest
    growth rate and the eigenvalue q of its mode, whether it is unstable, and the long-wave
    threshold beta_c = alpha (0 on the melted branch alpha V >= 1) that it is compared with."""
    q = p.lattice.eigenvalues()
    if _leaf(p) == 0.0:
        q = q[q > 1e-12]
    rates = lattice_growth_rates(p)
    i = int(np.argmax(rates))
    return {
        "max_growth_rate": float(rates[i]),
        "q_at_max": float(q[i]),
        "unstable": bool(rates[i] > 0.0),
        "critical_beta": p.alpha if p.alpha * p.V < 1.0 else 0.0,
    }


def lattice_critical_beta(p: Any) -> float:
    """The beta at which steady sliding on this finite lattice turns unstable (Brent's method on
    the largest growth rate over beta in (0, 2 alpha]): below the long-wave threshold alpha by an
    amount of the order of the smallest eigenvalue q, which it tends to as the lattice grows.
    NaN where the growth rate does not change sign there."""
    from scipy.optimize import brentq

    def growth(beta: float) -> float:
        return float(lattice_growth_rates(_with_beta(p, beta)).max())

    lo, hi = 1e-6, 2.0 * p.alpha + 1e-6
    if not growth(lo) > 0.0 > growth(hi):
        return float("nan")
    return float(brentq(growth, lo, hi, xtol=1e-12))


def _with_beta(p: Any, beta: float) -> Any:
    from stickslip.models.lattice.params import LatticeParams

    return LatticeParams(p.chain.replace(beta=beta), p.lattice)
