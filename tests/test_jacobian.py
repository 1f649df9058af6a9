"""The Jacobian about steady sliding assembled from the pieces (analysis.dynamics.jacobian) and the steady
state of a chain with per-block parameters (models.physics).

Uniform chains: the eigenvalues equal the Fourier modes' (eq. 5, Fig. 4; the relatives'
lambda^2 + phi'(V) lambda + w_k^2 = 0) where the modes diagonalise the finite chain. Disordered
chains (arrays of N values built here): the steady state balances the forces of the plain-Python
equations of docs/model.md, and the Jacobian equals their finite differences.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from stickslip import chain_params
from stickslip.analysis.dynamics import stability as st
from stickslip.analysis.dynamics.jacobian import chain_jacobian
from stickslip.analysis.dynamics.linear import finite_chain_wavenumbers
from stickslip.models import physics


def _disordered(p, **arrays):
    """``p`` with some parameters replaced by arrays of N values (bypassing ChainParams' checks of
    floats, as the per-block parameters will reach the analysis)."""
    q = p.replace()
    for name, a in arrays.items():
        object.__setattr__(q, name, np.asarray(a, dtype=float))
    return q


def _sorted(eig):
    eig = np.asarray(eig)
    return eig[np.lexsort((np.round(eig.imag, 8), np.round(eig.real, 8)))]


def _same_spectrum(a, b, tol=1e-10):
    a, b = _sorted(a), _sorted(b)
    assert a.shape == b.shape
    np.testing.assert_allclose(a.real, b.real, rtol=0, atol=tol)
    np.testing.assert_allclose(np.abs(a.imag), np.abs(b.imag), rtol=0, atol=tol)


@pytest.mark.parametrize("beta", [0.5, 1.0, 1.5])
def test_end_drive_eigenvalues_are_fourier_modes(beta):
    # D = 0: the theta Laplacian drops out, and the sine modes k_m of the free end diagonalise
    # the chain, so the 3N eigenvalues are those of eq. (5)'s mode matrices at k_m (Fig. 4).
    p = chain_params(N=25, beta=beta, D=0.0)
    k = finite_chain_wavenumbers(p.N)
    fourier = np.linalg.eigvals(st.chain_mode_matrix(p, k)).ravel()
    _same_spectrum(np.linalg.eigvals(chain_jacobian(p)), fourier)


def test_plate_ring_with_state_friction_is_fourier_modes_with_kp():
    # Periodic ends: exp(i k j) diagonalises both Laplacians at any D; the plate adds -Kp to the
    # x row of eq. (5)'s mode matrix.
    p = chain_params(N=16, drive="plate", ends="periodic", Kp=2.0, beta=0.7, D=0.05)
    k = 2.0 * np.pi * np.arange(p.N) / p.N
    A = st.chain_mode_matrix(p, k)
    A[..., 1, 0] -= p.Kp
    _same_spectrum(np.linalg.eigvals(chain_jacobian(p)), np.linalg.eigvals(A).ravel())


@pytest.mark.parametrize(
    "model, over",
    [
        ("train", {"N": 20}),
        ("carlson-langer", {"N": 20}),
        ("two-blocks", {}),
        ("carlson-langer", {"N": 12, "ends": "free"}),
        ("train", {"N": 9, "beta": 0.01}),
    ],
)
def test_relatives_eigenvalues_are_normal_modes(model, over):
    p = chain_params(model, **over)
    k, _ = st.normal_modes(p)
    _same_spectrum(np.linalg.eigvals(chain_jacobian(p)), st.mode_roots(p, k).ravel())


def test_uniform_matrices_are_the_former_builders():
    # eq. (5) with the free end and no-flux theta, written out (the former chain_jacobian).
    p = chain_params(N=7, beta=0.8, D=5.0)
    N, lin = p.N, p.friction_piece.linear(p)
    lap = -2.0 * np.eye(N) + np.eye(N, k=1) + np.eye(N, k=-1)
    lap_x = lap.copy()
    lap_x[-1, -1] = -1.0
    lap_t = lap.copy()
    lap_t[0, 0] += 1.0
    lap_t[-1, -1] += 1.0
    eye, zero = np.eye(N), np.zeros((N, N))
    J = np.block(
        [
            [zero, eye, zero],
            [p.K * lap_x, -lin.phi_v * eye, -lin.phi_theta * eye],
            [zero, lin.g_v * eye, lin.g_theta * eye + lin.diffusion * lap_t],
        ]
    )
    assert np.array_equal(chain_jacobian(p), J)
    assert np.array_equal(st.chain_jacobian(p), J)


# ------------------------------------------------------------------------------------------
# Disordered chains against the plain-Python equations of docs/model.md
# ------------------------------------------------------------------------------------------


def _rhs(p, x, v, th, t):
    """dx/dt, dv/dt, dtheta/dt of every block, all moving (docs/model.md), written out per model."""
    N, K = p.N, p.K

    def arr(name):
        return np.broadcast_to(np.asarray(getattr(p, name), dtype=float), (N,))

    if p.ends == "periodic":
        x0, xN1, th0, thN1 = x[-1], x[0], th[-1], th[0]
    else:
        x0, xN1, th0, thN1 = x[0], x[-1], th[0], th[-1]
    if p.drive == "end":
        x0 = p.V * t
    xl = np.concatenate(([x0], x[:-1]))
    xr = np.concatenate((x[1:], [xN1]))
    f = K * ((xl - x) - (x - xr))
    if p.drive == "plate":
        f = f + arr("Kp") * (p.V * t - x)
    if p.drive == "constant-force":
        f = f + arr("F")
    thl = np.concatenate(([th0], th[:-1]))
    thr = np.concatenate((th[1:], [thN1]))
    g = np.zeros(N)
    if p.friction == "state":
        phi = th + arr("beta") * v
        g = th * (1.0 - th) - arr("alpha") * th * v + arr("D") * (thl - 2.0 * th + thr)
    elif p.friction == "weakening":
        w = 1.0 - arr("sigma")
        phi = w / (1.0 + 2.0 * arr("alpha") * v / w)
    elif p.friction == "strengthening":
        phi = arr("F0") + arr("beta") * v
    else:
        a, b, dc, v0 = arr("rs_a"), arr("rs_b"), arr("Dc"), arr("v0")
        mu = a * np.arcsinh(v / (2.0 * v0) * np.exp((arr("mu0") + b * np.log(v0 * th / dc)) / a))
        phi = arr("sigma_n") * mu
        g = 1.0 - v * th / dc
    return v, f - phi, g


def _fd_jacobian(p, ss, t=3.0):
    """Central differences of _rhs about the steady state at time t."""
    N = p.N
    with_theta = p.friction_piece.has_state
    x = ss["x"] + (p.V * t if p.drive in ("end", "plate") else ss["v"][0] * t)
    y0 = np.concatenate([x, ss["v"]] + ([ss["theta"]] if with_theta else []))
    n = y0.size

    def F(y):
        th = y[2 * N :] if with_theta else np.zeros(N)
        out = _rhs(p, y[:N], y[N : 2 * N], th, t)
        return np.concatenate(out if with_theta else out[:2])

    J = np.zeros((n, n))
    for j in range(n):
        h = 1e-6 * max(1.0, abs(y0[j]))
        e = np.zeros(n)
        e[j] = h
        J[:, j] = (F(y0 + e) - F(y0 - e)) / (2.0 * h)
    return J, F(y0)


rng = np.random.default_rng(49)
N_D = 9

DISORDERED = [
    (
        "paper chain, random beta and D",
        chain_params(N=N_D, beta=0.8),
        {"beta": rng.uniform(0.5, 1.5, N_D), "D": rng.uniform(0.0, 2.0, N_D)},
    ),
    (
        "paper chain, random beta and alpha, D = 0",
        chain_params(N=N_D, beta=0.8, D=0.0),
        {"beta": rng.uniform(0.5, 1.5, N_D), "alpha": rng.uniform(0.5, 1.5, N_D)},
    ),
    (
        "train, random F0 and beta",
        chain_params("train", N=N_D),
        {"F0": rng.uniform(0.5, 1.5, N_D), "beta": rng.uniform(0.5, 2, N_D)},
    ),
    (
        "Carlson-Langer ring, random Kp, sigma and alpha",
        chain_params("carlson-langer", N=N_D),
        {"Kp": rng.uniform(0.5, 2.0, N_D), "sigma": rng.uniform(0.0, 0.1, N_D), "alpha": rng.uniform(1.0, 3.0, N_D)},
    ),
    (
        "plate, free ends, state friction, random beta",
        chain_params(N=N_D, drive="plate", Kp=1.5),
        {"beta": rng.uniform(0.5, 1.5, N_D), "D": rng.uniform(0.0, 1.0, N_D)},
    ),
    (
        "rate-and-state, random a and b",
        chain_params(N=N_D, friction="rate-state", K=30.0, V=0.01),
        {"rs_a": rng.uniform(0.008, 0.012, N_D), "rs_b": rng.uniform(0.01, 0.02, N_D)},
    ),
]


@pytest.mark.parametrize("name, base, arrays", DISORDERED, ids=[d[0] for d in DISORDERED])
def test_disordered_steady_state_and_jacobian(name, base, arrays):
    p = _disordered(base, **arrays)
    assert not physics.is_uniform(p)
    ss = physics.chain_steady_state(p, 0.0)
    J_fd, rates = _fd_jacobian(p, ss)
    N = p.N
    # Steady sliding: every block at V, no acceleration, no change of theta.
    np.testing.assert_allclose(rates[:N], p.V, rtol=0, atol=1e-15)
    np.testing.assert_allclose(rates[N:], 0.0, rtol=0, atol=1e-9)
    J = chain_jacobian(p)
    scale = np.max(np.abs(J))
    np.testing.assert_allclose(J, J_fd, rtol=0, atol=2e-7 * scale)


def test_random_theta0_with_diffusion_is_refused():
    # theta_0 = 1 - alpha_i V differs between blocks and D couples them: no closed form.
    p = _disordered(chain_params(N=5), alpha=np.linspace(0.5, 1.5, 5))
    with pytest.raises(ValueError, match="no closed-form steady state"):
        physics.chain_steady_state(p)


def test_disordered_end_drive_extensions_sum_from_the_free_end():
    beta = np.linspace(0.5, 1.5, 6)
    p = _disordered(chain_params(N=6), beta=beta)
    ss = physics.chain_steady_state(p, 0.0)
    c = (1.0 - p.V) + beta * p.V  # each block's theta_0 + beta_i V
    expected = np.array([c[i:].sum() for i in range(6)]) / p.K
    np.testing.assert_allclose(ss["ext"], expected, rtol=1e-14)
    assert physics.chain_steady_length(p) == pytest.approx(float(np.sum(expected[1:])), rel=1e-13)


@pytest.mark.parametrize("model", ["sakaguchi", "carlson-langer", "train"])
def test_uniform_chain_given_as_arrays_has_the_same_steady_state(model):
    p = chain_params(model, N=11)
    q = _disordered(
        p, **{name: np.full(p.N, float(getattr(p, name))) for name in p.used() if name not in ("N", "K", "V", "dt")}
    )
    a, b = physics.chain_steady_state(p, 2.5), physics.chain_steady_state(q, 2.5)
    for key in ("x", "v", "theta", "ext"):
        assert np.array_equal(a[key], b[key]), key
    assert np.array_equal(chain_jacobian(p), chain_jacobian(q))


def test_paper_steady_state_is_the_closed_form():
    p = chain_params(N=49, beta=0.5)
    ss = physics.chain_steady_state(p, 0.0)
    c = 1.0 - (1.0 - p.beta) * p.V
    i = np.arange(1, 50)
    np.testing.assert_allclose(ss["ext"], c / p.K * (49 - i + 1), rtol=1e-15)
    assert ss["friction"] == pytest.approx(c, rel=1e-15)
    assert math.isclose(physics.chain_steady_length(p), c / p.K * 49 * 48 / 2, rel_tol=1e-15)


def test_per_block_parameters_from_chain_params():
    # The package's own per-block parameters (chain_params with arrays) give the steady state and
    # Jacobian of the arrays built here, and the steady start is steady to round-off.
    from stickslip.run.state import ChainState, steady_deviation

    beta, D = np.linspace(0.6, 1.4, 9), np.linspace(0.0, 2.0, 9)
    p = chain_params(N=9, beta=beta, D=D)
    q = _disordered(chain_params(N=9), beta=beta, D=D)
    a, b = physics.chain_steady_state(p, 1.5), physics.chain_steady_state(q, 1.5)
    for key in ("x", "v", "theta", "ext"):
        assert np.array_equal(a[key], b[key]), key
    assert np.array_equal(chain_jacobian(p), chain_jacobian(q))
    assert steady_deviation(ChainState.steady(p), p) < 1e-13
