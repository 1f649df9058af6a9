"""Fits of synthetic records: exact recovery, coverage of the two-standard-error intervals, several
records with shared parameters, windows, weights and trends."""

import numpy as np
import pytest

from stickslip.lab import LoadHistory, RateState
from stickslip.lab.fitting import fit
from stickslip.lab.records import Record, detrend, synthetic
from stickslip.models.params import ParameterError

TRUE = RateState(a=0.005, b=0.008, Dc=20.0, mu0=0.6, V0=1.0, k=1e-3)
STEP = LoadHistory.steps([1.0, 10.0], [50.0, 100.0])
START = TRUE.with_values(a=0.007, b=0.006, Dc=10.0, mu0=0.59)
FREE = ("a", "b", "Dc", "mu0")
TRUTH = np.array([0.005, 0.008, 20.0, 0.6])


def test_exact_record_recovers_the_parameters():
    res = fit(synthetic(TRUE, STEP, n=300), START, FREE)
    np.testing.assert_allclose(res.values, TRUTH, rtol=1e-6)
    assert res.success and res.rms < 1e-9


def _coverage(n_records, seed):
    """The share of two-standard-error intervals that cover the truth, the fits' scatter over their
    mean standard error, and the fits' correlation matrix less the mean of the reported ones in
    units of a sample correlation's standard error, (1 - r^2) / sqrt(n)."""
    rng = np.random.default_rng(seed)
    est, err, corr = [], [], []
    for _ in range(n_records):
        res = fit(synthetic(TRUE, STEP, n=300, noise=2e-4, rng=rng), START, FREE)
        est.append(res.values)
        err.append(res.errors)
        corr.append(res.correlation)
    est, err = np.array(est), np.array(err)
    covered = np.abs(est - TRUTH) <= 2.0 * err
    r = np.mean(corr, axis=0)
    off = ~np.eye(len(FREE), dtype=bool)
    z = (np.corrcoef(est.T) - r)[off] / ((1.0 - r[off] ** 2) / np.sqrt(n_records))
    return covered.mean(), est.std(axis=0, ddof=1) / err.mean(axis=0), z


def test_two_standard_error_intervals_cover_the_truth_20_records():
    covered, ratio, corr = _coverage(20, 2024)
    # 80 intervals of 95.4 %: fewer than 70 covered would happen by chance once in ~1000 runs
    assert covered >= 70 / 80
    assert np.all((ratio > 0.55) & (ratio < 1.6))
    # the reported correlations (a and b: 0.8) are those of the fits' scatter
    assert np.all(np.abs(corr) < 3.5)


@pytest.mark.slow
def test_two_standard_error_intervals_cover_the_truth_200_records():
    covered, ratio, corr = _coverage(200, 7)
    assert 0.92 <= covered <= 0.985
    assert np.all((ratio > 0.8) & (ratio < 1.25))
    assert np.all(np.abs(corr) < 3.5)


def test_several_records_with_shared_parameters_and_own_mu0():
    a = synthetic(TRUE, STEP, n=200, name="up")
    down = LoadHistory.steps([10.0, 3.0], [20.0, 100.0])
    b = synthetic(TRUE.with_values(mu0=0.62), down, n=200, name="down")
    res = fit([a, b], START, FREE, per_record=("mu0",))
    assert res.names == ["a", "b", "Dc", "mu0[0]", "mu0[1]"]
    np.testing.assert_allclose(res.values, [0.005, 0.008, 20.0, 0.6, 0.62], rtol=1e-6)
    assert res.models[1].mu0 == pytest.approx(0.62, rel=1e-8)


def test_window_leaves_out_a_spoilt_stretch_and_weights_zero_do_too():
    rec = synthetic(TRUE, STEP, n=300)
    mu = rec.mu.copy()
    mu[rec.t > 120.0] += 0.01  # a slip event the model should not see
    spoilt = Record(rec.t, mu, STEP, window=(0.0, 120.0))
    np.testing.assert_allclose(fit(spoilt, START, FREE).values, TRUTH, rtol=1e-6)
    weighted = Record(rec.t, mu, STEP, weight=np.where(rec.t > 120.0, 0.0, 1.0))
    np.testing.assert_allclose(fit(weighted, START, FREE).values, TRUTH, rtol=1e-6)


def test_linear_trend_fitted_or_removed():
    rec = synthetic(TRUE, STEP, n=300)
    p = STEP.position(rec.t)
    trended = Record(rec.t, rec.mu + 2e-5 * p, STEP)
    res = fit(trended, START, (*FREE, "trend"))
    np.testing.assert_allclose(res.values, [*TRUTH, 2e-5], rtol=1e-5)
    # the same slope fitted over the first, steady stretch and removed
    flat = detrend(trended, window=(0.0, 50.0))
    np.testing.assert_allclose(flat.mu, rec.mu, atol=1e-12)


def test_record_from_csv_and_bad_fits(tmp_path):
    rec = synthetic(TRUE, STEP, n=101)
    path = tmp_path / "step.csv"
    rows = ["time,mu,load_point"] + [
        f"{float(t)!r},{float(m)!r},{float(p)!r}" for t, m, p in zip(rec.t, rec.mu, STEP.position(rec.t), strict=True)
    ]
    path.write_text("\n".join(rows) + "\n")
    back = Record.from_csv(path)
    np.testing.assert_allclose(back.history.position(back.t), STEP.position(rec.t), rtol=1e-12)
    # a sampled record keeps the step inside one sample interval: 1, (average), 10
    assert back.history.merged().breakpoints.size == 4
    with pytest.raises(ParameterError, match="cannot fit 'sigma'"):
        fit(rec, START, ("a", "sigma"))
    with pytest.raises(ParameterError, match="not free"):
        fit(rec, START, ("a",), per_record=("mu0",))
    with pytest.raises(ParameterError, match="k is required"):
        fit(rec, RateState(a=0.005, b=0.008, Dc=20.0, mu0=0.6, V0=1.0), ("a",))


def test_posterior_agrees_with_the_least_squares_errors():
    pytest.importorskip("emcee")
    from stickslip.lab.posterior import posterior

    res = fit(synthetic(TRUE, STEP, n=300, noise=2e-4, rng=5), START, FREE)
    post = posterior(res, walkers=16, steps=240, rng=1)
    assert post.samples.shape == (16 * 180, 4)
    # a Gaussian likelihood about a well-determined minimum: mean at the fit, spread its errors
    assert np.all(np.abs(post.mean - res.values) < 0.5 * res.errors)
    assert np.all((post.std > 0.7 * res.errors) & (post.std < 1.4 * res.errors))
    assert 0.2 < post.acceptance < 0.9
    # the seed makes the chain reproducible
    one, two = (posterior(res, walkers=8, steps=12, burn=0, rng=3) for _ in range(2))
    np.testing.assert_array_equal(one.samples, two.samples)


def test_a_slide_hold_slide_and_a_step_fitted_together():
    """Holds at V = 0 in a record, fitted with a velocity step: shared a, b, D_c, own mu0."""
    shs = LoadHistory.slide_hold_slide(10.0, 20.0, [10.0, 100.0], t_reslide=20.0)
    a = synthetic(TRUE, shs, n=400, name="shs")
    b = synthetic(TRUE.with_values(mu0=0.61), STEP, n=200, name="step")
    res = fit([a, b], START, FREE, per_record=("mu0",))
    np.testing.assert_allclose(res.values, [0.005, 0.008, 20.0, 0.6, 0.61], rtol=1e-6)


def test_stiffness_and_a_second_state_variable_fitted():
    two = RateState(a=0.005, b=(0.006, 0.003), Dc=(5.0, 60.0), mu0=0.6, V0=1.0, k=2e-3)
    h = LoadHistory.steps([1.0, 10.0, 1.0], [60.0, 60.0, 300.0])
    rec = synthetic(two, h, n=600)
    start = two.with_values(a=0.006, b1=0.005, Dc1=8.0, b2=0.002, Dc2=40.0, k=1.5e-3)
    res = fit(rec, start, ("a", "b1", "Dc1", "b2", "Dc2", "k"))
    np.testing.assert_allclose(res.values, [0.005, 0.006, 5.0, 0.003, 60.0, 2e-3], rtol=1e-5)
