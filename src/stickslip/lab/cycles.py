"""The cycles of a stick-slip record and their observables: period, stress drop, peak slip rate.

A spring-slider in stick-slip loads its spring slowly (friction rising at about k V) and drops it
in a fast slip. From samples (t_i, mu_i) of the spring's friction mu = k (p - x) this module finds
each drop and measures, cycle by cycle (:func:`cycle_table`):

- ``period``: the time between successive drops, each dated where mu falls through the record's
  middle level (mu_max + mu_min) / 2, by linear interpolation between the two samples around it
  (a drop is a fall from the upper to the lower quarter of the range, so that noise about the
  middle makes none);
- ``stress_drop``: the peak friction before the drop less the least friction after it, each
  extremum the vertex of a parabola fitted by least squares through the samples around it;
- ``peak_slip_rate``: V + max(-dmu/dt) / k, the slip rate at the steepest point of the drop, since
  dmu/dt = k (V - v) holds exactly for the spring; -dmu/dt from a Savitzky-Golay filter (a
  quadratic over five samples; centred differences where the samples are unevenly spaced), its
  maximum again the vertex of a parabola;
- ``peak_friction``: the peak friction before each drop.

The interpolations make every observable a continuous function of the samples, so that a model
sampled at the same times and measured the same way (:mod:`stickslip.lab.inversion`) varies
smoothly with its parameters, as a least-squares fit needs. :func:`observables` averages the
table and gives each mean its standard error (the scatter between cycles over the square root of
their number).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.signal import savgol_filter

from stickslip.models.params import ParameterError

__all__ = ["OBSERVABLES", "cycle_table", "observables"]

#: The observables of a cycle, in order, with their meaning.
OBSERVABLES = {
    "period": "time between successive slips",
    "stress_drop": "peak friction before a slip less the least friction after it",
    "peak_slip_rate": "greatest slip rate of a slip, V + max(-dmu/dt) / k",
    "peak_friction": "friction at the peak before a slip",
}

#: Samples each side of an extremum through which its parabola is fitted.
_HALF = 2


def _vertex(y: np.ndarray, i: int, sign: float) -> float:
    """The extreme value of the least-squares parabola through y[i - h .. i + h] (h = _HALF, fewer
    at an end), ``sign`` +1 for a maximum and -1 for a minimum; y[i] itself where the parabola
    has no extremum of that kind inside the stencil."""
    lo, hi = max(0, i - _HALF), min(y.size, i + _HALF + 1)
    if hi - lo < 3:
        return float(y[i])
    s = np.arange(lo, hi) - i
    c2, c1, c0 = np.polyfit(s, y[lo:hi], 2)
    if sign * c2 >= 0.0:
        return float(y[i])
    s0 = -c1 / (2.0 * c2)
    if abs(s0) > _HALF:
        return float(y[i])
    return float(c0 - c1 * c1 / (4.0 * c2))


def _crossings(mu: np.ndarray, mid: float, low: float, high: float) -> tuple[np.ndarray, np.ndarray]:
    """The samples j after which mu falls (``down``) or rises (``up``) through ``mid`` for good:
    the last such crossing before mu reaches ``low`` (``high``) having been above ``high``
    (below ``low``)."""
    down, up = [], []
    state = 0  # 1: above high since the last drop, -1: below low since the last rise
    last_fall = last_rise = -1
    for j in range(mu.size - 1):
        if mu[j] >= mid > mu[j + 1]:
            last_fall = j
        elif mu[j] < mid <= mu[j + 1]:
            last_rise = j
        if mu[j + 1] > high:
            if state == -1 and last_rise >= 0:
                up.append(last_rise)
            state = 1
        elif mu[j + 1] < low:
            if state == 1 and last_fall >= 0:
                down.append(last_fall)
            state = -1
    return np.array(down, dtype=np.int64), np.array(up, dtype=np.int64)


def _derivative(t: np.ndarray, mu: np.ndarray) -> np.ndarray:
    """dmu/dt by a Savitzky-Golay filter (quadratic over 2 _HALF + 1 samples) where the samples
    are evenly spaced, else by centred differences."""
    dt = np.diff(t)
    if mu.size > 2 * _HALF + 1 and np.ptp(dt) <= 1e-9 * dt.mean():
        return savgol_filter(mu, 2 * _HALF + 1, 2, deriv=1, delta=float(dt.mean()))
    return np.gradient(mu, t)


def cycle_table(t, mu, *, V: float, k: float, window: tuple[float, float] | None = None) -> pd.DataFrame:
    """The stick-slip cycles of a friction record (module docstring).

    Parameters
    ----------
    t, mu : arrays
        Sample times (increasing) and the spring's friction k (p - x).
    V : float
        Load-point velocity during the cycles (for the peak slip rate).
    k : float
        Spring stiffness, friction per unit displacement (for the peak slip rate).
    window : (t0, t1), optional
        Only the samples with t0 <= t <= t1 are read.

    Returns
    -------
    pandas.DataFrame
        One row per complete cycle (from one drop to the next): ``t_slip`` (the time of the drop
        that ends it), ``period``, ``stress_drop``, ``peak_slip_rate``, ``peak_friction`` and
        ``peak_drop_rate`` (max(-dmu/dt), which needs no k); the stress drop and the peak rates
        of a drop whose trough the record does not reach are NaN.

    Raises
    ------
    ParameterError
        Fewer than three drops in the window (two cycles are the least that show a period).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(0.0, 100.0, 10001)
    >>> mu = 0.6 + 0.01 * ((t % 20.0) / 20.0)  # a sawtooth: period 20, drop 0.01
    >>> c = cycle_table(t, mu, V=1.0, k=1.0)
    >>> round(float(c.period.mean()), 6), round(float(c.stress_drop.mean()), 4)
    (20.0, 0.01)
    """
    t = np.asarray(t, dtype=float)
    mu = np.asarray(mu, dtype=float)
    if window is not None:
        sel = (t >= window[0]) & (t <= window[1])
        t, mu = t[sel], mu[sel]
    if t.size < 8:
        raise ParameterError(f"a stick-slip record needs more samples in its window (got {t.size})")
    lo_, hi_ = mu.min(), mu.max()
    mid = 0.5 * (lo_ + hi_)
    # A drop: mu falls from above the upper quarter to below the lower quarter of the range (a
    # Schmitt trigger, so that noise near the middle makes no drops); it is dated where it falls
    # through the middle, and a rise likewise.
    low, high = lo_ + 0.25 * (hi_ - lo_), hi_ - 0.25 * (hi_ - lo_)
    down, up = _crossings(mu, mid, low, high)
    if down.size < 3:
        raise ParameterError(
            f"found {down.size} slip(s) in the record's window: a stick-slip inversion needs at least "
            "three (two cycles); give a longer record or a wider window"
        )
    frac = (mu[down] - mid) / (mu[down] - mu[down + 1])
    t_slip = t[down] + frac * (t[down + 1] - t[down])
    rate = -_derivative(t, mu)
    rows = []
    for c in range(down.size - 1):
        j0, j1 = down[c], down[c + 1]
        # the peak before drop c + 1: the greatest sample since the last rise through the middle
        rises = up[(up > j0) & (up < j1)]
        if rises.size == 0:
            continue
        r = rises[-1]
        ip = r + int(np.argmax(mu[r : j1 + 1]))
        # the trough after drop c + 1: the least sample before the next rise through the middle
        later = up[up > j1]
        end = later[0] if later.size else mu.size - 1
        it = j1 + int(np.argmin(mu[j1 : end + 1]))
        # the steepest fall of drop c + 1: between its peak and its trough
        iv = ip + int(np.argmax(rate[ip : it + 1]))
        peak = _vertex(mu, ip, 1.0)
        whole = later.size > 0  # the record goes on past the trough of this drop
        drop_rate = _vertex(rate, iv, 1.0) if whole else np.nan
        rows.append(
            {
                "t_slip": t_slip[c + 1],
                "period": t_slip[c + 1] - t_slip[c],
                "stress_drop": peak - _vertex(mu, it, -1.0) if whole else np.nan,
                "peak_slip_rate": V + drop_rate / k,
                "peak_friction": peak,
                "peak_drop_rate": drop_rate,
            }
        )
    table = pd.DataFrame(rows, columns=["t_slip", *OBSERVABLES, "peak_drop_rate"])
    if len(table) < 2:
        raise ParameterError(
            f"found {len(table)} complete cycle(s) in the record's window: a stick-slip inversion needs at least two"
        )
    return table


def observables(table: pd.DataFrame, names=tuple(OBSERVABLES)) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The mean of each observable over the cycles of ``table``, its standard error (the
    cycles' standard deviation over the square root of their number) and the number of cycles
    that gave it.

    Parameters
    ----------
    table : pandas.DataFrame
        From :func:`cycle_table` (or a table of cycles read from a file: the same columns).
    names : sequence of str
        Observables, of :data:`OBSERVABLES`.

    Returns
    -------
    (mean, stderr, count) : arrays, one value per name
    """
    mean, err, count = [], [], []
    for name in names:
        if name not in OBSERVABLES:
            raise ParameterError(f"unknown observable {name!r}: choose from {', '.join(OBSERVABLES)}")
        if name not in table:
            raise ParameterError(f"the table of cycles has no column {name!r}")
        x = np.asarray(table[name], dtype=float)
        x = x[np.isfinite(x)]
        if x.size == 0:
            raise ParameterError(f"no cycle gives the {name}")
        mean.append(float(x.mean()))
        err.append(float(x.std(ddof=1) / np.sqrt(x.size)) if x.size > 1 else np.nan)
        count.append(x.size)
    return np.array(mean), np.array(err), np.array(count)
