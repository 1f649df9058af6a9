"""Lifetimes with censoring: Kaplan-Meier survival, the exponential law of the tail, <T> against N.

The irregular motion of a short chain is a transient (Politi, Livi, Oppo and Kapral, Europhys.
Lett. 22, 571 (1993)): it ends on a periodic orbit (or in steady sliding) after a lifetime T. A
run that ends before T is *censored*: it says only T > its length. This module reads such data:

* :func:`kaplan_meier`: the survival function S(t) = P(T > t), Kaplan and Meier's product-limit
  estimate with its pointwise confidence band (``scipy.stats.ecdf`` of
  ``scipy.stats.CensoredData``; the band by the log-log transform of Greenwood's variance).
* :func:`exponential_fit`: the exponential law of the tail beyond ``t_from``, S(t) =
  S(t_from) exp(-(t - t_from) / tau). The maximum-likelihood rate with censoring has a closed
  form, rate = d / E, d the lifetimes ended beyond ``t_from`` and E the total time lived beyond
  it (by ended and censored alike); its standard error is rate / sqrt(d) (the inverse of the
  observed information), and the 95 % interval of tau is that of a Poisson count d in exposure E
  (chi-square with 2d and 2d + 2 degrees of freedom). With d = 0 only a lower bound on tau is
  given. Stable chaos predicts the exponential (the transient is memoryless); the fit tests it
  against a Weibull law (shape k, k = 1 the exponential) by the likelihood ratio.
* :func:`size_fits`: ln <T> against N (exponential growth, the signature of stable chaos) and
  against ln N (a power law), weighted least squares with the slope's error, which fits better
  (the smaller chi-square: both have two parameters), and the extrapolation of each to a larger N
  with its error.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
import pandas as pd
from scipy import optimize, stats

from stickslip.models.params import ParameterError

__all__ = ["kaplan_meier", "ExponentialFit", "exponential_fit", "size_fits", "line_fit"]


def _lifetimes(times: Any, ended: Any) -> tuple[np.ndarray, np.ndarray]:
    t = np.asarray(times, dtype=np.float64).ravel()
    e = np.asarray(ended, dtype=bool).ravel()
    if t.size != e.size:
        raise ParameterError("times and ended must have one entry per lifetime")
    if t.size == 0:
        raise ParameterError("lifetimes must not be empty")
    if not np.all(np.isfinite(t)) or np.any(t < 0):
        raise ParameterError("lifetimes must be finite and >= 0")
    return t, e


def kaplan_meier(times: Any, ended: Any, *, confidence: float = 0.95) -> pd.DataFrame:
    """The Kaplan-Meier estimate of the survival function S(t) = P(T > t) of censored lifetimes.

    Parameters
    ----------
    times : array_like
        Each lifetime, or for a censored one the time it was last seen alive.
    ended : array_like of bool
        True where the lifetime ended (observed), False where it was censored.
    confidence : float
        Level of the pointwise band (log-log transform of Greenwood's variance).

    Returns
    -------
    pandas.DataFrame
        Columns ``t`` (each distinct time), ``survival`` (S just after t), ``low`` and ``high``
        (the band), ``at_risk`` (lifetimes alive just before t) and ``ended`` (that ended at t).

    Examples
    --------
    >>> from stickslip.analysis.stats.survival import kaplan_meier
    >>> km = kaplan_meier([1.0, 2.0, 3.0, 4.0], [True, False, True, True])
    >>> km["survival"].round(4).tolist()
    [0.75, 0.75, 0.375, 0.0]
    """
    t, e = _lifetimes(times, ended)
    data = stats.CensoredData(uncensored=t[e], right=t[~e])
    sf = stats.ecdf(data).sf
    with np.errstate(divide="ignore", invalid="ignore"), warnings.catch_warnings():
        # undefined where S = 1 or 0 (no end yet, none left): the band is NaN there
        warnings.simplefilter("ignore", RuntimeWarning)
        band = sf.confidence_interval(confidence, method="log-log")
    grid = sf.quantiles
    at_risk = np.array([np.count_nonzero(t >= x) for x in grid])
    n_ended = np.array([np.count_nonzero(e & (t == x)) for x in grid])
    return pd.DataFrame(
        {
            "t": grid,
            "survival": sf.probabilities,
            "low": band.low.probabilities,
            "high": band.high.probabilities,
            "at_risk": at_risk,
            "ended": n_ended,
        }
    )


@dataclass(frozen=True)
class ExponentialFit:
    """The exponential law of censored lifetimes beyond ``t_from`` (:func:`exponential_fit`).

    Attributes
    ----------
    t_from : float
        Where the tail starts.
    n : int
        Lifetimes in all.
    n_tail : int
        Those beyond ``t_from``.
    ended : int
        Those of them that ended (d).
    exposure : float
        Total time lived beyond ``t_from``.
    rate : float
        d / exposure.
    rate_err : float
        Its standard error rate / sqrt(d) (NaN with d = 0).
    tau : float
        1 / rate (inf with d = 0).
    tau_err : float
        Its standard error tau / sqrt(d) (NaN with d = 0).
    tau_low : float
        The lower end of the 95 % interval of tau (Poisson count d in the exposure); with d = 0,
        the one-sided 95 % lower bound exposure / 3.0.
    tau_high : float
        The upper end of that interval (inf with d = 0).
    mean : float
        The mean lifetime the fit gives, t_from + tau (for t_from = 0 the censored-data mean).
    mean_err : float
        Its standard error.
    weibull_shape : float or None
        The Weibull law's shape k fitted to the same tail (None where fewer than 3 ended).
    exponential_p : float or None
        The p-value of the likelihood ratio of Weibull against exponential (small: not exponential).
    """

    t_from: float
    n: int
    n_tail: int
    ended: int
    exposure: float
    rate: float
    rate_err: float
    tau: float
    tau_err: float
    tau_low: float
    tau_high: float
    mean: float
    mean_err: float
    weibull_shape: float | None
    exponential_p: float | None

    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict."""
        return asdict(self)


def _weibull_test(t: np.ndarray, e: np.ndarray, rate: float) -> tuple[float | None, float | None]:
    """Weibull shape k of the censored tail (location 0) by maximum likelihood, and the p-value of
    the likelihood ratio against the exponential of ``rate`` (k = 1)."""
    if np.count_nonzero(e) < 3 or np.any(t <= 0):
        return None, None
    log_t = np.log(t)

    def nll(params: np.ndarray) -> float:
        k, lam = np.exp(params)
        z = (t / lam) ** k
        return -float(np.sum(e * (np.log(k / lam) + (k - 1) * (log_t - math.log(lam)))) - np.sum(z))

    best = optimize.minimize(nll, np.array([0.0, math.log(1.0 / rate)]), method="Nelder-Mead")
    k = float(np.exp(best.x[0]))
    expo = -float(np.sum(e * math.log(rate)) - rate * np.sum(t))
    ratio = max(0.0, 2.0 * (expo - float(best.fun)))
    return k, float(stats.chi2.sf(ratio, 1))


def exponential_fit(times: Any, ended: Any, *, t_from: float = 0.0) -> ExponentialFit:
    """The maximum-likelihood exponential law of censored lifetimes beyond ``t_from`` (module
    docstring): rate = d / E, its error rate / sqrt(d), tau = 1 / rate with its 95 % interval,
    and the likelihood-ratio test against a Weibull law.

    Parameters
    ----------
    times, ended : array_like
        As for :func:`kaplan_meier`.
    t_from : float
        Where the tail starts: lifetimes shorter than it are left out, the others counted from it.

    Returns
    -------
    ExponentialFit

    Examples
    --------
    >>> from stickslip.analysis.stats.survival import exponential_fit
    >>> fit = exponential_fit([1.0, 2.0, 3.0, 10.0], [True, True, True, False])
    >>> fit.ended, fit.exposure, fit.rate, fit.tau
    (3, 16.0, 0.1875, 5.333333333333333)
    """
    t, e = _lifetimes(times, ended)
    tail = t > t_from
    s, ev = t[tail] - t_from, e[tail]
    d, exposure = int(np.count_nonzero(ev)), float(np.sum(s))
    if d == 0:
        low = exposure / (stats.chi2.ppf(0.95, 2) / 2.0) if exposure > 0 else 0.0
        return ExponentialFit(
            float(t_from), t.size, s.size, 0, exposure, 0.0, math.nan, math.inf, math.nan, low, math.inf,
            math.inf, math.nan, None, None,
        )  # fmt: skip
    rate = d / exposure
    tau = 1.0 / rate
    # the Poisson interval of the count d in the exposure: chi-square with 2d and 2d + 2 dof
    tau_low = 2.0 * exposure / stats.chi2.ppf(0.975, 2 * d + 2)
    tau_high = 2.0 * exposure / stats.chi2.ppf(0.025, 2 * d)
    shape, p = _weibull_test(s, ev, rate)
    return ExponentialFit(
        float(t_from), t.size, s.size, d, exposure, rate, rate / math.sqrt(d), tau, tau / math.sqrt(d),
        tau_low, tau_high, t_from + tau, tau / math.sqrt(d), shape, p,
    )  # fmt: skip


def line_fit(x: Any, y: Any, y_err: Any) -> dict[str, Any]:
    """Weighted least squares y = a + b x with the standard errors of a and b (scaled by
    sqrt(chi2 / dof) where the scatter exceeds the errors), the covariance and chi-square.

    Parameters
    ----------
    x, y, y_err : array_like
        At least two points; ``y_err`` > 0.

    Returns
    -------
    dict
        ``intercept``, ``slope``, ``intercept_err``, ``slope_err``, ``cov`` (2 x 2, as scaled),
        ``chi2``, ``dof``, ``n``.

    Examples
    --------
    >>> from stickslip.analysis.stats.survival import line_fit
    >>> f = line_fit([0.0, 1.0, 2.0], [1.0, 3.0, 5.0], [0.1, 0.1, 0.1])
    >>> round(f["slope"], 12), round(f["intercept"], 12), round(f["chi2"], 12)
    (2.0, 1.0, 0.0)
    """
    x, y, s = (np.asarray(v, dtype=np.float64).ravel() for v in (x, y, y_err))
    if x.size < 2 or not (x.size == y.size == s.size) or np.any(~(s > 0)):
        raise ParameterError("a line fit needs at least two points with errors > 0")
    w = 1.0 / s**2
    A = np.column_stack([np.ones_like(x), x])
    cov = np.linalg.inv(A.T @ (A * w[:, None]))
    coef = cov @ (A.T @ (w * y))
    chi2 = float(np.sum(w * (y - A @ coef) ** 2))
    dof = x.size - 2
    scale = max(1.0, chi2 / dof) if dof > 0 else 1.0
    cov = cov * scale
    return {
        "intercept": float(coef[0]),
        "slope": float(coef[1]),
        "intercept_err": float(math.sqrt(cov[0, 0])),
        "slope_err": float(math.sqrt(cov[1, 1])),
        "cov": cov.tolist(),
        "chi2": chi2,
        "dof": dof,
        "n": int(x.size),
    }


def _exp(x: float) -> float:
    """exp(x), inf beyond the largest float (an extrapolation of exponential growth can be)."""
    return math.exp(x) if x < 709.0 else math.inf


def _extrapolate(fit: dict[str, Any], x: float) -> tuple[float, float]:
    """ln T at ``x`` on a line fit, and its standard error from the covariance."""
    cov = np.asarray(fit["cov"])
    g = np.array([1.0, x])
    return fit["intercept"] + fit["slope"] * x, float(math.sqrt(g @ cov @ g))


def size_fits(N: Any, mean: Any, mean_err: Any, *, extrapolate_to: float | None = None) -> dict[str, Any]:
    """ln <T> against N (exponential growth, stable chaos) and against ln N (a power law), and
    which fits better; each extrapolated to ``extrapolate_to`` with its error.

    Parameters
    ----------
    N : array_like
        System sizes (at least two, or three for a chi-square to compare).
    mean, mean_err : array_like
        <T> at each N and its standard error (the errors of ln <T> are mean_err / mean).
    extrapolate_to : float, optional
        A larger N (the paper's 399).

    Returns
    -------
    dict
        ``exponential`` and ``power``: the :func:`line_fit` of ln <T> on N and on ln N (slope: the
        rate per block, or the exponent), with ``ln_T_at``, ``ln_T_at_err`` (and in decades
        ``log10_T_at``, ``log10_T_at_err``), ``T_at`` and the 1 sigma range ``T_at_low``,
        ``T_at_high`` (inf beyond the largest float) where ``extrapolate_to`` is given; ``better``: the form
        with the smaller chi-square (``exponential`` or ``power``; None with two points).

    Examples
    --------
    >>> import math
    >>> import numpy as np
    >>> from stickslip.analysis.stats.survival import size_fits
    >>> N = np.array([3.0, 5.0, 7.0, 9.0])
    >>> f = size_fits(N, 10 * np.exp(0.5 * N), np.exp(0.5 * N), extrapolate_to=11)
    >>> round(f["exponential"]["slope"], 9), f["better"], round(f["exponential"]["T_at"] / (10 * math.exp(5.5)), 9)
    (0.5, 'exponential', 1.0)
    """
    n = np.asarray(N, dtype=np.float64).ravel()
    m = np.asarray(mean, dtype=np.float64).ravel()
    err = np.asarray(mean_err, dtype=np.float64).ravel()
    if np.any(~(m > 0)) or np.any(~(n > 0)):
        raise ParameterError("<T> and N must be > 0 for fits of ln <T>")
    y, s = np.log(m), err / m
    out: dict[str, Any] = {}
    for name, x, at in (("exponential", n, extrapolate_to), ("power", np.log(n), None)):
        fit = line_fit(x, y, s)
        if extrapolate_to is not None:
            at = extrapolate_to if name == "exponential" else math.log(extrapolate_to)
            ln_t, ln_err = _extrapolate(fit, at)
            fit.update(
                ln_T_at=ln_t,
                ln_T_at_err=ln_err,
                log10_T_at=ln_t / math.log(10.0),
                log10_T_at_err=ln_err / math.log(10.0),
                T_at=_exp(ln_t),
                T_at_low=_exp(ln_t - ln_err),
                T_at_high=_exp(ln_t + ln_err),
                at=float(extrapolate_to),
            )
        out[name] = fit
    chi_e, chi_p = out["exponential"]["chi2"], out["power"]["chi2"]
    out["better"] = None if n.size < 3 else ("exponential" if chi_e <= chi_p else "power")
    return out
