"""Steady sliding on the square lattice and its linear stability (eq. 5 and Fig. 4 in two
dimensions; docs/lattice.md): the steady state against the chain's closed form row by row, the
threshold beta_c = alpha of the long waves, and the simulation leaving or keeping steady sliding
as the modes' growth rates say."""

from __future__ import annotations

import numpy as np
import pytest

from stickslip.analysis.dynamics.lattice_stability import lattice_critical_beta, lattice_mode_matrix, lattice_stability
from stickslip.models.lattice.params import on_lattice
from stickslip.models.params import ParameterError
from stickslip.models.presets import chain_params
from stickslip.run.lattice import run_lattice, steady_fields

EDGES = "top=periodic,bottom=periodic"


def _model(beta, shape=(4, 12), edges=EDGES):
    # V = 0.5 keeps every block moving under small perturbations; K = 1, D = 0.5 put the longest
    # wave of a 12-block row well inside the long-wave band (q = 4 sin^2(pi / 50)).
    return on_lattice(chain_params(V=0.5, beta=beta, K=1.0, D=0.5), "square", shape, edges)


@pytest.mark.parametrize("edges", [EDGES, None])
def test_steady_sliding_is_the_chains_in_every_row(edges):
    """Pulled at the left edge with periodic or free top and bottom, every row is the chain of
    docs/model.md: x_{i-1} - x_i = (c / K)(C - i + 1), x_0 = 0 at t = 0, c = theta_0 + beta V."""
    p = _model(1.1, (3, 7), edges)
    x = steady_fields(p)["x"]
    c = (1.0 - p.alpha * p.V) + p.beta * p.V
    ext = (c / p.K) * (7 - np.arange(1, 8) + 1)
    want = -np.cumsum(ext)
    np.testing.assert_allclose(x, np.broadcast_to(want, (3, 7)), rtol=1e-12, atol=1e-12)


def test_plate_steady_sliding_is_uniform():
    p = on_lattice(chain_params("carlson-langer", friction="state", threshold="state", D=1.0), "square", (3, 4))
    s = steady_fields(p)
    c = (1.0 - p.alpha * p.V) + p.beta * p.V
    np.testing.assert_allclose(s["x"], -c / p.Kp, rtol=1e-12)


def test_threshold_of_the_long_waves_is_alpha():
    """The finite lattice turns unstable a little below beta = alpha, by an amount proportional to
    its smallest eigenvalue q_min (the longest wave), so the threshold tends to alpha as the row
    grows; beyond alpha every mode is stable. At q = 0 eq. (5)'s roots are the translation and
    those of lambda^2 + (beta + theta_0) lambda + theta_0 (beta - alpha)."""
    for beta, unstable in ((0.9, True), (1.0, False), (1.1, False)):
        assert lattice_stability(_model(beta))["unstable"] is unstable
    gaps = []
    for cols in (24, 48, 96):
        p = _model(0.9, (3, cols))
        beta_c = lattice_critical_beta(p)
        assert beta_c < p.alpha == lattice_stability(p)["critical_beta"]
        gaps.append((p.alpha - beta_c) / p.lattice.eigenvalues()[0])
    assert gaps[2] == pytest.approx(gaps[1], rel=0.05) and gaps[1] == pytest.approx(gaps[0], rel=0.1)
    p = _model(0.8)
    th0 = 1.0 - p.alpha * p.V
    roots = np.sort(np.linalg.eigvals(lattice_mode_matrix(p, 0.0)).real)
    want = np.sort(np.roots([1.0, p.beta + th0, th0 * (p.beta - p.alpha)]).real)
    np.testing.assert_allclose(roots[[0, 2]], want, atol=1e-12)
    assert abs(roots[1]) < 1e-12


def _deviation(p, beta_run):
    ss = steady_fields(p)
    sn = beta_run.snapshots
    dev = sn.x.values - p.V * sn.time.values[:, None, None] - ss["x"][None]
    return sn.time.values, np.sqrt((dev**2).mean(axis=(1, 2)))


def test_the_simulation_slides_steadily_above_and_departs_below():
    """From steady sliding perturbed by 1e-4, the deviation of x decays at beta = 1.1 at the
    rate of the slowest mode, and grows at beta = 0.9 (no event: every block keeps moving)."""
    above, below = _model(1.1), _model(0.9)
    run_a = run_lattice(above, 400.0, start="steady", perturbation=1e-4, seed=1, snapshot_every=50.0)
    run_b = run_lattice(below, 400.0, start="steady", perturbation=1e-4, seed=1, snapshot_every=50.0)
    t, dev_a = _deviation(above, run_a)
    _, dev_b = _deviation(below, run_b)
    assert dev_a[-1] < 1e-3 * dev_a[0] and dev_b[-1] > 10.0 * dev_b[0]
    rate = np.log(dev_a[5] / dev_a[2]) / (t[5] - t[2])
    assert rate == pytest.approx(lattice_stability(above)["max_growth_rate"], rel=0.1)
    assert run_a.summary["moving_at_end"] == run_b.summary["moving_at_end"] == above.lattice.n_blocks


def test_unperturbed_steady_sliding_stays():
    p = _model(1.1)
    run = run_lattice(p, 50.0, start="steady", snapshot_every=50.0)
    _, dev = _deviation(p, run)
    assert dev[-1] < 1e-9 and len(run.events) == 0


def test_no_steady_sliding_against_a_wall():
    with pytest.raises(ParameterError, match="fixed edge"):
        steady_fields(_model(1.1, (3, 4), "right=fixed"))
