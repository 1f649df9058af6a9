"""Analysis of chain runs: slip-size statistics (Figs. 7, 8); rupture fronts (Fig. 6) and time
averages (Fig. 5b) are importable here from :mod:`~stickslip.analysis.stats.fronts` and
:mod:`~stickslip.analysis.stats.order`. A slip's size is S = sum_i (x_i(end) - x_i(start)) (docs/model.md).

Power-law fit. The paper quotes p(S) ~ S^-tau with tau about 1.5 at beta = 1 (Fig. 7) and
about 1.6 for small S at beta = 0.2 (Fig. 8). A finite chain cuts the distribution off near
the largest possible event, so the fit is the maximum-likelihood estimate for a power law
*truncated* to [s_min, s_max],

    p(S) = S^-tau / Z(tau),   Z(tau) = (s_min^(1-tau) - s_max^(1-tau)) / (tau - 1),

computed here in closed form (the score equation is solved by bracketing). For tau > 1
``scipy.stats.truncpareto.fit`` with c and scale fixed solves the same equation (the tests check
that they agree); it is not called because for tau <= 1, which a fit range of junk can give, it
falls back to a generic numerical search. The KS distance is ``scipy.stats.ks_1samp``'s, the
bootstrap ``scipy.stats.bootstrap``'s. ``powerlaw.Fit(..., xmax=...)`` (powerlaw 2.0) is not used:
it keeps the untruncated estimate 1 + n / sum log(S / s_min) whenever it lies in (1.5, 3], the
range the paper reports (for tau = 1.5, s_max / s_min = 1e3 it returns about 1.57); its
``Power_Law(..., force_numerical_fit=True)`` is the tests' independent check of this module.

Fit range. Without an explicit s_min the lower end is chosen by :func:`choose_s_min`
(docs/statistics.md): the smallest slips of a chain do not follow the power law (on the
beta = 1 run of Fig. 7 the fit from the smallest S has KS distance about 0.5).
"""

from __future__ import annotations

import functools
import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr
from scipy import stats

from stickslip.analysis.stats.fronts import (
    CentralInterval,
    EdgeSpeed,
    FrontSpeed,
    central_interval,
    front_speed,
    leading_edge_speed,
    pick_front_events,
)

# Rupture fronts (Fig. 6) live in fronts, time averages (Fig. 5b) in order; their names stay
# importable here.
from stickslip.analysis.stats.order import TimeAverage, time_average
from stickslip.analysis.stats.truncated import TAU_BRACKET, fit_failure, log_normaliser, truncated_mle, var_log_ratio

__all__ = [
    "size_distribution",
    "fit_power_law",
    "choose_s_min",
    "s_min_scan",
    "PowerLawFit",
    "truncated_power_law_pdf",
    "front_speed",
    "FrontSpeed",
    "pick_front_events",
    "leading_edge_speed",
    "EdgeSpeed",
    "central_interval",
    "CentralInterval",
    "time_average",
    "TimeAverage",
]


# ---------------------------------------------------------------------------------------------
# Size distribution (Figs. 7a, 8a)


def _positive_finite(S: Any) -> tuple[np.ndarray, int]:
    """The finite, positive sizes as float64, and how many entries were dropped."""
    values = np.asarray(S, dtype=np.float64).ravel()
    keep = np.isfinite(values) & (values > 0.0)
    return values[keep], int(values.size - keep.sum())


def size_distribution(
    S: Any,
    bins: int | Any = 30,
    *,
    s_min: float | None = None,
    s_max: float | None = None,
) -> xr.Dataset:
    """Histogram of slip sizes on logarithmic bins as a probability density (Figs. 7a, 8a).

    The density is count / (n_binned * width), so sum(density * width) = 1 over the binned
    events: it estimates p(S) itself, and a power law p ~ S^-tau appears with slope -tau. (A
    plain count per log bin would have slope 1 - tau.) Sizes that are not positive and finite
    cannot sit on a log axis and are left out (counted in the attrs).

    Parameters
    ----------
    S : array_like
        Slip sizes (``events["S"]``).
    bins : int or array_like
        A number of logarithmically equal bins spanning [s_min, s_max], or increasing bin edges.
    s_min, s_max : float, optional
        The range of the bins (default the smallest and the largest positive S).

    Returns
    -------
    xarray.Dataset
        On dim ``bin``, coordinate ``S`` (geometric bin centre) and variables ``density``,
        ``count``, ``width``, ``lower``, ``upper``; attrs ``n_binned``, ``n_total``,
        ``n_dropped`` (non-positive or non-finite), ``n_outside`` (outside the edges).

    Examples
    --------
    >>> from stickslip.analysis.stats.statistics import size_distribution
    >>> d = size_distribution([1.0, 2.0, 4.0, 8.0, -1.0], bins=[1.0, 4.0, 16.0])
    >>> d["count"].values.tolist(), d.attrs["n_dropped"], float((d["density"] * d["width"]).sum())
    ([2, 2], 1, 1.0)
    """
    values, n_dropped = _positive_finite(S)
    if np.ndim(bins) == 0:
        n_bins = int(bins)
        if n_bins < 1:
            raise ValueError(f"bins must be >= 1 (got {bins!r})")
        if values.size == 0 and (s_min is None or s_max is None):
            raise ValueError("no positive sizes to bin and no explicit s_min, s_max")
        lo = float(values.min()) if s_min is None else float(s_min)
        hi = float(values.max()) if s_max is None else float(s_max)
        if not (0.0 < lo < hi):
            # a single distinct size still gets one finite bin around it
            if lo == hi and lo > 0.0:
                lo, hi = lo / 1.05, hi * 1.05
            else:
                raise ValueError(f"need 0 < s_min < s_max (got {lo!r}, {hi!r})")
        edges = np.geomspace(lo, hi, n_bins + 1)
    else:
        edges = np.asarray(bins, dtype=np.float64)
        if edges.ndim != 1 or edges.size < 2 or edges[0] <= 0.0 or np.any(np.diff(edges) <= 0.0):
            raise ValueError("bin edges must be a 1-d, strictly increasing, positive array")

    # np.histogram closes the last bin on the right, so S = s_max is counted.
    counts, _ = np.histogram(values, bins=edges)
    n_binned = int(counts.sum())
    width = np.diff(edges)
    with np.errstate(invalid="ignore", divide="ignore"):
        density = counts / (n_binned * width) if n_binned else np.full(width.shape, np.nan)
    centre = np.sqrt(edges[:-1] * edges[1:])
    return xr.Dataset(
        {
            "density": ("bin", density, {"long_name": "probability density of S (per unit of S)", "units": "1"}),
            "count": ("bin", counts.astype(np.int64), {"long_name": "events in bin"}),
            "width": ("bin", width, {"long_name": "bin width"}),
            "lower": ("bin", edges[:-1], {"long_name": "lower bin edge"}),
            "upper": ("bin", edges[1:], {"long_name": "upper bin edge"}),
        },
        coords={"S": ("bin", centre, {"long_name": "slip size S (geometric bin centre)"})},
        attrs={
            "n_binned": n_binned,
            "n_total": int(np.asarray(S).size),
            "n_dropped": n_dropped,
            "n_outside": int(values.size - n_binned),
            "normalisation": "sum(density * width) = 1 over the binned events",
        },
    )


# ---------------------------------------------------------------------------------------------
# Truncated power-law fit (Figs. 7a, 8a)


def _tau_from_mean(mean_log: float, span: float) -> float:
    """tau from the mean of log(S/s_min) over the events in range: truncated MLE, or the closed
    form if span = inf."""
    if math.isinf(span):
        # untruncated continuous power law: tau = 1 + n / sum log(S/s_min)
        tau = 1.0 + 1.0 / mean_log if mean_log > 0.0 else math.nan
        return tau if TAU_BRACKET[0] < tau < TAU_BRACKET[1] else math.nan
    return truncated_mle(mean_log, span)


def _fit_tau(log_ratio: np.ndarray, span: float) -> float:
    """tau from log(S/s_min) of the events in range (:func:`_tau_from_mean` of their mean)."""
    return _tau_from_mean(float(log_ratio.mean()), span)


def _resampled_taus(log_ratio: np.ndarray, span: float, axis: int = -1) -> np.ndarray:
    """tau of each resample along ``axis``: the vectorised statistic of ``scipy.stats.bootstrap``."""
    means = np.mean(log_ratio, axis=axis)
    return np.reshape([_tau_from_mean(float(m), span) for m in np.ravel(means)], np.shape(means))


@dataclass(frozen=True)
class PowerLawFit:
    """Maximum-likelihood exponent of p(S) ~ S^-tau on [s_min, s_max] (Figs. 7a, 8a;
    :func:`fit_power_law`).

    Attributes
    ----------
    tau : float
        The exponent.
    tau_err : float
        Its bootstrap standard error (NaN without bootstrap).
    tau_err_fisher : float
        The asymptotic error 1 / sqrt(n I(tau)) from the Fisher information.
    s_min : float
        Lower end of the fitted range.
    s_max : float
        Upper end.
    n : int
        Events in [s_min, s_max] used for the fit.
    n_total : int
        All finite positive events.
    bootstrap : int
        Resamples of the error.
    seed : int
        Their seed.
    truncated : bool
        Whether the upper cut-off enters the likelihood (False: s_max = inf, the classic
        estimator).
    method : str
        How tau was solved for.
    loglikelihood : float
        The maximised log-likelihood.
    ks_distance : float
        Kolmogorov-Smirnov distance between the fitted and the empirical CDF on the range.
    s_min_rule : str
        How s_min was set: "given", or "least KS distance" (:func:`choose_s_min`).
    """

    tau: float
    tau_err: float
    tau_err_fisher: float
    s_min: float
    s_max: float
    n: int
    n_total: int
    bootstrap: int
    seed: int
    truncated: bool
    method: str
    loglikelihood: float
    ks_distance: float
    s_min_rule: str = "given"

    def pdf(self, s: Any) -> np.ndarray:
        """The fitted density p(S) on [s_min, s_max] (zero outside), integrating to 1."""
        return truncated_power_law_pdf(s, self.tau, self.s_min, self.s_max)

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def truncated_power_law_pdf(s: Any, tau: float, s_min: float, s_max: float = math.inf) -> np.ndarray:
    """p(S) = S^-tau / Z(tau) on [s_min, s_max], zero outside: the model of :func:`fit_power_law`.

    Parameters
    ----------
    s : array_like
        Sizes at which to evaluate it.
    tau : float
        The exponent.
    s_min, s_max : float
        The range (s_max = inf: the untruncated law, tau > 1).

    Returns
    -------
    numpy.ndarray
        The density, integrating to 1 over [s_min, s_max].

    Examples
    --------
    >>> from stickslip.analysis.stats.statistics import truncated_power_law_pdf
    >>> truncated_power_law_pdf([0.5, 1.0, 4.0], 2.0, 1.0).tolist()  # S^-2 on [1, inf)
    [0.0, 1.0, 0.0625]
    """
    s = np.asarray(s, dtype=np.float64)
    log_z = log_normaliser(tau, s_min, s_max)
    inside = (s >= s_min) & (s <= s_max)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.exp(-tau * np.log(s) - log_z)
    return np.where(inside, out, 0.0)


def _truncated_cdf(s: np.ndarray, tau: float, s_min: float, s_max: float) -> np.ndarray:
    e = 1.0 - tau
    if abs(e) < 1e-12:
        return np.log(s / s_min) / math.log(s_max / s_min)
    if math.isinf(s_max):
        return 1.0 - (s / s_min) ** e
    w, span = np.log(s / s_min), math.log(s_max / s_min)
    if e > 0:
        # (e^{ew} - 1) / (e^{e span} - 1) without forming e^{e span}, which overflows for a long range
        return np.exp(e * (w - span)) * -np.expm1(-e * w) / -math.expm1(-e * span)
    return np.expm1(e * w) / math.expm1(e * span)


#: Defaults of :func:`choose_s_min`: candidates from the smallest S up to this quantile of S ...
S_MIN_MAX_QUANTILE = 0.9
#: ... and at most this fraction of s_max (at least a decade of range is left to fit) ...
S_MIN_MAX_FRACTION = 0.1
#: ... in this many log-spaced steps, each keeping at least this many events in [s_min, s_max].
S_MIN_CANDIDATES = 40
S_MIN_MIN_EVENTS = 50


def _range_fit(values: np.ndarray, lo: float, hi: float, truncated: bool) -> tuple[np.ndarray, float, float]:
    """Events in [lo, hi], log(S/lo) of them, and tau (truncated MLE, or the classic one)."""
    x = values[(values >= lo) & (values <= hi)]
    span = math.log(hi / lo) if truncated else math.inf
    log_ratio = np.log(x / lo)
    return x, span, _fit_tau(log_ratio, span) if x.size >= 2 else math.nan


def _ks_distance(x: np.ndarray, tau: float, lo: float, hi: float) -> float:
    """Kolmogorov-Smirnov distance between the fitted CDF on [lo, hi] and the sample x."""
    cdf = functools.partial(_truncated_cdf, tau=tau, s_min=lo, s_max=hi)
    # the distance only: the p-value would assume tau was not fitted to x
    return float(stats.ks_1samp(x, cdf, method="asymp").statistic)


def s_min_scan(
    S: Any,
    s_max: float | None = None,
    *,
    max_quantile: float = S_MIN_MAX_QUANTILE,
    max_fraction: float = S_MIN_MAX_FRACTION,
    n_candidates: int = S_MIN_CANDIDATES,
    min_events: int = S_MIN_MIN_EVENTS,
) -> pd.DataFrame:
    """The candidates of :func:`choose_s_min` with, for each, n, tau and the KS distance (Figs. 7, 8).

    Candidates: ``n_candidates`` log-spaced values from the smallest positive S to the smaller of
    its ``max_quantile`` quantile and ``max_fraction`` * s_max; the scan stops at the first
    candidate that leaves fewer than ``min_events`` events in [s_min, s_max]. Each gets the
    truncated maximum-likelihood fit on [s_min, s_max].

    Parameters
    ----------
    S : array_like
        Slip sizes.
    s_max : float, optional
        Upper end of the fits (default the largest S).
    max_quantile, max_fraction : float
        The largest candidate: the smaller of this quantile of S and this fraction of s_max.
    n_candidates : int
        Candidates scanned.
    min_events : int
        Fewest events a fit may use.

    Returns
    -------
    pandas.DataFrame
        One row per candidate: ``s_min``, ``n``, ``tau``, ``ks_distance``.
    """
    values, _ = _positive_finite(S)
    if values.size == 0:
        raise ValueError("no positive, finite slip sizes")
    hi_s = float(values.max()) if s_max is None else float(s_max)
    lo = float(values.min())
    top = min(float(np.quantile(values, max_quantile)), max_fraction * hi_s)
    grid = np.geomspace(lo, top, n_candidates) if top > lo else np.array([lo])
    rows = []
    for s_min in grid:
        s_min = float(s_min)
        if not hi_s > s_min:
            break
        x, _, tau = _range_fit(values, s_min, hi_s, True)
        if x.size < max(min_events, 2):
            break
        ks = _ks_distance(x, tau, s_min, hi_s) if math.isfinite(tau) else math.nan
        rows.append({"s_min": s_min, "n": int(x.size), "tau": float(tau), "ks_distance": ks})
    return pd.DataFrame(rows, columns=["s_min", "n", "tau", "ks_distance"])


def choose_s_min(S: Any, s_max: float | None = None, **candidates: Any) -> float:
    """Lower end of the power-law fit of Figs. 7, 8: the s_min with the least KS distance.

    Each candidate of :func:`s_min_scan` gets the truncated fit on [s_min, s_max] and its
    Kolmogorov-Smirnov distance D (the recipe of Clauset, Shalizi and Newman, SIAM Review 51, 661
    (2009), with the upper cut-off kept). A KS distance computed from n events is only resolved to
    about 1/sqrt(n), so candidates with D <= D_least + 1/sqrt(n) count as equally good and the
    smallest of them is taken (the most events). On a clean power law that is the smallest S;
    below a range of junk it is the start of the power law.

    Parameters
    ----------
    S : array_like
        Slip sizes.
    s_max : float, optional
        Upper end of the fits (default the largest S).
    **candidates
        The keywords of :func:`s_min_scan`.

    Returns
    -------
    float
        s_min; the smallest S where there is no candidate (too few events).
    """
    scan = s_min_scan(S, s_max, **candidates)
    scan = scan[np.isfinite(scan["ks_distance"].to_numpy(dtype=np.float64))]  # an empty scan's column is object
    if scan.empty:
        values, _ = _positive_finite(S)
        return float(values.min())
    D = scan["ks_distance"].to_numpy()
    good = D <= D.min() + 1.0 / np.sqrt(scan["n"].to_numpy())
    return float(scan["s_min"].to_numpy()[np.flatnonzero(good)[0]])


def fit_power_law(
    S: Any,
    s_min: float | None = None,
    s_max: float | None = None,
    *,
    cutoff: float | None = None,
    bootstrap: int = 200,
    seed: int = 0,
    truncated: bool = True,
) -> PowerLawFit:
    """Exponent tau of the slip-size distribution p(S) ~ S^-tau by maximum likelihood (Figs. 7, 8).

    The fit uses the events with s_min <= S <= s_max and maximises the likelihood of the power
    law truncated to that range (module docstring). With ``truncated=False`` the upper cut-off is
    ignored in the likelihood (s_max = inf, the classic estimator tau = 1 + n / sum log(S/s_min))
    but events above ``s_max`` are still left out; that estimate is biased upwards for a cut-off
    distribution.

    Parameters
    ----------
    S : array_like
        Slip sizes (non-positive and non-finite ones are left out).
    s_min : float, optional
        Lower end (default the least-KS choice of :func:`choose_s_min` on [., s_max]).
    s_max : float, optional
        Upper end (default ``cutoff``, else the largest S, the maximum-likelihood estimate of an
        upper cut-off).
    cutoff : float, optional
        The size where the system size cuts the distribution off (e.g. the smallest event that
        spans the chain, Fig. 8).
    bootstrap : int
        Resamples (with replacement) of the events in range for ``tau_err``, at the chosen s_min;
        0 skips it.
    seed : int
        Seed of the resampling (``numpy.random.default_rng``).
    truncated : bool
        Keep the upper cut-off in the likelihood.

    Returns
    -------
    PowerLawFit
        tau, its errors, the range and its events, the log-likelihood and the KS distance.

    Raises
    ------
    ValueError
        With fewer than 2 events in range, or where the likelihood has no maximum with tau in
        :data:`~stickslip.analysis.stats.truncated.TAU_BRACKET` (the message says which): such a fit
        is left out, not reported.

    Examples
    --------
    >>> import numpy as np
    >>> from stickslip.analysis.stats.statistics import fit_power_law
    >>> u = np.random.default_rng(1).uniform(size=5000)
    >>> S = (1.0 - u * (1.0 - 1e3 ** -0.5)) ** -2.0  # p(S) ~ S^-1.5 on [1, 1000]
    >>> fit = fit_power_law(S, s_min=1.0, s_max=1e3, bootstrap=0)
    >>> abs(fit.tau - 1.5) < 0.05, fit.n
    (True, 5000)
    """
    values, _ = _positive_finite(S)
    n_total = int(values.size)
    if n_total == 0:
        raise ValueError("no positive, finite slip sizes to fit")
    if s_max is not None:
        hi = float(s_max)
    elif cutoff is not None:
        hi = float(cutoff)
    else:
        hi = float(values.max())
    rule = "given"
    if s_min is not None:
        lo = float(s_min)
    elif hi > float(values.min()):
        lo, rule = choose_s_min(values, hi), "least KS distance"
    else:
        lo = float(values.min())
    if not (lo > 0.0 and hi > lo):
        raise ValueError(f"need 0 < s_min < s_max (got s_min={lo!r}, s_max={hi!r})")
    if bootstrap < 0:
        raise ValueError(f"bootstrap must be >= 0 (got {bootstrap!r})")

    x, span, tau = _range_fit(values, lo, hi, truncated)
    n = int(x.size)
    if n < 2:
        raise ValueError(f"need at least 2 events in [s_min, s_max] (got {n})")
    log_ratio = np.log(x / lo)
    if not math.isfinite(tau):
        why = fit_failure(float(log_ratio.mean()), span) if truncated else "every event in range is at s_min"
        raise ValueError(f"no power law on S in [{lo:.3g}, {hi:.3g}] ({n} events): {why}")

    tau_err = math.nan
    if bootstrap > 0:
        # one resample per batch keeps memory at n; "percentile" needs no jackknife (BCa would
        # refit n times)
        res = stats.bootstrap(
            (log_ratio,),
            functools.partial(_resampled_taus, span=span),
            n_resamples=bootstrap,
            batch=1,
            vectorized=True,
            method="percentile",
            rng=np.random.default_rng(seed),
        )
        estimates = np.asarray(res.bootstrap_distribution, dtype=np.float64)
        finite = estimates[np.isfinite(estimates)]  # a resample with every event at one end has no fit
        tau_err = float(finite.std(ddof=1)) if finite.size > 1 else math.nan

    s_hi = math.inf if not truncated else hi
    info = var_log_ratio(1.0 - tau, span) if truncated else 1.0 / (tau - 1.0) ** 2
    tau_err_fisher = 1.0 / math.sqrt(n * info) if info > 0 else math.nan
    loglik = float(-tau * np.log(x).sum() - n * log_normaliser(tau, lo, s_hi))
    ks = _ks_distance(x, tau, lo, s_hi)

    method = (
        "maximum likelihood, continuous power law truncated to [s_min, s_max]"
        if truncated
        else "maximum likelihood, continuous power law on [s_min, inf) (upper cut-off ignored)"
    )
    return PowerLawFit(
        tau=float(tau),
        tau_err=tau_err,
        tau_err_fisher=float(tau_err_fisher),
        s_min=lo,
        s_max=hi,
        n=n,
        n_total=n_total,
        bootstrap=int(bootstrap),
        seed=int(seed),
        truncated=bool(truncated),
        method=method,
        loglikelihood=loglik,
        ks_distance=ks,
        s_min_rule=rule,
    )
