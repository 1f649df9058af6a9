"""The finite-amplitude threshold delta* of slip-sequence decorrelation, and how it moves with N.

:func:`stickslip.analysis.dynamics.decorrelation.sequence_decorrelation` gives n(delta) for a list of
deltas and several windows ("seeds"): the slips that agree before the first disagreement, and
whether the twin disagreed within the window at all. From those rows:

- :func:`delta_star`: per window, delta* is the smallest delta of the list whose twin disagreed
  within the window (none: no delta of the list did; the window is *censored*). Over the windows
  with a delta*: the geometric mean 10^m, m the mean of log10 delta*, with the standard error of
  m (std / sqrt(k), in decades), and the range (the smallest and largest delta*). The bracket
  (``below``, ``low``]: ``low`` the smallest delta* of any window, ``below`` the largest delta of
  the list under it (at that delta and every smaller one no window disagreed). Where n(delta) is
  not monotone (a smaller delta disagrees while a larger one agrees), ``per_seed_monotone`` gives
  per window the smallest delta from which every larger delta of the list disagreed.
- :func:`threshold_fit`: least squares of log10 delta* (one point per window, censored windows
  left out) on log10 N: the slope with its standard error from the scatter of the windows
  about the line (ordinary least squares, s^2 = residual sum of squares / (points - 2),
  err = sqrt(s^2 / sum (x - mean x)^2)), and whether the data support a trend (the slope more than
  :data:`TREND_SIGMAS` errors from zero).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from stickslip.models.params import ParameterError

__all__ = ["delta_star", "threshold_fit", "TREND_SIGMAS"]

#: A fitted slope counts as a trend when it is more than this many standard errors from zero.
TREND_SIGMAS = 2.0


def delta_star(rows) -> dict[str, Any]:
    """delta* of decorrelation rows of one kind of perturbation (module docstring).

    Parameters
    ----------
    rows : iterable of dict
        Rows with ``delta``, ``seed`` and ``decorrelated`` (the rows of
        :class:`~stickslip.analysis.dynamics.decorrelation.Decorrelation`), every seed with every delta.

    Returns
    -------
    dict
        ``deltas`` (the list, sorted), ``seeds``, ``per_seed`` (delta* per window, None where
        censored), ``per_seed_monotone``, ``censored``, ``log10_mean``, ``log10_err`` (NaN with
        fewer than two windows), ``geometric_mean``, ``low``, ``high`` and ``below`` (None where
        there is nothing to give).

    Raises
    ------
    ParameterError
        No rows, no delta above 0, or a seed lacking some of the deltas.
    """
    rows = list(rows)
    if not rows:
        raise ParameterError("delta* needs decorrelation rows")
    deltas = sorted({float(r["delta"]) for r in rows if float(r["delta"]) > 0.0})
    if not deltas:
        raise ParameterError("delta* needs deltas above 0")
    seeds = sorted({int(r["seed"]) for r in rows})
    table: dict[tuple[int, float], bool] = {}
    for r in rows:
        if float(r["delta"]) > 0.0:
            table[(int(r["seed"]), float(r["delta"]))] = bool(r["decorrelated"])
    per_seed: list[float | None] = []
    monotone: list[float | None] = []
    for s in seeds:
        flags = [table.get((s, d)) for d in deltas]
        if any(f is None for f in flags):
            raise ParameterError(f"seed {s} lacks some of the deltas {deltas}")
        hit = [d for d, f in zip(deltas, flags, strict=True) if f]
        per_seed.append(hit[0] if hit else None)
        m = None
        for d, f in zip(reversed(deltas), reversed(flags), strict=True):
            if not f:
                break
            m = d
        monotone.append(m)
    found = np.array([v for v in per_seed if v is not None], dtype=float)
    logs = np.log10(found)
    out: dict[str, Any] = {
        "deltas": deltas,
        "seeds": seeds,
        "per_seed": per_seed,
        "per_seed_monotone": monotone,
        "censored": len(per_seed) - int(found.size),
        "log10_mean": float(logs.mean()) if found.size else math.nan,
        "log10_err": float(logs.std(ddof=1) / math.sqrt(found.size)) if found.size > 1 else math.nan,
        "geometric_mean": float(10.0 ** logs.mean()) if found.size else None,
        "low": float(found.min()) if found.size else None,
        "high": float(found.max()) if found.size else None,
        "below": None,
    }
    if found.size:
        under = [d for d in deltas if d < found.min()]
        out["below"] = under[-1] if under else None
    return out


def threshold_fit(Ns, values) -> dict[str, Any]:
    """Least squares of log10 delta* on log10 N (module docstring).

    Parameters
    ----------
    Ns : sequence of int
        The chain lengths.
    values : sequence of list
        Parallel to ``Ns``: for each N, the per-window delta* (None for a censored window).

    Returns
    -------
    dict
        ``slope``, ``slope_err``, ``intercept`` (log10 delta* at N = 1), ``points``,
        ``censored``, ``Ns`` (the distinct N fitted) and ``trend`` (``'shrinks'``, ``'grows'`` or
        ``'none'``: the slope within :data:`TREND_SIGMAS` errors of zero, or not enough points or
        N for an error: three points and two values of N at least).
    """
    x: list[float] = []
    y: list[float] = []
    censored = 0
    for N, vals in zip(Ns, values, strict=True):
        for v in vals:
            if v is None:
                censored += 1
            else:
                x.append(math.log10(float(N)))
                y.append(math.log10(float(v)))
    out: dict[str, Any] = {
        "slope": math.nan,
        "slope_err": math.nan,
        "intercept": math.nan,
        "points": len(x),
        "censored": censored,
        "Ns": sorted({int(round(10.0**v)) for v in x}),
        "trend": "none",
    }
    xa, ya = np.asarray(x), np.asarray(y)
    if xa.size < 3 or np.unique(xa).size < 2:
        return out
    sxx = float(np.sum((xa - xa.mean()) ** 2))
    slope = float(np.sum((xa - xa.mean()) * (ya - ya.mean())) / sxx)
    intercept = float(ya.mean() - slope * xa.mean())
    resid = ya - (intercept + slope * xa)
    s2 = float(np.sum(resid**2) / (xa.size - 2))
    err = math.sqrt(s2 / sxx)
    out.update(slope=slope, slope_err=err, intercept=intercept)
    if abs(slope) > TREND_SIGMAS * err:
        out["trend"] = "shrinks" if slope < 0 else "grows"
    return out
