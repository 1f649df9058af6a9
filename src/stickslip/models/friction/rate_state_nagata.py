"""Rate-and-state friction with the Nagata law (Nagata, Nakatani and Yoshida 2012), regularised at v = 0.

The friction is the aging law's, sigma_n mu(v, theta) with

    mu(v, theta) = a asinh( v / (2 v0) exp((mu0 + b ln(v0 theta / D_c)) / a) ),

and the state evolves by the aging law with a term in the shear-stress rate:

    dtheta/dt = 1 - v theta / D_c - (c / b) theta dmu/dt,   dmu/dt = (df/dt) / sigma_n,

where df/dt is the rate of the elastic force on the block: the springs' and the drive's,

    df_i/dt = K (v_{i-1} - 2 v_i + v_{i+1}) [+ Kp (V - v_i) with the plate drive],

with v_0 the pulling point's velocity V (the load history's dp/dt) at the end drive. That is the
rate of the force the friction balances when the block's inertia is negligible: for the
spring-slider (N = 1, end drive, free end) it is K (V - v), which in the mass -> 0 limit is the
laboratory's dtau/dt = k (V - v) (:mod:`stickslip.lab.compiled`, ``nagata``), so the inertial route
tends to the quasi-static one. The kernels build it only for this law (``PIECE.context``,
:func:`stickslip.kernels.laws._dtheta_in`) and pass it to :func:`rate` as ``ctx.stress_rate``.

With c = 0 the law is the aging law (:mod:`stickslip.models.friction.rate_state`), to the bit: the
stress term is skipped there. A stuck block ages at dtheta/dt = 1 - (c / b) theta dmu/dt: loaded at
a constant stress rate its theta relaxes towards b sigma_n / (c df/dt). Steady sliding at v = V:
the stress is constant, theta_0 = D_c / V and mu_ss = mu0 + (a - b) ln(V / v0) (c drops out).
Linearised about steady sliding, g depends on the neighbours' velocities through df/dt, which
:class:`~stickslip.models.piece.Linearisation` does not hold: the stability analysis refuses the
law (:func:`linearised`); the spring-slider's critical stiffness with mass M (per unit normal
stress, sigma_n = 1) is k_c = (b - a) (a D_c + M V^2) / (D_c (a D_c (1 + c) + c M V^2)), the
laboratory's (b - a) / (D_c (1 + c)) at M = 0 (docs/models/rate-state.md, "The Nagata law").
"""

from __future__ import annotations

from typing import Any

from stickslip.models.friction import rate_state as aging
from stickslip.models.piece import LabLaw, Param, Piece, kernel_params, njit

READS = (*aging.READS, "rs_c")
Params = kernel_params(__name__, READS)
#: What :func:`rate` reads besides the block's own values (:attr:`~stickslip.models.piece.Piece.context`).
CONTEXT = ("stress_rate",)


@njit(cache=True, inline="always")
def accel(f, v, th, lp):
    """f - sigma_n mu(v, theta): the aging law's friction (:func:`~stickslip.models.friction.rate_state.mu_lp`)."""
    return f - lp.sigma_n * aging.mu_lp(v, th, lp)


@njit(cache=True, inline="always")
def rate(thl, th, thr, v, lp, ctx):
    """The Nagata law dtheta/dt = 1 - v theta / D_c - (c / b) theta (df/dt) / sigma_n, with
    df/dt = ``ctx.stress_rate`` (module docstring), on moving and stopped blocks alike; the aging
    law's rate to the bit where c = 0."""
    w = 0.0
    if lp.rs_c != 0.0:
        w = lp.rs_c / lp.rs_b * th * ctx.stress_rate / lp.sigma_n
    return (1.0 - v * th / lp.Dc) - w


@njit(cache=True, inline="always")
def lab_rate(x, th, cb, dtau):
    """The Nagata law as the lab writes it, dtheta/dt = 1 - x - (c / b) theta dtau/dt with
    x = v theta / D_c, ``cb`` = c / b and ``dtau`` the rate of the spring's friction k (V - v)
    (:class:`~stickslip.models.piece.LabLaw`)."""
    return 1.0 - x - cb * th * dtau


def steady_sliding(p: Any) -> tuple[float, float]:
    """theta_0 = D_c / V and c = sigma_n mu(V, theta_0): the aging law's (the stress term vanishes)."""
    return aging.steady_sliding(p)


def linearised(p: Any):
    """Refused: the law's rate reads the neighbours' velocities (module docstring).

    Raises
    ------
    ParameterError
        Always, in one line.
    """
    from stickslip.models.params import ParameterError  # params imports the pieces

    raise ParameterError(
        f"friction {p.friction} has no linearisation here (its rate reads the stress rate); "
        "its spring-slider's k_c is in docs/models/rate-state.md"
    )


def critical_stiffness(p: Any) -> float:
    """k_c = sigma_n (b - a) (a D_c + M V^2 / sigma_n) / (D_c (a D_c (1 + c) + c M V^2 / sigma_n))
    of the spring-slider with mass M (module docstring): the Hopf point of the characteristic cubic
    M l^3 + (a s / V + M V / D_c) l^2 + (K (1 + c) + s (a - b) / D_c) l + K V / D_c = 0, s = sigma_n.
    Negative for velocity strengthening (a > b)."""
    s, a, b, c, dc = p.sigma_n, p.rs_a, p.rs_b, p.rs_c, p.Dc
    mv2 = float(p.M) * p.V**2 / s
    return s * (b - a) * (a * dc + mv2) / (dc * (a * dc * (1.0 + c) + c * mv2))


def extras(p: Any) -> dict[str, float]:
    """The spring-slider's critical stiffness in closed form, with and without inertia."""
    return {
        "k_c_spring_slider": critical_stiffness(p),
        "k_c_quasi_static": p.sigma_n * (p.rs_b - p.rs_a) / (p.Dc * (1.0 + p.rs_c)),
    }


def check(p: Any) -> str | None:
    """V > 0 (the start value theta_0 = D_c / V), and b > 0 where c != 0 (the term is c / b)."""
    if not p.V > 0.0:
        return f"friction {p.friction} needs V > 0 (runs start at theta = D_c / V; got V={p.V:g})"
    if p.rs_c != 0.0 and not p.rs_b > 0.0:
        return (
            f"friction {p.friction} needs rs_b > 0 where rs_c != 0 "
            f"(its term is (c / b) theta dmu/dt; got rs_b={p.rs_b:g})"
        )
    return None


PIECE = Piece(
    "friction",
    "rate-state-nagata",
    "sigma_n mu with mu = a asinh(v / (2 v0) exp((mu0 + b ln(v0 theta / D_c)) / a)); "
    "dtheta_i/dt = 1 - v_i theta_i / D_c - (c / b) theta_i (df_i/dt) / sigma_n, df_i/dt the rate of "
    "the elastic force on block i (Nagata law, regularised at v = 0)",
    READS,
    params=(
        Param(
            "rs_c",
            2.0,
            "Nagata's stress-rate coefficient c of rate-and-state friction (friction rate-state-nagata)",
            low=0.0,
            symbol=r"c",
        ),
    ),
    check=check,
    has_state=True,
    rate_and_state=True,
    context=CONTEXT,
    theta0=aging.PIECE.theta0,
    theta_range=aging.PIECE.theta_range,
    steady=steady_sliding,
    linear=linearised,
    module=__name__,
    lab=LabLaw("nagata", 1.0, "dtheta/dt = 1 - v theta / D_c - (c / b) theta dtau/dt", "Nagata et al. 2012"),
    stability_extras=extras,
    label=r"$\sigma_n\,[\mu_0 + a \ln(v/v_0) + b \ln(v_0\theta/D_c)]$, Nagata law",
)
