"""The slip-size fit of Figs. 7, 8 and the exponents study (analysis.stats.chain_runs.size_statistics) on
synthetic power laws: it gives back their exponent, and great events added show as an excess."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from stickslip.analysis.stats.chain_runs import size_statistics

N = 50


def _power_law_events(tau: float, n: int, s_span: float, seed: int) -> pd.DataFrame:
    """Sizes drawn from p(S) ~ S^-tau on [1, inf) by inverting the CDF; S >= s_span spans the chain."""
    u = np.random.default_rng(seed).random(n)
    S = (1.0 - u) ** (1.0 / (1.0 - tau))
    return pd.DataFrame({"S": S, "n_blocks": np.where(S >= s_span, N, 1), "max_block": np.where(S >= s_span, N, 1)})


@pytest.mark.parametrize("tau", [1.3, 1.6, 2.0])
def test_synthetic_power_law_gives_back_its_exponent(tau):
    events = _power_law_events(tau, 20000, 100.0, seed=1)
    st = size_statistics(events, N, small_only=True, spanning="n_blocks", bootstrap=100)
    fit = st["fit"]
    assert fit.s_max == pytest.approx(events.loc[events.S >= 100.0, "S"].min())
    assert abs(fit.tau - tau) < 4.0 * fit.tau_err
    assert fit.tau_err < 0.05
    # a pure power law has no excess of great events: observed / expected near 1
    assert st["observed"] > 20
    assert abs(st["excess"] - 1.0) < 4.0 / math.sqrt(st["observed"])


def test_added_great_events_show_as_excess():
    events = _power_law_events(1.6, 20000, 100.0, seed=2)
    base = size_statistics(events, N, small_only=True, spanning="n_blocks", bootstrap=0)
    extra = int(4 * base["observed"])
    bump = pd.DataFrame({"S": np.full(extra, 500.0), "n_blocks": N, "max_block": N})
    st = size_statistics(
        pd.concat([events, bump], ignore_index=True), N, small_only=True, spanning="n_blocks", bootstrap=0
    )
    # the bump also enters the count above s_min that the prediction scales, so less than 5x
    assert st["observed"] == 5 * base["observed"]
    assert st["excess"] > 3.5 * base["excess"]


def test_spanning_choice_is_checked():
    with pytest.raises(ValueError, match="spanning"):
        size_statistics(_power_law_events(1.6, 100, 10.0, 0), N, small_only=True, spanning="blocks")
