"""Frequency-magnitude statistics of a slip catalogue: magnitude, b-value, completeness, Gutenberg-Richter.

Magnitude. A slip of size S = sum_i Delta x_i is the model's seismic moment up to a constant
(rigidity times block area: every block has the same). The magnitude is the moment-magnitude
analogue of Hanks and Kanamori (J. Geophys. Res. 84, 2348 (1979)), Mw = (2/3) log10 M0 + const,

    M = (2/3) log10 S,

with the constant dropped (model units). With it the b-value is the seismologists' number and
p(S) ~ S^-tau reads N(>= M) ~ 10^(-b M) with

    b = (3/2) (tau - 1)

(tau = 1.5 gives b = 0.75; b = 1 is tau = 5/3). Carlson and Langer plot against ln S; their
slope per unit of ln S is tau - 1 = (2/3) b.

What is written here by hand, and why: the b-value of Aki (1965) with Utsu's (1966) correction
for magnitudes binned to dm, its error by Shi and Bolt (1982), and the goodness-of-fit
completeness test of Wiemer and Wyss (2000) are one-line formulas that no library of this
package's dependencies provides (scipy has no b-value; ``scipy.stats.bootstrap`` resamples the
estimate for the bootstrap error). The doubly truncated Gutenberg-Richter fit solves the
likelihood equation of the truncated exponential (``scipy.stats.truncexpon`` for b > 0) with the
power-law fit's solver (:mod:`stickslip.analysis.stats.truncated`), so that the two agree.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from scipy import stats

from stickslip.analysis.stats.truncated import TAU_BRACKET, fit_failure, truncated_mle, var_log_ratio

__all__ = [
    "magnitude",
    "size_from_magnitude",
    "b_from_tau",
    "tau_from_b",
    "bin_magnitudes",
    "BValue",
    "b_value",
    "completeness",
    "Completeness",
    "TruncatedGR",
    "truncated_gr_fit",
    "DM",
    "MIN_EVENTS_B",
]

#: Magnitude bin of the catalogue's b-value (catalogues report magnitudes to one decimal).
DM = 0.1
#: Fewest events at or above the completeness magnitude for a b-value.
MIN_EVENTS_B = 50
LOG10_E = math.log10(math.e)
LN10 = math.log(10.0)


def magnitude(S: Any) -> np.ndarray:
    """Magnitude M = (2/3) log10 S of slips of size S (the moment-magnitude analogue; module docstring).

    Parameters
    ----------
    S : array_like
        Slip sizes.

    Returns
    -------
    numpy.ndarray
        M; NaN for S <= 0.

    Examples
    --------
    >>> from stickslip.analysis.stats.magnitudes import magnitude
    >>> magnitude([1.0, 1000.0]).tolist()
    [0.0, 2.0]
    """
    S = np.asarray(S, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(S > 0, (2.0 / 3.0) * np.log10(np.where(S > 0, S, 1.0)), np.nan)


def size_from_magnitude(M: Any) -> np.ndarray:
    """The size S = 10^(3 M / 2) of magnitude M (inverse of :func:`magnitude`).

    Parameters
    ----------
    M : array_like
        Magnitudes.

    Returns
    -------
    numpy.ndarray
        The sizes.
    """
    return 10.0 ** (1.5 * np.asarray(M, dtype=np.float64))


def b_from_tau(tau: float) -> float:
    """b-value of p(S) ~ S^-tau in the magnitude M = (2/3) log10 S: b = (3/2)(tau - 1).

    Parameters
    ----------
    tau : float
        The size exponent.

    Returns
    -------
    float
        The b-value (b = 0.75 for the paper's tau = 1.5).

    Examples
    --------
    >>> from stickslip.analysis.stats.magnitudes import b_from_tau, tau_from_b
    >>> b_from_tau(1.5), tau_from_b(0.75)
    (0.75, 1.5)
    """
    return 1.5 * (tau - 1.0)


def tau_from_b(b: float) -> float:
    """Size exponent tau = 1 + (2/3) b of a b-value (inverse of :func:`b_from_tau`).

    Parameters
    ----------
    b : float
        The b-value.

    Returns
    -------
    float
        tau.
    """
    return 1.0 + b / 1.5


def bin_magnitudes(M: Any, dm: float = DM) -> np.ndarray:
    """Magnitudes rounded to the nearest multiple of ``dm``, as a catalogue reports them.

    Parameters
    ----------
    M : array_like
        Magnitudes.
    dm : float
        The bin; 0 leaves them as they are.

    Returns
    -------
    numpy.ndarray
        The binned magnitudes.
    """
    M = np.asarray(M, dtype=np.float64)
    if dm <= 0:
        return M.copy()
    return np.round(M / dm) * dm


@dataclass(frozen=True)
class BValue:
    """Maximum-likelihood b-value of N(>= M) ~ 10^(-b M) above the completeness magnitude mc
    (:func:`b_value`).

    Attributes
    ----------
    b : float
        Aki-Utsu, log10(e) / (mean(M) - (mc - dm/2)) on magnitudes binned to ``dm``.
    b_err_shi_bolt : float
        2.30 b^2 sqrt(sum (M - mean)^2 / (n (n - 1))) (Shi and Bolt 1982).
    b_err_aki : float
        b / sqrt(n) (Aki 1965).
    b_err_bootstrap : float
        Standard deviation of b over ``bootstrap`` resamples of the magnitudes (NaN without).
    mc : float
        Completeness magnitude.
    dm : float
        Magnitude bin.
    n : int
        Events with M >= mc.
    a : float
        log10 of the number of events at or above mc, the a-value at M = mc.
    bootstrap : int
        Resamples of the bootstrap error.
    seed : int
        Their seed.
    method : str
        The estimator in words.
    """

    b: float
    b_err_shi_bolt: float
    b_err_aki: float
    b_err_bootstrap: float
    mc: float
    dm: float
    n: int
    a: float
    bootstrap: int
    seed: int
    method: str = "Aki-Utsu maximum likelihood with the binning correction mc - dm/2"

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def _aki_utsu(m: np.ndarray, mc: float, dm: float, axis: int = -1) -> np.ndarray:
    """log10(e) / (mean(m) - (mc - dm/2)) along ``axis`` (vectorised for ``scipy.stats.bootstrap``)."""
    excess = np.mean(m, axis=axis) - (mc - dm / 2.0)
    with np.errstate(divide="ignore"):
        return np.where(excess > 0, LOG10_E / np.where(excess > 0, excess, 1.0), np.inf)


def b_value(M: Any, mc: float, *, dm: float = DM, bootstrap: int = 200, seed: int = 0) -> BValue:
    """b-value of the events with binned magnitude >= ``mc`` by the Aki-Utsu estimator
    (Gutenberg-Richter law).

    The magnitudes are binned to ``dm`` (:func:`bin_magnitudes`) and those with M >= mc kept. The
    estimator is Aki's maximum likelihood log10(e) / (mean(M) - M0) with M0 = mc - dm/2, the lower
    edge of the lowest bin (Utsu's correction for binned magnitudes; dm = 0 gives Aki's for
    continuous ones).

    Parameters
    ----------
    M : array_like
        Magnitudes (:func:`magnitude`).
    mc : float
        Completeness magnitude, a bin centre (:func:`completeness`).
    dm : float
        The bin.
    bootstrap : int
        Resamples of the bootstrap error (0: none).
    seed : int
        Their seed.

    Returns
    -------
    BValue
        b with three errors, n and the a-value.

    Raises
    ------
    ValueError
        With fewer than 2 events above mc, or all of them in one bin (every magnitude equal: the
        estimator then returns log10(e) / (dm/2), a number set by the bin alone).
    """
    m = bin_magnitudes(M, dm)
    m = m[np.isfinite(m) & (m >= mc - 1e-9 * max(dm, 1.0))]
    n = int(m.size)
    if n < 2:
        raise ValueError(f"need at least 2 events with M >= mc = {mc:g} for a b-value (got {n})")
    if float(np.ptp(m)) <= 1e-9 * max(dm, 1.0):
        raise ValueError(
            f"all {n} magnitudes at or above mc = {mc:g} are equal ({float(m[0]):.3g}): no spread, no b-value"
        )
    b = float(_aki_utsu(m, mc, dm))
    shi_bolt = 2.30 * b * b * math.sqrt(float(np.sum((m - m.mean()) ** 2)) / (n * (n - 1)))
    err_boot = math.nan
    if bootstrap > 0:
        res = stats.bootstrap(
            (m,),
            lambda x, axis=-1: _aki_utsu(x, mc, dm, axis),
            n_resamples=bootstrap,
            vectorized=True,
            # resamples in batches of at most 2**24 magnitudes: the memory of a large catalogue
            # times many resamples stays bounded (one batch, as before, where it fits)
            batch=None if bootstrap * n <= 2**24 else max(1, 2**24 // n),
            method="percentile",
            rng=np.random.default_rng(seed),
        )
        draws = np.asarray(res.bootstrap_distribution)
        draws = draws[np.isfinite(draws)]
        err_boot = float(draws.std(ddof=1)) if draws.size > 1 else math.nan
    return BValue(
        b=b,
        b_err_shi_bolt=shi_bolt,
        b_err_aki=b / math.sqrt(n),
        b_err_bootstrap=err_boot,
        mc=float(mc),
        dm=float(dm),
        n=n,
        a=math.log10(n),
        bootstrap=int(bootstrap),
        seed=int(seed),
    )


@dataclass(frozen=True)
class Completeness:
    """Completeness magnitude mc and how it was found (:func:`completeness`).

    Attributes
    ----------
    mc : float
        The completeness magnitude.
    method : str
        "goodness of fit 95%", "goodness of fit 90%" or "maximum curvature".
    R : float
        The goodness of fit (percent) at mc; NaN for maximum curvature.
    scan : list of tuple
        The candidates tried, each (mc, n, b, R).
    """

    mc: float
    method: str
    R: float
    scan: list[tuple[float, int, float, float]]

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def _gft_residual(m: np.ndarray, mc: float, dm: float, b: float) -> float:
    """Wiemer and Wyss's R: 100 - 100 sum abs(B_i - S_i) / sum B_i over the bins M_i >= mc, with B_i
    the observed and S_i the Gutenberg-Richter cumulative counts N(>= M_i) of the fit."""
    top = float(m.max())
    centres = mc + dm * np.arange(int(round((top - mc) / dm)) + 1)
    observed = np.array([np.count_nonzero(m >= c - dm / 2) for c in centres], dtype=float)
    predicted = observed[0] * 10.0 ** (-b * (centres - mc))
    return 100.0 - 100.0 * float(np.abs(observed - predicted).sum()) / float(observed.sum())


def completeness(M: Any, *, dm: float = DM, min_events: int = MIN_EVENTS_B) -> Completeness:
    """Completeness magnitude of a catalogue by the goodness-of-fit test of Wiemer and Wyss (2000).

    Candidates: every bin centre from the most populated bin (the maximum curvature of the
    frequency-magnitude distribution) upwards while at least ``min_events`` events remain at or
    above it. At each, the Aki-Utsu b-value is fitted and R = 100 - 100 sum abs(B_i - S_i) / sum B_i
    compares the observed cumulative counts B_i with the Gutenberg-Richter ones S_i. mc is the first
    candidate with R >= 95, else the first with R >= 90 (Woessner and Wiemer 2005), else the maximum
    curvature. In a simulated catalogue nothing goes undetected: mc marks where the slips start to
    follow Gutenberg-Richter.

    Parameters
    ----------
    M : array_like
        Magnitudes.
    dm : float
        The bin.
    min_events : int
        Fewest events at or above a candidate.

    Returns
    -------
    Completeness
        mc, the rule that chose it, R there and the scan.
    """
    m = bin_magnitudes(M, dm)
    m = m[np.isfinite(m)]
    if m.size < 2:
        raise ValueError(f"need at least 2 magnitudes for a completeness magnitude (got {m.size})")
    step = dm if dm > 0 else 0.1
    m_b = bin_magnitudes(m, step)
    values, counts = np.unique(np.round(m_b / step).astype(np.int64), return_counts=True)
    maxc = float(values[np.argmax(counts)] * step)
    scan: list[tuple[float, int, float, float]] = []
    mc = maxc
    while True:
        n = int(np.count_nonzero(m_b >= mc - step / 2))
        if n < max(min_events, 2):
            break
        b = float(_aki_utsu(m_b[m_b >= mc - step / 2], mc, step))
        R = _gft_residual(m_b[m_b >= mc - step / 2], mc, step, b) if math.isfinite(b) else math.nan
        scan.append((round(mc, 10), n, b, R))
        mc += step
    for level in (95.0, 90.0):
        for c, _, _, R in scan:
            if R >= level:
                return Completeness(mc=c, method=f"goodness of fit {level:.0f}%", R=R, scan=scan)
    return Completeness(mc=round(maxc, 10), method="maximum curvature", R=math.nan, scan=scan)


@dataclass(frozen=True)
class TruncatedGR:
    """Doubly truncated Gutenberg-Richter law: magnitudes exponential with rate b ln 10 on
    [m_min, m_max] (:func:`truncated_gr_fit`).

    Attributes
    ----------
    b : float
        The b-value.
    b_err : float
        Its error from the Fisher information of the truncated exponential.
    m_min : float
        Lower end of the range.
    m_max : float
        Upper end of the range.
    n : int
        Events in it.
    loglikelihood : float
        The maximised log-likelihood.
    tau : float
        1 + (2/3) b, the size exponent it means.
    """

    b: float
    b_err: float
    m_min: float
    m_max: float
    n: int
    loglikelihood: float
    tau: float

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


#: log(S / s_min) per unit of M - m_min (M = (2/3) log10 S).
LN_PER_M = 1.5 * LN10


def _log_truncexp_normaliser(beta: float, width: float) -> float:
    """log of the integral of exp(-beta u) over [0, width], finite for any beta."""
    x = beta * width
    if abs(x) < 1e-6:
        return math.log(width) - x / 2.0
    if x > 0:
        return math.log(-math.expm1(-x)) - math.log(beta)
    return -x + math.log(-math.expm1(x)) - math.log(-beta)


def truncated_gr_fit(M: Any, m_min: float, m_max: float | None = None) -> TruncatedGR:
    """Doubly truncated Gutenberg-Richter fit (Page 1968): maximum likelihood of b for continuous
    magnitudes on [m_min, m_max].

    u = M - m_min has the truncated exponential density of rate beta = b ln 10 on [0, W],
    W = m_max - m_min (``scipy.stats.truncexpon`` for beta > 0; beta <= 0 is a flat or growing
    density). The likelihood is concave in beta and its maximum solves E_beta[u] = mean(u). For
    M = (2/3) log10 S this is the power law in S truncated to [S(m_min), S(m_max)] with
    tau = 1 + (2/3) b, the model of :func:`stickslip.analysis.stats.statistics.fit_power_law`: the
    equation is solved in those units (u 1.5 ln 10 = log(S / s_min)) by the same bracketed,
    checked root (:func:`stickslip.analysis.stats.truncated.truncated_mle`), so the two fits agree.

    Parameters
    ----------
    M : array_like
        Magnitudes (not binned).
    m_min : float
        Lower end.
    m_max : float, optional
        Upper end (default the largest M).

    Returns
    -------
    TruncatedGR
        b, its error, the range and tau.

    Raises
    ------
    ValueError
        With fewer than 2 magnitudes in range, or where the likelihood has no maximum with tau in
        :data:`~stickslip.analysis.stats.truncated.TAU_BRACKET` (the message says why): the fit is then
        left out, not reported.
    """
    M = np.asarray(M, dtype=np.float64)
    top = float(np.nanmax(M)) if m_max is None else float(m_max)
    u = M[np.isfinite(M) & (M >= m_min) & (M <= top)] - m_min
    width = top - m_min
    n = int(u.size)
    if n < 2 or not width > 0:
        raise ValueError(f"need at least 2 magnitudes in [{m_min:g}, {top:g}] for a truncated Gutenberg-Richter fit")
    span, mean_log = width * LN_PER_M, float(u.mean()) * LN_PER_M
    tau = truncated_mle(mean_log, span)
    if not math.isfinite(tau):
        why = fit_failure(mean_log, span)
        lo, hi = (b_from_tau(t) for t in TAU_BRACKET)
        why = why.replace(f"tau in [{TAU_BRACKET[0]:g}, {TAU_BRACKET[1]:g}]", f"b in [{lo:g}, {hi:g}]")
        raise ValueError(f"no truncated Gutenberg-Richter law on M in [{m_min:.3g}, {top:.3g}] ({n} events): {why}")
    beta = (tau - 1.0) * LN_PER_M
    # Fisher information per event in beta: Var(u) of the fitted law
    info = var_log_ratio(-beta, width)
    beta_err = 1.0 / math.sqrt(n * info) if info > 0 else math.nan
    # log-likelihood of u: -beta sum(u) - n log(integral of e^{-beta u} over [0, W])
    loglik = -beta * float(u.sum()) - n * _log_truncexp_normaliser(beta, width)
    return TruncatedGR(
        b=beta / LN10,
        b_err=beta_err / LN10,
        m_min=float(m_min),
        m_max=top,
        n=n,
        loglikelihood=loglik,
        tau=float(tau),
    )
