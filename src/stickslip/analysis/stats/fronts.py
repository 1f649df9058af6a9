"""Rupture fronts of a chain run (Fig. 6): front speed, leading-edge speed, their intervals.

Blocks are numbered 1..N (docs/model.md); the functions take the labelled tables of a chain run
(``events``, ``first_move``) and return frozen dataclasses. Importable also from
:mod:`stickslip.analysis.stats.statistics`.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr
from scipy import stats

# ---------------------------------------------------------------------------------------------
# Rupture fronts (Fig. 6)


@dataclass(frozen=True)
class FrontSpeed:
    """Speed of a rupture front fitted from first-motion times (Fig. 6; :func:`front_speed`).

    Least squares of block index i against first-move time t over blocks i_min..i_max:
    i = i_0 + speed (t - t_start).

    Attributes
    ----------
    event : int
        The event's number.
    speed : float
        Blocks per time unit (the paper: c = 1.43 in large events at beta = 1, below the sound
        speed sqrt(K) = 3.16).
    speed_err : float
        Standard error of the slope.
    intercept : float
        i_0.
    t_start : float
        The event's first first-move time.
    i_min : int
        The first block fitted.
    i_max : int
        The last block fitted.
    n_blocks : int
        How many blocks were fitted.
    rms : float
        Root mean square of the residuals, in blocks.
    """

    event: int
    speed: float
    speed_err: float
    intercept: float
    t_start: float
    i_min: int
    i_max: int
    n_blocks: int
    rms: float

    def arrival_time(self, i: Any) -> np.ndarray:
        """First-move time of block i on the fitted line (absolute time)."""
        return self.t_start + (np.asarray(i, dtype=np.float64) - self.intercept) / self.speed

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def front_speed(
    first_move: pd.DataFrame,
    event: int,
    *,
    i_min: int | None = None,
    i_max: int | None = None,
) -> FrontSpeed:
    """Rupture-front speed of one event from the time each block first moved (Fig. 6).

    The paper measures the leading edge "for large i", away from the pulled end where the rupture
    starts, so by default the fit uses the far half of the blocks the event reached:
    i_min = ceil(i_far / 2), i_max = i_far, with i_far the farthest block that moved.

    Parameters
    ----------
    first_move : pandas.DataFrame
        The run's long table (``event``, ``block``, ``t_first``; ``ChainRun.first_move``), blocks
        numbered 1..N; blocks that did not move are absent or have NaN ``t_first``.
    event : int
        The event's number.
    i_min, i_max : int, optional
        The blocks fitted (default the far half).

    Returns
    -------
    FrontSpeed
        The fitted speed, its error and the fitted range.

    Raises
    ------
    ValueError
        Where the event has fewer than 3 moved blocks in the range, or they first moved at one time.

    Examples
    --------
    >>> import pandas as pd
    >>> from stickslip.analysis.stats.statistics import front_speed
    >>> fm = pd.DataFrame({"event": 0, "block": range(1, 21), "t_first": [i / 1.43 for i in range(1, 21)]})
    >>> round(front_speed(fm, 0).speed, 9), front_speed(fm, 0).i_min
    (1.43, 10)
    """
    rows = first_move[(first_move["event"] == event) & np.isfinite(first_move["t_first"])]
    if rows.empty:
        raise ValueError(f"event {event} has no first-move times")
    blocks = rows["block"].to_numpy(dtype=np.int64)
    times = rows["t_first"].to_numpy(dtype=np.float64)
    i_far = int(blocks.max())
    lo = int(math.ceil(i_far / 2)) if i_min is None else int(i_min)
    hi = i_far if i_max is None else int(i_max)
    use = (blocks >= lo) & (blocks <= hi)
    n = int(use.sum())
    if n < 3:
        raise ValueError(f"event {event}: need at least 3 moved blocks in [{lo}, {hi}] (got {n})")
    t0 = float(times.min())
    t = times[use] - t0
    i = blocks[use].astype(np.float64)
    if np.ptp(t) == 0.0:
        raise ValueError(f"event {event}: the blocks in [{lo}, {hi}] first moved at one time: no speed")
    fit = stats.linregress(t, i)  # least squares; stderr = sqrt(s^2 / sum (t - mean t)^2)
    residual = i - (fit.intercept + fit.slope * t)
    return FrontSpeed(
        event=int(event),
        speed=float(fit.slope),
        speed_err=float(fit.stderr),
        intercept=float(fit.intercept),
        t_start=t0,
        i_min=lo,
        i_max=hi,
        n_blocks=n,
        rms=float(np.sqrt(np.mean(residual**2))),
    )


@dataclass(frozen=True)
class EdgeSpeed:
    """Speed of the leading edge of the Delta x_i windows of one event, as the paper reads Fig. 6
    (:func:`leading_edge_speed`).

    For each stored window (Delta x_i = x_i(t + Delta t) - x_i(t)) the edge is the farthest block
    whose Delta x_i is at least ``edge_fraction`` of that window's largest Delta x_i. The speed is
    the least-squares slope of edge against time over the windows whose edge lies in
    [i_min, i_max) (the far half, as :func:`front_speed`; a window whose edge has reached i_max is
    left out: it only says the front got there within the window, and so are the windows after it).

    Attributes
    ----------
    event : int
        The event's number.
    speed : float
        The slope, blocks per time unit.
    speed_err : float
        Its standard error (NaN with 2 windows).
    i_min : int
        The lowest edge fitted.
    i_max : int
        The edge at which the fit stops (left out).
    n_windows : int
        Windows fitted.
    edge_fraction : float
        The share of a window's largest Delta x_i that marks its edge.
    edges : tuple
        The edge of every window.
    times : tuple
        The end time of every window.
    """

    event: int
    speed: float
    speed_err: float
    i_min: int
    i_max: int
    n_windows: int
    edge_fraction: float
    edges: tuple[int, ...]
    times: tuple[float, ...]

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def leading_edge_speed(
    profiles: xr.Dataset,
    event: int,
    *,
    edge_fraction: float = 0.05,
    i_min: int | None = None,
    i_max: int | None = None,
) -> EdgeSpeed:
    """Rupture-front speed of one event from the leading edge of its Delta x_i windows (Fig. 6).

    Parameters
    ----------
    profiles : xarray.Dataset
        The run's stored windows (``ChainRun.profiles``: dim ``profile_row`` with
        ``profile_event``, ``profile_t`` (window start), optionally ``profile_t_next`` (window
        end), ``profile_dx(profile_row, block)``).
    event : int
        The event's number.
    edge_fraction : float
        The share of a window's largest Delta x_i that marks its edge.
    i_min, i_max : int, optional
        The range of edges fitted (default the far half of the blocks the event reached,
        i_min = ceil(i_far / 2), i_max = i_far, i_far the farthest edge).

    Returns
    -------
    EdgeSpeed
        The speed, its error and every window's edge.

    Raises
    ------
    ValueError
        Where the event has no stored windows, or fewer than two with the edge in range.
    """
    rows = np.flatnonzero(profiles["profile_event"].values == event)
    if rows.size == 0:
        raise ValueError(f"no displacement profiles stored for event {event}")
    sub = profiles.isel(profile_row=rows)
    order = np.argsort(sub["profile_t"].values, kind="stable")
    dx = sub["profile_dx"].transpose("profile_row", "block").values[order]
    blocks = sub["block"].values if "block" in sub.coords else np.arange(1, dx.shape[1] + 1)
    has_end = "profile_t_next" in sub.coords
    t_end = (sub["profile_t_next"] if has_end else sub["profile_t"]).values[order]
    if not has_end or np.all(t_end == sub["profile_t"].values[order]):
        # window ends: the next window's start, the last one as long as the one before it
        starts = sub["profile_t"].values[order]
        width = float(np.median(np.diff(starts))) if starts.size > 1 else 0.0
        t_end = np.append(starts[1:], starts[-1] + width)
    edges = np.zeros(dx.shape[0], dtype=np.int64)
    for k in range(dx.shape[0]):
        peak = float(np.nanmax(dx[k])) if np.isfinite(dx[k]).any() else 0.0
        moved = np.flatnonzero(dx[k] >= edge_fraction * peak) if peak > 0 else np.array([], dtype=int)
        edges[k] = int(blocks[moved.max()]) if moved.size else 0
    i_far = int(edges.max())
    lo = int(math.ceil(i_far / 2)) if i_min is None else int(i_min)
    hi = i_far if i_max is None else int(i_max)
    # only the advance: windows before the edge first reaches its farthest block
    advancing = np.arange(edges.size) < int(np.argmax(edges))
    use = advancing & (edges >= lo) & (edges < hi)
    n = int(use.sum())
    if n < 2:
        raise ValueError(f"event {event}: need at least 2 windows with the edge in [{lo}, {hi}) (got {n})")
    t, i = t_end[use], edges[use].astype(np.float64)
    fit = stats.linregress(t - t[0], i)  # window ends differ: the edge advances in time
    return EdgeSpeed(
        event=int(event),
        speed=float(fit.slope),
        speed_err=float(fit.stderr) if n > 2 else math.nan,  # two windows fix a line, not its error
        i_min=lo,
        i_max=hi,
        n_windows=n,
        edge_fraction=float(edge_fraction),
        edges=tuple(int(e) for e in edges),
        times=tuple(float(x) for x in t_end),
    )


@dataclass(frozen=True)
class CentralInterval:
    """Where a stated value lies in a per-event distribution (Fig. 6: the paper's c = 1.43;
    :func:`central_interval`).

    Attributes
    ----------
    value : float
        The stated value.
    level : float
        The share of the sample the interval holds.
    lo : float
        Lower bound of the central ``level`` of the sample (the 5th percentile for 0.9).
    hi : float
        Upper bound (the 95th percentile for 0.9).
    inside : bool
        lo <= value <= hi.
    percentile : float
        The share of the sample below ``value`` (ties count half), in percent.
    median : float
        The sample's median.
    quartiles : tuple of float
        Its first and third quartiles.
    n : int
        Its finite values.
    """

    value: float
    level: float
    lo: float
    hi: float
    inside: bool
    percentile: float
    median: float
    quartiles: tuple[float, float]
    n: int

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def central_interval(sample: Any, value: float, *, level: float = 0.9) -> CentralInterval:
    """Is ``value`` inside the central ``level`` of ``sample`` (Fig. 6's row), and at which percentile.

    Parameters
    ----------
    sample : array_like
        Per-event values (front speeds); NaN are left out.
    value : float
        The stated value (the paper's c = 1.43).
    level : float
        The share of the sample the interval holds, in (0, 1).

    Returns
    -------
    CentralInterval
        The interval, whether ``value`` lies in it, and its percentile.

    Examples
    --------
    >>> from stickslip.analysis.stats.statistics import central_interval
    >>> c = central_interval(range(1, 101), 50.5)
    >>> c.inside, c.percentile
    (True, 50.0)
    """
    x = np.asarray(sample, dtype=np.float64)
    x = x[np.isfinite(x)]
    if x.size == 0:
        raise ValueError("empty sample")
    if not 0.0 < level < 1.0:
        raise ValueError(f"level must lie in (0, 1) (got {level!r})")
    tail = (1.0 - level) / 2.0
    lo, hi = (float(q) for q in np.quantile(x, [tail, 1.0 - tail]))
    pct = stats.percentileofscore(x, value, kind="mean")  # ties count half
    q1, q3 = (float(q) for q in np.quantile(x, [0.25, 0.75]))
    return CentralInterval(
        value=float(value),
        level=float(level),
        lo=lo,
        hi=hi,
        inside=bool(lo <= value <= hi),
        percentile=float(pct),
        median=float(np.median(x)),
        quartiles=(q1, q3),
        n=int(x.size),
    )


def pick_front_events(events: pd.DataFrame, N: int, *, intermediate: tuple[float, float] = (0.3, 0.7)) -> pd.DataFrame:
    """One large and one intermediate event for the rupture-front figure (Fig. 6).

    Large: the largest-S event whose rupture reached block N (the paper's event near t = 19100).
    Intermediate: among events whose farthest moved block lies in ``intermediate`` * N, the one
    closest to N/2 (the paper's event near t = 40400).

    Parameters
    ----------
    events : pandas.DataFrame
        The event table (``S``, ``max_block``).
    N : int
        Blocks of the chain.
    intermediate : tuple of float
        The range of an intermediate event's farthest block, as fractions of N.

    Returns
    -------
    pandas.DataFrame
        The chosen rows of ``events`` with a ``kind`` column ("large", "intermediate"); a kind
        with no candidate is left out.
    """
    chosen = []
    reached = events[events["max_block"] >= N]
    if not reached.empty:
        chosen.append(reached.loc[[reached["S"].idxmax()]].assign(kind="large"))
    lo, hi = intermediate[0] * N, intermediate[1] * N
    middle = events[(events["max_block"] >= lo) & (events["max_block"] <= hi)]
    if not middle.empty:
        distance = (middle["max_block"] - N / 2.0).abs()
        chosen.append(middle.loc[[distance.idxmin()]].assign(kind="intermediate"))
    if not chosen:
        return events.iloc[0:0].assign(kind=pd.Series(dtype=str))
    return pd.concat(chosen).reset_index(drop=True)
