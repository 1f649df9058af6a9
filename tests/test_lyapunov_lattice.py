"""The lattice's norm (stickslip.models.lattice.norm; docs/lattice.md, docs/lyapunov.md) and the
Lyapunov exponent on a square: extensions written out by hand, identical states at distance 0,
and a square of one row giving the chain's exponent bit for bit."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stickslip.analysis.dynamics.lyapunov import largest_lyapunov
from stickslip.analysis.dynamics.lyapunov_lattice import LatticeEngine, lattice_lyapunov
from stickslip.models.lattice import lattice, norm
from stickslip.models.presets import chain_params
from stickslip.run.lattice import initial_state


def test_square_extensions_by_hand():
    """Pulled at the left: e[r, c] = dx[r, c - 1] - dx[r, c], dx[r, 0] = 0; pulled at the top:
    the same down each column."""
    dx = np.array([[1.0, 3.0, 7.0], [2.0, 2.0, -1.0]])
    left = lattice("square", (2, 3), "top=free,bottom=free", edge_drive=True)
    want = np.array([[-1.0, -2.0, -4.0], [-2.0, 0.0, 3.0]])
    np.testing.assert_array_equal(left.strain(dx.ravel()), want.ravel())
    top = lattice("square", (2, 3), "top=driven,left=free,right=free,bottom=free", edge_drive=True)
    want = np.array([[-1.0, -3.0, -7.0], [-1.0, 1.0, 8.0]])
    np.testing.assert_array_equal(top.strain(dx.ravel()), want.ravel())


@pytest.mark.parametrize("side", ["left", "right", "top", "bottom"])
def test_unstrain_inverts_strain(side):
    others = {"left": "right", "right": "left", "top": "bottom", "bottom": "top"}
    edges = f"{side}=driven,{others[side]}=free," + ",".join(
        f"{s}=free" for s in ("top", "bottom", "left", "right") if s not in (side, others[side])
    )
    lat = lattice("square", (3, 4), edges, edge_drive=True)
    dx = np.random.default_rng(1).standard_normal(12)
    np.testing.assert_allclose(lat.unstrain(lat.strain(dx)), dx, rtol=0, atol=1e-14)


def test_one_row_extensions_are_the_chains():
    dx = np.random.default_rng(2).standard_normal(7)
    row = lattice("square", (1, 7), "top=free,bottom=free", edge_drive=True)
    chain = lattice("chain", 7, edge_drive=True)
    np.testing.assert_array_equal(row.strain(dx), chain.strain(dx))
    np.testing.assert_array_equal(row.unstrain(dx), chain.unstrain(dx))


def test_distance_of_identical_states_is_zero_and_of_a_shift_by_hand():
    p = chain_params("carlson-langer", lattice="square", shape=(3, 4))
    s = initial_state(p, "rest", amplitude=0.01, seed=4)
    same = (s.xg, s.vg, s.thg)
    assert norm.distance(p.lattice, same, tuple(a.copy() for a in same), p) == 0.0
    engine = LatticeEngine(p)
    assert not np.any(engine.separation(s, s.copy()))
    x = s.xg.copy()
    x[p.lattice.blocks()] += 0.5  # the plate: every block by its leaf spring, sqrt(Kp) * 0.5 each
    assert norm.distance(p.lattice, same, (x, s.vg, s.thg), p) == pytest.approx(math.sqrt(12 * p.Kp) * 0.5)


def test_twin_is_d0_away_on_the_references_branch():
    p = chain_params("carlson-langer", lattice="square", shape=(3, 4))
    engine = LatticeEngine(p)
    ref = initial_state(p, "rest", amplitude=0.01, seed=4)
    direction = np.random.default_rng(0).standard_normal(36)
    twin = engine.twin(ref, direction, 1e-6)
    dy = engine.separation(ref, twin)
    assert np.linalg.norm(dy) == pytest.approx(1e-6, rel=1e-6)
    assert not np.any(dy[12:])  # every block stuck: no velocity; no theta in this model
    assert np.array_equal(twin.mov, ref.mov) and twin.step == ref.step


def test_a_square_of_one_row_gives_the_chains_exponent():
    """The paper's chain (N = 9) and the square 1 x 9 pulled at its left: the same reference,
    twins and ln(d / d0), so the same exponent bit for bit (the chain in its absolute frame)."""
    chain = largest_lyapunov(chain_params(N=9), 1000.0, interval=10.0, frame="absolute")
    square = lattice_lyapunov(chain_params(lattice="square", shape=(1, 9)), 1000.0, interval=10.0)
    assert square.lyapunov == chain.lyapunov
    np.testing.assert_array_equal(square.log_growth, chain.log_growth)
    assert square.reference_sha256 == chain.reference_sha256 and square.events == chain.events


def test_exponent_on_a_small_square():
    p = chain_params("carlson-langer", lattice="square", shape=(3, 3))
    res = lattice_lyapunov(p, 300.0, interval=5.0, start="rest", perturbation=0.01)
    assert res.renormalisations == 54 and math.isfinite(res.lyapunov)


@pytest.mark.parametrize("name", ["stickslip.models.lattice.norm", "stickslip.analysis.dynamics.lyapunov_lattice"])
def test_examples_in_the_docstrings_run(name):
    import doctest
    import importlib

    result = doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS, verbose=False)
    assert result.attempted > 0 and result.failed == 0, result
