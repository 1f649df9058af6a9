"""The order parameter of the stick-slip transition and the final state of a chain run.

Sakaguchi's chain (eq. 4) slides steadily for beta > 1 and stick-slips for beta <= 1 (section 3);
Fig. 5(b) shows <L> falling continuously below the steady length as beta drops below 1. The
order parameter here is

    m = 1 - <L> / L_ss,

zero in steady sliding and positive in stick-slip (L_ss: the exact discrete steady length,
docs/model.md). Its samples L(t) are strongly correlated in time (the chain loads for ~L_ss / V
between large events), so its error bar comes from batch means whose batch length is set by
the integrated autocorrelation time (:func:`integrated_time`), not from the naive formula.

:func:`classify_final_state` names the end of a run ``steady`` / ``stick-slip`` / ``undecided``
from numbers measured over the last two quarters of the run.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
import xarray as xr

__all__ = [
    "order_summary",
    "integrated_time",
    "batch_means",
    "MeanEstimate",
    "mean_with_error",
    "order_parameter",
    "classify_final_state",
    "FINAL_STATES",
    "quarter_stats",
    "transition_bracket",
    "power_law_fit",
    "TimeAverage",
    "time_average",
]

#: The three final states of a study point.
FINAL_STATES = ("steady", "stick-slip", "undecided")

#: Batch length in units of the integrated autocorrelation time.
BATCH_TAUS = 10.0
#: Fewest batches for which the batch-means error is called reliable.
MIN_BATCHES = 8


def _autocorrelation(x: np.ndarray) -> np.ndarray:
    """Normalised autocorrelation function of ``x`` (FFT, zero-padded: no wrap-around)."""
    x = np.asarray(x, dtype=float) - np.mean(x)
    n = x.size
    size = 1 << (2 * n - 1).bit_length()
    f = np.fft.rfft(x, size)
    acf = np.fft.irfft(f * np.conjugate(f), size)[:n]
    return acf / acf[0] if acf[0] > 0 else np.zeros(n)


def integrated_time(x: np.ndarray, *, c: float = 6.0) -> float:
    """Integrated autocorrelation time tau_int = 1/2 + sum_{t>=1} rho(t) of a series, in samples.

    Summed up to Sokal's self-consistent window, the smallest W with W >= c tau_int(W)
    (A. Sokal, "Monte Carlo methods in statistical mechanics", 1997). Var(mean) ~ 2 tau_int
    sigma^2 / n.

    Parameters
    ----------
    x : numpy.ndarray
        The series, equally spaced in time.
    c : float
        Window factor of Sokal's rule.

    Returns
    -------
    float
        tau_int in samples; 0.5 for a constant series; for a series shorter than its window the
        estimate at the largest window (an underestimate: see :func:`mean_with_error`'s
        ``reliable``).

    Examples
    --------
    >>> import numpy as np
    >>> from stickslip.analysis.stats.order import integrated_time
    >>> float(integrated_time(np.random.default_rng(0).normal(size=20000))) < 0.6  # white noise
    True
    """
    x = np.asarray(x, dtype=float)
    if x.size < 2 or not np.ptp(x) > 0:
        return 0.5
    rho = _autocorrelation(x)
    taus = 0.5 + np.cumsum(rho[1:])
    windows = np.arange(1, x.size)
    ok = windows >= c * taus
    w = int(np.argmax(ok)) if ok.any() else x.size - 2
    return float(max(taus[w], 0.5))


def batch_means(x: np.ndarray, batch: int) -> tuple[float, int]:
    """Standard error of the mean of ``x`` from non-overlapping batches of ``batch`` samples.

    Parameters
    ----------
    x : numpy.ndarray
        The series.
    batch : int
        Samples per batch; the samples left over at the start are dropped, so the batches end
        with the series.

    Returns
    -------
    tuple of (float, int)
        The error of the mean, the standard deviation of the batch means over sqrt(number of
        batches), and the number of batches.
    """
    x = np.asarray(x, dtype=float)
    batch = max(int(batch), 1)
    k = x.size // batch
    if k < 2:
        return math.nan, k
    means = x[x.size - k * batch :].reshape(k, batch).mean(axis=1)
    return float(np.std(means, ddof=1) / math.sqrt(k)), k


@dataclass(frozen=True)
class MeanEstimate:
    """A time average with its error (:func:`mean_with_error`).

    Attributes
    ----------
    mean : float
        The average.
    err : float
        Its standard error from batch means.
    err_tau : float
        sqrt(2 tau_int var / n), the error from the autocorrelation time.
    tau_int : float
        Integrated autocorrelation time, samples.
    batch : int
        Samples per batch.
    n_batches : int
        Batches.
    n : int
        Samples.
    reliable : bool
        At least :data:`MIN_BATCHES` batches of :data:`BATCH_TAUS` tau_int each.
    """

    mean: float
    err: float
    err_tau: float
    tau_int: float
    batch: int
    n_batches: int
    n: int
    reliable: bool

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def mean_with_error(x: np.ndarray) -> MeanEstimate:
    """Mean of a correlated series and its error by batch means.

    The batch length is ``BATCH_TAUS * tau_int`` (:func:`integrated_time`): batches much longer
    than the correlation time have nearly independent means, and the relative bias of the variance
    estimate is about 2 tau_int / batch.

    Parameters
    ----------
    x : numpy.ndarray
        The series, equally spaced in time.

    Returns
    -------
    MeanEstimate
        The mean, its error, tau_int and the batches. If the series holds fewer than
        ``MIN_BATCHES`` batches of ``BATCH_TAUS`` tau_int, it is cut into ``MIN_BATCHES`` batches
        and the estimate is flagged ``reliable = False`` (the error is then likely too small).
    """
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    n = int(x.size)
    if n == 0:
        return MeanEstimate(math.nan, math.nan, math.nan, math.nan, 0, 0, 0, False)
    mean = float(np.mean(x))
    if not np.ptp(x) > 0:
        return MeanEstimate(mean, 0.0, 0.0, 0.5, 1, n, n, True)
    tau = integrated_time(x)
    batch = int(math.ceil(BATCH_TAUS * tau))
    reliable = n // batch >= MIN_BATCHES
    if not reliable:
        batch = max(n // MIN_BATCHES, 1)
    err, k = batch_means(x, batch)
    err_tau = math.sqrt(2.0 * tau * float(np.var(x)) / n)
    return MeanEstimate(mean, err, err_tau, tau, batch, k, n, bool(reliable))


def order_parameter(L: np.ndarray, L_ss: float) -> MeanEstimate:
    """m = 1 - <L>/L_ss with its batch-means error (Fig. 5b as an order parameter).

    Parameters
    ----------
    L : numpy.ndarray
        Samples of L = x_1 - x_N, equally spaced in time.
    L_ss : float
        Steady length (:func:`stickslip.models.physics.chain_steady_length`).

    Returns
    -------
    MeanEstimate
        m and its error (:func:`mean_with_error`); m = 0 in steady sliding.
    """
    return mean_with_error(1.0 - np.asarray(L, dtype=float) / float(L_ss))


def quarter_stats(t: np.ndarray, m: np.ndarray, stuck: np.ndarray | None, t_end: float) -> dict[str, float]:
    """m and the fraction of samples with some block stuck over the third and fourth quarters of
    ``[0, t_end]`` (what :func:`classify_final_state` compares).

    Parameters
    ----------
    t : numpy.ndarray
        Sampling times.
    m : numpy.ndarray
        m = 1 - L / L_ss at those times.
    stuck : numpy.ndarray or None
        1 where some block is stuck at the sample, else 0 (None: not recorded).
    t_end : float
        End of the run.

    Returns
    -------
    dict
        ``m_q3``, ``m_err_q3``, ``m_q4``, ``m_err_q4`` and, with ``stuck``, ``stuck_q3``,
        ``stuck_q4``.
    """
    t = np.asarray(t, dtype=float)
    out: dict[str, float] = {}
    for name, lo, hi in (("q3", 0.5, 0.75), ("q4", 0.75, 1.0 + 1e-12)):
        sel = (t >= lo * t_end) & (t < hi * t_end)
        est = mean_with_error(np.asarray(m)[sel])
        out[f"m_{name}"], out[f"m_err_{name}"] = est.mean, est.err
        if stuck is not None:
            s = np.asarray(stuck, dtype=float)[sel]
            out[f"stuck_{name}"] = float(s.mean()) if s.size else math.nan
    return out


def classify_final_state(
    *,
    reached_steady: bool,
    stuck_q3: float,
    stuck_q4: float,
    m_q3: float,
    m_err_q3: float,
    m_q4: float,
    m_err_q4: float,
    drift_z: float = 4.0,
    decay: float = 0.5,
) -> tuple[str, str]:
    """Final state of a run: ``steady``, ``stick-slip`` or ``undecided``, and why.

    - ``steady``: the run reached steady sliding (every block within tolerance of it);
    - ``stick-slip``: some block is stuck during the last quarter of the run, the fraction of
      time with a stuck block there is at least ``decay`` times that of the third quarter (it
      is not dying out), and m does not drift between the two quarters by more than
      ``drift_z`` combined errors;
    - ``undecided``: anything else: sliding but not yet steady, stick-slip dying out, or m
      still drifting. Such a point is reported as it is, never averaged as settled.

    Parameters
    ----------
    reached_steady : bool
        Whether the run reached steady sliding.
    stuck_q3, stuck_q4 : float
        Fraction of samples with a stuck block in the third and fourth quarters.
    m_q3, m_err_q3, m_q4, m_err_q4 : float
        m and its error in those quarters (:func:`quarter_stats`).
    drift_z : float
        Largest drift of m between the quarters, in combined errors.
    decay : float
        Least ratio of the stuck fractions (fourth over third quarter) of lasting stick-slip.

    Returns
    -------
    tuple of (str, str)
        The state and one line saying why.
    """
    if reached_steady:
        return "steady", "reached steady sliding"
    if not (math.isfinite(stuck_q4) and stuck_q4 > 0):
        return "undecided", "no block stuck in the last quarter, but not yet steady sliding"
    if math.isfinite(stuck_q3) and stuck_q4 < decay * stuck_q3:
        return "undecided", f"stuck fraction falling ({stuck_q3:.3g} -> {stuck_q4:.3g})"
    errs = math.hypot(m_err_q3, m_err_q4) if math.isfinite(m_err_q3) and math.isfinite(m_err_q4) else math.nan
    if math.isfinite(errs) and errs > 0 and abs(m_q4 - m_q3) > drift_z * errs:
        return "undecided", f"m drifting ({m_q3:.3g} -> {m_q4:.3g}, {abs(m_q4 - m_q3) / errs:.1f} errors)"
    return "stick-slip", "blocks stick in the last quarter at a steady rate"


def transition_bracket(betas, states) -> dict[str, Any]:
    """Where the final state changes from stick-slip to steady sliding along beta (one N).

    Parameters
    ----------
    betas : sequence of float
        The runs' beta, in any order.
    states : sequence of str
        Each run's final state, ``stick-slip``, ``steady`` or ``undecided``
        (:func:`classify_final_state`).

    Returns
    -------
    dict
        ``lo``, the largest beta whose run ends in stick-slip, and ``hi``, the smallest beta above
        ``lo`` whose run ends steady: the transition lies in [lo, hi] (``estimate`` the midpoint,
        ``uncertainty`` half the width; NaN where a side is missing); ``undecided``, the undecided
        betas between them; ``contradictions``, steady runs below ``lo``.

    Examples
    --------
    >>> from stickslip.analysis.stats.order import transition_bracket
    >>> b = transition_bracket([0.9, 1.0, 1.1, 1.2], ["stick-slip", "stick-slip", "undecided", "steady"])
    >>> b["lo"], b["hi"], b["undecided"]
    (1.0, 1.2, [1.1])
    """
    order = np.argsort(np.asarray(betas, dtype=float))
    b = np.asarray(betas, dtype=float)[order]
    s = np.asarray(states, dtype=object)[order]
    stick = b[s == "stick-slip"]
    if stick.size == 0:
        return {
            "lo": math.nan,
            "hi": float(b[s == "steady"].min()) if (s == "steady").any() else math.nan,
            "estimate": math.nan,
            "uncertainty": math.nan,
            "undecided": b[s == "undecided"].tolist(),
            "contradictions": 0,
        }
    lo = float(stick.max())
    above = b[(s == "steady") & (b > lo)]
    hi = float(above.min()) if above.size else math.nan
    between = b[(s == "undecided") & (b > lo) & ((b < hi) if math.isfinite(hi) else True)].tolist()
    contradictions = int(np.count_nonzero((s == "steady") & (b < lo)))
    est = 0.5 * (lo + hi) if math.isfinite(hi) else math.nan
    return {
        "lo": lo,
        "hi": hi,
        "estimate": est,
        "uncertainty": 0.5 * (hi - lo) if math.isfinite(hi) else math.nan,
        "undecided": between,
        "contradictions": contradictions,
    }


def power_law_fit(x, y, yerr=None) -> dict[str, float]:
    """Least-squares fit of log y = log A + b log x, weighted by the relative errors ``yerr / y``
    when given (the exponent b of m ~ (beta_c - beta)^b, or of beta_t - 1 ~ N^b).

    Parameters
    ----------
    x, y : array_like
        The points; those not positive and finite are left out.
    yerr : array_like, optional
        Errors of y.

    Returns
    -------
    dict
        ``b`` and its standard error ``b_err``, the prefactor ``A`` and the points used ``n``;
        NaN with fewer than 3 points.

    Examples
    --------
    >>> import numpy as np
    >>> from stickslip.analysis.stats.order import power_law_fit
    >>> fit = power_law_fit([10, 100, 1000], 2.0 * np.array([10, 100, 1000]) ** -0.5)
    >>> round(fit["b"], 12), round(fit["A"], 12)
    (-0.5, 2.0)
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    ok = (x > 0) & (y > 0) & np.isfinite(x) & np.isfinite(y)
    if np.count_nonzero(ok) < 3:
        return {"b": math.nan, "b_err": math.nan, "A": math.nan, "n": int(np.count_nonzero(ok))}
    lx, ly = np.log(x[ok]), np.log(y[ok])
    w = None
    if yerr is not None:
        rel = np.asarray(yerr, dtype=float)[ok] / y[ok]
        w = 1.0 / np.maximum(rel, 1e-3)
    coef, cov = np.polyfit(lx, ly, 1, w=w, cov="unscaled" if w is not None and ok.sum() < 4 else True)
    return {
        "b": float(coef[0]),
        "b_err": float(math.sqrt(cov[0, 0])),
        "A": float(math.exp(coef[1])),
        "n": int(np.count_nonzero(ok)),
    }


# Time averages (Fig. 5b)
@dataclass(frozen=True)
class TimeAverage:
    """Time average of a sampled series with a batch-means standard error (Fig. 5b; :func:`time_average`).

    Attributes
    ----------
    mean : float
        The average over the samples with t >= t_from.
    stderr : float
        The standard deviation of the means of ``n_batches`` consecutive equal batches over
        sqrt(n_batches) (stick-slip samples are correlated, so the naive error would be too
        small); NaN with fewer samples than batches.
    t_from : float
        The first sampling time averaged over.
    t_to : float
        The last.
    n_samples : int
        Samples used.
    n_batches : int
        Batches of the error.
    """

    mean: float
    stderr: float
    t_from: float
    t_to: float
    n_samples: int
    n_batches: int

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def order_summary(run, params, t_from: float) -> dict[str, Any]:
    """The order parameter m = 1 - <L>/L_ss of one chain run of eq. (4) (section 3, Fig. 5b read
    as a phase transition) and its final state.

    Parameters
    ----------
    run : ChainRun
        The run, sampled with ``sample_moving`` (its samples hold ``t``, ``L``, ``t_moving`` and
        ``n_moving``); a run stopped at steady sliding counts as steady from ``t_steady`` to its
        ``t_end``.
    params : ChainParams
        Its parameters (for L_ss and N).
    t_from : float
        Start of the window averaged over.

    Returns
    -------
    dict
        m over t >= ``t_from`` with its batch-means error (:func:`order_parameter`), the fraction
        of samples with some block stuck, the event rate and largest event in the window, the
        time steady sliding was reached, the statistics of the last two quarters
        (:func:`quarter_stats`) and the final state with its reason
        (:func:`classify_final_state`).
    """
    from stickslip.models.physics import chain_steady_length

    L_ss = chain_steady_length(params)
    s = run.summary
    t_end = float(run.options.t_end)
    dt_s = float(run.options.sample_interval)
    t = run.samples["t"].values
    L = run.samples["L"].values
    tm = run.samples["t_moving"].values
    stuck = (run.samples["n_moving"].values < params.N).astype(float)
    reached = bool(s.get("stopped_early", False))
    if reached:
        # steady sliding from t_steady on: L = L_ss and nothing stuck at the remaining sample times
        t_rest = (
            np.arange(math.floor(float(s["t_steady"]) / dt_s + 1e-9) + 1, math.floor(t_end / dt_s + 1e-9) + 1) * dt_s
        )
        t = np.concatenate([t[t < t_rest[0]] if t_rest.size else t, t_rest])
        L = np.concatenate([run.samples["L"].values[: t.size - t_rest.size], np.full(t_rest.size, L_ss)])
        tm_keep = tm < t_rest[0] if t_rest.size else np.ones(tm.size, bool)
        tm = np.concatenate([tm[tm_keep], t_rest])
        stuck = np.concatenate([stuck[tm_keep], np.zeros(t_rest.size)])
    m = 1.0 - L / L_ss
    late = t >= t_from - 1e-9
    est = order_parameter(L[late], L_ss)
    late_m = tm >= t_from - 1e-9
    stuck_fraction = float(stuck[late_m].mean()) if late_m.any() else math.nan
    q = quarter_stats(t, m, None, t_end)
    q.update({k: v for k, v in quarter_stats(tm, np.zeros(tm.size), stuck, t_end).items() if k.startswith("stuck")})
    state, reason = classify_final_state(
        reached_steady=reached,
        stuck_q3=q["stuck_q3"],
        stuck_q4=q["stuck_q4"],
        m_q3=q["m_q3"],
        m_err_q3=q["m_err_q3"],
        m_q4=q["m_q4"],
        m_err_q4=q["m_err_q4"],
    )
    ev = run.events[run.events["t_start"] >= t_from]
    window = t_end - t_from
    return {
        "order_parameter": est.mean,
        "order_parameter_err": est.err,
        "order_parameter_err_tau": est.err_tau,
        "tau_int": est.tau_int * dt_s,
        "batch_time": est.batch * dt_s,
        "n_batches": est.n_batches,
        "err_reliable": est.reliable,
        "L_mean": float(np.mean(L[late])) if late.any() else math.nan,
        "L_steady": L_ss,
        "stuck_fraction": stuck_fraction,
        "event_rate": len(ev) / window if window > 0 else math.nan,
        "n_events": int(len(ev)),
        "S_max": float(ev["S"].max()) if len(ev) else 0.0,
        "max_blocks": int(ev["n_blocks"].max()) if len(ev) else 0,
        "t_steady": float(s["t_steady"]) if reached else None,
        "final_state": state,
        "final_reason": reason,
        **q,
    }


def time_average(series: xr.DataArray, t_from: float | None = None, *, n_batches: int = 10) -> TimeAverage:
    """<L>, the time average of L(t) = x_1 - x_N (or any series on coordinate ``t``) for Fig. 5b,
    with its error from batch means (:func:`stickslip.analysis.stats.order.batch_means`; the samples left
    over are dropped at the start).

    Parameters
    ----------
    series : xarray.DataArray
        The samples over coordinate ``t`` (``run.samples["L"]``).
    t_from : float, optional
        First time averaged over (default the first sample).
    n_batches : int
        Batches of the error.

    Returns
    -------
    TimeAverage
        The mean, its error and the window.

    Raises
    ------
    ValueError
        Without a coordinate ``t``, or without samples at t >= t_from.
    """
    if "t" not in series.coords:
        raise ValueError("series needs a coordinate 't'")
    t = series["t"].to_numpy()
    values = series.to_numpy().astype(np.float64)
    start = float(t.min()) if t_from is None else float(t_from)
    keep = (t >= start) & np.isfinite(values)
    y = values[keep]
    n = int(y.size)
    if n == 0:
        raise ValueError(f"no samples at t >= {start:g}")
    stderr = math.nan
    if n_batches >= 2 and n >= n_batches:
        # The project's one batch-means estimator (the order parameter's too).
        stderr, _ = batch_means(y, n // n_batches)
    return TimeAverage(
        mean=float(y.mean()),
        stderr=stderr,
        t_from=start,
        t_to=float(t[keep].max()),
        n_samples=n,
        n_batches=int(n_batches),
    )
