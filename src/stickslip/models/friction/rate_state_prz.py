"""Rate-and-state friction with the PRZ law (Perrin, Rice and Zheng 1995), regularised at v = 0.

The friction force is sigma_n mu(v, theta) with the law's own state term, theta measured against
2 D_c:

    mu(v, theta) = a asinh( v / (2 v0) exp((mu0 + b ln(v0 theta / (2 D_c))) / a) ),

which for v >> v0 exp(-psi / a) equals mu0 + a ln(v / v0) + b ln(v0 theta / (2 D_c)), and the
state evolves by

    dtheta/dt = 1 - (v theta / (2 D_c))^2

(same parameters as :mod:`stickslip.models.friction.rate_state`; the laboratory's ``prz`` law of
:mod:`stickslip.lab.laws`, whose D_c is this D_c). The rate is even in v, so reading it at v or at
abs(v) is the same where Heun's predictor dips below v = 0; the friction is read at abs(v), like
the aging law's. A stuck block (v = 0) ages, dtheta/dt = 1, like the aging law's. With
Omega = v theta / (2 D_c) at a fixed velocity, d Omega / d(slip) = (1 - Omega^2) / (2 D_c): after
a step of the velocity from V0 to V1, Omega = tanh(slip / (2 D_c) + atanh(V1 / V0)) for V1 < V0
(coth in place of tanh for V1 > V0), so ln Omega relaxes from ln(V1 / V0) to 0.

Steady sliding at v = V: Omega = 1, theta_0 = 2 D_c / V, mu_ss = mu0 + (a - b) ln(V / v0)
(regularised). Runs start at theta_0 = 2 D_c / V. Linearised about steady sliding the law has
dphi/dtheta = sigma_n b r / theta_0 with theta_0 twice the aging law's, and dg/dv = -2 / V,
dg/dtheta = -V / D_c: the products the spring-slider's characteristic equation reads,
(dphi/dtheta)(dg/dv) = -sigma_n b r / D_c and dg/dtheta, are the aging law's, so the critical
stiffness is too, k_c = sigma_n (b - a) / D_c (1 + M V^2 / (sigma_n a D_c)), sigma_n (b - a) / D_c
at quasi-static order (docs/models/rate-state.md, "The PRZ law").
"""

from __future__ import annotations

import math
from typing import Any

from stickslip.models.friction import rate_state as aging
from stickslip.models.piece import LabLaw, Linearisation, Piece, kernel_params, njit

READS = aging.READS
Params = kernel_params(__name__, READS)


@njit(cache=True, inline="always")
def accel(f, v, th, lp):
    """f - sigma_n mu(v, theta) with mu = a asinh(abs(v) / (2 v0) exp((mu0 + b ln(v0 theta / (2 D_c))) / a)):
    the aging law's :func:`~stickslip.models.friction.rate_state.mu_lp` at theta / 2 (halving is
    exact in floating point, so v0 (theta / 2) / D_c is v0 theta / (2 D_c) to the bit)."""
    return f - lp.sigma_n * aging.mu_lp(v, 0.5 * th, lp)


@njit(cache=True, inline="always")
def rate(thl, th, thr, v, lp):
    """The PRZ law dtheta/dt = 1 - (v theta / (2 D_c))^2, on moving and stopped blocks alike."""
    w = v * th / (2.0 * lp.Dc)
    return 1.0 - w * w


@njit(cache=True, inline="always")
def rate_lap(lap, th, v, lp):
    """:func:`rate`, which reads no neighbour: the law has no diffusion of theta (``lap`` unread;
    :mod:`stickslip.models.lattice`)."""
    return rate(th, th, th, v, lp)


@njit(cache=True, inline="always")
def lab_rate(x, th, cb, dtau):
    """The PRZ law as the lab writes it, dtheta/dt = 1 - x^2 with x = v theta / (2 D_c)
    (:class:`~stickslip.models.piece.LabLaw`, scale 2; ``cb``, ``dtau`` unread)."""
    return 1.0 - x * x


def steady_sliding(p: Any) -> tuple[float, float]:
    """theta_0 = 2 D_c / V and c = sigma_n mu(V, theta_0) = sigma_n mu_ss (regularised)."""
    theta0 = 2.0 * p.Dc / p.V
    return -float(accel(0.0, float(p.V), theta0, PIECE.kernel_params(p))), theta0


def linearised(p: Any) -> Linearisation:
    """The law linearised about steady sliding at v = V, theta_0 = 2 D_c / V.

    With z = V / (2 v0) exp(psi / a), psi = mu0 + b ln(v0 theta_0 / (2 D_c)) = mu0 + b ln(v0 / V),
    and r = z / sqrt(1 + z^2): dphi/dv = sigma_n a r / V, dphi/dtheta = sigma_n b r / theta_0; the
    PRZ law g = 1 - (v theta / (2 D_c))^2 gives dg/dv = -2 theta_0 / (2 D_c) = -2 / V and
    dg/dtheta = -2 V / (2 D_c) = -V / D_c.
    """
    theta0 = 2.0 * p.Dc / p.V
    inv_z = 2.0 * p.v0 / p.V * math.exp(-aging.psi(p, 0.5 * theta0))
    r = 1.0 / math.sqrt(1.0 + inv_z * inv_z)
    return Linearisation(
        theta0=theta0,
        phi_v=p.sigma_n * p.rs_a * r / p.V,
        phi_theta=p.sigma_n * p.rs_b * r / theta0,
        g_v=-2.0 / p.V,
        g_theta=-p.V / p.Dc,
    )


def check_v(p: Any) -> str | None:
    """Steady sliding and the start value theta_0 = 2 D_c / V need V > 0."""
    if not p.V > 0.0:
        return f"friction {p.friction} needs V > 0 (runs start at theta = 2 D_c / V; got V={p.V:g})"
    return None


PIECE = Piece(
    "friction",
    "rate-state-prz",
    "sigma_n mu with mu = a asinh(v / (2 v0) exp((mu0 + b ln(v0 theta / (2 D_c))) / a)); "
    "dtheta_i/dt = 1 - (v_i theta_i / (2 D_c))^2 (Perrin-Rice-Zheng law, regularised at v = 0)",
    READS,
    check=check_v,
    has_state=True,
    rate_and_state=True,
    theta0=lambda p: 2.0 * p.Dc / p.V,
    theta_range=aging.PIECE.theta_range,
    steady=steady_sliding,
    linear=linearised,
    module=__name__,
    lab=LabLaw("prz", 2.0, "dtheta/dt = 1 - (v theta / 2 D_c)^2", "Perrin, Rice and Zheng 1995"),
    stability_extras=aging.extras,
    label=r"$\sigma_n\,[\mu_0 + a \ln(v/v_0) + b \ln(v_0\theta/2D_c)]$, PRZ law",
)
