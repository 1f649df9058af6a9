"""Slip-size statistics across the family: Carlson-Langer beside Fig. 8 (experiments/family.py)."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from stickslip.analysis.chain_runs import size_statistics
from stickslip.experiments.family import cl_statistics

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


def test_cl_statistics_returns_its_numbers_and_files(tmp_path):
    res = cl_statistics(4e3, tmp_path, fig8_N=19, fig8_t_end=4e4, bootstrap=10)
    keys = {
        "model",
        "N",
        "t_end",
        "t_from",
        "n_events",
        "n_spanning",
        "s_span",
        "tau",
        "tau_err",
        "s_min",
        "s_max",
        "n_fit",
        "excess",
        "observed",
        "expected",
        "spanning",
    }
    for name, model, n in (("carlson_langer", "carlson-langer", 100), ("fig8", "sakaguchi", 19)):
        assert keys <= set(res[name])
        assert res[name]["model"] == model and res[name]["N"] == n
        assert res[name]["n_events"] > 0
    assert res["carlson_langer"]["spanning"] == "n_blocks"
    assert res["fig8"]["spanning"] == "max_block"
    assert (tmp_path / "family_sizes.png").stat().st_size > 0
    assert (tmp_path / "family_sizes.pdf").read_bytes().startswith(b"%PDF")
    drawn = pd.read_parquet(tmp_path / "family_sizes.parquet")
    assert set(drawn["model"]) == {"carlson-langer", "fig8"} and (drawn["S"] > 0).all()
    pd.testing.assert_frame_equal(pd.read_csv(tmp_path / "family_sizes.csv"), drawn, check_dtype=False)
    stored = json.loads((tmp_path / "family_sizes.json").read_text())
    assert stored["carlson_langer"]["tau"] == pytest.approx(res["carlson_langer"]["tau"])
