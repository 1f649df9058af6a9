"""The Dieterich-Ruina rate-and-state law, aging form, regularised at v = 0.

Friction force sigma_n mu(v, theta) on a moving block with

    mu(v, theta) = a asinh( v / (2 v0) exp(psi / a) ),   psi = mu0 + b ln(v0 theta / D_c)

(Rice & Ben-Zion 1996; Lapusta et al. 2000): for v >> v0 exp(-psi / a) it equals
mu0 + a ln(v / v0) + b ln(v0 theta / D_c) up to terms of relative size exp(-2 psi / a), and
mu = 0 at v = 0, so a block that starts from rest meets no friction at v = 0. Heun's predictor
may take a moving block's v below 0 within a step; the law is read at abs(v) there, so friction
keeps braking and the stop rule (v <= 0 at the end of the step) catches a block that stops.
The state follows the aging law dtheta/dt = 1 - v theta / D_c on every block: a stuck block
ages (theta grows by 1 per unit time). No diffusion.

Steady sliding at v = V: theta_0 = D_c / V and mu_ss = mu0 + (a - b) ln(V / v0) (regularised).
Runs start at theta_0 = D_c / V. The start rule is the constant threshold Fs (the state
threshold reads eq. (4)'s theta in [0, 1]); the stop rule is the family's (v <= 0 stops).
The spring-slider (N = 1, end drive, unit mass) is unstable below the critical stiffness
k_c = sigma_n (b - a) / D_c (1 + V^2 / (sigma_n a D_c)) (Rice & Ruina 1983): docs/models/rate-state.md.

Its compiled functions :func:`accel` and :func:`rate` are what every integrator evaluates
(contract in :mod:`stickslip.kernels.laws`); :func:`mu_lp` is the friction coefficient they share
with the slip law (:mod:`stickslip.models.friction.slip`).
"""

from __future__ import annotations

import math
from typing import Any

from stickslip.models.piece import LabLaw, Linearisation, Param, Piece, kernel_params, njit

READS = ("rs_a", "rs_b", "Dc", "v0", "mu0", "sigma_n")
Params = kernel_params(__name__, READS)

_LN2 = math.log(2.0)


@njit(cache=True, inline="always")
def mu_lp(v, th, lp):
    """mu = a asinh(abs(v) / (2 v0) exp((mu0 + b ln(v0 theta / D_c)) / a)) (module docstring), from
    the parameters ``lp`` (rs_a, rs_b, Dc, v0, mu0 by name).

    Read at abs(v): a moving block has v > 0, and where Heun's predictor dips below 0 within a step
    the friction keeps braking, so the stop rule catches a block that stops in the step (the odd
    extension would push it on into a spurious two-step cycle). Through log z: for z > e^20,
    asinh(z) = ln(2 z) to round-off, and exp cannot overflow.
    """
    s = 0.5 * abs(v) / lp.v0
    # One return statement: numba inlines the law into the kernels.
    mu = 0.0
    if s != 0.0:
        lz = math.log(s) + (lp.mu0 + lp.rs_b * math.log(lp.v0 * th / lp.Dc)) / lp.rs_a
        if lz > 20.0:
            mu = lp.rs_a * (lz + _LN2)
        else:
            mu = lp.rs_a * math.asinh(math.exp(lz))
    return mu


@njit(cache=True, inline="always")
def accel(f, v, th, lp):
    """f - sigma_n mu(v, theta): the force on a moving block less its rate-and-state friction."""
    return f - lp.sigma_n * mu_lp(v, th, lp)


@njit(cache=True, inline="always")
def rate(thl, th, thr, v, lp):
    """The aging law dtheta/dt = 1 - v theta / D_c, on moving and stopped blocks alike."""
    return 1.0 - v * th / lp.Dc


@njit(cache=True, inline="always")
def rate_lap(lap, th, v, lp):
    """:func:`rate`, which reads no neighbour: the law has no diffusion of theta (``lap`` unread;
    :mod:`stickslip.models.lattice`)."""
    return rate(th, th, th, v, lp)


@njit(cache=True, inline="always")
def lab_rate(x, th, cb, dtau):
    """The aging law as the lab writes it, dtheta/dt = 1 - x with x = v theta / D_c
    (:class:`~stickslip.models.piece.LabLaw`; ``cb``, ``dtau`` unread)."""
    return 1.0 - x


def psi(p: Any, theta: float) -> float:
    """psi / a with psi = mu0 + b ln(v0 theta / D_c): the exponent of the regularised law."""
    return (p.mu0 + p.rs_b * math.log(p.v0 * theta / p.Dc)) / p.rs_a


def mu(p: Any, v: float, theta: float) -> float:
    """mu(abs(v), theta) of the parameters ``p``: the kernels' :func:`mu_lp`."""
    return float(mu_lp(float(v), float(theta), PIECE.kernel_params(p)))


def steady_sliding(p: Any) -> tuple[float, float]:
    """theta_0 = D_c / V and c = sigma_n mu(V, theta_0)."""
    theta0 = p.Dc / p.V
    return p.sigma_n * mu(p, p.V, theta0), theta0


def linearised(p: Any) -> Linearisation:
    """The law linearised about steady sliding at v = V, theta_0 = D_c / V (the slip law's too:
    its dg/dv and dg/dtheta at steady state are the aging law's).

    With z = V / (2 v0) exp(psi / a) and r = z / sqrt(1 + z^2) (1 to round-off away from v = 0):
    dphi/dv = sigma_n a r / V, dphi/dtheta = sigma_n b r / theta_0; the aging law
    g = 1 - v theta / D_c gives dg/dv = -theta_0 / D_c = -1 / V and dg/dtheta = -V / D_c.
    """
    theta0 = p.Dc / p.V
    inv_z = 2.0 * p.v0 / p.V * math.exp(-psi(p, theta0))
    r = 1.0 / math.sqrt(1.0 + inv_z * inv_z)
    return Linearisation(
        theta0=theta0,
        phi_v=p.sigma_n * p.rs_a * r / p.V,
        phi_theta=p.sigma_n * p.rs_b * r / theta0,
        g_v=-theta0 / p.Dc,
        g_theta=-p.V / p.Dc,
    )


def critical_stiffness(p: Any) -> float:
    """k_c = sigma_n (b - a) / D_c (1 + V^2 / (sigma_n a D_c)) of the spring-slider, unit mass
    (Rice & Ruina 1983; the unregularised law): steady sliding is unstable for K < k_c.
    Negative for velocity strengthening (a > b): stable at every K."""
    return p.sigma_n * (p.rs_b - p.rs_a) / p.Dc * (1.0 + p.V**2 / (p.sigma_n * p.rs_a * p.Dc))


def extras(p: Any) -> dict[str, float]:
    """The spring-slider's critical stiffness in closed form, with and without inertia."""
    return {
        "k_c_spring_slider": critical_stiffness(p),
        "k_c_quasi_static": p.sigma_n * (p.rs_b - p.rs_a) / p.Dc,
    }


def check_v(p: Any) -> str | None:
    """Steady sliding and the start value theta_0 = D_c / V need V > 0."""
    if not p.V > 0.0:
        return f"friction {p.friction} needs V > 0 (runs start at theta = D_c / V; got V={p.V:g})"
    return None


PIECE = Piece(
    "friction",
    "rate-state",
    "sigma_n mu with mu = a asinh(v / (2 v0) exp((mu0 + b ln(v0 theta / D_c)) / a)); "
    "dtheta_i/dt = 1 - v_i theta_i / D_c (Dieterich-Ruina, aging law, regularised at v = 0)",
    READS,
    params=(
        Param(
            "rs_a", 0.01, "direct-effect coefficient a of rate-and-state friction", low=0.0, low_open=True, symbol=r"a"
        ),
        Param("rs_b", 0.015, "state-effect coefficient b of rate-and-state friction", low=0.0, symbol=r"b"),
        Param(
            "Dc",
            0.001,
            "characteristic slip distance D_c of rate-and-state friction",
            low=0.0,
            low_open=True,
            symbol=r"D_c",
        ),
        Param("v0", 0.001, "reference velocity v0 of rate-and-state friction", low=0.0, low_open=True, symbol=r"v_0"),
        Param(
            "mu0", 0.6, "friction coefficient mu0 at v = v0 in steady state (rate-and-state)", low=0.0, symbol=r"\mu_0"
        ),
        Param(
            "sigma_n",
            5.0,
            "normal stress sigma_n times the rate-and-state coefficient mu",
            low=0.0,
            low_open=True,
            symbol=r"\sigma_n",
        ),
    ),
    check=check_v,
    has_state=True,
    rate_and_state=True,
    theta0=lambda p: p.Dc / p.V,
    theta_range=(0.0, float("inf"), True),  # ln(v0 theta / D_c) needs theta > 0
    steady=steady_sliding,
    linear=linearised,
    module=__name__,
    lab=LabLaw("aging", 1.0, "dtheta/dt = 1 - v theta / D_c", "Dieterich 1979"),
    stability_extras=extras,
    label=r"$\sigma_n\,[\mu_0 + a \ln(v/v_0) + b \ln(v_0\theta/D_c)]$",
)
