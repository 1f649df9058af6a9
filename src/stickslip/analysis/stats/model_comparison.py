"""Which distribution the slip sizes follow: candidate fits, Vuong's test, the KS-bootstrap goodness of fit.

The recipe is that of Clauset, Shalizi and Newman (SIAM Review 51, 661 (2009)), with the upper
end of the range kept: every candidate is a density normalised on the fit range [s_min, s_max]
(s_max = inf: Clauset's [s_min, inf)) and fitted there by maximum likelihood:

=========================  ==============================================================
``power_law``              p ~ S^-tau; on a finite range the truncated power law of Figs. 7, 8
                           (:func:`stickslip.analysis.stats.statistics.fit_power_law`)
``power_law_exp_cutoff``   p ~ S^-alpha exp(-lambda S) (Clauset et al.'s "truncated power law")
``lognormal``              ``scipy.stats.lognorm``
``exponential``            ``scipy.stats.expon``
``stretched_exponential``  p ~ S^(beta-1) exp(-(lambda S)^beta): ``scipy.stats.weibull_min``
=========================  ==============================================================

Two candidates are compared by the log-likelihood ratio R = sum_i (log p1(S_i) - log p2(S_i)),
normalised by its standard deviation, R / (sqrt(n) sigma), with Vuong's (1989) two-sided p-value
erfc(abs(R) / sqrt(2 n sigma^2)); for nested candidates (the power law is the exponential cut-off's
lambda = 0) Wilks' chi^2 with one degree of freedom instead. The goodness of fit of the power law
is the semi-parametric KS bootstrap of Clauset et al. (section 4.1): synthetic catalogues from the
fit above s_min and the data below it, each refitted with its own s_min.

Written by hand, and why: scipy has no Vuong test, no KS bootstrap with refitted s_min, and no
power law with exponential cutoff; the ``powerlaw`` package has all three but is not used for
the numbers (docs/statistics.md: its fits ignore ``xmax`` for exponents in (1.5, 3]), only in
the tests, which check these functions against it on the same data.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy import integrate, optimize, special, stats

from stickslip.analysis.stats.statistics import choose_s_min, fit_power_law, truncated_power_law_pdf

__all__ = [
    "CANDIDATES",
    "CandidateFit",
    "fit_candidate",
    "fit_candidates",
    "vuong",
    "compare_distributions",
    "power_law_gof",
    "NESTED",
]

CANDIDATES = ("power_law", "power_law_exp_cutoff", "lognormal", "exponential", "stretched_exponential")
#: Pairs where the first is the second with one parameter fixed: Wilks' test, not Vuong's.
NESTED = frozenset({("power_law", "power_law_exp_cutoff")})


@dataclass(frozen=True)
class CandidateFit:
    """One candidate distribution's maximum-likelihood fit to slip sizes on [s_min, s_max]
    (:func:`fit_candidate`).

    Attributes
    ----------
    name : str
        The candidate (:data:`CANDIDATES`).
    params : dict
        Its fitted parameters by name.
    loglikelihood : float
        The total log-likelihood.
    n_params : int
        Parameters fitted (k).
    aic : float
        2 k - 2 log L.
    s_min : float
        Lower end of the range.
    s_max : float
        Upper end of the range.
    n : int
        Events in it.
    logpdf : numpy.ndarray
        Per-event log-densities (not in ``to_dict``).
    pdf : callable
        The fitted density, normalised on the range.
    """

    name: str
    params: dict[str, float]
    loglikelihood: float
    n_params: int
    aic: float
    s_min: float
    s_max: float
    n: int
    logpdf: np.ndarray = field(repr=False, compare=False)
    pdf: Callable[[Any], np.ndarray] = field(repr=False, compare=False)

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "params": self.params,
            "loglikelihood": self.loglikelihood,
            "n_params": self.n_params,
            "aic": self.aic,
            "s_min": self.s_min,
            "s_max": self.s_max,
            "n": self.n,
        }


def _log_mass(dist, lo: float, hi: float) -> float:
    """log(F(hi) - F(lo)) of a frozen scipy distribution, from its log survival function."""
    a = float(dist.logsf(lo))
    if math.isinf(hi):
        return a
    b = float(dist.logsf(hi))
    return a + math.log1p(-math.exp(b - a)) if b < a else -math.inf


def _scipy_logpdf(make, x: np.ndarray, lo: float, hi: float) -> Callable[[np.ndarray], np.ndarray]:
    """The log-density of the frozen distribution ``make(theta)`` truncated to [lo, hi], as a function of theta."""

    def logpdf(theta: np.ndarray) -> np.ndarray:
        dist = make(theta)
        return dist.logpdf(x) - _log_mass(dist, lo, hi)

    return logpdf


def _log_cutoff_normaliser(alpha: float, lam: float, lo: float, hi: float) -> float:
    """log of the integral of S^-alpha exp(-lambda S) over [lo, hi], by quadrature in u = log(S / lo).

    (The incomplete gamma function it equals, lambda^(alpha-1) Gamma(1 - alpha, lambda lo), has
    a negative first argument for alpha > 1, which scipy does not take.)
    """
    span = math.log(hi / lo) if math.isfinite(hi) else math.inf
    e = 1.0 - alpha
    z = lam * lo

    def f(u: float) -> float:
        return math.exp(e * u - z * math.expm1(u)) if u < 700 else 0.0

    value, _ = integrate.quad(f, 0.0, span, limit=200, epsabs=0.0, epsrel=1e-11)
    return e * math.log(lo) - z + math.log(value)


#: Largest gain in log-likelihood a Newton step from a fit's optimum may still promise: above it the
#: search stopped short of the maximum and the fit is left out.
MAX_DECREMENT = 1e-3


def _maximise(negll: Callable[[np.ndarray], float], start: np.ndarray) -> np.ndarray:
    """The minimum of a negative log-likelihood in unconstrained coordinates (Nelder-Mead, then
    polished by BFGS), checked: finite, and the Newton decrement g^T H^-1 g / 2 there (gradient g
    by finite differences, H^-1 BFGS's) below :data:`MAX_DECREMENT`; else ValueError."""
    best = optimize.minimize(
        negll, start, method="Nelder-Mead", options={"xatol": 1e-10, "fatol": 1e-12, "maxiter": 4000}
    )
    polished = optimize.minimize(negll, best.x, method="BFGS")
    x = polished.x if polished.fun <= best.fun else best.x
    value = negll(x)
    if not math.isfinite(value) or value >= 1e300:
        raise ValueError("the likelihood is not finite at the search's end")
    g = optimize.approx_fprime(x, negll, 1e-7 * np.maximum(1.0, np.abs(x)))
    decrement = 0.5 * float(g @ np.atleast_2d(polished.hess_inv) @ g)
    if not math.isfinite(decrement) or abs(decrement) > MAX_DECREMENT:
        raise ValueError(
            f"the search did not reach the likelihood's maximum (a Newton step would gain {decrement:.2g})"
        )
    return x


def fit_candidate(name: str, S: Any, s_min: float, s_max: float = math.inf) -> CandidateFit:
    """Maximum-likelihood fit of one candidate distribution to the sizes S in [s_min, s_max].

    Each density is normalised on [s_min, s_max]; positive parameters are fitted on a log scale.

    Parameters
    ----------
    name : str
        One of :data:`CANDIDATES`: ``power_law``, ``power_law_exp_cutoff``, ``lognormal``,
        ``exponential``, ``stretched_exponential``.
    S : array_like
        Slip sizes.
    s_min, s_max : float
        The range.

    Returns
    -------
    CandidateFit
        The fitted parameters, log-likelihood and AIC.

    Raises
    ------
    ValueError
        With fewer than 2 events in range.
    """
    values = np.asarray(S, dtype=np.float64)
    x = values[np.isfinite(values) & (values >= s_min) & (values <= s_max)]
    n = int(x.size)
    if n < 2:
        raise ValueError(f"need at least 2 sizes in [{s_min:g}, {s_max:g}] to fit {name} (got {n})")
    lo, hi = float(s_min), float(s_max)
    logx = np.log(x)
    if name == "power_law":
        if math.isinf(hi):
            tau = 1.0 + n / float(np.sum(np.log(x / lo)))
        else:
            tau = fit_power_law(x, s_min=lo, s_max=hi, bootstrap=0).tau

        def pdf(s, tau=tau):
            return truncated_power_law_pdf(s, tau, lo, hi)

        params, k = {"tau": tau}, 1
        logpdf = np.log(pdf(x))
    elif name == "power_law_exp_cutoff":

        def logpdf_of(theta):
            alpha, lam = theta[0], math.exp(theta[1])
            return -alpha * logx - lam * x - _log_cutoff_normaliser(alpha, lam, lo, hi)

        tau0 = 1.0 + n / float(np.sum(np.log(x / lo)))
        theta = _maximise(lambda t: -float(np.sum(logpdf_of(t))), np.array([tau0, math.log(0.1 / float(x.mean()))]))
        alpha, lam = float(theta[0]), math.exp(float(theta[1]))
        logpdf = logpdf_of(theta)
        log_c = _log_cutoff_normaliser(alpha, lam, lo, hi)

        def pdf(s, alpha=alpha, lam=lam, log_c=log_c):
            s = np.asarray(s, dtype=np.float64)
            inside = (s >= lo) & (s <= hi)
            with np.errstate(divide="ignore", invalid="ignore"):
                return np.where(inside, np.exp(-alpha * np.log(s) - lam * s - log_c), 0.0)

        params, k = {"alpha": alpha, "lambda": lam}, 2
    else:
        if name == "lognormal":
            start = np.array([float(logx.mean()), math.log(max(float(logx.std()), 1e-3))])

            def make(t):
                return stats.lognorm(math.exp(t[1]), scale=math.exp(t[0]))

            names = ("mu", "sigma")

            def shown(t):
                return (float(t[0]), math.exp(float(t[1])))

        elif name == "exponential":
            start = np.array([-math.log(max(float(x.mean()) - lo, 1e-12 * lo))])

            def make(t):
                return stats.expon(scale=math.exp(-t[0]))

            names = ("lambda",)

            def shown(t):
                return (math.exp(float(t[0])),)

        elif name == "stretched_exponential":
            start = np.array([-math.log(float(x.mean())), math.log(0.5)])

            def make(t):
                return stats.weibull_min(math.exp(t[1]), scale=math.exp(-t[0]))

            names = ("lambda", "beta")

            def shown(t):
                return (math.exp(float(t[0])), math.exp(float(t[1])))

        else:
            raise ValueError(f"unknown candidate {name!r} (one of {', '.join(CANDIDATES)})")
        logpdf_of = _scipy_logpdf(make, x, lo, hi)

        def negll(t):
            value = -float(np.sum(logpdf_of(t)))
            return value if math.isfinite(value) else 1e300

        theta = _maximise(negll, start)
        logpdf = logpdf_of(theta)
        dist, log_m = make(theta), _log_mass(make(theta), lo, hi)

        def pdf(s, dist=dist, log_m=log_m):
            s = np.asarray(s, dtype=np.float64)
            return np.where((s >= lo) & (s <= hi), np.exp(dist.logpdf(s) - log_m), 0.0)

        params, k = dict(zip(names, shown(theta), strict=True)), len(names)
    loglik = float(np.sum(logpdf))
    return CandidateFit(name, params, loglik, k, 2 * k - 2 * loglik, lo, hi, n, np.asarray(logpdf), pdf)


def fit_candidates(S: Any, s_min: float, s_max: float = math.inf) -> dict[str, CandidateFit | str]:
    """Every candidate of :data:`CANDIDATES` fitted on [s_min, s_max].

    Parameters
    ----------
    S : array_like
        Slip sizes.
    s_min, s_max : float
        The range.

    Returns
    -------
    dict
        Name -> :class:`CandidateFit`, or a string saying why the fit failed.
    """
    out: dict[str, CandidateFit | str] = {}
    for name in CANDIDATES:
        # the search passes through parameters where scipy's densities overflow; those are
        # rejected by their likelihood, not worth a warning
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)
            try:
                out[name] = fit_candidate(name, S, s_min, s_max)
            except (ValueError, ArithmeticError, RuntimeError) as exc:
                out[name] = f"no fit: {exc}"
    return out


def vuong(logpdf1: Any, logpdf2: Any, *, nested: bool = False) -> dict[str, float]:
    """Log-likelihood ratio test of two fitted densities on the same events (Vuong 1989).

    Parameters
    ----------
    logpdf1, logpdf2 : array_like
        Per-event log-densities of the two fits (:attr:`CandidateFit.logpdf`).
    nested : bool
        The first is the second with one parameter fixed: then p = chi2(1).sf(2 abs(R)) (Wilks).

    Returns
    -------
    dict
        ``R`` = sum(l1 - l2) (> 0: the first is favoured), ``normalized_ratio`` =
        R / (sqrt(n) sigma) with sigma the standard deviation of l1 - l2, and ``p`` =
        erfc(abs(R) / sqrt(2 n sigma^2)): the probability of a ratio this far from 0 if both were
        equally good.
    """
    d = np.asarray(logpdf1, dtype=np.float64) - np.asarray(logpdf2, dtype=np.float64)
    n = d.size
    R = float(d.sum())
    sigma = float(d.std())
    ratio = R / (math.sqrt(n) * sigma) if sigma > 0 else math.nan
    if nested:
        p = float(stats.chi2.sf(2.0 * abs(R), 1))
    else:
        p = float(special.erfc(abs(R) / math.sqrt(2.0 * n * sigma**2))) if sigma > 0 else math.nan
    return {"R": R, "normalized_ratio": ratio, "p": p, "nested": bool(nested), "n": int(n)}


def compare_distributions(
    S: Any, s_min: float, s_max: float = math.inf, *, significance: float = 0.1
) -> dict[str, Any]:
    """Fit every candidate on [s_min, s_max] and compare the power law with each of the others
    (Clauset, Shalizi and Newman 2009).

    Parameters
    ----------
    S : array_like
        Slip sizes.
    s_min, s_max : float
        The range.
    significance : float
        Largest p of a verdict.

    Returns
    -------
    dict
        ``fits`` (name -> :meth:`CandidateFit.to_dict`, or a string saying why there is no fit),
        ``comparisons`` (one per alternative: :func:`vuong` of power law against it and a
        ``verdict``: "power law", the alternative's name, or "undecided" when p >
        ``significance``), ``best_aic`` (the candidate of least AIC) and the fitted objects under
        ``objects``.
    """
    fits = fit_candidates(S, s_min, s_max)
    pl = fits["power_law"]
    comparisons = []
    for name in CANDIDATES[1:]:
        alt = fits[name]
        if isinstance(pl, str) or isinstance(alt, str):
            comparisons.append({"alternative": name, "verdict": None, "reason": pl if isinstance(pl, str) else alt})
            continue
        test = vuong(pl.logpdf, alt.logpdf, nested=("power_law", name) in NESTED)
        if not math.isfinite(test["p"]) or test["p"] > significance:
            verdict = "undecided"
        else:
            verdict = "power_law" if test["R"] > 0 else name
        comparisons.append({"alternative": name, **test, "verdict": verdict})
    good = {k: v for k, v in fits.items() if not isinstance(v, str)}
    return {
        "s_min": float(s_min),
        "s_max": float(s_max),
        "significance": significance,
        "fits": {k: (v if isinstance(v, str) else v.to_dict()) for k, v in fits.items()},
        "comparisons": comparisons,
        "best_aic": min(good, key=lambda k: good[k].aic) if good else None,
        "objects": good,
    }


def _draw_truncated_power_law(rng: np.random.Generator, n: int, tau: float, lo: float, hi: float) -> np.ndarray:
    """n draws of the power law truncated to [lo, hi] by inverting its CDF."""
    u = rng.random(n)
    e = 1.0 - tau
    span = math.log(hi / lo)
    if abs(e) < 1e-12:
        return lo * np.exp(u * span)
    x = e * span
    # w = log(1 + u (e^x - 1)) / e, without forming e^x (it overflows for a long range)
    w = (x + np.log(u + (1.0 - u) * math.exp(-x))) / e if x > 0 else np.log1p(u * math.expm1(x)) / e
    return lo * np.exp(np.clip(w, 0.0, span))


def power_law_gof(S: Any, s_max: float | None = None, *, sims: int = 200, seed: int = 0) -> dict[str, Any]:
    """Goodness of fit of the truncated power law of Figs. 7, 8 by the KS bootstrap of Clauset et al.
    (2009, sec. 4.1).

    The data's fit (s_min by :func:`~stickslip.analysis.stats.statistics.choose_s_min`) has KS distance
    D. Each synthetic catalogue has as many sizes up to s_max as the data: each one, with the
    probability n_tail / n, drawn from the fitted power law, else drawn from the data below s_min;
    it is fitted the same way (its own s_min) and gives D_k.

    Parameters
    ----------
    S : array_like
        Slip sizes.
    s_max : float, optional
        Upper end (default the largest S).
    sims : int
        Synthetic catalogues.
    seed : int
        Their seed.

    Returns
    -------
    dict
        ``D``, ``p`` (the fraction of D_k >= D: small p, p <= 0.1 for Clauset et al., rejects the
        power law), ``sims``, ``seed`` and the fit's ``tau``, ``s_min``, ``s_max``, ``n``.
    """
    values = np.asarray(S, dtype=np.float64)
    values = values[np.isfinite(values) & (values > 0)]
    hi = float(values.max()) if s_max is None else float(s_max)
    values = values[values <= hi]
    fit = fit_power_law(values, s_max=hi, bootstrap=0)  # no fit: the ValueError says why
    below = values[values < fit.s_min]
    n, n_tail = int(values.size), int(fit.n)
    rng = np.random.default_rng(seed)
    exceed = 0
    distances = []
    for _ in range(int(sims)):
        k = int(rng.binomial(n, n_tail / n))
        tail = _draw_truncated_power_law(rng, k, fit.tau, fit.s_min, hi)
        head = rng.choice(below, size=n - k, replace=True) if below.size else np.empty(0)
        synthetic = np.concatenate([head, tail])
        try:
            lo = choose_s_min(synthetic, hi)
            d = fit_power_law(synthetic, s_min=lo, s_max=hi, bootstrap=0).ks_distance
        except ValueError:
            continue
        distances.append(d)
        exceed += d >= fit.ks_distance
    done = len(distances)
    return {
        "D": fit.ks_distance,
        "p": exceed / done if done else math.nan,
        "sims": done,
        "seed": int(seed),
        "tau": fit.tau,
        "s_min": fit.s_min,
        "s_max": hi,
        "n": n_tail,
        "method": "KS bootstrap (Clauset, Shalizi and Newman 2009): data below s_min resampled, s_min refitted",
    }
