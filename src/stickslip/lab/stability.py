"""Linear stability of steady sliding of the quasi-static spring-slider: the critical stiffness k_c.

Perturb steady sliding at V (theta_k = s_k D_c,k / V) with the load point moving on at V. Every law
of :mod:`stickslip.lab.laws` but Nagata's linearises alike, d(delta theta_k / theta_k)/dt =
-rho_k (delta v / V + delta theta_k / theta_k) with rho_k = V / D_c,k, and the spring,
-k delta x = delta mu + eta delta v, gives the characteristic equation in the growth rate s

    k V / s + a + eta V - sum_k b_k rho_k / (s + rho_k) = 0

(Ruina 1983; Gu, Rice, Ruina and Tse 1984). One state variable: a s^2 + (kV + (a' - b) rho) s +
kV rho = 0 with a' = a + eta V, neutral at k_c = (b - a') / D_c. Nagata's law adds
-(c / b) theta dtau/dt to the rate, so its term is (b rho - c k V) / (s + rho) and
k_c = (b - a') / (D_c (1 + c)). Two state variables, with kappa = k V and sigma = rho_1 + rho_2,
the cubic a' s^3 + A2 s^2 + A1 s + A0 has
A2 = kappa + a' sigma - b_1 rho_1 - b_2 rho_2, A1 = kappa sigma + rho_1 rho_2 (a' - b_1 - b_2),
A0 = kappa rho_1 rho_2, neutral (a Hopf point) where A2 A1 = a' A0: the quadratic

    sigma kappa^2 + (c1 + sigma c2 - a' rho_1 rho_2) kappa + c1 c2 = 0,  c1 = rho_1 rho_2 (a' - b_1 - b_2),
    c2 = a' sigma - b_1 rho_1 - b_2 rho_2,

whose largest root over V is k_c (independent of V when eta = 0). :func:`critical_stiffness_numeric`
finds k_c from the eigenvalues of the Jacobian of the compiled right-hand side itself (any law, any
number of state variables, either form), the check of both closed forms.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from stickslip.lab.laws import RateState, friction_of, rhs, steady_theta
from stickslip.models.params import ParameterError, check_number

__all__ = ["critical_stiffness", "critical_stiffness_numeric", "growth_rate"]


def critical_stiffness(model: RateState, V: float | None = None) -> float:
    """k_c in friction per unit displacement (module docstring), in closed form for one state
    variable and for two of the aging, slip or PRZ laws; else :func:`critical_stiffness_numeric`.

    Parameters
    ----------
    model : RateState
    V : float, optional
        The sliding velocity (default V0); k_c depends on it only through eta V.

    Returns
    -------
    float
        k_c; steady sliding is linearly unstable for k < k_c. Negative or zero where it is
        stable at every stiffness (velocity strengthening).

    Examples
    --------
    >>> critical_stiffness(RateState(a=0.005, b=0.01, Dc=10.0, mu0=0.6, V0=1.0))
    0.0005
    """
    V = model.V0 if V is None else check_number("V", V, low=0.0, low_open=True)
    ap = model.a + model.eta * V
    if model.n_states == 1:
        # Nagata's law adds c kappa to the evolution term: kappa (1 + c) = (b - a') rho.
        c = model.c[0] if model.law[0] == "nagata" else 0.0
        return (model.b[0] - ap) / (model.Dc[0] * (1.0 + c))
    if "nagata" in model.law or model.n_states > 2:
        return critical_stiffness_numeric(model, V)
    (b1, b2), (l1, l2) = model.b, model.Dc
    r1, r2 = V / l1, V / l2
    sig = r1 + r2
    c1 = r1 * r2 * (ap - b1 - b2)
    c2 = ap * sig - b1 * r1 - b2 * r2
    B = c1 + sig * c2 - ap * r1 * r2
    disc = B * B - 4.0 * sig * c1 * c2
    if disc < 0.0:
        return -math.inf
    return (-B + math.sqrt(disc)) / (2.0 * sig) / V


def _jacobian(model: RateState, k: float, V: float, M: float = 0.0) -> np.ndarray:
    """The Jacobian of :func:`stickslip.lab.laws.rhs` at steady sliding, by central differences
    (over (tau, v, theta) where the block has a mass M > 0)."""
    th = steady_theta(model, V)
    args = list(model.arrays(M))
    args[3] = k
    mu = friction_of(model, V, th)
    y = np.concatenate([[mu + model.eta * V], [V] if M > 0.0 else [], th])
    n = y.size
    J = np.empty((n, n))
    fp, fm = np.empty(n), np.empty(n)
    for i in range(n):
        d = 1e-6 * max(abs(y[i]), 1e-12)
        yp, ym = y.copy(), y.copy()
        yp[i] += d
        ym[i] -= d
        rhs(0.0, yp, fp, V, *args)
        rhs(0.0, ym, fm, V, *args)
        J[:, i] = (fp - fm) / (2.0 * d)
    return J


def growth_rate(model: RateState, k: float, V: float | None = None, M: float = 0.0) -> float:
    """The largest real part of the eigenvalues of the linearised spring-slider at stiffness k
    (module docstring; > 0: steady sliding at V is unstable), massless or of mass M.

    Parameters
    ----------
    model : RateState
    k : float
        Stiffness in friction per unit displacement.
    V : float, optional
        Sliding velocity (default V0).
    M : float
        Mass per unit normal stress (0: the quasi-static spring-slider).

    Returns
    -------
    float
    """
    V = model.V0 if V is None else V
    return float(np.max(np.linalg.eigvals(_jacobian(model, k, V, M)).real))


def critical_stiffness_numeric(
    model: RateState, V: float | None = None, *, M: float = 0.0, k_max: float | None = None
) -> float:
    """k_c as the largest stiffness at which the linearised system has a growing mode: a scan
    over k on a log grid up to ``k_max`` (default ``10 sum |b_k| / D_c,k``, times
    1 + M V^2 / (a min D_c) with a mass), refined by Brent's method (module docstring). With a
    mass M and one state variable it is Rice and Ruina's (b - a) / D_c (1 + M V^2 / (a D_c))
    (:func:`stickslip.lab.inertial.critical_stiffness_inertial`).

    Parameters
    ----------
    model : RateState
    V : float, optional
        Sliding velocity (default V0).
    M : float
        Mass per unit normal stress of the inertial spring-slider (0: quasi-static).
    k_max : float, optional
        Top of the scan.

    Returns
    -------
    float
        k_c; 0 where no stiffness in the range is unstable.
    """
    V = model.V0 if V is None else check_number("V", V, low=0.0, low_open=True)
    scale = sum(abs(b) / dc for b, dc in zip(model.b, model.Dc, strict=True)) + sum(abs(c) for c in model.c) / min(
        model.Dc
    )
    if scale == 0.0:
        return 0.0
    M = check_number("M", M, low=0.0)
    k_max = 10.0 * scale * (1.0 + M * V * V / (model.a * min(model.Dc))) if k_max is None else k_max
    ks = np.geomspace(k_max * 1e-8, k_max, 241)
    # A small offset keeps the neutral mode (k = k_c exactly) on the stable side.
    g = np.array([growth_rate(model, k, V, M) for k in ks])
    tol = 1e-9 * V / min(model.Dc)
    unstable = np.flatnonzero(g > tol)
    if unstable.size == 0:
        return 0.0
    i = unstable[-1]
    if i == ks.size - 1:
        raise ParameterError(f"steady sliding is unstable up to k_max = {k_max:g}; give a larger k_max")
    return float(brentq(lambda k: growth_rate(model, k, V, M), ks[i], ks[i + 1], xtol=1e-14 * k_max, rtol=1e-12))
