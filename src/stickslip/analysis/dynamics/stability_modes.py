"""Linear stability of the relatives without a state variable (docs/model.md, "The family the
paper stands in"): the plate drive of Carlson-Langer (weakening friction) and the train model
(strengthening friction). Each normal mode obeys lambda^2 + phi'(V) lambda + w_k^2 = 0,
w_k^2 = Kp + 4 K sin^2(k/2) (no Kp for the end drive); phi'(V) is the friction piece's slope.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
import xarray as xr

from stickslip.analysis.dynamics.jacobian import chain_jacobian
from stickslip.analysis.dynamics.linear import GROWTH_TOL, _sorted_by_real_part, finite_chain_wavenumbers, lattice_q
from stickslip.models import physics, pieces
from stickslip.models.params import ChainParams

# ---------------------------------------------------------------------------------------------
# The relatives without a state variable: plate drive (Carlson-Langer) and the train model
# ---------------------------------------------------------------------------------------------
#
# With friction weakening (CL's phi) or strengthening (F0 + beta v) a moving block has no state
# variable, and steady sliding v_i = V of every block, linearised, is
#     d dx_i/dt = dv_i,  d dv_i/dt = K (dx_{i-1} - 2 dx_i + dx_{i+1}) - Kp dx_i - phi'(V) dv_i
# (the Kp term only for the plate drive). A normal mode of the spring Laplacian with -q_k,
# q_k = 4 sin^2(k/2), has w_k^2 = Kp + K q_k and obeys lambda^2 + phi'(V) lambda + w_k^2 = 0.


def friction_slope(p: ChainParams) -> float:
    """phi'(V): slope of the moving friction at steady sliding (weakening or strengthening).

    Weakening (CL), phi(v) = (1 - sigma) / (1 + 2 alpha v / (1 - sigma)): phi'(V) = -2 alpha g
    with g = (1 + 2 alpha V / (1 - sigma))^-2. Strengthening (train), F0 + beta v: beta.
    """
    slope = p.friction_piece.slope
    if slope is not None:
        if p.drive_piece.applied is not None:
            # A force drive: the slope at the velocity where friction balances the force.
            return slope(physics.BlockView(p, 0, V=physics.steady_velocity(p)))
        return slope(p)
    raise ValueError(f"friction {p.friction} has a state variable: use chain_mode_matrix (eq. 5)")


def weakening_g(p: ChainParams) -> float:
    """g = (1 + 2 alpha V / (1 - sigma))^-2 of CL's velocity weakening; -phi'(V) = 2 alpha g."""
    return pieces.weakening_g(p)


def normal_modes(p: ChainParams) -> tuple[np.ndarray, str]:
    """Wavenumbers k of the normal modes of the finite chain's spring Laplacian, and their kind.

    Plate drive: periodic ends k = 2 pi j / N (j = 0..N-1, ``exp(i k j)``); free ends
    (x_0 = x_1, x_{N+1} = x_N) the cosine modes k = pi j / N (j = 0..N-1). End drive, free end
    (dx_0 = 0, dx_{N+1} = dx_N): the sine modes k_m = (2m - 1) pi / (2N + 1), m = 1..N.
    Fixed ends have no steady sliding (a spring to a fixed wall stretches for ever): refused.
    """
    N = p.N
    if not p.ends_piece.steady_sliding:
        raise ValueError(f"ends {p.ends} have no steady sliding (the springs to the walls stretch without bound)")
    if not physics.has_steady_state(p):
        raise ValueError(f"drive {p.drive} has no steady sliding")
    on_ghost = physics.ghost_rows(p)["x0"] != (0.0, 0.0)  # x_0 is not the pulling point
    if on_ghost and p.ends_piece.ring:
        return 2.0 * np.pi * np.arange(N) / N, "periodic: exp(i k j), k = 2 pi j / N, j = 0..N-1"
    if on_ghost:
        return np.pi * np.arange(N) / N, "free ends: cos(k (i - 1/2)), k = pi j / N, j = 0..N-1"
    return finite_chain_wavenumbers(N), "end drive, free end: sin(k i), k = (2m - 1) pi / (2N + 1), m = 1..N"


def mode_frequency_squared(p: ChainParams, k: np.ndarray | float) -> np.ndarray:
    """w_k^2 = Kp + 4 K sin^2(k/2) for the plate drive, 4 K sin^2(k/2) for the end drive (the
    drive's stiffness, :func:`stickslip.models.physics.drive_stiffness`)."""
    return float(physics.drive_stiffness(p)[0]) + p.K * lattice_q(k)


def mode_roots(p: ChainParams, k: np.ndarray | float) -> np.ndarray:
    """Both roots of lambda^2 + phi'(V) lambda + w_k^2 = 0, shape (..., 2), larger real part first."""
    b = friction_slope(p)
    w2 = np.asarray(mode_frequency_squared(p, k), dtype=float)
    disc = np.sqrt((0.25 * b * b - w2).astype(complex))
    roots = np.stack([-0.5 * b + disc, -0.5 * b - disc], axis=-1)
    return _sorted_by_real_part(roots)


def mode_growth_rates(p: ChainParams) -> pd.DataFrame:
    """Growth rates of steady sliding mode by mode (plate drive or train model; no state variable).

    One row per normal mode of :func:`normal_modes`: ``j``, ``k``, ``omega2`` (w_k^2),
    ``growth_rate`` (largest Re lambda), ``growth_rate_2`` (the other root's) and ``frequency``
    (``|Im lambda|``).
    """
    k, _ = normal_modes(p)
    roots = mode_roots(p, k)
    return pd.DataFrame(
        {
            "j": np.arange(k.size),
            "k": k,
            "omega2": mode_frequency_squared(p, k),
            "growth_rate": roots[:, 0].real,
            "growth_rate_2": roots[:, 1].real,
            "frequency": np.abs(roots[:, 0].imag),
        }
    )


def chain_jacobian_2n(p: ChainParams) -> np.ndarray:
    """The 2N x 2N matrix of the linearised chain without state variable, variables (dx, dv):
    dv' = K L dx - Kp dx [plate] - phi'(V) dv with L the spring Laplacian under the model's ends.
    The one builder assembled from the pieces, :func:`stickslip.analysis.dynamics.jacobian.chain_jacobian`,
    which this is (built from the ends directly, not from :func:`normal_modes`)."""
    if p.friction_piece.has_state:
        raise ValueError(f"friction {p.friction} has a state variable: use chain_jacobian (eq. 5)")
    return chain_jacobian(p)


@dataclass(frozen=True)
class ModeStability:
    """Stability of steady sliding over the normal modes (plate drive or train model).

    ``growth`` is :func:`mode_growth_rates`; ``max_growth_rate`` and ``min_growth_rate`` are the
    largest and smallest of the modes' growth rates; ``all_unstable`` says every mode grows,
    ``stable`` that every mode decays.
    """

    friction_slope: float
    modes: str
    growth: pd.DataFrame
    max_growth_rate: float
    k_at_max: float
    min_growth_rate: float
    k_at_min: float
    all_unstable: bool
    stable: bool


def mode_stability(p: ChainParams) -> ModeStability:
    """Growth rates of steady sliding of a chain without state variable, mode by mode.

    lambda^2 + phi'(V) lambda + w_k^2 = 0 for each normal mode: with CL's weakening every mode
    grows (Re lambda >= alpha g > 0), with strengthening (train) every mode decays for beta > 0.
    """
    _, modes = normal_modes(p)
    df = mode_growth_rates(p)
    i_max, i_min = int(df["growth_rate"].idxmax()), int(df["growth_rate"].idxmin())
    return ModeStability(
        friction_slope=friction_slope(p),
        modes=modes,
        growth=df,
        max_growth_rate=float(df["growth_rate"].iloc[i_max]),
        k_at_max=float(df["k"].iloc[i_max]),
        min_growth_rate=float(df["growth_rate"].iloc[i_min]),
        k_at_min=float(df["k"].iloc[i_min]),
        all_unstable=bool((df["growth_rate"] > GROWTH_TOL).all()),
        stable=bool((df["growth_rate"] < -GROWTH_TOL).all()),
    )


def mode_dispersion(p: ChainParams, k: np.ndarray | None = None) -> xr.Dataset:
    """Re and Im of both roots of lambda^2 + phi'(V) lambda + w_k^2 = 0 against k in [0, pi].

    The curve of the figure like Fig. 4 for the plate drive and the train model; the finite
    chain's modes (:func:`normal_modes`) lie on it (folded into [0, pi] on the periodic chain).
    """
    k = np.linspace(0.0, np.pi, 629) if k is None else np.asarray(k, dtype=float)
    roots = mode_roots(p, k)
    return xr.Dataset(
        {
            "real": (("k", "branch"), roots.real, {"long_name": "Re(lambda)"}),
            "imag": (("k", "branch"), roots.imag, {"long_name": "Im(lambda)"}),
        },
        coords={"k": ("k", k, {"long_name": "lattice wavenumber k"}), "branch": ("branch", np.arange(2))},
        attrs={
            name: v if isinstance(v, str) else float(v) for name, v in p.to_dict().items() if name not in ("Fs", "dt")
        },
    )
