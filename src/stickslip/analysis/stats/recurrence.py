"""Recurrence of slips: inter-event times, their coefficient of variation, renewal-model fits with AIC.

The inter-event times of a catalogue (all slips, or only the system-spanning ones: the model's
characteristic earthquakes) are fitted by maximum likelihood with the renewal models of
earthquake recurrence, each a ``scipy.stats`` distribution with its location fixed at 0:

=================  ===========================  =====================================
``exponential``    ``scipy.stats.expon``        Poisson: no memory, CV = 1
``gamma``          ``scipy.stats.gamma``        shape k: CV = 1 / sqrt(k)
``weibull``        ``scipy.stats.weibull_min``  shape k: k > 1 quasi-periodic
``bpt``            ``scipy.stats.invgauss``     Brownian passage time (Matthews, Ellsworth
                                                and Reasenberg 2002): mean mu, aperiodicity
                                                alpha = its CV; scipy's shape is alpha^2 and
                                                its scale mu / alpha^2
=================  ===========================  =====================================

and ranked by AIC = 2 k - 2 log L. The errors of the parameters are from the observed
information: the Hessian of the log-likelihood in the logarithms of the parameters
(``scipy.differentiate.hessian``), inverted (the delta method takes them back to the
parameters); ``scipy.stats`` fits give none.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy import differentiate, stats

__all__ = ["RENEWAL_MODELS", "inter_event_times", "fit_renewal", "renewal_pdf", "recurrence", "MIN_INTERVALS"]

#: Fewest inter-event times for a fit.
MIN_INTERVALS = 10

RENEWAL_MODELS = ("exponential", "gamma", "weibull", "bpt")
_DISTS = {"exponential": stats.expon, "gamma": stats.gamma, "weibull": stats.weibull_min, "bpt": stats.invgauss}


def inter_event_times(t_start: Any) -> np.ndarray:
    """Times between successive slip starts, the recurrence intervals.

    Parameters
    ----------
    t_start : array_like
        Start times of the slips (``events["t_start"]``), in any order.

    Returns
    -------
    numpy.ndarray
        The differences of the sorted start times (one fewer than the slips).

    Examples
    --------
    >>> from stickslip.analysis.stats.recurrence import inter_event_times
    >>> inter_event_times([5.0, 1.0, 2.5]).tolist()
    [1.5, 2.5]
    """
    t = np.sort(np.asarray(t_start, dtype=np.float64))
    return np.diff(t)


def _native(name: str, fitted: tuple[float, ...]) -> tuple[float, ...]:
    """scipy's fitted (shapes..., loc, scale) without loc: the parameters fitted."""
    return (fitted[-1],) if name == "exponential" else (fitted[0], fitted[-1])


def _loglik(name: str, dt: np.ndarray, log_params: np.ndarray) -> np.ndarray:
    """Sum of log-densities at parameters exp(log_params), vectorised over trailing axes (for the Hessian)."""
    p = np.exp(log_params)
    x = dt.reshape((-1,) + (1,) * (p.ndim - 1))
    dist = _DISTS[name]
    if name == "exponential":
        values = dist.logpdf(x, scale=p[0])
    else:
        values = dist.logpdf(x, p[0], scale=p[1])
    return np.sum(values, axis=0)


def fit_renewal(name: str, dt: Any) -> dict[str, Any]:
    """Maximum-likelihood fit of a renewal model to inter-event times.

    Parameters
    ----------
    name : str
        One of :data:`RENEWAL_MODELS`: ``exponential`` (Poisson), ``gamma``, ``weibull``, ``bpt``
        (Brownian passage time, the inverse Gaussian).
    dt : array_like
        Inter-event times (:func:`inter_event_times`).

    Returns
    -------
    dict
        ``params`` (by name), ``errors`` (one-sigma, from the observed information),
        ``loglikelihood``, ``aic``, ``n``, and the ``mean`` and ``cv`` the fitted model implies.

    Raises
    ------
    ValueError
        For fewer than 2 positive times, or where scipy's fit does not end at a maximum of the
        likelihood (the observed information is not positive definite): left out, not reported.
    """
    dt = np.asarray(dt, dtype=np.float64)
    dt = dt[np.isfinite(dt) & (dt > 0)]
    if dt.size < 2:
        raise ValueError(f"need at least 2 positive inter-event times (got {dt.size})")
    dist = _DISTS[name]
    native = np.array(_native(name, dist.fit(dt, floc=0)), dtype=np.float64)
    log_p = np.log(native)
    loglik = float(_loglik(name, dt, log_p))
    # One fourth-order difference with steps of 2% in each parameter: the log-likelihood of many
    # events is too large for smaller steps (rounding), and refining them costs 20 times as much.
    # A sharply peaked likelihood (nearly periodic slips: a Weibull shape of hundreds) needs
    # smaller steps: they shrink tenfold until the information is positive definite, as it is at
    # a maximum; if it never is, the fit did not end at one and is left out.
    for step in (0.02, 2e-3, 2e-4, 2e-5):
        hess = differentiate.hessian(lambda lp: _loglik(name, dt, lp), log_p, initial_step=step, order=4, maxiter=1)
        info = -np.atleast_2d(hess.ddf)
        if np.all(np.isfinite(info)) and np.all(np.linalg.eigvalsh(0.5 * (info + info.T)) > 0):
            break
    else:
        raise ValueError(f"{name}: the search did not end at a maximum of the likelihood")
    cov = np.linalg.inv(info)
    log_err = np.sqrt(np.diag(cov))
    err = native * log_err  # delta method from the log scale
    k = native.size
    if name == "exponential":
        params = {"scale": native[0]}
        errors = {"scale": err[0]}
        frozen = dist(scale=native[0])
    elif name == "bpt":
        mu_s, scale = native
        alpha = math.sqrt(mu_s)
        frozen = dist(mu_s, scale=scale)
        # mean = mu_s * scale: its error from the covariance of the log-parameters
        var_log_mean = float(cov[0, 0] + cov[1, 1] + 2 * cov[0, 1]) if np.all(np.isfinite(log_err)) else math.nan
        params = {"mean": mu_s * scale, "aperiodicity": alpha}
        errors = {"mean": mu_s * scale * math.sqrt(max(var_log_mean, 0.0)), "aperiodicity": 0.5 * alpha * log_err[0]}
    else:
        params = {"shape": native[0], "scale": native[1]}
        errors = {"shape": err[0], "scale": err[1]}
        frozen = dist(native[0], scale=native[1])
    mean, var = (float(v) for v in frozen.stats("mv"))
    return {
        "model": name,
        "params": {k_: float(v) for k_, v in params.items()},
        "errors": {k_: float(v) for k_, v in errors.items()},
        "loglikelihood": loglik,
        "aic": 2 * k - 2 * loglik,
        "n": int(dt.size),
        "mean": mean,
        "cv": math.sqrt(var) / mean if mean > 0 else math.nan,
    }


def renewal_pdf(fit: dict[str, Any], x: Any) -> np.ndarray:
    """Density of a fitted renewal model.

    Parameters
    ----------
    fit : dict
        A record of :func:`fit_renewal`.
    x : array_like
        Inter-event times at which to evaluate it.

    Returns
    -------
    numpy.ndarray
        The fitted density at ``x``.
    """
    p, model = fit["params"], fit["model"]
    dist = _DISTS[model]
    if model == "exponential":
        return dist.pdf(x, scale=p["scale"])
    if model == "bpt":
        a2 = p["aperiodicity"] ** 2
        return dist.pdf(x, a2, scale=p["mean"] / a2)
    return dist.pdf(x, p["shape"], scale=p["scale"])


def recurrence(t_start: Any, *, min_intervals: int = MIN_INTERVALS) -> dict[str, Any]:
    """Inter-event times of the slips starting at ``t_start``: their statistics and every renewal fit.

    Parameters
    ----------
    t_start : array_like
        Start times of the slips.
    min_intervals : int
        Fewest inter-event times to fit.

    Returns
    -------
    dict
        ``n``, ``mean``, ``median``, ``cv`` (standard deviation over mean: 1 for a Poisson
        process, below 1 quasi-periodic, above 1 clustered), ``fits`` (:func:`fit_renewal` per
        model, ranked by ``delta_aic`` from the best, with Akaike ``weight``), ``best``. With fewer
        than ``min_intervals`` times there is no fit, and ``reason`` says so.
    """
    dt = inter_event_times(t_start)
    dt = dt[dt > 0]
    out: dict[str, Any] = {"n": int(dt.size)}
    if dt.size:
        out.update(mean=float(dt.mean()), median=float(np.median(dt)))
        out["cv"] = float(dt.std(ddof=1) / dt.mean()) if dt.size > 1 else math.nan
    if dt.size < max(min_intervals, 2):
        out.update(fits=[], best=None, reason=f"{dt.size} inter-event times; a fit needs at least {min_intervals}")
        return out
    fits = []
    for name in RENEWAL_MODELS:
        try:
            fits.append(fit_renewal(name, dt))
        except (ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
            fits.append({"model": name, "reason": f"no fit: {exc}"})
    good = [f for f in fits if "aic" in f]
    if good:
        best_aic = min(f["aic"] for f in good)
        weights = np.exp(-0.5 * (np.array([f["aic"] for f in good]) - best_aic))
        for f, w in zip(good, weights / weights.sum(), strict=True):
            f["delta_aic"] = f["aic"] - best_aic
            f["weight"] = float(w)
    out["fits"] = fits
    out["best"] = min(good, key=lambda f: f["aic"])["model"] if good else None
    return out
