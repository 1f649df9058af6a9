"""The estimators of a slip catalogue on synthetic catalogues drawn from known laws.

Coverage: 100 seeded catalogues of each law; the estimates recover the true parameters and the
one-sigma intervals hold them 60-76% of the time (68% expected; 100 draws give a binomial
spread of about 5%, so a wrong error by a factor 1.5 either way falls outside). The model
comparison is checked against the ``powerlaw`` package on the same data.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy import stats

from stickslip.analysis.stats import magnitudes as mg
from stickslip.analysis.stats import model_comparison as mc
from stickslip.analysis.stats.recurrence import fit_renewal, recurrence
from stickslip.analysis.stats.statistics import fit_power_law

SEEDS = range(100)


def _covered(estimates, errors, truth) -> int:
    return int(np.sum(np.abs(np.asarray(estimates) - truth) <= np.asarray(errors)))


def _gutenberg_richter(seed: int, n: int = 400, b: float = 1.0, dm: float = 0.1) -> np.ndarray:
    """Magnitudes of Gutenberg-Richter with slope b, complete from the bin centred on 0."""
    rng = np.random.default_rng(seed)
    return -dm / 2 + rng.exponential(1.0 / (b * math.log(10.0)), n)


def test_b_value_recovers_b_1_and_its_one_sigma_intervals_cover_68_percent():
    b, shi_bolt, boot = [], [], []
    for seed in SEEDS:
        fit = mg.b_value(_gutenberg_richter(seed), 0.0, dm=0.1, bootstrap=100, seed=seed)
        b.append(fit.b)
        shi_bolt.append(fit.b_err_shi_bolt)
        boot.append(fit.b_err_bootstrap)
    assert abs(np.mean(b) - 1.0) < 0.02  # unbiased to well within the spread of the mean (0.005)
    assert np.std(b) == pytest.approx(np.mean(shi_bolt), rel=0.2)
    assert 60 <= _covered(b, shi_bolt, 1.0) <= 76
    assert 60 <= _covered(b, boot, 1.0) <= 76


def test_the_binning_correction_is_what_makes_binned_magnitudes_unbiased():
    # without the dm/2 of Utsu, b of magnitudes binned to 0.1 comes out 1 / (1 - 0.05 ln 10), 13% high
    M = mg.bin_magnitudes(_gutenberg_richter(0, n=200_000), 0.1)
    assert mg.b_value(M, 0.0, dm=0.1, bootstrap=0).b == pytest.approx(1.0, abs=0.01)
    assert mg.b_value(M, 0.0, dm=0.0, bootstrap=0).b == pytest.approx(1.0 / (1 - 0.05 * math.log(10.0)), abs=0.01)


def test_shi_bolt_error_is_the_closed_form():
    M = np.array([0.0, 0.1, 0.1, 0.3, 0.5, 0.9, 1.4])
    fit = mg.b_value(M, 0.0, dm=0.1, bootstrap=0)
    b = math.log10(math.e) / (M.mean() + 0.05)
    assert fit.b == pytest.approx(b, rel=1e-12)
    assert fit.b_err_shi_bolt == pytest.approx(2.30 * b**2 * M.std(ddof=1) / math.sqrt(M.size), rel=1e-12)


def test_completeness_finds_where_detection_becomes_complete():
    # Gutenberg-Richter from -1, with slips below M = 1 detected with probability 10^(M - 1) / 2:
    # the catalogue is complete from M = 1 on
    rng = np.random.default_rng(5)
    M = -1.05 + rng.exponential(1.0 / math.log(10.0), 200_000)
    kept = M[(M >= 0.95) | (rng.random(M.size) < 0.5 * 10.0 ** (M - 0.95))]
    c = mg.completeness(kept, dm=0.1)
    assert c.method.startswith("goodness of fit")
    assert 0.9 <= c.mc <= 1.2


def _truncated_power_law(seed: int, n: int, tau: float, lo: float, hi: float) -> np.ndarray:
    u = np.random.default_rng(seed).random(n)
    e = 1.0 - tau
    return lo * (1.0 + u * ((hi / lo) ** e - 1.0)) ** (1.0 / e)


def test_truncated_power_law_recovers_tau_and_its_intervals_cover_68_percent():
    tau, err = [], []
    for seed in SEEDS:
        fit = fit_power_law(_truncated_power_law(seed, 500, 1.5, 1.0, 1e3), s_min=1.0, s_max=1e3, bootstrap=100)
        tau.append(fit.tau)
        err.append(fit.tau_err)
    assert abs(np.mean(tau) - 1.5) < 0.01
    assert 60 <= _covered(tau, err, 1.5) <= 76


def test_truncated_gutenberg_richter_is_the_same_law_as_the_truncated_power_law():
    S = _truncated_power_law(1, 5000, 1.6, 1.0, 1e4)
    gr = mg.truncated_gr_fit(mg.magnitude(S), 0.0, float(mg.magnitude(1e4)))
    fit = fit_power_law(S, s_min=1.0, s_max=1e4, bootstrap=0)
    assert gr.tau == pytest.approx(fit.tau, abs=1e-7)
    assert gr.b == pytest.approx(1.5 * (fit.tau - 1.0), abs=1e-7)
    assert gr.b_err == pytest.approx(1.5 * fit.tau_err_fisher, rel=1e-4)
    assert mg.b_from_tau(1.5) == 0.75 and mg.tau_from_b(1.0) == pytest.approx(5 / 3)


def test_weibull_recurrence_is_recovered_and_its_intervals_cover_68_percent():
    k, scale, k_err, scale_err = [], [], [], []
    for seed in SEEDS:
        dt = stats.weibull_min(1.5, scale=2.0).rvs(200, random_state=np.random.default_rng(seed))
        f = fit_renewal("weibull", dt)
        k.append(f["params"]["shape"])
        scale.append(f["params"]["scale"])
        k_err.append(f["errors"]["shape"])
        scale_err.append(f["errors"]["scale"])
    assert abs(np.mean(k) - 1.5) < 0.03 and abs(np.mean(scale) - 2.0) < 0.03
    assert 60 <= _covered(k, k_err, 1.5) <= 76
    assert 60 <= _covered(scale, scale_err, 2.0) <= 76


def test_renewal_models_rank_a_weibull_catalogue_and_a_poisson_one():
    rng = np.random.default_rng(2)
    weibull = np.cumsum(stats.weibull_min(3.0, scale=10.0).rvs(2000, random_state=rng))
    rec = recurrence(weibull)
    assert rec["best"] == "weibull" and rec["cv"] == pytest.approx(0.36, abs=0.03)  # Weibull k = 3: CV 0.363
    poisson = np.cumsum(rng.exponential(5.0, 2000))
    rec = recurrence(poisson)
    exp_fit = next(f for f in rec["fits"] if f["model"] == "exponential")
    assert exp_fit["delta_aic"] < 4 and rec["cv"] == pytest.approx(1.0, abs=0.05)
    # BPT: its aperiodicity is the CV of inverse-Gaussian times
    bpt = fit_renewal("bpt", stats.invgauss(0.25, scale=4.0).rvs(4000, random_state=rng))
    assert bpt["params"]["aperiodicity"] == pytest.approx(0.5, abs=0.02)
    assert bpt["params"]["mean"] == pytest.approx(1.0, abs=0.03)
    assert recurrence([0.0, 1.0, 3.0])["reason"].startswith("2 inter-event times")


@pytest.mark.parametrize(
    "sample",
    [
        lambda rng: np.exp(rng.normal(0.0, 1.5, 3000)),  # lognormal
        lambda rng: stats.weibull_min(0.5, scale=5.0).rvs(3000, random_state=rng),  # stretched exponential
    ],
    ids=["lognormal", "stretched-exponential"],
)
def test_comparisons_agree_with_the_powerlaw_package(sample):
    powerlaw = pytest.importorskip("powerlaw")
    S = sample(np.random.default_rng(3))
    s_min = 1.0
    mine = mc.compare_distributions(S, s_min)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref = powerlaw.Fit(S, xmin=s_min, verbose=False)
        names = {"power_law_exp_cutoff": "truncated_power_law"}
        assert mine["fits"]["power_law"]["params"]["tau"] == pytest.approx(ref.power_law.alpha, rel=1e-10)
        assert mine["fits"]["lognormal"]["params"]["mu"] == pytest.approx(ref.lognormal.mu, abs=2e-3)
        assert mine["fits"]["lognormal"]["params"]["sigma"] == pytest.approx(ref.lognormal.sigma, abs=2e-3)
        assert mine["fits"]["exponential"]["params"]["lambda"] == pytest.approx(ref.exponential.Lambda, rel=1e-3)
        for c in mine["comparisons"]:
            R, p = ref.distribution_compare(
                "power_law", names.get(c["alternative"], c["alternative"]), normalized_ratio=True
            )
            assert c["normalized_ratio"] == pytest.approx(R, abs=2e-3), c["alternative"]
            # a p-value the reference rounds to 0 is one far below any significance level
            assert c["p"] == pytest.approx(p, rel=0.02, abs=1e-12), c["alternative"]


def test_vuong_closed_form_and_the_verdicts():
    l1 = np.array([0.0, 1.0, 2.0, 3.0])
    l2 = np.array([0.5, 0.0, 1.0, 1.0])
    d = l1 - l2
    v = mc.vuong(l1, l2)
    assert v["R"] == pytest.approx(3.5)
    assert v["normalized_ratio"] == pytest.approx(3.5 / (2.0 * d.std()))
    assert v["p"] == pytest.approx(math.erfc(3.5 / math.sqrt(8.0 * d.var())))
    assert mc.vuong(l1, l2, nested=True)["p"] == pytest.approx(stats.chi2.sf(7.0, 1))
    # on an exponential sample the exponential wins against the power law
    S = 1.0 + np.random.default_rng(0).exponential(3.0, 2000)
    verdicts = {c["alternative"]: c["verdict"] for c in mc.compare_distributions(S, 1.0)["comparisons"]}
    assert verdicts["exponential"] == "exponential"


@pytest.mark.slow  # a bootstrap of the KS statistic (about 11 s, measured)
def test_ks_bootstrap_accepts_a_power_law_and_rejects_a_lognormal():
    S = _truncated_power_law(4, 2000, 1.5, 1.0, 1e4)
    assert mc.power_law_gof(S, 1e4, sims=40, seed=1)["p"] > 0.1
    L = np.exp(np.random.default_rng(4).normal(0.0, 1.0, 2000))
    assert mc.power_law_gof(L, sims=40, seed=1)["p"] <= 0.1
