"""The truncated power law of slip sizes, p(S) ~ S^-tau on [s_min, s_max] (Figs. 7, 8), as the
truncated exponential density of u = log(S / s_min) on [0, span], span = log(s_max / s_min),
proportional to exp(e u) with e = 1 - tau: its mean, variance and normaliser written to stay
finite for any e and span, and the maximum-likelihood exponent.

The doubly truncated Gutenberg-Richter law of the magnitudes M = (2/3) log10 S
(:mod:`stickslip.analysis.stats.magnitudes`) is the same law: M - m_min = u / (1.5 ln 10), exponential
with rate b ln 10 where -e = (tau - 1) = b / 1.5. Both fits solve their likelihood equation here,
so they agree: b = (3/2)(tau - 1).
"""

from __future__ import annotations

import math

import numpy as np
from scipy import optimize

__all__ = ["TAU_BRACKET", "mean_log_ratio", "var_log_ratio", "log_normaliser", "truncated_mle", "fit_failure"]

# |(1 - tau) log(s_max/s_min)| below this: use the series of the mean of log(S/s_min).
_SERIES = 1e-6
# exp() of more than this overflows a float64.
_EXP_LIMIT = 700.0


def mean_log_ratio(e: float, span: float) -> float:
    """E[log(S/s_min)] for p(S) ~ S^-tau on [s_min, s_max], e = 1 - tau, span = log(s_max/s_min).

    u = log(S/s_min) has density proportional to exp(e u) on [0, span] (a truncated
    exponential), whose mean is span / (1 - exp(-e span)) - 1/e, span/2 at e = 0.

    Parameters
    ----------
    e : float
        1 - tau.
    span : float
        log(s_max / s_min).

    Returns
    -------
    float
        The mean.
    """
    x = e * span
    if abs(x) < _SERIES:
        return span / 2.0 + e * span * span / 12.0
    x = min(max(x, -_EXP_LIMIT), _EXP_LIMIT)
    return span / (-math.expm1(-x)) - 1.0 / e


def var_log_ratio(e: float, span: float) -> float:
    """Var[log(S/s_min)] under the truncated power law: the Fisher information per event in tau.

    For the truncated exponential density of u on [0, span]: 1/e^2 - span^2 e^{x} / (e^{x} - 1)^2
    with x = e span, span^2/12 at e = 0.

    Parameters
    ----------
    e : float
        1 - tau.
    span : float
        log(s_max / s_min).

    Returns
    -------
    float
        The variance.
    """
    x = e * span
    if abs(x) < 1e-4:
        return span * span / 12.0 * (1.0 - x * x / 60.0)
    x = min(max(x, -_EXP_LIMIT), _EXP_LIMIT)
    # span^2 e^x / (e^x - 1)^2 = span^2 / (4 sinh^2(x/2))
    return 1.0 / (e * e) - span * span / (4.0 * math.sinh(x / 2.0) ** 2)


def log_normaliser(tau: float, s_min: float, s_max: float) -> float:
    """log Z(tau), Z = integral of S^-tau over [s_min, s_max] (s_max may be inf for tau > 1).

    Parameters
    ----------
    tau : float
        The exponent.
    s_min, s_max : float
        The range.

    Returns
    -------
    float
        log Z, finite for any tau and range.
    """
    e = 1.0 - tau
    if math.isinf(s_max):
        return e * math.log(s_min) - math.log(-e)
    span = math.log(s_max / s_min)
    x = e * span
    if abs(x) < _SERIES:
        return math.log(span) + x / 2.0
    # Z = s_min^e (exp(x) - 1) / e, written to stay finite for large |x|
    if x > 0:
        return e * math.log(s_min) + x + math.log(-math.expm1(-x) / e)
    return e * math.log(s_min) + math.log(math.expm1(x) / e)


#: The exponents a fit of p(S) ~ S^-tau searches: slip sizes of models and earthquakes have tau
#: between 1 and 3 (b between 0 and 3); a likelihood whose maximum lies outside this bracket says
#: the sizes do not follow a power law on the range (a bimodal sample: tau = -77 on the two-blocks
#: chain), and the fit is left out with that reason instead of reported.
TAU_BRACKET = (-1.0, 6.0)


def truncated_mle(mean_log: float, span: float) -> float:
    """The tau solving the likelihood equation E_tau[log(S/s_min)] = mean of log(S/s_min), or NaN.

    The truncated power law is an exponential family in tau, so the log-likelihood is concave
    and this root is its unique maximum. The mean is increasing in e = 1 - tau, so the root lies
    in :data:`TAU_BRACKET` exactly when the score changes sign across it; it is then found by
    Brent's method and checked: the score at the root (the gradient of the log-likelihood per
    event) vanishes to rounding. NaN where the maximum is not inside the bracket (or all
    events sit at one end of the range, where there is no interior maximum).

    Parameters
    ----------
    mean_log : float
        Mean of log(S / s_min) over the events in range.
    span : float
        log(s_max / s_min).

    Returns
    -------
    float
        tau, or NaN (:func:`fit_failure` says why).
    """
    if not 0.0 < mean_log < span:
        return math.nan

    def score(e: float) -> float:
        return mean_log_ratio(e, span) - mean_log

    e_lo, e_hi = 1.0 - TAU_BRACKET[1], 1.0 - TAU_BRACKET[0]
    if not score(e_lo) < 0.0 < score(e_hi):
        return math.nan
    e = optimize.brentq(score, e_lo, e_hi, xtol=1e-14, rtol=4 * np.finfo(float).eps, maxiter=200)
    if abs(score(e)) > 1e-9 * span:
        return math.nan  # not converged (never seen: brentq keeps a sign change)
    return 1.0 - e


def fit_failure(mean_log: float, span: float) -> str:
    """Why :func:`truncated_mle` has no tau for this mean of log(S/s_min) on a range of ``span``.

    Parameters
    ----------
    mean_log : float
        Mean of log(S / s_min) over the events in range.
    span : float
        log(s_max / s_min).

    Returns
    -------
    str
        The reason, in words.
    """
    if mean_log <= 0.0:
        return "every event in range is at s_min: the likelihood has no maximum"
    if mean_log >= span:
        return "every event in range is at s_max: the likelihood has no maximum"
    return (
        f"the likelihood's maximum lies outside tau in [{TAU_BRACKET[0]:g}, {TAU_BRACKET[1]:g}]: "
        "the sizes do not follow a power law on this range"
    )
