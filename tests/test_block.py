"""Runs of eq. (1): slip table, statistics, decimation, scaling to M = sigma = 1, period law."""

from __future__ import annotations

import numpy as np
import pytest

from stickslip.analysis.dynamics.slip_limit import PAPER_DURATION, PAPER_FORCE_AT_STOP, period_sweep, solve_slip_limit
from stickslip.models.params import BlockParams, ParameterError, scale_block
from stickslip.run.block import BlockState, simulate_block


@pytest.fixture(scope="module")
def paper_run():
    """The paper's run (Fig. 1) long enough for three slips."""
    return simulate_block(BlockParams(), 1100.0)


def test_paper_run_slips(paper_run):
    run = paper_run
    p = run.params
    # The first slip starts when K V t first exceeds Fs: t = Fs / (K V) = 300, to within a step.
    assert 300.0 < run.slips["t_c"].iloc[0] <= 300.0 + p.dt
    assert len(run.slips) == 3
    s = run.series
    for row in run.slips.itertuples():
        i_c = int(round(row.t_c / p.dt))
        i_e = int(round(row.t_e / p.dt))
        stopped = s["stopped"].values
        # stopped before the start, moving through the slip, stopped at its end
        assert stopped[i_c] and not stopped[i_c + 1 : i_e].any() and stopped[i_e]
        assert row.slip == s["x"].values[i_e] - s["x"].values[i_c]
        assert row.force_at_stop == pytest.approx(p.K * (p.V * row.t_e - s["x"].values[i_e]), abs=1e-12)
    assert np.isnan(run.slips["period"].iloc[0])
    assert np.allclose(run.slips["period"].iloc[1:], np.diff(run.slips["t_c"]))


def test_paper_run_statistics(paper_run):
    run = paper_run
    s = run.series
    stopped = s["stopped"].values
    assert run.v_min == s["v"].values.min() == 0.0
    assert run.v_max == s["v"].values.max()
    assert run.n_stops == int(np.sum(~stopped[:-1] & stopped[1:]))
    assert run.n_starts == run.n_stops == 3
    assert run.final == BlockState(
        x=float(s["x"][-1]), v=float(s["v"][-1]), theta=float(s["theta"][-1]), stopped=bool(stopped[-1])
    )
    assert np.allclose(s["f"], run.params.K * (run.params.V * s["t"] - s["x"]))
    summary = run.summary()
    assert summary["events"] == 3
    assert summary["period"] == pytest.approx(np.diff(run.slips["t_c"]).mean())
    # Paper's numbers (section 2): the slip of eq. (1) at V = 0.001 is that of eq. (3) up to
    # the grid (t_e within one step of the true stop, the paper's 1.035 one step before it) and
    # an O(V) shift of the force, K V (t_e - t_c) = 0.0104 at most (about 1e-3 in fact).
    assert summary["slip_duration"] == pytest.approx(PAPER_DURATION, abs=2 * run.params.dt)
    assert summary["force_at_stop"] == pytest.approx(PAPER_FORCE_AT_STOP, abs=0.003)


def test_decimation_keeps_statistics(paper_run):
    every = 997
    dec = simulate_block(BlockParams(), 1100.0, every=every)
    full = paper_run.series
    assert dec.series["t"].size == full["t"].size // every + 2
    picked = np.r_[np.arange(0, dec.steps + 1, every), dec.steps]
    for name in ("t", "x", "v", "theta", "stopped"):
        assert np.array_equal(dec.series[name].values, full[name].values[picked])
    assert dec.slips.equals(paper_run.slips)
    assert (dec.v_min, dec.v_max, dec.n_stops, dec.n_starts) == (
        paper_run.v_min, paper_run.v_max, paper_run.n_stops, paper_run.n_starts
    )  # fmt: skip
    assert dec.final == paper_run.final


@pytest.mark.parametrize("M, sigma, exact", [(2.0, 0.5, True), (1.7, 0.6, False)])
def test_scaling_to_unit_mass(M, sigma, exact):
    """Section 2: eq. (1) with M, sigma equals the scaled eq. (1) with x = (sigma/M) x~."""
    p = BlockParams(K=12.0, V=0.02, beta=0.7, alpha=1.3, Fs=2.5, M=M, sigma=sigma)
    q = scale_block(p)
    assert (q.M, q.sigma) == (1.0, 1.0)
    c = sigma / M
    s0 = BlockState(x=-0.1, v=0.0, theta=0.4)
    t_end = 150.0
    a = simulate_block(p, t_end, initial=s0)
    b = simulate_block(q, t_end, initial=BlockState(x=s0.x / c, v=0.0, theta=s0.theta))
    assert len(a.slips) >= 2
    for name, factor in (("x", c), ("v", c), ("theta", 1.0), ("f", sigma)):
        got, want = a.series[name].values, factor * b.series[name].values
        if exact:  # powers of two: scaling commutes with rounding
            assert np.array_equal(got, want), name
        else:
            assert np.allclose(got, want, rtol=1e-9, atol=1e-12), name
    assert np.array_equal(a.series["stopped"].values, b.series["stopped"].values)
    assert np.allclose(a.slips["t_c"], b.slips["t_c"])


def test_restart_continues_with_new_velocity():
    p = BlockParams(V=0.02)
    whole = simulate_block(p, 200.0)
    first = simulate_block(p, 120.0)
    second = simulate_block(p, 80.0, initial=first.restart_state())
    # x shifted by V times the first run's t_end: same spring force and dynamics
    assert second.final.x + p.V * 120.0 == pytest.approx(whole.final.x, abs=1e-8)
    assert len(first.slips) + len(second.slips) == len(whole.slips) >= 2
    assert second.final.theta == pytest.approx(whole.final.theta, abs=1e-8)
    f_end = p.K * (p.V * 120.0 - first.final.x)
    assert p.K * (0.0 - first.restart_state().x) == pytest.approx(f_end, rel=1e-12)


def test_many_short_slips_grow_the_table():
    # Fs below sigma theta: the block starts and stops within single steps (chatter), which
    # overflows the first slip buffer; the table must still hold every slip.
    p = BlockParams(V=0.01, Fs=0.5)
    run = simulate_block(p, 20.0, initial=BlockState(x=-0.06, theta=1.0))
    assert len(run.slips) > 16
    assert len(run.slips) == run.n_stops == run.n_starts - (not run.final.stopped)
    assert (run.slips["duration"] > 0).all()


def test_block_state_validation():
    with pytest.raises(ParameterError, match="v must be 0"):
        BlockState(v=0.1, stopped=True)
    with pytest.raises(ParameterError, match="theta"):
        BlockState(theta=-0.1)
    with pytest.raises(ParameterError, match="x"):
        BlockState(x=float("nan"))
    with pytest.raises(ParameterError, match="t_end"):
        simulate_block(BlockParams(), -1.0)
    with pytest.raises(ParameterError, match="every"):
        simulate_block(BlockParams(), 1.0, every=0)


@pytest.mark.parametrize("V", [0.001, 0.002, 0.005, 0.01])
def test_period_law_matches_simulation(V):
    """Fig. 3: the period law from eq. (3) matches the simulated period within 0.5% for V <= 0.01."""
    p = BlockParams(V=V)
    law = solve_slip_limit(p, dense=False)
    T = law.law_a + law.law_b / (p.K * V)
    run = simulate_block(p, p.Fs / (p.K * V) + 3.5 * T, every=10**9)
    periods = np.diff(run.slips["t_c"].to_numpy())
    assert len(periods) == 3
    assert np.all(np.abs(periods / T - 1.0) < 0.005)
    # and the paper's printed law, T = 1.035 + 3.432 / (K V)
    assert np.all(np.abs(periods / (1.035 + 3.432 / (p.K * V)) - 1.0) < 0.005)


def test_period_sweep_table():
    V = [0.003, 0.01]
    table = period_sweep(BlockParams(), V, periods=2)
    assert list(table["V"]) == V
    law = solve_slip_limit(dense=False)
    assert np.allclose(table["period_law"], [law.period(v) for v in V])
    assert (table["n_periods"] == 2).all()
    assert (table["rel_dev"].abs() < 0.005).all()
