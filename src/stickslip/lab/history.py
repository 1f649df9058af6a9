"""Load-point histories of a friction experiment: velocity steps, holds, tables and lab records.

A history is the load-point position p(t) as a continuous, piecewise-linear function of time:
breakpoints 0 <= t_0 < t_1 < ... < t_n and positions p_0 <= p_1 <= ... <= p_n, so the
load-point velocity V(t) = dp/dt is constant on each interval [t_i, t_i+1) and may jump at a
breakpoint (a velocity step, the start or the end of a hold at V = 0). Velocity steps, holds,
piecewise-linear tables of position and a lab record read from CSV are all of this one form, so
every solver sees the same object: :meth:`LoadHistory.position`, :meth:`LoadHistory.velocity`
and the breakpoints, where an integrator restarts.

The load point never moves backwards (V >= 0): a negative velocity, times that do not increase
or a record with gaps (NaN) or without the columns named is refused with a
:class:`~stickslip.models.params.ParameterError` of one line.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from stickslip.models.params import ParameterError

__all__ = ["LoadHistory"]


def _finite_array(name: str, values) -> np.ndarray:
    try:
        arr = np.asarray(values, dtype=float).ravel()
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be numbers (got {values!r:.40})") from None
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        raise ParameterError(f"{name} must be finite numbers (entry {bad[0]} is {arr[bad[0]]!r})")
    return arr


@dataclass(frozen=True, eq=False)
class LoadHistory:
    """The load-point position p(t), piecewise linear and continuous (module docstring).

    Build one with :meth:`steps`, :meth:`slide_hold_slide`, :meth:`table`, :meth:`from_velocities`
    or :meth:`from_csv`; the constructor takes the breakpoints themselves.

    Parameters
    ----------
    times : array of float
        Breakpoints 0 <= t_0 < t_1 < ... < t_n (the units of the experiment, e.g. s).
    positions : array of float
        Load-point displacement p_i at each breakpoint, non-decreasing (e.g. um).

    Raises
    ------
    ParameterError
        Fewer than two breakpoints, times negative or not increasing, positions
        decreasing (a negative velocity) or not finite.

    Examples
    --------
    >>> h = LoadHistory.steps([1.0, 10.0], [10.0, 20.0])
    >>> float(h.position(15.0)), float(h.velocity(15.0)), h.breakpoints.tolist()
    (60.0, 10.0, [0.0, 10.0, 30.0])
    """

    times: np.ndarray
    positions: np.ndarray

    def __post_init__(self):
        t = _finite_array("times", self.times)
        p = _finite_array("positions", self.positions)
        if t.size < 2 or t.size != p.size:
            raise ParameterError(
                f"a load history needs at least two breakpoints with one position each (got {t.size} times, "
                f"{p.size} positions)"
            )
        if t[0] < 0.0:
            raise ParameterError(f"times must be >= 0 (got {t[0]:g})")
        dt = np.diff(t)
        if np.any(dt <= 0.0):
            i = int(np.flatnonzero(dt <= 0.0)[0])
            raise ParameterError(f"times must increase (t[{i}] = {t[i]:g}, t[{i + 1}] = {t[i + 1]:g})")
        dp = np.diff(p)
        if np.any(dp < 0.0):
            i = int(np.flatnonzero(dp < 0.0)[0])
            raise ParameterError(
                f"load-point velocity must be >= 0 (the position falls from {p[i]:g} to {p[i + 1]:g} "
                f"between t = {t[i]:g} and {t[i + 1]:g})"
            )
        t.flags.writeable = False
        p.flags.writeable = False
        object.__setattr__(self, "times", t)
        object.__setattr__(self, "positions", p)
        v = dp / dt
        v.flags.writeable = False
        # Read at every integration (the integrators' tables, their choice of method): once here.
        object.__setattr__(self, "_velocities", v)

    # -- building ------------------------------------------------------------------------------

    @classmethod
    def steps(cls, velocities: Sequence[float], durations: Sequence[float]) -> LoadHistory:
        """Constant load-point velocities V_i held for durations T_i in turn (V_i = 0 is a hold).

        Parameters
        ----------
        velocities : sequence of float
            V_i >= 0, in displacement per unit time.
        durations : sequence of float
            T_i > 0, one per velocity.

        Returns
        -------
        LoadHistory
            Breakpoints at the cumulative sums of the durations; the position is continuous.
        """
        v = _finite_array("velocities", velocities)
        d = _finite_array("durations", durations)
        if v.size == 0 or v.size != d.size:
            raise ParameterError(f"give one duration per velocity (got {v.size} velocities, {d.size} durations)")
        if np.any(v < 0.0):
            raise ParameterError(f"velocities must be >= 0 (got {v[v < 0.0][0]:g})")
        if np.any(d <= 0.0):
            raise ParameterError(f"durations must be > 0 (got {d[d <= 0.0][0]:g})")
        # The positions from the displacements V_i T_i themselves, not from differences of the summed times.
        return cls(np.concatenate([[0.0], np.cumsum(d)]), np.concatenate([[0.0], np.cumsum(v * d)]))

    @classmethod
    def slide_hold_slide(
        cls, V: float, t_slide: float, holds: Iterable[float], *, t_reslide: float | None = None
    ) -> LoadHistory:
        """A slide-hold-slide test: slide at V for t_slide, then for each hold time t_h a hold at
        V = 0 for t_h followed by a slide at V for t_reslide (default t_slide).

        Returns
        -------
        LoadHistory
        """
        holds = _finite_array("holds", list(holds))
        t_reslide = t_slide if t_reslide is None else t_reslide
        velocities, durations = [V], [t_slide]
        for th in holds:
            velocities += [0.0, V]
            durations += [th, t_reslide]
        return cls.steps(velocities, durations)

    @classmethod
    def from_velocities(cls, times: Sequence[float], velocities: Sequence[float]) -> LoadHistory:
        """A history from a velocity held on each interval: V_i on [t_i, t_i+1).

        Parameters
        ----------
        times : sequence of float
            t_0 < t_1 < ... < t_n (n + 1 values; a trailing velocity for t_n is allowed and unused).
        velocities : sequence of float
            V_i >= 0 for i < n.

        Returns
        -------
        LoadHistory
            Positions p_i = p_0 = 0 plus the sum over j < i of V_j (t_j+1 - t_j).
        """
        t = _finite_array("times", times)
        v = _finite_array("velocities", velocities)
        if v.size not in (t.size - 1, t.size):
            raise ParameterError(f"give a velocity for each interval between times (got {t.size} times, {v.size})")
        v = v[: t.size - 1]
        if np.any(v < 0.0):
            i = int(np.flatnonzero(v < 0.0)[0])
            raise ParameterError(f"velocities must be >= 0 (got {v[i]:g} at t = {t[i]:g})")
        if t.size >= 2 and np.any(np.diff(t) <= 0.0):
            i = int(np.flatnonzero(np.diff(t) <= 0.0)[0])
            raise ParameterError(f"times must increase (t[{i}] = {t[i]:g}, t[{i + 1}] = {t[i + 1]:g})")
        p = np.concatenate([[0.0], np.cumsum(v * np.diff(t))])
        return cls(t, p)

    @classmethod
    def table(cls, times: Sequence[float], positions: Sequence[float]) -> LoadHistory:
        """A piecewise-linear table of load-point position against time (the constructor)."""
        return cls(np.asarray(times, dtype=float), np.asarray(positions, dtype=float))

    @classmethod
    def from_csv(
        cls,
        path: str | Path,
        *,
        time: str = "time",
        displacement: str | None = None,
        velocity: str | None = None,
    ) -> LoadHistory:
        """A lab record: time and load-point displacement (a table) or velocity (held on each
        sample interval), read from a CSV file with a header line.

        Parameters
        ----------
        path : str or Path
            The CSV file.
        time : str
            Name of the time column.
        displacement, velocity : str, optional
            Name of the load-point displacement or velocity column; by default the first of
            ``load_point``, ``displacement``, ``lp_disp``, then ``velocity``, ``vlp``, ``V`` present.

        Raises
        ------
        ParameterError
            The file cannot be read, a column is missing, a value is not finite, times do not
            increase or the load point moves backwards.
        """
        columns = read_csv_columns(path)
        return cls.from_columns(columns, column(columns, time, path), path, displacement, velocity)

    @classmethod
    def from_columns(
        cls,
        columns: dict[str, np.ndarray],
        t: np.ndarray,
        path: str | Path,
        displacement: str | None = None,
        velocity: str | None = None,
    ) -> LoadHistory:
        """The load point of a record's columns at its times ``t`` (:meth:`from_csv`, and the fit's
        records): the displacement column named, else the velocity column, else the first of
        :data:`DISPLACEMENT_NAMES`, then :data:`VELOCITY_NAMES` present.

        Parameters
        ----------
        columns : dict of str to array
            The record's columns by name (:func:`read_csv_columns`).
        t : array of float
            The times.
        path : str or Path
            The file, for the messages.
        displacement, velocity : str, optional
            The column to read.

        Returns
        -------
        LoadHistory
            A table of the displacements, or the velocities held on each sample interval.
        """
        if displacement is None and velocity is None:
            displacement = next((c for c in DISPLACEMENT_NAMES if c in columns), None)
            if displacement is None:
                velocity = next((c for c in VELOCITY_NAMES if c in columns), None)
            if displacement is None and velocity is None:
                raise ParameterError(
                    f"{path}: no load-point column (looked for {', '.join(DISPLACEMENT_NAMES + VELOCITY_NAMES)}; "
                    f"found {', '.join(columns)})"
                )
        if displacement is not None:
            return cls(t, column(columns, displacement, path))
        return cls.from_velocities(t, column(columns, velocity, path))

    # -- reading -------------------------------------------------------------------------------

    @property
    def breakpoints(self) -> np.ndarray:
        """The times t_i where the load-point velocity may change (the first is 0, the last t_end)."""
        return self.times

    @property
    def t_end(self) -> float:
        """The last breakpoint."""
        return float(self.times[-1])

    @property
    def velocities(self) -> np.ndarray:
        """V_i = (p_i+1 - p_i) / (t_i+1 - t_i), the load-point velocity on each interval (exact up to
        the rounding of the summed positions and times: a short step after long ones keeps fewer
        digits). Read-only, computed once."""
        return self._velocities

    def merged(self, rtol: float = 1e-9) -> LoadHistory:
        """The same history without the breakpoints where the velocity does not change (to
        ``rtol`` of the larger of the two velocities there): a record sampled at a steady rate
        becomes one interval, so an integrator restarts only where the load point's velocity
        really steps; a hold beside a slow slide stays apart however slow the slide."""
        v = self.velocities
        keep = np.concatenate([[True], np.abs(np.diff(v)) > rtol * np.maximum(np.abs(v[:-1]), np.abs(v[1:])), [True]])
        if keep.all():
            return self
        return LoadHistory(self.times[keep], self.positions[keep])

    def segment(self, t) -> np.ndarray:
        """The index i of the interval [t_i, t_i+1) holding each t (the last interval holds t_end)."""
        i = np.searchsorted(self.times, np.asarray(t, dtype=float), side="right") - 1
        return np.clip(i, 0, self.times.size - 2)

    def position(self, t) -> np.ndarray:
        """p(t), linear between breakpoints (held at p_n after t_end)."""
        return np.interp(np.asarray(t, dtype=float), self.times, self.positions)

    def velocity(self, t) -> np.ndarray:
        """V(t) = dp/dt, the right-hand value at a breakpoint."""
        return self.velocities[self.segment(t)]

    def __repr__(self) -> str:
        v = self.velocities
        return (
            f"LoadHistory({v.size} segments, t_end={self.t_end:g}, V from {v.min():g} to {v.max():g}, "
            f"{int(np.sum(v == 0.0))} holds)"
        )


#: Column names looked for in a lab record, in this order.
DISPLACEMENT_NAMES = ("load_point", "displacement", "lp_disp")
VELOCITY_NAMES = ("velocity", "vlp", "V")


def read_csv_columns(path: str | Path) -> dict[str, np.ndarray]:
    """The columns of a CSV file with a header line, as float arrays by name (pandas' reader).

    Raises
    ------
    ParameterError
        The file cannot be read or a column is not numeric.
    """
    import pandas as pd

    try:
        frame = pd.read_csv(path)
    except (OSError, ValueError, pd.errors.ParserError) as exc:
        raise ParameterError(f"{path}: cannot read a CSV table ({str(exc).splitlines()[0]})") from None
    out = {}
    for name in frame.columns:
        values = pd.to_numeric(frame[name], errors="coerce").to_numpy(dtype=float)
        out[str(name).strip()] = values
    return out


def column(columns: dict[str, np.ndarray], name: str, path) -> np.ndarray:
    """One column of :func:`read_csv_columns`, refused if it is missing or holds a gap (NaN)."""
    if name not in columns:
        raise ParameterError(f"{path}: no column {name!r} (columns: {', '.join(columns)})")
    values = columns[name]
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        raise ParameterError(f"{path}: column {name!r} has no number in data row {bad[0] + 1} (NaN or text)")
    if values.size == 0:
        raise ParameterError(f"{path}: column {name!r} is empty")
    return values
