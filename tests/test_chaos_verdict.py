"""The revised verdict (issue 51, item 5) on constructed measurements: each branch, and the
ambiguous cases between them."""

from __future__ import annotations

import pytest

from stickslip.analysis.dynamics.chaos_verdict import VERDICTS, chaos_verdict
from stickslip.models.params import ParameterError

# an irregular point of the paper's chain at beta = 0.5 as the lifetimes study measures it
IRREGULAR = {
    "starts": 8,
    "lyapunov": -1.0e-4,
    "lyapunov_err": 3.0e-5,
    "threshold": (1e-4, 1e-2),
    "growth": (1.86, 0.25),
}


def test_every_start_settled_is_periodic_with_its_periods():
    v = chaos_verdict(starts=8, periodic=8, periods=[25, 20, 20])
    assert v.verdict == "periodic"
    assert "20, 25 slips" in v.text and "all 8 starts" in v.text


def test_settled_wins_over_a_positive_exponent():
    # settling is seen directly; an exponent measured from another start does not overrule it
    v = chaos_verdict(starts=4, periodic=3, steady=1, lyapunov=0.3, lyapunov_err=0.01)
    assert v.verdict == "periodic" and "1 in steady sliding" in v.text


def test_every_start_in_steady_sliding_is_steady():
    assert chaos_verdict(starts=3, steady=3).verdict == "steady"


def test_a_positive_exponent_beyond_two_errors_is_chaotic():
    v = chaos_verdict(starts=8, lyapunov=0.025, lyapunov_err=0.001)
    assert v.verdict == "chaotic" and "8 of 8 starts irregular" in v.text
    # no threshold, no growth needed; lifetimes not measured at all is fine too
    assert chaos_verdict(lyapunov=0.34, lyapunov_err=0.03).verdict == "chaotic"


def test_an_exponent_at_exactly_two_errors_is_not_chaotic():
    v = chaos_verdict(**{**IRREGULAR, "lyapunov": 2.0e-5, "lyapunov_err": 1.0e-5})
    assert v.verdict == "stable chaos"
    assert chaos_verdict(**{**IRREGULAR, "lyapunov": 2.01e-5, "lyapunov_err": 1.0e-5}).verdict == "chaotic"
    # three errors asked for: 2.5 errors is not enough
    v = chaos_verdict(**{**IRREGULAR, "lyapunov": 2.5e-5, "lyapunov_err": 1.0e-5}, sigmas=3.0)
    assert v.verdict == "stable chaos"


def test_stable_chaos_needs_all_three():
    v = chaos_verdict(**IRREGULAR)
    assert v.verdict == "stable chaos"
    assert len(v.reasons) == 4 and "(0.0001, 0.01]" in v.text and "b = 1.86" in v.text
    # a point where some starts settled and others did not is still judged on the others
    assert chaos_verdict(**{**IRREGULAR, "periodic": 4}).verdict == "stable chaos"


@pytest.mark.parametrize(
    "change, says",
    [
        ({"lyapunov": None}, "no exponent measured"),
        ({"lyapunov": float("nan")}, "no exponent measured"),
        ({"threshold": None}, "no decorrelation threshold measured"),
        ({"threshold": (None, None)}, "no finite decorrelation threshold"),
        ({"threshold": (1e-4, None)}, "no finite decorrelation threshold"),
        ({"threshold": (None, 1e-10)}, "below the deltas tested"),
        ({"growth": None}, "growth of the lifetimes with N not measured"),
        ({"growth": (0.3, 0.2)}, "do not grow with N"),
        ({"growth": (-0.5, 0.1)}, "do not grow with N"),
        ({"growth": (float("nan"), 0.1)}, "not measured"),
    ],
)
def test_each_missing_or_failed_test_leaves_it_undetermined(change, says):
    v = chaos_verdict(**{**IRREGULAR, **change})
    assert v.verdict == "undetermined"
    assert says in v.text
    assert v.to_dict()["verdict"] == "undetermined" and v.to_dict()["verdict_text"] == v.text


def test_without_lifetimes_the_other_tests_still_speak():
    v = chaos_verdict(**{**IRREGULAR, "starts": 0})
    assert v.verdict == "stable chaos" and "lifetimes not measured" in v.reasons


def test_counts_that_do_not_add_up_are_refused():
    with pytest.raises(ParameterError, match="periodic"):
        chaos_verdict(starts=3, periodic=2, steady=2)
    with pytest.raises(ParameterError, match="periodic"):
        chaos_verdict(starts=3, periodic=-1)


def test_the_verdicts_are_the_listed_ones():
    seen = {
        chaos_verdict(starts=1, periodic=1).verdict,
        chaos_verdict(starts=1, steady=1).verdict,
        chaos_verdict(lyapunov=1.0, lyapunov_err=0.1).verdict,
        chaos_verdict(**IRREGULAR).verdict,
        chaos_verdict(starts=1).verdict,
    }
    assert seen == set(VERDICTS)
