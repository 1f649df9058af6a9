"""Linear stability of steady sliding: the block (eq. 2) and the chain (eq. 5, Fig. 4).

Expected values come from outside the code under test: the paper's numbers, characteristic
polynomials and Routh-Hurwitz conditions derived here by hand, finite-difference Jacobians of
right-hand sides of eqs. (1) and (4) written out here, and a periodic chain whose spectrum is
the union of the Fourier modes.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as hs

from stickslip.analysis.dynamics import stability as st
from stickslip.models.params import BlockParams, ChainParams, scale_block
from stickslip.models.physics import chain_steady_state


def _match(a: np.ndarray, b: np.ndarray) -> float:
    """Largest distance between two multisets of eigenvalues (greedy nearest matching)."""
    b = list(b)
    worst = 0.0
    for z in a:
        j = int(np.argmin([abs(z - w) for w in b]))
        worst = max(worst, abs(z - b.pop(j)))
    return worst


# ---------------------------------------------------------------------------------------------
# Single block
# ---------------------------------------------------------------------------------------------


def block_cubic(K, beta, alpha, V, M=1.0, sigma=1.0):
    """det(lambda I - J) of eq. (2), expanded by hand along the first row.

    J = [[0, 1, 0], [-K/M, -beta/M, -sigma/M], [0, -alpha th, -th]] with th = 1 - alpha V:
    lambda [(lambda + beta/M)(lambda + th) - sigma alpha th / M] + (K/M)(lambda + th).
    """
    th = 1.0 - alpha * V
    return [1.0, beta / M + th, (K + th * (beta - sigma * alpha)) / M, K * th / M]


def block_rhs(y, K, V, beta, alpha, M, sigma):
    """Eq. (1) while moving, in the frame of the pulling point: y = (lag = V t - x, v, theta)."""
    lag, v, th = y
    return np.array([V - v, (K * lag - sigma * th - beta * v) / M, th * (1 - th) - alpha * th * v])


def fd_jacobian(f, y0, h=1e-6):
    n = len(y0)
    J = np.empty((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = h
        J[:, j] = (f(y0 + e) - f(y0 - e)) / (2 * h)
    return J


def hopf_by_hand(K, beta, alpha=1.0, M=1.0, sigma=1.0):
    """Root of a1 a2 = a3 for the cubic above: a quadratic in th, solved here."""
    b, k, a = beta / M, K / M, sigma * alpha / M
    # b k + th (b - a)(b + th) = 0  <=>  th^2 + b th - b k / (a - b) = 0
    th = (-b + math.sqrt(b * b + 4 * b * k / (a - b))) / 2
    return (1 - th) / alpha


def test_paper_hopf_point_three_digits():
    """Section 2: the Hopf bifurcation is at V_c = 0.106 for K = 10, beta = 0.08."""
    hp = st.hopf_point(BlockParams(K=10, beta=0.08))
    assert hp.V is not None
    assert abs(hp.V - 0.106) < 1e-3
    assert math.floor(hp.V * 1000) / 1000 == 0.106  # the paper's digits, truncated
    assert hp.V == pytest.approx(hopf_by_hand(10, 0.08), abs=1e-10)
    closed = st.hopf_point_closed_form(BlockParams(K=10, beta=0.08))
    assert closed == pytest.approx(hopf_by_hand(10, 0.08), abs=1e-12)


def test_hopf_point_is_a_crossing_pair():
    """At V_c a complex pair sits on the imaginary axis with omega^2 = a2 (a1 a2 = a3)."""
    hp = st.hopf_point(BlockParams(K=10, beta=0.08))
    eig = st.block_eigenvalues(BlockParams(K=10, beta=0.08, V=hp.V))
    a = block_cubic(10, 0.08, 1, hp.V)
    assert abs(eig[0].real) < 1e-9
    assert abs(eig[0].imag) == pytest.approx(math.sqrt(a[2]), rel=1e-9)
    assert hp.omega == pytest.approx(math.sqrt(a[2]), rel=1e-9)
    # the third root is -a1
    assert eig[2].real == pytest.approx(-a[1], rel=1e-9)
    # unstable below, stable above (section 2: "unstable for V < V_c")
    assert not st.block_stability(BlockParams(K=10, beta=0.08, V=hp.V - 0.01)).stable
    assert st.block_stability(BlockParams(K=10, beta=0.08, V=hp.V + 0.01)).stable


def test_beta_one_stable_for_every_V():
    """Section 2: for K = 10, beta = 1 steady sliding is linearly stable for any V > 0."""
    p = BlockParams(K=10, beta=1.0)
    assert st.hopf_point(p).V is None
    for V in np.concatenate([np.geomspace(1e-6, 0.999, 200), [1.001, 1.5, 3.0, 10.0]]):
        s = st.block_stability(p.replace(V=float(V)))
        assert s.stable, V
        assert s.growth_rate < 0.0


def test_melting_point_alpha_V_one_is_marginal():
    """At alpha V = 1 the branch theta_0 = 1 - alpha V meets theta = 0: one zero eigenvalue,
    the other two those of M x'' = -K x - beta x' (roots of lambda^2 + lambda + 10)."""
    s = st.block_stability(BlockParams(K=10, beta=1.0, V=1.0))
    assert abs(s.eigenvalues[0]) < 1e-12
    assert _match(s.eigenvalues[1:], np.roots([1.0, 1.0, 10.0])) < 1e-12
    assert not s.stable


@pytest.mark.parametrize("K", [0.5, 1.0, 10.0, 100.0])
@pytest.mark.parametrize("beta", [1.0, 1.2, 3.0])
def test_no_hopf_point_for_beta_at_least_sigma_alpha(K, beta):
    """bk + th (b - a)(b + th) > 0 for every th when b >= a: no Hopf point."""
    assert st.hopf_point(BlockParams(K=K, beta=beta)).V is None
    assert st.hopf_point_closed_form(BlockParams(K=K, beta=beta)) is None


@settings(max_examples=40, deadline=None)
@given(
    K=hs.floats(0.1, 200.0),
    beta=hs.floats(0.0, 3.0),
    alpha=hs.floats(0.1, 3.0),
    M=hs.floats(0.2, 5.0),
    sigma=hs.floats(0.2, 5.0),
    frac=hs.floats(0.0, 0.999),
)
def test_eigenvalues_are_roots_of_the_cubic(K, beta, alpha, M, sigma, frac):
    V = frac / alpha
    p = BlockParams(K=K, beta=beta, alpha=alpha, M=M, sigma=sigma, V=V)
    roots = np.roots(block_cubic(K, beta, alpha, V, M, sigma))
    assert np.allclose(st.block_characteristic_polynomial(p), block_cubic(K, beta, alpha, V, M, sigma))
    eig = st.block_eigenvalues(p)
    scale = 1.0 + np.abs(roots).max()
    assert _match(eig, roots) < 1e-6 * scale


@pytest.mark.parametrize(
    "K,beta,alpha,M,sigma,V",
    [(10, 0.08, 1, 1, 1, 0.1), (10, 1, 1, 1, 1, 0.3), (3, 0.4, 2, 2, 0.7, 0.2), (50, 0.01, 0.5, 1, 1, 1.2)],
)
def test_jacobian_by_finite_differences(K, beta, alpha, M, sigma, V):
    """The matrix of eq. (2) is the derivative of eq. (1) at steady sliding."""
    th0 = max(1 - alpha * V, 0.0)
    lag0 = (sigma * th0 + beta * V) / K
    y0 = np.array([lag0, V, th0])
    f = lambda y: block_rhs(y, K, V, beta, alpha, M, sigma)  # noqa: E731
    assert np.allclose(f(y0), 0.0, atol=1e-14)
    J = fd_jacobian(f, y0)
    # the frame variable is lag = -dx: flip its sign to compare with (dx, dv, dtheta)
    S = np.diag([-1.0, 1.0, 1.0])
    J_x = S @ J @ S
    p = BlockParams(K=K, beta=beta, alpha=alpha, M=M, sigma=sigma, V=V)
    assert np.allclose(st.block_jacobian(p), J_x, atol=1e-7)


def test_scaling_to_unit_mass_and_sigma_keeps_the_spectrum():
    """Section 2: M and sigma scale out (time is not rescaled, so eigenvalues are unchanged)."""
    p = BlockParams(K=7, beta=0.3, alpha=1.5, M=2.5, sigma=0.6, V=0.2)
    assert _match(st.block_eigenvalues(p), st.block_eigenvalues(scale_block(p))) < 1e-12
    hp, hs_ = st.hopf_point(p), st.hopf_point(scale_block(p))
    assert (hp.V is None) == (hs_.V is None)


@settings(max_examples=30, deadline=None)
@given(K=hs.floats(0.5, 100.0), x=hs.floats(0.02, 0.98), alpha=hs.floats(0.3, 3.0))
def test_hopf_point_by_root_finding_matches_routh_hurwitz(K, x, alpha):
    # beta below the limit where V_c reaches 0 (th = 1): b^2 + b (1 - a + k) - a = 0
    s = 1 - alpha + K
    beta_top = 0.5 * (-s + math.sqrt(s * s + 4 * alpha))
    beta = x * beta_top
    hp = st.hopf_point(BlockParams(K=K, beta=beta, alpha=alpha))
    expected = hopf_by_hand(K, beta, alpha)
    assert hp.V is not None
    assert hp.V == pytest.approx(expected, rel=1e-8, abs=1e-10)
    assert st.hopf_beta_limit(BlockParams(K=K, alpha=alpha)) == pytest.approx(beta_top, rel=1e-12)


def test_hopf_curve_dataset():
    curve = st.hopf_curve(BlockParams(K=10), np.array([0.02, 0.08, 0.5]))
    assert curve["V_c"].sel(beta=0.08) == pytest.approx(hopf_by_hand(10, 0.08), abs=1e-10)
    assert np.isnan(curve["V_c"].sel(beta=0.5))
    assert np.allclose(curve["V_c"], curve["V_c_closed_form"], equal_nan=True, atol=1e-10)


# ---------------------------------------------------------------------------------------------
# Chain
# ---------------------------------------------------------------------------------------------


def chain_cubic(K, D, V, beta, alpha, k):
    """det(lambda I - A(k)) of eq. (5) for exp(i k j), expanded by hand (q = 2 - 2 cos k)."""
    q = 2 - 2 * math.cos(k)
    th = 1 - alpha * V
    r = th + D * q
    return [1.0, beta + r, beta * r - alpha * th + K * q, K * q * r]


@settings(max_examples=40, deadline=None)
@given(
    K=hs.floats(0.1, 100.0),
    D=hs.floats(0.0, 50.0),
    V=hs.floats(0.0, 0.9),
    beta=hs.floats(0.0, 3.0),
    alpha=hs.floats(0.0, 1.0),
    k=hs.floats(0.0, math.pi),
)
def test_mode_matrix_eigenvalues_are_roots_of_the_cubic(K, D, V, beta, alpha, k):
    p = ChainParams(K=K, D=D, V=V, beta=beta, alpha=alpha, dt=0.001)
    eig = np.linalg.eigvals(st.chain_mode_matrix(p, k))
    roots = np.roots(chain_cubic(K, D, V, beta, alpha, k))
    assert _match(eig, roots) < 1e-6 * (1 + np.abs(roots).max())


@pytest.mark.parametrize("N", [6, 11])
def test_periodic_chain_spectrum_is_the_union_of_fourier_modes(N):
    """A periodic ring of eq. (5), built here, has exactly the modes k = 2 pi m / N."""
    p = ChainParams(K=10, D=5, V=0.1, beta=0.7, alpha=1.0)
    th = 1 - p.V
    ring = -2 * np.eye(N) + np.roll(np.eye(N), 1, axis=1) + np.roll(np.eye(N), -1, axis=1)
    I, Z = np.eye(N), np.zeros((N, N))
    A = np.block([[Z, I, Z], [p.K * ring, -p.beta * I, -I], [Z, -th * I, -th * I + p.D * ring]])
    full = np.linalg.eigvals(A)
    modes = np.concatenate([np.linalg.eigvals(st.chain_mode_matrix(p, 2 * np.pi * m / N)) for m in range(N)])
    assert _match(full, modes) < 1e-8


def _chain_rhs(y, p: ChainParams):
    """Eq. (4) while every block moves, with the ends of docs/model.md, in the frame x_0 = 0.

    y = (u_1..u_N, v_1..v_N, theta_1..theta_N), u_i = x_i - V t.
    """
    N = p.N
    u, v, th = y[:N], y[N : 2 * N], y[2 * N :]
    u_ext = np.concatenate([[0.0], u, [u[-1]]])  # pulling point u_0 = 0, free end u_{N+1} = u_N
    t_ext = np.concatenate([[th[0]], th, [th[-1]]])  # no-flux ends
    f = p.K * (u_ext[2:] - 2 * u + u_ext[:-2])
    lap = t_ext[2:] - 2 * th + t_ext[:-2]
    return np.concatenate([v - p.V, f - th - p.beta * v, th * (1 - th) - p.alpha * th * v + p.D * lap])


@pytest.mark.parametrize("N", [1, 2, 7])
def test_finite_chain_matrix_by_finite_differences(N):
    p = ChainParams(N=N, K=10, D=5, V=0.05, beta=0.8, alpha=0.9)
    ss = chain_steady_state(p)
    y0 = np.concatenate([ss["x"], ss["v"], ss["theta"]])
    assert np.allclose(_chain_rhs(y0, p), 0.0, atol=1e-12)
    J = fd_jacobian(lambda y: _chain_rhs(y, p), y0)
    assert np.allclose(st.chain_jacobian(p), J, atol=1e-7)


def test_finite_chain_without_diffusion_has_exact_fourier_modes():
    """D = 0: the spring Laplacian with u_0 = 0, u_{N+1} = u_N has sin(k i) modes,
    sin(k (N + 1)) = sin(k N) gives k_m = (2m - 1) pi / (2N + 1)."""
    N = 9
    p = ChainParams(N=N, K=10, D=0.0, V=0.001, beta=0.6)
    km = np.array([(2 * m - 1) * np.pi / (2 * N + 1) for m in range(1, N + 1)])
    modes = np.concatenate([np.linalg.eigvals(st.chain_mode_matrix(p, k)) for k in km])
    assert _match(st.chain_finite_eigenvalues(p), modes) < 1e-8


@pytest.mark.parametrize("beta", [0.5, 1.5, 3.0])
@pytest.mark.parametrize("k", [1e-3, 3e-3])
def test_long_wave_eigenvalue(beta, k):
    """Near k = 0 the translation mode moves to -K q / (beta - alpha) (perturbation of the
    cubic: lambda ~ -a3 / a2 with a3 ~ K q th, a2 ~ th (beta - alpha))."""
    p = ChainParams(K=10, D=5, V=0.001, beta=beta)
    q = 2 - 2 * math.cos(k)
    expected = -p.K * q / (beta - 1.0)
    eig = np.linalg.eigvals(st.chain_mode_matrix(p, k))
    near = eig[np.argmin(np.abs(eig))]
    # relative corrections are O(q): (beta D + K) q / a2 and a1 lambda / a2
    assert near.real == pytest.approx(expected, rel=300 * q)
    lw = st.chain_long_wave(p)
    assert lw["c2"] == pytest.approx(-p.K / (beta - 1.0))


@pytest.mark.parametrize(
    "K,D,V,alpha",
    [
        (10, 5, 0.001, 1.0),
        (1, 0, 0.3, 1.0),
        (50, 20, 0.5, 1.0),
        (3, 1, 0.9, 0.8),
        (10, 5, 0.2, 0.4),
        (0.3, 60, 0.01, 2.0),
    ],
)
def test_critical_beta_equals_closed_form(K, D, V, alpha):
    """Fig. 4: long-wave instability for beta < alpha (= 1 in the paper), whatever K, D, V."""
    p = ChainParams(K=K, D=D, V=V, alpha=alpha, dt=0.001)
    assert st.chain_critical_beta(p) == alpha
    assert st.chain_critical_beta_numeric(p) == pytest.approx(alpha, abs=5e-6)


@pytest.mark.parametrize("beta,unstable", [(0.5, True), (0.9, True), (0.99, True), (1.01, False), (1.5, False)])
def test_fig4_sign_of_growth(beta, unstable):
    """Fig. 4 at K = 10, D = 5: unstable for beta < 1, stable for beta > 1."""
    s = st.chain_stability(ChainParams(K=10, D=5, V=0.001, beta=beta))
    assert s.unstable is unstable
    assert (s.max_growth_rate > 0) is unstable
    assert s.critical_beta == 1.0


def test_fig4_beta_one_is_marginal():
    s = st.chain_stability(ChainParams(K=10, D=5, V=0.001, beta=1.0))
    assert s.marginal and not s.unstable
    assert -1e-6 < s.max_growth_rate < 0.0
    # lambda = i w k + mu k^2 in the cubic: w^2 = K th / (1 + th), mu = (w^2 - D - K) / (2 (1 + th))
    th, k = 1 - 0.001, 1e-3
    mu = (10 * th / (1 + th) - 5 - 10) / (2 * (1 + th))
    re = np.linalg.eigvals(st.chain_mode_matrix(ChainParams(K=10, D=5, V=0.001, beta=1.0), k)).real.max()
    assert re == pytest.approx(mu * k * k, rel=1e-3)
    # at k = 0 the two largest roots of lambda^2 + (beta + th) lambda + th (beta - 1) vanish
    ds = st.fig4_data(ChainParams(K=10, D=5, V=0.001), betas=(1.0,), k=np.array([0.0, 0.5]))
    assert np.allclose(ds["real"].sel(beta=1.0, k=0.0).isel(branch=slice(0, 2)), 0.0, atol=1e-12)


def test_fig4_uniform_mode_growth_rate():
    """At k = 0, beta = 0.5: the larger root of lambda^2 + (beta + th) lambda + th (beta - 1)."""
    th = 1 - 0.001
    b = 0.5
    root = (-(b + th) + math.sqrt((b + th) ** 2 - 4 * th * (b - 1))) / 2
    ds = st.fig4_data(ChainParams(K=10, D=5, V=0.001), k=np.array([0.0, 1.0]))
    assert float(ds["real"].sel(beta=0.5, k=0.0, branch=0)) == pytest.approx(root, rel=1e-10)
    assert set(ds["beta"].values) == {0.5, 1.0, 1.5}


@pytest.mark.parametrize("beta", [0.5, 0.8, 1.2, 1.5])
@pytest.mark.parametrize("N", [50, 100])
def test_finite_chain_agrees_with_fourier(beta, N):
    """The finite chain (3N x 3N, ends of docs/model.md) is unstable exactly when beta < 1 for
    long chains, and its least stable eigenvalue follows the Fourier branch at k_1."""
    df = st.compare_fourier_finite(ChainParams(K=10, D=5, V=0.001, beta=beta), [N])
    row = df.iloc[0]
    assert bool(row["finite_max_real"] > 0) is (beta < 1.0)
    assert row["finite_max_real"] == pytest.approx(row["fourier_k1"], rel=0.03 if N == 100 else 0.1)
