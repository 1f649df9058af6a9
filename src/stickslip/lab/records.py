"""Friction records of a laboratory test: time, friction and the load history that drove it.

A :class:`Record` is what :func:`stickslip.lab.fitting.fit` fits: samples (t_i, mu_i) of the friction, the
:class:`~stickslip.lab.history.LoadHistory` of the load point, and optionally weights (one over the
noise of each sample) and a window of time that the fit reads. :func:`detrend` removes a linear
trend of friction with load-point displacement (slip hardening or weakening over a whole test, which
rate-and-state friction does not describe), fitted over a window; :func:`synthetic` makes noisy
records from known parameters.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from stickslip.lab.history import LoadHistory, column, read_csv_columns
from stickslip.models.params import ParameterError, check_number

__all__ = ["Record", "detrend", "synthetic"]

#: Friction column names looked for in a CSV record, in this order.
FRICTION_NAMES = ("mu", "friction")


@dataclass(frozen=True, eq=False)
class Record:
    """Samples of friction under a load history.

    Parameters
    ----------
    t : array
        Sample times, increasing, within the history.
    mu : array
        Friction at each sample.
    history : LoadHistory
        The load point.
    weight : float or array, optional
        Weight of each sample in the residuals (one over its noise; default 1).
    window : (float, float), optional
        Only samples with t0 <= t <= t1 are fitted.
    name : str
        A label for reports.
    v_init : float, optional
        Slip rate at the start (steady sliding); default the first load-point velocity.
    """

    t: np.ndarray
    mu: np.ndarray
    history: LoadHistory
    weight: float | np.ndarray | None = None
    window: tuple[float, float] | None = None
    name: str = ""
    v_init: float | None = None

    def __post_init__(self):
        t = np.asarray(self.t, dtype=float).ravel()
        mu = np.asarray(self.mu, dtype=float).ravel()
        if t.size != mu.size or t.size < 2:
            raise ParameterError(
                f"a record needs at least two samples of t and mu, as many of each (got {t.size}, {mu.size})"
            )
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(mu))):
            raise ParameterError("a record's t and mu must be finite numbers (a gap, NaN, is not fitted)")
        if np.any(np.diff(t) <= 0.0):
            raise ParameterError("a record's times must increase")
        h = self.history
        if t[0] < h.times[0] or t[-1] > h.t_end:
            raise ParameterError(f"a record's times must lie within its history [{h.times[0]:g}, {h.t_end:g}]")
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "mu", mu)
        if self.weight is not None:
            w = np.broadcast_to(np.asarray(self.weight, dtype=float), t.shape)
            if not np.all(np.isfinite(w)) or np.any(w < 0.0):
                raise ParameterError("weights must be finite and >= 0")
            object.__setattr__(self, "weight", np.array(w))
        if self.window is not None:
            t0, t1 = (float(x) for x in self.window)
            if not t0 < t1:
                raise ParameterError(f"window must be (t0, t1) with t0 < t1 (got {self.window!r})")
            object.__setattr__(self, "window", (t0, t1))

    @property
    def mask(self) -> np.ndarray:
        """The samples the fit reads (inside the window, weight > 0)."""
        m = np.ones(self.t.size, dtype=bool)
        if self.window is not None:
            m &= (self.t >= self.window[0]) & (self.t <= self.window[1])
        if self.weight is not None:
            m &= self.weight > 0.0
        return m

    @property
    def weights(self) -> np.ndarray:
        """The weight of each sample (1 where none was given)."""
        return np.ones(self.t.size) if self.weight is None else np.asarray(self.weight)

    @classmethod
    def from_csv(
        cls,
        path: str | Path,
        *,
        time: str = "time",
        friction: str | None = None,
        displacement: str | None = None,
        velocity: str | None = None,
        window: tuple[float, float] | None = None,
    ) -> Record:
        """A record from a CSV file with a header line: time, friction (``mu`` or ``friction``) and
        the load point's displacement or velocity (:meth:`LoadHistory.from_csv`).

        Raises
        ------
        ParameterError
            A column missing or holding a gap, times not increasing, the load point moving back.
        """
        columns = read_csv_columns(path)
        if friction is None:
            friction = next((c for c in FRICTION_NAMES if c in columns), FRICTION_NAMES[0])
        t = column(columns, time, path)
        mu = column(columns, friction, path)
        history = LoadHistory.from_columns(columns, t, path, displacement, velocity)
        return cls(t, mu, history, window=window, name=Path(path).stem)

    def __repr__(self) -> str:
        span = f"t {self.t[0]:g}..{self.t[-1]:g}"
        return f"Record({self.name or 'unnamed'}: {self.t.size} samples, {span}, {self.history!r})"


def detrend(record: Record, *, window: tuple[float, float] | None = None, slope: float | None = None) -> Record:
    """Remove a linear trend of friction with load-point displacement, mu - s (p(t) - p(t_0)).

    Parameters
    ----------
    record : Record
    window : (float, float), optional
        Times over which the slope s is fitted (least squares of mu against p); use a stretch of
        steady sliding. Default the whole record.
    slope : float, optional
        A slope s to remove instead of fitting one.

    Returns
    -------
    Record
        The record with the trend removed (the friction at t_0 unchanged); its ``name`` says so.
    """
    p = record.history.position(record.t)
    p = p - p[0]
    if slope is None:
        sel = np.ones(p.size, dtype=bool)
        if window is not None:
            sel = (record.t >= window[0]) & (record.t <= window[1])
        if np.count_nonzero(sel) < 3 or np.ptp(p[sel]) == 0.0:
            raise ParameterError("detrend needs at least three samples over which the load point moves")
        slope = float(np.polyfit(p[sel], record.mu[sel], 1)[0])
    slope = check_number("slope", slope)
    return replace(record, mu=record.mu - slope * p, name=f"{record.name} (detrended, {slope:.3g} per unit slip)")


def synthetic(model, history: LoadHistory, *, n: int = 500, noise: float = 0.0, rng=None, name: str = "") -> Record:
    """A record of the quasi-static spring-slider with known parameters, sampled at ``n`` even times,
    with Gaussian noise of standard deviation ``noise`` added to the friction.

    Parameters
    ----------
    model : RateState
        The true parameters (k required).
    history : LoadHistory
    n : int
        Samples, evenly spaced over the history.
    noise : float
        Standard deviation of the noise; the record's weights are 1 / noise where it is > 0.
    rng : numpy.random.Generator or int, optional
        The random numbers (a seed makes the record reproducible).
    name : str

    Returns
    -------
    Record
    """
    from stickslip.lab.spring_slider import quasi_static

    t = np.linspace(history.times[0], history.t_end, int(check_number("n", n, low=2, integer=True)))
    ds = quasi_static(model, history, t=t)
    mu = ds.mu.values.copy()
    if noise > 0.0:
        mu += np.random.default_rng(rng).normal(0.0, noise, mu.size)
    w = None if noise <= 0.0 else 1.0 / noise
    return Record(t, mu, history, weight=w, name=name or "synthetic")
