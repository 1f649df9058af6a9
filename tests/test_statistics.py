"""Slip statistics (Figs. 7, 8), rupture-front speed (Fig. 6), time averages (Fig. 5b).

Expected values come from the sampling distributions themselves (known tau, known front speed,
closed-form bin probabilities) and, for the estimator, from the ``powerlaw`` package's own
numerical maximisation of the truncated likelihood.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import stats

from stickslip.analysis.stats.statistics import (
    fit_power_law,
    front_speed,
    pick_front_events,
    size_distribution,
    time_average,
    truncated_power_law_pdf,
)


def bounded_power_law(n: int, tau: float, s_min: float, s_max: float, seed: int) -> np.ndarray:
    """Inverse-CDF samples of p(S) ~ S^-tau on [s_min, s_max]."""
    u = np.random.default_rng(seed).random(n)
    e = 1.0 - tau
    return (s_min**e + u * (s_max**e - s_min**e)) ** (1.0 / e)


def bounded_cdf(s, tau, s_min, s_max):
    e = 1.0 - tau
    return (np.asarray(s) ** e - s_min**e) / (s_max**e - s_min**e)


# --- size distribution -------------------------------------------------------------------------


def test_density_matches_bin_probabilities_of_a_known_power_law():
    tau, a, b = 1.5, 1.0, 1e3
    S = bounded_power_law(200_000, tau, a, b, seed=1)
    dist = size_distribution(S, 15, s_min=a, s_max=b)
    edges = np.geomspace(a, b, 16)
    expected_prob = np.diff(bounded_cdf(edges, tau, a, b))
    np.testing.assert_allclose(dist["lower"], edges[:-1], rtol=1e-12)
    np.testing.assert_allclose(dist["upper"], edges[1:], rtol=1e-12)
    # density * width is the share of events in the bin: binomial noise only
    share = (dist["density"] * dist["width"]).values
    sigma = np.sqrt(expected_prob * (1 - expected_prob) / S.size)
    assert np.all(np.abs(share - expected_prob) < 5 * sigma)
    # and the density at the geometric centre approaches the pdf (slope -tau on log axes)
    slope = np.polyfit(np.log(dist["S"]), np.log(dist["density"]), 1)[0]
    assert slope == pytest.approx(-tau, abs=0.02)


def test_density_is_normalised_for_bin_width_and_counts_nonpositive_sizes():
    S = np.array([0.0, -1.0, np.nan, 1.0, 2.0, 2.0, 4.0, 8.0, 100.0])
    dist = size_distribution(S, [1.0, 3.0, 10.0])
    assert dist["count"].values.tolist() == [3, 2]  # 1, 2, 2 | 4, 8 ; 100 outside
    assert dist.attrs["n_dropped"] == 3
    assert dist.attrs["n_outside"] == 1
    assert dist.attrs["n_binned"] == 5
    np.testing.assert_allclose(dist["density"], [3 / (5 * 2.0), 2 / (5 * 7.0)])
    np.testing.assert_allclose(dist["S"], [math.sqrt(3.0), math.sqrt(30.0)])


@settings(max_examples=50, deadline=None)
@given(
    st.lists(st.floats(min_value=1e-3, max_value=1e6, allow_nan=False), min_size=2, max_size=300),
    st.integers(min_value=1, max_value=40),
)
def test_sum_of_density_times_width_is_one(values, bins):
    dist = size_distribution(np.array(values), bins)
    assert float((dist["density"] * dist["width"]).sum()) == pytest.approx(1.0, rel=1e-12)
    assert int(dist["count"].sum()) == len(values)


def test_size_distribution_rejects_bad_bins():
    with pytest.raises(ValueError):
        size_distribution([1.0, 2.0], [1.0, 1.0, 2.0])
    with pytest.raises(ValueError):
        size_distribution([1.0, 2.0], 0)


# --- power-law fit -----------------------------------------------------------------------------


@pytest.mark.parametrize("ratio", [1e3, 1e4])
@pytest.mark.parametrize("seed", [11, 12])
def test_truncated_fit_recovers_the_exponent(ratio, seed):
    tau, a = 1.5, 0.5
    S = bounded_power_law(20_000, tau, a, a * ratio, seed=seed)
    fit = fit_power_law(S, s_min=a, s_max=a * ratio, bootstrap=200, seed=seed)
    assert fit.n == S.size and fit.truncated
    assert abs(fit.tau - tau) < 3 * fit.tau_err
    assert abs(fit.tau - tau) < 0.05
    # bootstrap error and the asymptotic (Fisher) error agree for large n
    assert fit.tau_err == pytest.approx(fit.tau_err_fisher, rel=0.25)


def test_truncated_fit_equals_powerlaw_packages_numerical_mle():
    powerlaw = pytest.importorskip("powerlaw")
    a, b = 2.0, 2e3
    for tau in (0.8, 1.5, 2.2):
        S = bounded_power_law(5_000, tau, a, b, seed=5)
        fit = fit_power_law(S, s_min=a, s_max=b, bootstrap=0)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            reference = powerlaw.Power_Law(data=S, xmin=a, xmax=b, discrete=False, force_numerical_fit=True, verbose=0)
        assert fit.tau == pytest.approx(reference.alpha, abs=5e-4)
        assert fit.loglikelihood == pytest.approx(reference.loglikelihood, rel=1e-6)


def test_fit_maximises_the_likelihood_written_independently():
    a, b = 1.0, 1e3
    S = bounded_power_law(3_000, 1.5, a, b, seed=9)
    fit = fit_power_law(S, s_min=a, s_max=b, bootstrap=0)

    def loglik(tau):
        return np.sum(np.log((tau - 1) / (a ** (1 - tau) - b ** (1 - tau))) - tau * np.log(S))

    assert fit.loglikelihood == pytest.approx(loglik(fit.tau), rel=1e-10)
    h = 1e-3
    assert loglik(fit.tau) > loglik(fit.tau - h)
    assert loglik(fit.tau) > loglik(fit.tau + h)
    # curvature of the likelihood gives the Fisher error
    curvature = (loglik(fit.tau + h) - 2 * loglik(fit.tau) + loglik(fit.tau - h)) / h**2
    assert fit.tau_err_fisher == pytest.approx(1 / math.sqrt(-curvature), rel=1e-3)


@pytest.mark.parametrize("ratio", [1e3, 1e4])
def test_ignoring_the_upper_cutoff_biases_the_exponent(ratio):
    tau, a = 1.5, 1.0
    S = bounded_power_law(20_000, tau, a, a * ratio, seed=3)
    truncated = fit_power_law(S, s_min=a, s_max=a * ratio, bootstrap=100)
    ignored = fit_power_law(S, s_min=a, s_max=a * ratio, bootstrap=100, truncated=False)
    # the classic estimator, written out here
    assert ignored.tau == pytest.approx(1 + S.size / np.sum(np.log(S / a)), rel=1e-12)
    bias = ignored.tau - tau
    assert bias > 5 * ignored.tau_err  # biased upwards, well beyond its own error
    assert abs(truncated.tau - tau) < 3 * truncated.tau_err


def test_fit_uses_only_events_inside_the_cutoffs_and_defaults_to_the_data_range():
    S = bounded_power_law(2_000, 1.5, 1.0, 100.0, seed=4)
    fit = fit_power_law(S, s_min=2.0, s_max=50.0, bootstrap=0)
    assert fit.n == int(np.sum((S >= 2.0) & (S <= 50.0)))
    assert fit.n_total == S.size
    default = fit_power_law(S, bootstrap=0)
    assert default.s_min == S.min() and default.s_max == S.max() and default.n == S.size


def test_bootstrap_is_reproducible_from_its_seed():
    S = bounded_power_law(1_000, 1.5, 1.0, 100.0, seed=8)
    assert fit_power_law(S, seed=3).tau_err == fit_power_law(S, seed=3).tau_err
    assert fit_power_law(S, seed=3).tau_err != fit_power_law(S, seed=4).tau_err


def _junk_and_power_law() -> np.ndarray:
    """A fixed sample: 3001 events of tau = 1.6 on [1, 1e3] above 400 of uniform junk below 1."""
    rng = np.random.default_rng(2024)
    u = rng.random(3001)
    e = 1.0 - 1.6
    return np.concatenate([(1.0 + u * (1e3**e - 1.0)) ** (1.0 / e), rng.uniform(0.01, 1.0, 400)])


# (keywords of fit_power_law, tau, tau_err, ks_distance, s_min, n): the values the hand-written KS
# distance and bootstrap loop gave on _junk_and_power_law() before scipy.stats took them over
REGRESSION = [
    ({}, 1.5754763128768638, 0.010466400479238684, 0.017787975901909583, 0.9656812090451317, 3016),
    ({"s_min": 2.0}, 1.594015055862196, 0.01669676461851616, 0.012477106222560652, 2.0, 1994),
    (
        {"truncated": False, "s_min": 1.0, "s_max": 1e3},
        1.6331043125824554,
        0.00898001123168779,
        0.026457507575145978,
        1.0,
        3001,
    ),
    (
        {"cutoff": 500.0, "bootstrap": 50, "seed": 7},
        1.5717571783944853,
        0.012948352953286318,
        0.017756833160408627,
        0.9656812090451317,
        2993,
    ),
]


@pytest.mark.parametrize("kwargs, tau, tau_err, ks, s_min, n", REGRESSION, ids=[str(r[0]) for r in REGRESSION])
def test_fit_keeps_its_values_on_a_fixed_sample(kwargs, tau, tau_err, ks, s_min, n):
    fit = fit_power_law(_junk_and_power_law(), **kwargs)
    assert (fit.s_min, fit.n) == (s_min, n)
    assert fit.tau == pytest.approx(tau, rel=1e-12)
    # far inside their own errors; the bootstrap draws the same resamples as before
    assert fit.tau_err == pytest.approx(tau_err, rel=1e-12)
    assert fit.ks_distance == pytest.approx(ks, rel=1e-9)


def test_untruncated_fit_is_the_closed_form_mle_with_a_plain_bootstrap_and_ks_distance():
    S = _junk_and_power_law()
    fit = fit_power_law(S, s_min=1.0, s_max=1e3, truncated=False, bootstrap=30, seed=11)
    x = S[(S >= 1.0) & (S <= 1e3)]  # in the order of the sample: the resamples index it
    n = x.size
    # Clauset, Shalizi and Newman (2009), eq. (3.1): tau = 1 + n / sum log(x / s_min)
    tau = 1.0 + n / np.log(x).sum()
    assert fit.tau == pytest.approx(tau, rel=1e-12)
    # bootstrap written from its definition: resample the events with replacement, refit
    rng = np.random.default_rng(11)
    logs = np.log(x)
    taus = [1.0 + n / logs[rng.integers(0, n, size=n)].sum() for _ in range(30)]
    assert fit.tau_err == pytest.approx(np.std(taus, ddof=1), rel=1e-10)
    # KS distance to the untruncated CDF 1 - x^(1 - tau) at the fitted tau
    cdf = 1.0 - np.sort(x) ** (1.0 - tau)
    steps = np.arange(1, n + 1) / n
    assert fit.ks_distance == pytest.approx(max(np.max(steps - cdf), np.max(cdf - steps + 1.0 / n)), rel=1e-9)


@pytest.mark.parametrize("tau, ratio, seed", [(1.5, 1e3, 1), (1.6, 1e2, 2), (2.2, 1e4, 3)])
def test_truncated_fit_equals_scipys_truncpareto_fit(tau, ratio, seed):
    # scipy.stats.truncpareto (b = tau - 1, c = s_max / s_min) solves the same score equation by
    # its own root finder when tau > 1; below that it falls back to a generic numerical search
    S = bounded_power_law(5000, tau, 2.0, 2.0 * ratio, seed)
    fit = fit_power_law(S, s_min=2.0, s_max=2.0 * ratio, bootstrap=0)
    b, c, loc, scale = stats.truncpareto.fit(S, fc=ratio, floc=0.0, fscale=2.0)
    assert (c, loc, scale) == (ratio, 0.0, 2.0)
    assert fit.tau == pytest.approx(b + 1.0, abs=1e-10)


def test_truncated_pdf_integrates_to_one():
    from scipy import integrate

    for tau in (0.7, 1.0, 1.5, 2.5):
        total, _ = integrate.quad(
            lambda s, tau=tau: float(truncated_power_law_pdf(s, tau, 0.1, 1e3)),
            0.1,
            1e3,
            points=np.geomspace(0.1, 1e3, 9)[1:-1].tolist(),
            limit=400,
        )
        assert total == pytest.approx(1.0, rel=1e-7)


def test_fit_rejects_too_few_events():
    with pytest.raises(ValueError):
        fit_power_law([1.0], bootstrap=0)
    with pytest.raises(ValueError):
        fit_power_law([1.0, 2.0, 3.0], s_min=5.0, s_max=10.0)


# --- rupture fronts ----------------------------------------------------------------------------


def synthetic_front(speed: float, reach: int, t0: float, noise: float, seed: int, event: int = 7) -> pd.DataFrame:
    """A front that starts fast near the pulled end and then runs at ``speed`` (Fig. 6)."""
    rng = np.random.default_rng(seed)
    i = np.arange(1, reach + 1)
    t = np.where(i <= 40, i / 3.0, 40 / 3.0 + (i - 40) / speed) + rng.normal(0.0, noise, i.size)
    return pd.DataFrame({"event": event, "block": i, "t_first": t0 + t})


def test_front_speed_recovers_a_known_speed_on_the_far_part():
    table = pd.concat(
        [
            synthetic_front(1.43, 399, 19_100.0, 0.2, seed=1, event=7),
            synthetic_front(2.5, 150, 500.0, 0.2, seed=2, event=8),
        ]
    )
    front = front_speed(table, 7)
    assert front.i_min == 200 and front.i_max == 399 and front.n_blocks == 200
    assert front.speed == pytest.approx(1.43, abs=3 * front.speed_err)
    assert front.speed == pytest.approx(1.43, rel=0.01)
    assert front.t_start == pytest.approx(19_100.0 + 1 / 3.0, abs=1.0)
    # the fast start near i = 1 would spoil a fit over the whole chain
    whole = front_speed(table, 7, i_min=1)
    assert abs(whole.speed - 1.43) > 5 * whole.speed_err
    other = front_speed(table, 8, i_min=60, i_max=150)
    assert other.speed == pytest.approx(2.5, rel=0.01)


def test_front_speed_is_exact_on_a_noiseless_front_and_ignores_unmoved_blocks():
    table = synthetic_front(1.43, 300, 0.0, 0.0, seed=0)
    table = pd.concat([table, pd.DataFrame({"event": [7], "block": [301], "t_first": [np.nan]})])
    front = front_speed(table, 7, i_min=100, i_max=300)
    assert front.speed == pytest.approx(1.43, rel=1e-12)
    assert front.rms < 1e-9
    np.testing.assert_allclose(front.arrival_time([100, 300]), [40 / 3 + 60 / 1.43, 40 / 3 + 260 / 1.43])


def test_front_speed_keeps_its_values_on_a_fixed_front():
    # the values of the hand-written least squares before scipy.stats.linregress took it over
    front = front_speed(synthetic_front(1.43, 399, 19_100.0, 0.2, seed=1, event=7), 7)
    assert front.speed == pytest.approx(1.4293040070889855, rel=1e-12)
    assert front.speed_err == pytest.approx(0.0004481497983172533, rel=1e-10)
    assert front.intercept == pytest.approx(21.672586747604484, rel=1e-12)
    assert front.rms == pytest.approx(0.2547187449800156, rel=1e-12)


def test_front_speed_of_blocks_that_started_together_is_refused():
    table = pd.DataFrame({"event": 7, "block": np.arange(1, 11), "t_first": np.r_[0.0, np.full(9, 3.0)]})
    with pytest.raises(ValueError, match="one time"):
        front_speed(table, 7, i_min=2)


def test_front_speed_needs_moved_blocks():
    table = synthetic_front(1.43, 10, 0.0, 0.0, seed=0)
    with pytest.raises(ValueError):
        front_speed(table, 99)
    with pytest.raises(ValueError):
        front_speed(table, 7, i_min=9, i_max=10)


def test_pick_front_events():
    events = pd.DataFrame(
        {
            "event": [0, 1, 2, 3, 4],
            "S": [10.0, 5000.0, 300.0, 6000.0, 200.0],
            "max_block": [10, 399, 180, 399, 220],
            "t_start": [1.0, 2.0, 3.0, 4.0, 5.0],
        }
    )
    chosen = pick_front_events(events, 399)
    assert chosen.set_index("kind")["event"].to_dict() == {"large": 3, "intermediate": 2}


# --- time averages -----------------------------------------------------------------------------


def test_time_average_of_a_known_series():
    t = np.arange(0.0, 1000.0, 1.0)
    L = np.where(t < 200, 0.0, 5.0 + np.sin(2 * np.pi * t / 100.0))
    avg = time_average(xr.DataArray(L, coords={"t": t}, dims="t"), t_from=200.0, n_batches=8)
    assert avg.mean == pytest.approx(5.0, abs=1e-12)  # 800 samples = 8 whole periods
    assert avg.n_samples == 800 and avg.t_from == 200.0 and avg.t_to == 999.0
    assert avg.stderr == pytest.approx(0.0, abs=1e-12)  # each batch is one whole period
    rng = np.random.default_rng(0)
    noise = xr.DataArray(rng.normal(3.0, 2.0, 10_000), coords={"t": np.arange(10_000.0)}, dims="t")
    avg = time_average(noise, n_batches=20)
    assert avg.stderr == pytest.approx(2.0 / 100.0, rel=0.4)


# --- automatic fit range, per-event distributions ---------------------------------------------


def test_default_fit_finds_the_power_law_above_junk_and_recovers_tau():
    tau, a = 1.5, 10.0
    law = bounded_power_law(5_000, tau, a, 1e4, seed=21)
    junk = np.random.default_rng(22).uniform(0.5, a, 3_000)  # not a power law below s_min
    S = np.concatenate([law, junk])
    fit = fit_power_law(S, bootstrap=100)
    assert fit.s_min_rule == "least KS distance"
    assert a / 2 <= fit.s_min <= 2 * a
    assert abs(fit.tau - tau) < 3 * fit.tau_err + 0.02
    # from the smallest S the fit is rejected outright and tau is far off
    naive = fit_power_law(S, s_min=float(S.min()), bootstrap=0)
    assert naive.ks_distance > 5 * fit.ks_distance and abs(naive.tau - tau) > 0.2


def test_default_s_max_is_the_callers_cutoff_and_explicit_ranges_are_kept():
    S = bounded_power_law(3_000, 1.5, 1.0, 1e3, seed=23)
    fit = fit_power_law(S, cutoff=100.0, bootstrap=0)
    assert fit.s_max == 100.0 and fit.n == int(np.sum((S >= fit.s_min) & (S <= 100.0)))
    given = fit_power_law(S, s_min=2.0, s_max=50.0, bootstrap=0)
    assert (given.s_min, given.s_max, given.s_min_rule) == (2.0, 50.0, "given")


def test_choose_s_min_stays_importable_from_chain_runs():
    from stickslip.analysis.stats import chain_runs, statistics

    assert chain_runs.choose_s_min is statistics.choose_s_min


def test_central_interval_places_a_value_in_a_known_distribution():
    from stickslip.analysis.stats.statistics import central_interval

    sample = np.arange(1, 101, dtype=float)  # 1..100
    inside = central_interval(sample, 50.5)
    assert inside.inside and inside.percentile == pytest.approx(50.0)
    assert (inside.lo, inside.hi) == pytest.approx((5.95, 95.05))
    low = central_interval(sample, 3.0)
    assert not low.inside and low.percentile == pytest.approx(2.5)
    assert central_interval(sample, 3.0, level=0.98).inside


def test_central_interval_percentile_counts_ties_half():
    from stickslip.analysis.stats.statistics import central_interval

    sample = [1.0, 2.0, 2.0, 3.0, 4.0]
    # 1 below, 2 equal: (1 + 2 / 2) / 5
    assert central_interval(sample, 2.0).percentile == pytest.approx(40.0, rel=1e-15)
    assert central_interval(sample, 0.5).percentile == 0.0 and central_interval(sample, 5.0).percentile == 100.0


def test_leading_edge_speed_of_a_known_front():
    from stickslip.analysis.stats.statistics import leading_edge_speed

    speed, N, window = 1.6, 200, 20.0
    t_first = np.arange(1, N + 1) / speed
    starts = np.arange(0.0, t_first.max() + 60.0, window)
    dx = np.zeros((starts.size, N))
    for k, s in enumerate(starts):
        dx[k] = 0.05 * np.clip(np.minimum(s + window, t_first + 60.0) - np.maximum(s, t_first), 0.0, None)
    profiles = xr.Dataset(
        {"profile_dx": (("profile_row", "block"), dx)},
        coords={
            "profile_event": ("profile_row", np.full(starts.size, 4)),
            "profile_t": ("profile_row", starts),
            "block": np.arange(1, N + 1),
        },
    )
    edge = leading_edge_speed(profiles, 4)
    # each edge sits within one block-step of the front at the window's end
    assert edge.speed == pytest.approx(speed, rel=0.05)
    assert edge.n_windows >= 2 and edge.i_max == N
