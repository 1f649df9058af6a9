"""Linear stability of steady sliding: the single block (eq. 2) and the chain (eq. 5, Fig. 4).

Single block. Steady sliding v_0 = V, theta_0 = 1 - alpha V (section 2). Eq. (1) linearised
about it, in the variables (dx, dv, dtheta) and with general M, sigma, alpha, is

    d dx/dt     = dv
    M d dv/dt   = -K dx - sigma dtheta - beta dv
    d dtheta/dt = (1 - 2 theta_0 - alpha v_0) dtheta - alpha theta_0 dv

(eq. (2) of the paper is the case M = sigma = alpha = 1). Its characteristic polynomial is the
cubic lambda^3 + a1 lambda^2 + a2 lambda + a3 with, for theta_0 = 1 - alpha V,
a1 = beta/M + theta_0, a2 = (K + theta_0 (beta - sigma alpha)) / M, a3 = K theta_0 / M, and
the Routh-Hurwitz condition a1 a2 > a3 reads

    beta K / M + theta_0 (beta - sigma alpha) (beta / M + theta_0) > 0.

A Hopf point V_c exists only for beta < sigma alpha; for beta >= sigma alpha (the paper's
beta = 1) steady sliding is stable at every V > 0. For alpha V >= 1 the branch 1 - alpha V is
negative and the physical steady state is theta_0 = 0 (fully melted surface).

Chain. A Fourier mode exp(i k j) of eq. (5), k the lattice wavenumber in [0, pi], turns both
discrete Laplacians into -q with q = 2 (1 - cos k); its 3 x 3 mode matrix gives Fig. 4. At
k -> 0 one eigenvalue vanishes like -K k^2 / (beta - alpha), so long waves are unstable
exactly for beta < alpha, independent of K, D and V (the derivation is in docs/stability.md).
The finite chain with the ends of docs/model.md has a 3N x 3N matrix, :func:`chain_jacobian`
(:mod:`stickslip.analysis.dynamics.jacobian`, assembled from the pieces).
Both read the friction law's linearisation (:class:`~stickslip.models.piece.Linearisation`), so a
law with a state variable other than eq. (4)'s (rate-and-state) gets its mode matrices, finite
Jacobian and critical spring constant (:func:`critical_stiffness`) from the same code.

Relatives without state variable (docs/model.md, "The family the paper stands in"): the plate drive
of Carlson-Langer (weakening friction) and the train model (strengthening friction). Each normal
mode obeys lambda^2 + phi'(V) lambda + w_k^2 = 0, w_k^2 = Kp + 4 K sin^2(k/2) (no Kp for the end
drive): :func:`mode_stability`, checked against the 2N x 2N matrix :func:`chain_jacobian_2n`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
import xarray as xr
from scipy.optimize import brentq

from stickslip.analysis.dynamics.jacobian import chain_jacobian  # noqa: F401  (the one builder, from the pieces)
from stickslip.analysis.dynamics.linear import GROWTH_TOL, _sorted_by_real_part, finite_chain_wavenumbers, lattice_q

# The relatives without a state variable live in stability_modes; their names stay importable here.
from stickslip.analysis.dynamics.stability_modes import (  # noqa: F401
    ModeStability,
    chain_jacobian_2n,
    friction_slope,
    mode_dispersion,
    mode_frequency_squared,
    mode_growth_rates,
    mode_roots,
    mode_stability,
    normal_modes,
    weakening_g,
)
from stickslip.models.params import BlockParams, ChainParams
from stickslip.models.physics import block_steady_state
from stickslip.models.piece import Linearisation


def steady_theta(V: float, alpha: float) -> float:
    """The stable steady state of the theta equation at v = V (section 2).

    theta (1 - theta) = alpha theta V has the roots 1 - alpha V and 0; the first is the
    paper's theta_0 while it is positive, the melted state 0 beyond alpha V = 1.
    """
    return max(1.0 - alpha * V, 0.0)


# ---------------------------------------------------------------------------------------------
# Single block, eq. (2)
# ---------------------------------------------------------------------------------------------


def block_jacobian(p: BlockParams) -> np.ndarray:
    """The 3 x 3 matrix of eq. (2), variables (dx, dv, dtheta), general M, sigma, alpha."""
    theta0 = max(block_steady_state(p)["theta"], 0.0)  # melted branch beyond alpha V = 1
    return np.array(
        [
            [0.0, 1.0, 0.0],
            [-p.K / p.M, -p.beta / p.M, -p.sigma / p.M],
            [0.0, -p.alpha * theta0, 1.0 - 2.0 * theta0 - p.alpha * p.V],
        ]
    )


def block_eigenvalues(p: BlockParams) -> np.ndarray:
    """Eigenvalues of the linearised block, eq. (2), largest real part first."""
    return _sorted_by_real_part(np.linalg.eigvals(block_jacobian(p)))


def block_characteristic_polynomial(p: BlockParams) -> np.ndarray:
    """Coefficients [1, a1, a2, a3] of det(lambda - J) for eq. (2) (valid for alpha V <= 1)."""
    theta0 = steady_theta(p.V, p.alpha)
    return np.array(
        [
            1.0,
            p.beta / p.M + theta0,
            (p.K + theta0 * (p.beta - p.sigma * p.alpha)) / p.M,
            p.K * theta0 / p.M,
        ]
    )


@dataclass(frozen=True)
class BlockStability:
    """Linear stability of steady sliding of the block at one V (eq. 2).

    ``eigenvalues`` are sorted by real part, largest first; ``growth_rate`` is the largest real
    part; ``stable`` means growth_rate < 0 (beyond round-off).
    """

    V: float
    theta0: float
    eigenvalues: np.ndarray
    growth_rate: float
    stable: bool


def block_stability(p: BlockParams) -> BlockStability:
    """Eigenvalues and stability of steady sliding of the block at p.V, eq. (2)."""
    eig = block_eigenvalues(p)
    growth = float(eig[0].real)
    return BlockStability(
        V=p.V,
        theta0=steady_theta(p.V, p.alpha),
        eigenvalues=eig,
        growth_rate=growth,
        stable=growth < -GROWTH_TOL,
    )


def _block_growth(p: BlockParams, V: np.ndarray) -> np.ndarray:
    """Largest real part of the eq. (2) eigenvalues at each V (vectorised over V)."""
    theta0 = np.maximum(1.0 - p.alpha * V, 0.0)
    J = np.zeros((V.size, 3, 3))
    J[:, 0, 1] = 1.0
    J[:, 1, 0] = -p.K / p.M
    J[:, 1, 1] = -p.beta / p.M
    J[:, 1, 2] = -p.sigma / p.M
    J[:, 2, 1] = -p.alpha * theta0
    J[:, 2, 2] = 1.0 - 2.0 * theta0 - p.alpha * V
    return np.linalg.eigvals(J).real.max(axis=-1)


@dataclass(frozen=True)
class HopfPoint:
    """The Hopf point of steady sliding of the block, section 2 (eq. 2).

    ``V`` is the pulling velocity V_c at which a complex pair crosses the imaginary axis
    (None where there is none), ``theta0`` the steady state there and ``omega`` the frequency
    of the pair. ``regime`` says in words what holds over 0 < V < 1/alpha.
    """

    V: float | None
    theta0: float | None
    omega: float | None
    regime: str


def _v_scan(alpha: float) -> np.ndarray:
    """Pulling velocities covering 0 < V < 1/alpha, dense near both ends.

    theta_0 stays >= 1e-4: closer to 1/alpha the margin a1 a2 - a3 is O(theta_0^2) and its
    sign is lost in round-off; a Hopf point there needs beta < 1e-8 sigma alpha M / K.
    """
    theta = np.unique(np.concatenate([np.geomspace(1e-4, 0.5, 300), 1.0 - np.geomspace(1e-9, 0.5, 300)]))
    return np.sort((1.0 - theta) / alpha)


def hopf_point(p: BlockParams) -> HopfPoint:
    """Hopf point V_c of the block by root finding on the largest real part of eq. (2).

    The growth rate is scanned over 0 < V < 1/alpha (beyond it the melted steady state
    theta_0 = 0 has the eigenvalues 1 - alpha V and those of M x'' = -K x - beta x', all
    stable), and each sign change is refined with Brent's method. The paper: V_c = 0.106 at
    K = 10, beta = 0.08; none at beta = 1 (stable for all V > 0). p.V is not read.
    """
    if p.alpha == 0.0:
        # theta_0 = 1 whatever V: the linearisation does not depend on V.
        growth = float(_block_growth(p, np.array([0.0]))[0])
        word = "stable" if growth < -GROWTH_TOL else "not stable"
        return HopfPoint(None, None, None, f"no Hopf point: alpha = 0, {word} for every V")
    V = _v_scan(p.alpha)
    growth = _block_growth(p, V)
    unstable = growth > 0.0
    if not unstable.any():
        return HopfPoint(None, None, None, "no Hopf point: stable for every 0 < V")
    if unstable.all():
        return HopfPoint(None, None, None, "no Hopf point: unstable for every 0 < V < 1/alpha")
    flips = np.flatnonzero(unstable[:-1] != unstable[1:])
    # The Routh-Hurwitz margin is monotone in theta_0, so there is one crossing; take the last.
    i = flips[-1]
    Vc = brentq(lambda v: float(_block_growth(p, np.array([v]))[0]), V[i], V[i + 1], xtol=1e-14, rtol=1e-14)
    eig = block_eigenvalues(p.replace(V=Vc))
    side = "V < V_c" if unstable[i] else "V > V_c"
    return HopfPoint(
        V=float(Vc),
        theta0=steady_theta(Vc, p.alpha),
        omega=float(abs(eig[0].imag)),
        regime=f"steady sliding unstable for {side}, stable beyond",
    )


def hopf_point_closed_form(p: BlockParams) -> float | None:
    """V_c from the Routh-Hurwitz condition of the cubic of eq. (2) (see the module docstring).

    With b = beta/M, k = K/M, a = sigma alpha / M: b k + theta_0 (b - a)(b + theta_0) = 0 gives
    theta_c = (-b + sqrt(b^2 + 4 b k / (a - b))) / 2 and V_c = (1 - theta_c) / alpha, which lies
    in 0 < V < 1/alpha only for 0 < b < a and theta_c < 1. None where there is no Hopf point.
    """
    b, k, a = p.beta / p.M, p.K / p.M, p.sigma * p.alpha / p.M
    if p.alpha == 0.0 or not 0.0 < b < a:
        return None
    theta_c = 0.5 * (-b + np.sqrt(b * b + 4.0 * b * k / (a - b)))
    if theta_c >= 1.0:
        return None
    return float((1.0 - theta_c) / p.alpha)


def hopf_beta_limit(p: BlockParams) -> float:
    """Largest beta with a Hopf point at p's K, M, sigma, alpha: where V_c(beta) reaches 0.

    Setting theta_0 = 1 in the Routh-Hurwitz margin, b^2 + b (1 - a + k) - a = 0 with
    b = beta/M, k = K/M, a = sigma alpha/M; 0.0990 for the paper's K = 10.
    """
    a, k = p.sigma * p.alpha / p.M, p.K / p.M
    s = 1.0 - a + k
    return float(p.M * 0.5 * (-s + np.sqrt(s * s + 4.0 * a)))


def hopf_curve(p: BlockParams, beta: np.ndarray) -> xr.Dataset:
    """The stability map of section 2: the Hopf curve V_c(beta) at p's K (and M, sigma, alpha).

    Returns a Dataset over ``beta`` with ``V_c`` (root finding, NaN where there is no Hopf
    point) and ``V_c_closed_form``. Steady sliding is unstable below the curve.
    """
    beta = np.asarray(beta, dtype=float)
    numeric, closed = [], []
    for b in beta:
        q = p.replace(beta=float(b))
        hp = hopf_point(q)
        cf = hopf_point_closed_form(q)
        numeric.append(np.nan if hp.V is None else hp.V)
        closed.append(np.nan if cf is None else cf)
    return xr.Dataset(
        {
            "V_c": ("beta", np.array(numeric), {"long_name": "Hopf point V_c (root finding)"}),
            "V_c_closed_form": ("beta", np.array(closed), {"long_name": "Hopf point V_c (Routh-Hurwitz)"}),
        },
        coords={"beta": ("beta", beta, {"long_name": "viscous friction beta"})},
        attrs={
            k: v if isinstance(v, str) else float(v)
            for k, v in p.to_dict().items()
            if k not in ("V", "beta", "Fs", "dt")
        },
    )


def block_growth_map(p: BlockParams, beta: np.ndarray, V: np.ndarray) -> xr.DataArray:
    """Largest real part of the eq. (2) eigenvalues over a (beta, V) grid (stability map)."""
    beta = np.asarray(beta, dtype=float)
    V = np.asarray(V, dtype=float)
    rows = [_block_growth(p.replace(beta=float(b)), V) for b in beta]
    return xr.DataArray(
        np.array(rows),
        dims=("beta", "V"),
        coords={"beta": beta, "V": V},
        name="growth_rate",
        attrs={"long_name": "largest Re(lambda) of eq. (2)"},
    )


# ---------------------------------------------------------------------------------------------
# Chain, eq. (5) and Fig. 4
# ---------------------------------------------------------------------------------------------


def _linear(p: ChainParams) -> Linearisation:
    """The friction law linearised at steady sliding; refused for laws without theta."""
    linear = p.friction_piece.linear
    if linear is None:
        raise ValueError(f"friction {p.friction} has no state variable: use mode_stability")
    return linear(p)


def chain_mode_matrix(p: ChainParams, k: np.ndarray | float) -> np.ndarray:
    """The 3 x 3 matrix of eq. (5) for the Fourier mode exp(i k j), shape (..., 3, 3).

    Variables (dx, dv, dtheta); both Laplacians give -q = -2 (1 - cos k). For friction
    phi(v, theta) and state law g(v, theta) (+ D times the Laplacian) linearised at steady
    sliding (:class:`~stickslip.models.piece.Linearisation`):
    dx' = dv, dv' = -K q dx - phi_v dv - phi_theta dtheta,
    dtheta' = (g_theta - D q) dtheta + g_v dv. For eq. (4)'s law phi_v = beta, phi_theta = 1,
    g_v = -alpha theta_0, g_theta = 1 - 2 theta_0 - alpha V: eq. (5).
    """
    q = lattice_q(k)
    lin = _linear(p)
    A = np.zeros(q.shape + (3, 3))
    A[..., 0, 1] = 1.0
    A[..., 1, 0] = -p.K * q
    A[..., 1, 1] = -lin.phi_v
    A[..., 1, 2] = -lin.phi_theta
    A[..., 2, 1] = lin.g_v
    A[..., 2, 2] = lin.g_theta - lin.diffusion * q
    return A


def chain_dispersion(p: ChainParams, k: np.ndarray) -> xr.Dataset:
    """Eigenvalues of the Fourier modes of eq. (5) against k (Fig. 4).

    Returns a Dataset over (k, branch) with ``real`` and ``imag``; branch 0 has the largest
    real part, branch 1 the second largest (the two curves of Fig. 4).
    """
    k = np.asarray(k, dtype=float)
    eig = _sorted_by_real_part(np.linalg.eigvals(chain_mode_matrix(p, k)))
    return xr.Dataset(
        {
            "real": (("k", "branch"), eig.real, {"long_name": "Re(lambda)"}),
            "imag": (("k", "branch"), eig.imag, {"long_name": "Im(lambda)"}),
        },
        coords={
            "k": ("k", k, {"long_name": "lattice wavenumber k"}),
            "branch": ("branch", np.arange(3)),
        },
        attrs={
            name: v if isinstance(v, str) else float(v)
            for name, v in p.to_dict().items()
            if name not in ("N", "Fs", "dt")
        },
    )


def chain_k_grid(n: int = 600) -> np.ndarray:
    """Wavenumbers in (0, pi]: geometric from 1e-4 (the long-wave limit) and uniform beyond."""
    return np.unique(np.concatenate([np.geomspace(1e-4, 0.1, n // 3), np.linspace(0.0, np.pi, n)[1:]]))


def chain_critical_beta(p: ChainParams) -> float:
    """Critical beta of the long-wave instability in closed form (Fig. 4; docs/stability.md).

    beta_c = alpha for 0 <= alpha V < 1, whatever K > 0, D and V: long waves are unstable for
    beta < alpha and every k > 0 is stable for beta >= alpha. On the melted branch
    (alpha V >= 1, theta_0 = 0) the state variable decouples and beta_c = 0.

    Parameters
    ----------
    p : ChainParams
        The chain of eq. (4) (its alpha and V).

    Returns
    -------
    float
        beta_c (1 for the paper's alpha = 1).
    """
    return p.alpha if p.alpha * p.V < 1.0 else 0.0


def chain_long_wave(p: ChainParams) -> dict[str, float]:
    """The k -> 0 limit of eq. (5) in closed form (docs/stability.md).

    At k = 0 the mode matrix has the eigenvalue 0 (rigid translation) and the roots of
    lambda^2 + (beta + theta_0) lambda + theta_0 (beta - alpha) = 0 (the uniform sliding
    velocity with the steady-state friction slope beta - alpha). For beta != alpha the zero
    eigenvalue moves to lambda = c2 k^2 + O(k^4) with c2 = -K / (beta - alpha).
    Returns c2 (NaN at beta = alpha, where the expansion is in k, not k^2), the two k = 0
    roots, critical_beta and theta0.
    """
    theta0 = steady_theta(p.V, p.alpha)
    slope = p.beta - p.alpha
    b = p.beta + theta0
    disc = np.sqrt(complex(b * b - 4.0 * theta0 * slope))
    roots = sorted([(-b + disc) / 2.0, (-b - disc) / 2.0], key=lambda z: -z.real)
    return {
        "theta0": theta0,
        "c2": -p.K / slope if slope != 0.0 and theta0 > 0.0 else float("nan"),
        "uniform_root_1": float(roots[0].real),
        "uniform_root_2": float(roots[1].real),
        "critical_beta": chain_critical_beta(p),
    }


@dataclass(frozen=True)
class ChainStability:
    """Linear stability of steady sliding of the chain over Fourier modes (eq. 5, Fig. 4).

    ``max_growth_rate`` is the largest real part over 0 < k <= pi (the trivial translation mode
    at k = 0 is left out) and ``k_at_max`` where it is reached. ``unstable`` means it is
    positive; ``marginal`` that beta equals the critical value, where Re(lambda) -> 0 as
    k -> 0 and is negative for every k > 0 (the paper counts beta = 1 as unstable, "beta <= 1").
    """

    beta: float
    critical_beta: float
    critical_beta_numeric: float
    max_growth_rate: float
    k_at_max: float
    unstable: bool
    marginal: bool


def _max_fourier_growth(p: ChainParams, k: np.ndarray) -> tuple[float, float]:
    re = np.linalg.eigvals(chain_mode_matrix(p, k)).real.max(axis=-1)
    i = int(np.argmax(re))
    return float(re[i]), float(k[i])


def chain_critical_beta_numeric(p: ChainParams, k: np.ndarray | None = None) -> float:
    """Critical beta from the mode matrices: the beta where max_k Re(lambda) changes sign.

    Brent's method on beta over [0, 2 alpha + 1] with the k grid of :func:`chain_k_grid`
    (smallest k = 1e-4), so the result differs from the closed form by O((K + D) k_min^2).
    NaN where the bracket has no sign change (e.g. alpha = 0: stable at every beta > 0).
    """
    k = chain_k_grid() if k is None else np.asarray(k, dtype=float)

    def growth(beta: float) -> float:
        return _max_fourier_growth(p.replace(beta=beta), k)[0]

    lo, hi = 0.0, 2.0 * p.alpha + 1.0
    if not (growth(lo) > 0.0 > growth(hi)):
        return float("nan")
    return float(brentq(growth, lo, hi, xtol=1e-12, rtol=1e-12))


def chain_stability(p: ChainParams, k: np.ndarray | None = None) -> ChainStability:
    """Stability of steady sliding of the chain over its Fourier modes (eq. 5, Fig. 4)."""
    k = chain_k_grid() if k is None else np.asarray(k, dtype=float)
    growth, k_max = _max_fourier_growth(p, k)
    beta_c = chain_critical_beta(p)
    return ChainStability(
        beta=p.beta,
        critical_beta=beta_c,
        critical_beta_numeric=chain_critical_beta_numeric(p, k),
        max_growth_rate=growth,
        k_at_max=k_max,
        unstable=growth > GROWTH_TOL,
        marginal=bool(np.isclose(p.beta, beta_c, rtol=0.0, atol=1e-12)),
    )


def chain_finite_eigenvalues(p: ChainParams) -> np.ndarray:
    """Eigenvalues of the finite linearised chain about steady sliding (:func:`chain_jacobian`:
    eq. (5) with the ends of docs/model.md, or the law's linearisation for another friction).

    Parameters
    ----------
    p : ChainParams
        The chain; N = 1 is the spring-slider.

    Returns
    -------
    numpy.ndarray
        The 3N complex eigenvalues, largest real part first: steady sliding is linearly stable
        when the first has a negative real part.

    Examples
    --------
    >>> from stickslip import chain_params
    >>> from stickslip.analysis.dynamics.stability import chain_finite_eigenvalues
    >>> bool(chain_finite_eigenvalues(chain_params(N=9, beta=1.2))[0].real < 0)
    True
    """
    return _sorted_by_real_part(np.linalg.eigvals(chain_jacobian(p)))


def critical_stiffness(p: ChainParams) -> float:
    """Critical spring constant K_c of steady sliding of the finite chain (end drive, free end).

    The K at which the largest real part of the eigenvalues of :func:`chain_jacobian` crosses zero
    (a Hopf point): steady sliding is unstable for K < K_c. For the spring-slider (N = 1) with
    rate-and-state friction this is k_c = sigma_n (b - a) / D_c (1 + V^2 / (sigma_n a D_c))
    (Rice & Ruina 1983; docs/models/rate-state.md). Brent's method on K, bracketed by halving and
    doubling from K = 1.

    Parameters
    ----------
    p : ChainParams
        The chain (its K is the unknown).

    Returns
    -------
    float
        K_c; NaN where no bracket is found (steady sliding stable at every K, as with velocity
        strengthening, or unstable at every K).

    Examples
    --------
    >>> from stickslip import chain_params
    >>> from stickslip.analysis.dynamics.stability import critical_stiffness
    >>> round(critical_stiffness(chain_params(friction="rate-state", N=1)), 9)
    25.5
    """

    def growth(K: float) -> float:
        return float(chain_finite_eigenvalues(p.replace(K=K))[0].real)

    lo, hi = 1.0, 1.0
    for _ in range(80):
        if growth(lo) > GROWTH_TOL:  # beyond round-off of the translation mode near K = 0
            break
        lo *= 0.5
    else:
        return float("nan")
    for _ in range(80):
        if growth(hi) < 0.0:
            break
        hi *= 2.0
    else:
        return float("nan")
    if hi < lo:
        return float("nan")
    return float(brentq(growth, lo, hi, xtol=1e-14, rtol=1e-13))


def compare_fourier_finite(p: ChainParams, Ns: list[int] | tuple[int, ...]) -> pd.DataFrame:
    """The finite chain's least stable eigenvalue against the Fourier branch (eq. 5).

    For each N: ``finite_max_real`` (largest real part of the 3N x 3N matrix), ``fourier_k1``
    (largest real part of the mode matrix at k_1 = pi / (2N + 1)), ``fourier_on_grid`` (largest
    over the N wavenumbers k_m of the chain) and ``fourier_sup`` (over all 0 < k <= pi).
    The x and theta Laplacians have different end conditions, so the match is exact only at
    D = 0 and approaches it as N grows.
    """
    rows = []
    sup = _max_fourier_growth(p, chain_k_grid())[0]
    for N in Ns:
        q = p.replace(N=int(N))
        km = finite_chain_wavenumbers(int(N))
        re_m = np.linalg.eigvals(chain_mode_matrix(q, km)).real.max(axis=-1)
        rows.append(
            {
                "N": int(N),
                "beta": p.beta,
                "finite_max_real": float(chain_finite_eigenvalues(q)[0].real),
                "fourier_k1": float(re_m[0]),
                "fourier_on_grid": float(re_m.max()),
                "fourier_sup": sup,
            }
        )
    return pd.DataFrame(rows)


#: The three values of beta of Fig. 4 (K = 10, D = 5).
FIG4_BETAS = (0.5, 1.0, 1.5)


def fig4_data(p: ChainParams, betas=FIG4_BETAS, k: np.ndarray | None = None) -> xr.Dataset:
    """Fig. 4: Re and Im of the eigenvalues of the Fourier modes of eq. (5) for several beta.

    A Dataset over (beta, k, branch), branch 0 and 1 being the two largest real parts; k is
    the lattice wavenumber on [0, pi] (k = 0 included: there the translation mode is 0).
    """
    k = np.linspace(0.0, np.pi, 629) if k is None else np.asarray(k, dtype=float)
    parts = [chain_dispersion(p.replace(beta=float(b)), k) for b in betas]
    ds = xr.concat(parts, dim=xr.DataArray(np.asarray(betas, dtype=float), dims="beta", name="beta"))
    ds.attrs.pop("beta", None)
    return ds
