"""Decorrelation of event sequences and the verdict of the chaos study (issue 26, items 3 and 4).

Known answers: a periodic orbit of the single block (eq. 1) never decorrelates, whatever delta;
two identical runs never do; two blocks (chaotic) always do, later for smaller delta. The verdict
is checked on synthetic n(delta) of the three kinds: logarithmic growth (n = c ln(1/delta)),
power-law growth (n ~ 1/delta) and none.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from stickslip.analysis.dynamics.decorrelation import (
    GridSequences,
    event_decorrelation,
    first_disagreement,
    growth_power,
    sequence_decorrelation,
    verdict,
)
from stickslip.models.params import ChainParams
from stickslip.models.presets import chain_params
from stickslip.run.located import LocatedStepper, start_state

CYCLE = ChainParams(N=1, K=10.0, V=0.05, beta=1.0, Fs=3.0)
DELTAS = (1e-12, 1e-10, 1e-8, 1e-6)


def _after(params, start, amplitude, t0):
    state = start_state(params, start, perturbation=amplitude)
    state, _ = LocatedStepper(params).advance(state, round(t0 / params.dt))
    return state


def test_first_disagreement_by_hand():
    a = [1.0, 2.0, 3.0, 4.0]
    assert first_disagreement(a, a) is None
    assert first_disagreement(a, [1.0, 2.0 * (1 + 1e-6), 3.0]) is None  # within rtol, shorter
    assert first_disagreement(a, [1.0, 2.0, 3.1, 4.0]) == 2
    assert first_disagreement(a, [1.5, 2.0, 3.0, 4.0]) == 0
    assert first_disagreement(a, [1.0, 2.0, 3.0, 4.0 * (1 + 2e-3)], rtol=1e-3) == 3
    assert first_disagreement([], a) is None
    # the same sizes, but another start block or another number of blocks: another slip
    blocks = [[1, 1], [2, 1], [1, 3], [4, 1]]
    assert first_disagreement(a, a, 1e-3, blocks, blocks) is None
    assert first_disagreement(a, a, 1e-3, blocks, [[1, 1], [2, 1], [2, 3], [4, 1]]) == 2
    assert first_disagreement(a, a, 1e-3, blocks, [[1, 1], [2, 2], [1, 3], [4, 1]]) == 1


def test_periodic_block_never_decorrelates():
    state = _after(CYCLE, "rest", 0.0, 200.0)
    res = event_decorrelation(CYCLE, state, DELTAS, t_max=1500.0)
    assert res.reference_events > 20
    for row in res.rows:
        assert row["decorrelated"] is False
        assert row["events"] == res.reference_events


@pytest.mark.slow
def test_identical_runs_never_decorrelate():
    params = chain_params("two-blocks")
    state = _after(params, "rest", 0.01, 500.0)
    res = event_decorrelation(params, state, (0.0,), t_max=2000.0)
    (row,) = res.rows
    assert row["decorrelated"] is False and row["events"] == res.reference_events > 40


@pytest.mark.slow  # the located engine on two blocks, compiled here first (about 80 s, measured)
def test_two_blocks_decorrelate_later_for_smaller_delta():
    params = chain_params("two-blocks")
    state = _after(params, "rest", 0.01, 500.0)
    res = event_decorrelation(params, state, DELTAS, t_max=2000.0)
    n = [r["events"] for r in res.rows]
    assert all(r["decorrelated"] for r in res.rows), res.rows
    assert n[0] > n[-1] > 0
    assert n[0] < res.reference_events
    # exponential growth of the separation: n grows as ln(1/delta), a small power
    assert growth_power(DELTAS, n, [True] * 4) < 0.25


def test_growth_power_of_synthetic_laws():
    d = np.array(DELTAS)
    assert growth_power(d, 100.0 / d**0.5 - 1, [True] * 4) == pytest.approx(0.5)
    log_law = 3.0 * np.log(1 / d)
    assert 0.03 < growth_power(d, log_law, [True] * 4) < 0.08
    assert math.isnan(growth_power(d, log_law, [True, False, False, False]))


def _rows(table):
    """Rows of (delta, seed, decorrelated) from {seed: {delta: decorrelated}}."""
    return [{"delta": d, "seed": s, "decorrelated": f} for s, by in table.items() for d, f in by.items()]


#: Synthetic n(delta) of three windows: seed 0 from 1e-4 on, seed 1 at 1e-6 and 1e-2 (not monotone),
#: seed 2 never; no window at 1e-8.
THRESHOLD = _rows(
    {
        0: {1e-8: False, 1e-6: False, 1e-4: True, 1e-2: True},
        1: {1e-8: False, 1e-6: True, 1e-4: False, 1e-2: True},
        2: {1e-8: False, 1e-6: False, 1e-4: False, 1e-2: False},
    }
)
NEVER = _rows({s: {d: False for d in (1e-12, 1e-6, 1e-1)} for s in (0, 1)})


def test_verdict_on_synthetic_inputs():
    chaotic = verdict(0.05, 0.001, NEVER, window=1000)
    assert chaotic.label == "chaotic"  # the flow decides, whatever the sequences do
    regular = verdict(-1e-6, 3e-6, NEVER, window=1000)
    assert regular.label == "regular" and regular.window == 1000 and regular.threshold is None
    assert regular.text.startswith("regular over 1000 slips for delta <= 0.1")
    stable = verdict(1e-7, 1e-7, THRESHOLD, window=1000)
    assert stable.label == "stable chaos" and stable.threshold == (1e-8, 1e-6)
    assert (stable.windows_decorrelated, stable.windows) == (2, 3)
    assert "at delta >= 1e-06 (delta* 1e-06 .. 0.0001), never at delta <= 1e-08" in stable.text
    # an exponent below zero beyond its errors does not make a finite threshold regular
    assert verdict(-0.3, 0.01, THRESHOLD, window=1000).label == "stable chaos"
    assert verdict(0.003, 0.002, THRESHOLD, window=1000).label == "stable chaos"  # within 2 errors
    assert verdict(0.003, 0.002, THRESHOLD, window=1000, sigmas=1.0).label == "chaotic"
    # the smallest delta decorrelated: no threshold within the list
    low = _rows({0: {1e-8: True, 1e-6: True}})
    assert verdict(1e-7, 1e-7, low, window=500).label == "undetermined"
    assert verdict(None, None, THRESHOLD, window=1000).label == "undetermined"
    assert verdict(float("nan"), 0.1, THRESHOLD, window=1000).label == "undetermined"
    d = stable.to_dict()
    assert d["verdict"] == "stable chaos" and d["threshold_below"] == 1e-8 and d["threshold_low"] == 1e-6


def test_delta_star_by_hand():
    from stickslip.analysis.dynamics.threshold import delta_star

    out = delta_star(THRESHOLD)
    assert out["per_seed"] == [1e-4, 1e-6, None] and out["censored"] == 1
    assert out["per_seed_monotone"] == [1e-4, 1e-2, None]
    # log10 delta* = -4, -6: mean -5, sample std sqrt(2), standard error sqrt(2) / sqrt(2) = 1
    assert out["log10_mean"] == pytest.approx(-5.0) and out["log10_err"] == pytest.approx(1.0)
    assert out["geometric_mean"] == pytest.approx(1e-5)
    assert (out["low"], out["high"], out["below"]) == (1e-6, 1e-4, 1e-8)
    one = delta_star(_rows({0: {1e-3: False, 1e-1: True}}))
    assert one["per_seed"] == [0.1] and math.isnan(one["log10_err"]) and one["below"] == 1e-3
    none = delta_star(NEVER)
    assert none["geometric_mean"] is None and none["censored"] == 2 and math.isnan(none["log10_mean"])
    with pytest.raises(ValueError, match="lacks"):
        delta_star(THRESHOLD[:-1])


def test_threshold_fit_by_hand():
    from stickslip.analysis.dynamics.threshold import threshold_fit

    # x = log10 N = 1, 1, 2, 2; y = -3, -5, -4, -6: slope -1, intercept -3, residuals +-1,
    # s^2 = 4 / 2, sum (x - 1.5)^2 = 1, so the slope's error is sqrt(2): no trend at two errors
    fit = threshold_fit([10, 100, 1000], [[1e-3, 1e-5], [1e-4, 1e-6], [None]])
    assert fit["slope"] == pytest.approx(-1.0) and fit["intercept"] == pytest.approx(-3.0)
    assert fit["slope_err"] == pytest.approx(math.sqrt(2.0))
    assert (fit["points"], fit["censored"], fit["Ns"], fit["trend"]) == (4, 1, [10, 100], "none")
    exact = threshold_fit([10, 100, 1000], [[1e-2], [1e-3], [1e-4]])
    assert exact["slope"] == pytest.approx(-1.0) and exact["slope_err"] == pytest.approx(0.0, abs=1e-12)
    assert exact["trend"] == "shrinks"
    assert threshold_fit([10, 100, 1000], [[1e-4], [1e-3], [1e-2]])["trend"] == "grows"
    short = threshold_fit([10, 10], [[1e-3], [1e-4]])  # one N: no slope
    assert math.isnan(short["slope"]) and short["trend"] == "none"


def test_cli_decorrelation_json(capsys):
    import json

    from stickslip.cli import main

    status = main(
        ["lyapunov", "--model", "two-blocks", "--switches", "located", "--decorrelation"]
        + ["--transient", "500", "--t-end", "2500", "--json"]
    )
    out = json.loads(capsys.readouterr().out)
    assert status in (0, None)
    rows = out["decorrelation"]
    assert [r["delta"] for r in rows] == list(DELTAS)
    assert all(r["decorrelated"] for r in rows) and rows[0]["events"] > rows[-1]["events"]
    assert main(["lyapunov", "--model", "two-blocks", "--decorrelation", "--betas", "1"]) == 2


# ------------------------------------------------------------------------------------------
# Slip sequences: the comparison's logic on scripted sequences, then the engine's map


class _Scripted:
    """Slips every 10 steps: t_start = k dt, size 1 + k / 100, start block k % 3, one block. A
    twin's slips change from slip ``flip`` on (another start block) or stop after slip ``stop``
    (a twin that stops slipping); a change of Fs acts as a twin with flip = 7."""

    switches = "scripted"

    class State:
        def __init__(self, step=0, flip=None, stop=None):
            self.step, self.flip, self.stop = step, flip, stop

        def copy(self):
            return _Scripted.State(self.step, self.flip, self.stop)

    def __init__(self, params, flips):
        self.params = params
        self.flips = flips  # delta -> (flip, stop)

    def prepare(self, state):
        return state.copy()

    def twin(self, params, state, direction, delta):
        flip, stop = self.flips[delta]
        return _Scripted.State(state.step, flip, stop)

    def run(self, params, state, step):
        flip = 7 if params.Fs != self.params.Fs else state.flip
        ks = np.arange(state.step // 10 + 1, step // 10 + 1)
        if state.stop is not None:
            ks = ks[ks <= state.stop]
        blocks = (ks % 3) + (0 if flip is None else (ks >= flip))
        rows = np.column_stack((ks * 10 * params.dt, 1 + ks / 100, blocks, np.ones(len(ks))))
        out = state.copy()
        out.step = step
        return out, rows.reshape(-1, 4)


def test_sequence_comparison_counts_agreeing_slips_and_missing_ones():
    p = ChainParams(N=1)
    flips = {1e-9: (None, None), 1e-6: (25, None), 1e-3: (None, 40)}
    src = _Scripted(p, flips)
    res = sequence_decorrelation(src, _Scripted.State(), (1e-9, 1e-6, 1e-3), events=100, chunk=0.3)
    by = {r["delta"]: r for r in res.rows}
    assert res.reference_events == 100 and res.windows[0]["reference_events"] == 100
    assert by[1e-9]["decorrelated"] is False and by[1e-9]["events"] == 100
    # slip k (1-based) is row k - 1: the 25th slip is the first other one, 24 agree before it
    assert by[1e-6]["events"] == 24 and by[1e-6]["t_decorrelated"] == pytest.approx(250 * p.dt)
    # a twin that stops slipping after 40 slips: it has run twice the window, the 41st is missing
    assert by[1e-3]["decorrelated"] is True and by[1e-3]["events"] == 40
    # a window of time: both run as long, and a slip the twin lacks at the end is not counted
    res = sequence_decorrelation(src, _Scripted.State(), (1e-3,), events=None, t_max=0.5 * 300 * p.dt * 10 / 10)
    (row,) = res.rows
    assert row["decorrelated"] is False and row["events"] == res.reference_events == 15
    # a change of Fs; and seeds: windows one after the other
    res = sequence_decorrelation(src, _Scripted.State(), (1e-4,), perturbation="Fs", events=30, seeds=3, chunk=0.3)
    assert [r["events"] for r in res.rows] == [6, 0, 0]
    assert [w["reference_events"] for w in res.windows] == [30, 30, 30]


def test_parameter_perturbations_are_checked_against_the_model():
    from stickslip.models.params import ParameterError

    src = _Scripted(chain_params("batista-carlson"), {})
    with pytest.raises(ParameterError, match="perturbation Fs needs a model that reads Fs"):
        sequence_decorrelation(src, _Scripted.State(), (1e-3,), perturbation="Fs")
    with pytest.raises(ParameterError, match="perturbation V needs ends that do not read t"):
        sequence_decorrelation(
            _Scripted(ChainParams(N=3, ends="fixed"), {}), _Scripted.State(), (1e-3,), perturbation="V"
        )
    with pytest.raises(ParameterError, match="perturbation must be one of state, Fs, V"):
        sequence_decorrelation(src, _Scripted.State(), (1e-3,), perturbation="K")


def _grid_state(params, t):
    from stickslip.run.driver import run_chain
    from stickslip.run.errors import short_runs_expected

    with short_runs_expected():
        return run_chain(params, t).state


def test_grid_chunks_and_restarted_clock_give_the_slips_of_one_run():
    """Chunks continue the run exactly; a state moved back to t = 0 with its positions relative
    to the drive kept has the same slips (eq. 4 reads positions only relative to V t)."""
    from stickslip.run.driver import run_chain

    p = ChainParams(N=9, beta=0.5)
    st = _grid_state(p, 3000.0)
    one = run_chain(p, 6000.0, start=st).events
    src = GridSequences(p)
    s, a = src.run(p, st.copy(), round(4500.0 / p.dt))
    s, b = src.run(p, s, round(6000.0 / p.dt))
    rows = np.concatenate((a, b))
    assert len(rows) == len(one) > 5
    assert np.array_equal(rows[:, 1], one["S"].to_numpy()) and np.array_equal(rows[:, 2], one["start_block"])
    moved = src.prepare(st)
    assert moved.step == 0
    _, c = src.run(p, moved, round(3000.0 / p.dt))
    assert len(c) == len(one)
    assert np.array_equal(c[:, 2:], rows[:, 2:])
    assert np.allclose(c[:, 1], rows[:, 1], rtol=1e-9)
    assert np.allclose(c[:, 0] + 3000.0, rows[:, 0], atol=p.dt / 2)


@pytest.mark.parametrize("perturbation", ["state", "Fs", "V"])
def test_grid_periodic_block_keeps_its_slips_under_every_perturbation(perturbation):
    """One block's stick-slip cycle (eq. 1): every slip is block 1 alone, so no perturbation that
    keeps the cycle can change the sequence's slips; sizes move by about delta."""
    st = _grid_state(CYCLE, 200.0)
    res = sequence_decorrelation(GridSequences(CYCLE), st, (1e-12, 1e-6, 1e-3), perturbation=perturbation, events=300)
    assert res.reference_events == 300
    for row in res.rows:
        assert row["decorrelated"] is False and row["events"] == 300, row


def test_grid_two_blocks_decorrelate_later_for_smaller_delta():
    params = chain_params("two-blocks")
    from stickslip.run.driver import run_chain

    st = run_chain(params, 500.0, start="rest", perturbation=0.01).state
    res = sequence_decorrelation(GridSequences(params), st, (1e-12, 1e-8, 1e-4), events=1000)
    n = [r["events"] for r in res.rows]
    assert all(r["decorrelated"] for r in res.rows), res.rows
    assert n[0] > n[-1] and n[0] < 200


def test_cli_decorrelation_grid_rows_and_seeds(capsys):
    import json

    from stickslip.cli import main

    argv = ["lyapunov", "--N", "1", "--K", "10", "--V", "0.05", "--decorrelation", "--transient", "200"]
    status = main(argv + ["--perturb", "V", "--deltas", "1e-6,1e-3", "--events", "100", "--seeds", "2", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert status in (0, None)
    assert [(r["seed"], r["delta"]) for r in out["decorrelation"]] == [(0, 1e-6), (0, 1e-3), (1, 1e-6), (1, 1e-3)]
    assert all(not r["decorrelated"] and r["events"] == 100 for r in out["decorrelation"])
    assert out["decorrelation_switches"] == "grid" and out["decorrelation_perturbation"] == "V"
    assert [w["reference_events"] for w in out["decorrelation_windows"]] == [100, 100]
    assert main(argv + ["--deltas", "2"]) == 2
    assert main(["lyapunov", "--N", "1", "--events", "10"]) == 2


@pytest.mark.slow  # a thousand slips of N = 99 and four twins (15 s, measured)
def test_a_thousand_slips_of_the_chain_in_minutes():
    """The chain of eq. (4), N = 99, beta = 0.5: 1000 slips of the reference and four twins on
    the engine's map (how long it takes is for the benchmarks to say)."""
    p = ChainParams(N=99, beta=0.5)
    st = _grid_state(p, 5e5)
    res = sequence_decorrelation(GridSequences(p), st, DELTAS, events=1000)
    assert res.reference_events == 1000 and len(res.rows) == 4


def test_a_reference_that_stops_slipping_ends_its_window():
    """Steady sliding (eq. 1 above the inverse transition, V = 0.5) has no slips: the window of
    slips ends once the reference has been quiet for long, and nothing is compared."""
    from stickslip.analysis.dynamics.decorrelation import QUIET_STEPS
    from stickslip.run.state import initial_state

    p = ChainParams(N=1, V=0.5)
    res = sequence_decorrelation(GridSequences(p), initial_state(p, "steady"), (1e-6,), events=10)
    assert res.reference_events == 0 and res.windows[0]["t_window"] > QUIET_STEPS * p.dt
    assert res.rows[0]["decorrelated"] is False and res.rows[0]["events"] == 0
