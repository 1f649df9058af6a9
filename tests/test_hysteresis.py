"""The adiabatic sweep of V of the single block: the subcritical transition of section 2."""

from __future__ import annotations

import numpy as np
import pytest

from stickslip.analysis.dynamics.hysteresis import SweepSettings, hysteresis_sweep
from stickslip.models.params import BlockParams, ParameterError
from stickslip.run.block import simulate_block

PAPER_V_UP = 0.345  # section 2: beta = 1, Fs = 3, K = 10


@pytest.fixture(scope="module")
def paper_sweep():
    """The default sweep (V 0.25 -> 0.45 -> 0.25, dV = 0.005) at the paper's parameters."""
    return hysteresis_sweep(BlockParams(K=10, beta=1.0, Fs=3.0))


def test_V_up_matches_the_paper(paper_sweep):
    assert paper_sweep.settings.dV <= 0.005
    assert paper_sweep.V_up is not None
    assert abs(paper_sweep.V_up - PAPER_V_UP) <= 0.005 + 1e-12


def test_steady_sliding_is_not_left_going_down(paper_sweep):
    """beta = 1: steady sliding is linearly stable at every V (eq. 2), so the small steps of
    the way down never bring stick-slip back: the loop stays open in this range."""
    assert paper_sweep.V_down is None
    down = paper_sweep.data.sel(direction="down")
    assert not down["stuck"].any()
    assert np.allclose(down["v_min"], down["V"], atol=1e-6)
    assert np.allclose(down["v_max"], down["V"], atol=1e-6)


def test_bifurcation_diagram_branches(paper_sweep):
    """Below V_up the block sticks (min v = 0) and slips faster than V; above it slides at V."""
    up = paper_sweep.data.sel(direction="up")
    below = up.where(up["V"] < paper_sweep.V_up, drop=True)
    above = up.where(up["V"] >= paper_sweep.V_up, drop=True)
    assert below["stuck"].all() and not above["stuck"].any()
    assert np.all(below["v_min"] == 0.0)
    assert np.all(below["v_max"] > 2 * below["V"])
    assert np.allclose(above["v_max"], above["V"], atol=1e-3)
    # stick-slip period near V = 0.3: a slip of about 1.6 plus the stick (3 - f_stop) / (K V)
    assert 1.5 < float(below["period"].sel(V=0.3)) < 4.0


def test_carrying_the_state_over_continues_the_run():
    """Two holds at one V, restarted with x -> x - V t_seg, equal one run of twice the length."""
    p = BlockParams(V=0.3)
    one = simulate_block(p, 40.0, every=8000)
    first = simulate_block(p, 20.0, every=4000)
    second = simulate_block(p, 20.0, initial=first.restart_state(), every=4000)
    assert second.final.x + p.V * 20.0 == pytest.approx(one.final.x, abs=1e-9)
    assert second.final.v == pytest.approx(one.final.v, abs=1e-9)
    assert second.final.theta == pytest.approx(one.final.theta, abs=1e-9)


def test_loop_closes_where_steady_sliding_loses_stability():
    """beta = 0.08, Fs = 1.2: stick-slip ends going up, and going down it comes back only
    below the Hopf point V_c = 0.1066 (eq. 2), where steady sliding is unstable."""
    r = hysteresis_sweep(
        BlockParams(K=10, beta=0.08, Fs=1.2),
        SweepSettings(V_min=0.02, V_max=0.3, dV=0.02, time_per_step=100.0),
    )
    assert r.V_up is not None and r.V_down is not None
    assert r.V_down < 0.1066 < r.V_up


@pytest.mark.parametrize(
    "kw",
    [
        {"dV": 0.0},
        {"V_min": 0.0},
        {"V_min": 0.4, "V_max": 0.3},
        {"dV": 0.5},
        {"time_per_step": -1.0},
        {"transient": 1.0},
        {"V_min": 0.1, "V_max": 0.5, "dV": 1e-6},
    ],
)
def test_bad_settings_are_rejected(kw):
    with pytest.raises(ParameterError):
        SweepSettings(**kw)


def test_grid_holds_the_end_points():
    s = SweepSettings(V_min=0.25, V_max=0.45, dV=0.005)
    grid = s.V_grid()
    assert grid[0] == 0.25 and grid[-1] == 0.45 and len(grid) == 41
    assert 0.345 in grid


@pytest.mark.slow  # two finer, longer sweeps (about 15 s, measured)
def test_V_up_converges_in_time_per_step_and_dV():
    """Finer steps and longer holds: V_up stays within 0.005 of the paper's 0.345."""
    for dV, T in ((0.001, 400.0), (0.005, 2000.0)):
        r = hysteresis_sweep(BlockParams(), SweepSettings(V_min=0.3, V_max=0.4, dV=dV, time_per_step=T))
        assert abs(r.V_up - PAPER_V_UP) <= 0.005
