"""Survival of censored lifetimes (issue 51, item 2): Kaplan-Meier against the product-limit
formula by hand, the exponential fit on lifetimes drawn from a known exponential law, and the fits
of ln <T> on N and on ln N."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stickslip.analysis.stats.survival import exponential_fit, kaplan_meier, line_fit, size_fits
from stickslip.models.params import ParameterError


def _censored(rng, tau: float, n: int, budget: float):
    """Lifetimes from the exponential law of mean ``tau``, censored at ``budget`` and, for a third
    of them, at a random earlier time."""
    life = rng.exponential(tau, n)
    cut = np.where(rng.random(n) < 1 / 3, rng.uniform(0, budget, n), budget)
    return np.minimum(life, cut), life <= cut


def test_kaplan_meier_is_the_product_limit_formula():
    t = np.array([2.0, 3.0, 3.0, 5.0, 7.0, 8.0, 8.0, 11.0])
    e = np.array([1, 1, 0, 1, 0, 1, 1, 0], dtype=bool)
    km = kaplan_meier(t, e)
    # by hand: S just after each distinct time = prod (1 - ended / at risk)
    s, expected = 1.0, []
    for x in np.unique(t):
        at_risk, died = np.sum(t >= x), np.sum(e & (t == x))
        s *= 1 - died / at_risk
        expected.append(s)
    assert km["t"].tolist() == np.unique(t).tolist()
    assert km["survival"].to_numpy() == pytest.approx(expected, rel=1e-12)
    assert km["at_risk"].tolist() == [8, 7, 5, 4, 3, 1] and km["ended"].tolist() == [1, 1, 1, 0, 2, 0]
    assert np.all(km["low"] <= km["survival"] + 1e-12) and np.all(km["survival"] <= km["high"] + 1e-12)


def test_kaplan_meier_follows_the_law_the_lifetimes_were_drawn_from():
    rng = np.random.default_rng(1)
    t, e = _censored(rng, 100.0, 2000, 250.0)
    km = kaplan_meier(t, e)
    inside = km[km["t"] < 200]
    truth = np.exp(-inside["t"] / 100.0)
    # the 95% band holds the true law at most times (pointwise: a few per cent may lie outside)
    assert np.mean((inside["low"] <= truth) & (truth <= inside["high"])) > 0.9
    assert np.max(np.abs(inside["survival"] - truth)) < 0.04


def test_the_exponential_fit_recovers_the_mean_with_its_stated_error():
    rng = np.random.default_rng(2)
    taus, errs, covered = [], [], 0
    for _ in range(300):
        t, e = _censored(rng, 100.0, 200, 150.0)
        fit = exponential_fit(t, e)
        taus.append(fit.tau)
        errs.append(fit.tau_err)
        covered += fit.tau_low <= 100.0 <= fit.tau_high
        assert fit.ended == int(np.sum(e)) and fit.exposure == pytest.approx(np.sum(t))
    taus = np.array(taus)
    assert abs(taus.mean() - 100.0) < 4 * taus.std() / math.sqrt(len(taus))
    # the stated error is the scatter of the estimate over draws, within 15 per cent
    assert np.mean(errs) == pytest.approx(taus.std(), rel=0.15)
    assert 0.91 <= covered / 300 <= 0.99


def test_the_tail_fit_and_the_weibull_test():
    rng = np.random.default_rng(3)
    # an exponential tail after a fixed delay of 50: the fit from 50 finds tau, the test passes
    t, e = _censored(rng, 80.0, 1500, 300.0)
    fit = exponential_fit(t + 50.0, e, t_from=50.0)
    assert fit.tau == pytest.approx(80.0, abs=4 * fit.tau_err) and fit.mean == pytest.approx(50.0 + fit.tau)
    assert fit.weibull_shape == pytest.approx(1.0, abs=0.1) and fit.exponential_p > 0.01
    # lifetimes of a Weibull law with shape 3 are not exponential
    life = 100.0 * rng.weibull(3.0, 500)
    fit = exponential_fit(life, np.ones(500, dtype=bool))
    assert fit.weibull_shape == pytest.approx(3.0, rel=0.15) and fit.exponential_p < 1e-6


def test_no_ended_lifetime_gives_a_lower_bound():
    fit = exponential_fit([100.0, 200.0, 300.0], [False, False, False])
    assert fit.ended == 0 and fit.tau == math.inf and fit.rate == 0.0
    # P(no end in exposure 600) = exp(-600 / tau) = 0.05 at tau = 600 / ln 20
    assert fit.tau_low == pytest.approx(600.0 / math.log(20.0), rel=1e-9)


def test_line_fits_and_which_form_fits_better():
    N = np.arange(3.0, 15.0, 2.0)
    rng = np.random.default_rng(4)
    # planted exponential growth with 5% errors
    mean = 20.0 * np.exp(0.4 * N) * (1 + 0.05 * rng.standard_normal(N.size))
    f = size_fits(N, mean, 0.05 * mean, extrapolate_to=20.0)
    assert f["better"] == "exponential"
    assert f["exponential"]["slope"] == pytest.approx(0.4, abs=3 * f["exponential"]["slope_err"])
    ln_truth = math.log(20.0) + 0.4 * 20.0
    assert abs(f["exponential"]["ln_T_at"] - ln_truth) < 3 * f["exponential"]["ln_T_at_err"]
    assert f["exponential"]["T_at_low"] < f["exponential"]["T_at"] < f["exponential"]["T_at_high"]
    # planted power law N^3
    mean = 2.0 * N**3 * (1 + 0.05 * rng.standard_normal(N.size))
    f = size_fits(N, mean, 0.05 * mean)
    assert f["better"] == "power" and f["power"]["slope"] == pytest.approx(3.0, abs=3 * f["power"]["slope_err"])
    # the weighted slope and its error against numpy's polyfit
    x, y, s = np.array([1.0, 2.0, 3.0, 4.0]), np.array([1.1, 1.9, 3.2, 3.9]), np.array([0.1, 0.2, 0.1, 0.3])
    coef, cov = np.polyfit(x, y, 1, w=1 / s, cov="unscaled")
    fit = line_fit(x, y, s)
    chi2 = fit["chi2"]
    assert fit["slope"] == pytest.approx(coef[0]) and fit["intercept"] == pytest.approx(coef[1])
    assert fit["slope_err"] == pytest.approx(math.sqrt(cov[0, 0] * max(1.0, chi2 / 2)))


def test_bad_lifetimes_are_refused():
    with pytest.raises(ParameterError):
        kaplan_meier([1.0, -1.0], [True, True])
    with pytest.raises(ParameterError):
        exponential_fit([1.0], [True, False])
    with pytest.raises(ParameterError):
        size_fits([3, 5], [0.0, 1.0], [1.0, 1.0])
