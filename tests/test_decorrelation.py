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

from stickslip.analysis.decorrelation import (
    event_decorrelation,
    first_disagreement,
    growth_power,
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


def test_periodic_block_never_decorrelates():
    state = _after(CYCLE, "rest", 0.0, 200.0)
    res = event_decorrelation(CYCLE, state, DELTAS, t_max=1500.0)
    assert res.reference_events > 20
    for row in res.rows:
        assert row["decorrelated"] is False
        assert row["events"] == res.reference_events


def test_identical_runs_never_decorrelate():
    params = chain_params("two-blocks")
    state = _after(params, "rest", 0.01, 500.0)
    res = event_decorrelation(params, state, (0.0,), t_max=2000.0)
    (row,) = res.rows
    assert row["decorrelated"] is False and row["events"] == res.reference_events > 40


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


def test_verdict_on_synthetic_inputs():
    d = np.array(DELTAS)
    log_n = np.round(3.0 * np.log(1 / d))
    power_n = np.round(1e-3 / d)
    yes = [True] * 4
    assert verdict(0.05, 0.001, d, log_n, yes) == "chaotic"
    assert verdict(0.05, 0.001, d, [0] * 4, [False] * 4) == "chaotic"  # the flow decides
    assert verdict(1e-5, 2e-5, d, log_n, yes) == "stable chaos"
    assert verdict(1e-5, 2e-5, d, power_n, yes) == "regular"
    assert verdict(1e-5, 2e-5, d, log_n, [True, True, True, False]) == "regular"
    assert verdict(-0.3, 0.01, d, log_n, yes) == "regular"
    assert verdict(0.003, 0.002, d, log_n, yes) == "stable chaos"  # within 2 errors
    assert verdict(0.003, 0.002, d, log_n, yes, sigmas=1.0) == "chaotic"
    assert verdict(None, None, d, log_n, yes) == "undetermined"
    assert verdict(float("nan"), 0.1, d, log_n, yes) == "undetermined"


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
    assert main(["lyapunov", "--model", "two-blocks", "--decorrelation"]) == 2
