"""Rate-and-state friction with Ruina's slip law (Ruina 1983), regularised at v = 0.

The friction force is the aging law's, sigma_n mu(v, theta) with

    mu(v, theta) = a asinh( v / (2 v0) exp((mu0 + b ln(v0 theta / D_c)) / a) )

(:mod:`stickslip.models.friction.rate_state`, same parameters), and the state evolves by slip only:

    dtheta/dt = -(v theta / D_c) ln(v theta / D_c).

Read at abs(v), like the friction (Heun's predictor of a moving block may dip below v = 0 within a
step). At v = 0 the rate is 0 (the limit of x ln x): a stuck block does not heal, the slip law's
known difference from the aging law. In terms of Omega = v theta / D_c at a fixed velocity,
d ln(Omega) / d(slip) = -ln(Omega) / D_c: after a step of the velocity from V0 to V1, ln Omega
decays from ln(V1 / V0) as exp(-slip / D_c), so the friction's response to steps up and down is
symmetric in ln V (the aging law's is not; Ruina 1983, Ampuero & Rubin 2008).

Steady sliding, the start value theta_0 = D_c / V and the linearisation about steady sliding are
the aging law's: at v theta / D_c = 1 both laws have dg/dv = -1 / V and dg/dtheta = -V / D_c,
so the critical stiffness of the spring-slider is the same (Ruina 1983).
"""

from __future__ import annotations

import math

from stickslip.models.friction import rate_state as aging
from stickslip.models.piece import LabLaw, Piece, kernel_params, njit

READS = aging.READS
Params = kernel_params(__name__, READS)


@njit(cache=True, inline="always")
def accel(f, v, th, lp):
    """f - sigma_n mu(v, theta): the force on a moving block less its friction (the aging law's mu)."""
    return f - lp.sigma_n * aging.mu_lp(v, th, lp)


@njit(cache=True, inline="always")
def rate(thl, th, thr, v, lp):
    """Ruina's slip law dtheta/dt = -(v theta / D_c) ln(v theta / D_c), read at abs(v); 0 at v = 0."""
    w = abs(v) * th / lp.Dc
    # One return statement: numba inlines the law into the kernels.
    g = 0.0
    if w != 0.0:
        g = -w * math.log(w)
    return g


@njit(cache=True, inline="always")
def rate_lap(lap, th, v, lp):
    """:func:`rate`, which reads no neighbour: the law has no diffusion of theta (``lap`` unread;
    :mod:`stickslip.models.lattice`)."""
    return rate(th, th, th, v, lp)


@njit(cache=True, inline="always")
def lab_rate(x, th, cb, dtau):
    """Ruina's slip law as the lab writes it, dtheta/dt = -x ln x with x = v theta / D_c, 0 at x = 0
    (:class:`~stickslip.models.piece.LabLaw`; ``cb``, ``dtau`` unread)."""
    g = 0.0
    if x > 0.0:
        g = -x * math.log(x)
    return g


PIECE = Piece(
    "friction",
    "rate-state-slip",
    "sigma_n mu with mu = a asinh(v / (2 v0) exp((mu0 + b ln(v0 theta / D_c)) / a)); "
    "dtheta_i/dt = -(v_i theta_i / D_c) ln(v_i theta_i / D_c) (Ruina's slip law, regularised at v = 0)",
    READS,
    check=aging.check_v,
    has_state=True,
    rate_and_state=True,
    theta0=lambda p: p.Dc / p.V,
    theta_range=aging.PIECE.theta_range,
    steady=aging.steady_sliding,
    linear=aging.linearised,
    module=__name__,
    lab=LabLaw("slip", 1.0, "dtheta/dt = -(v theta / D_c) ln(v theta / D_c)", "Ruina 1983"),
    stability_extras=aging.extras,
    label=r"$\sigma_n\,[\mu_0 + a \ln(v/v_0) + b \ln(v_0\theta/D_c)]$, slip law",
)
