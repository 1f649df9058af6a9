"""The single block and spring of section 2: runs of eq. (1) and their slips.

A run starts at t = 0 from a :class:`BlockState` and advances eq. (1) with the compiled Heun
step of :mod:`stickslip.kernels.block` (start and stop rules of docs/model.md). It returns a
:class:`BlockRun`: the time series as an xarray Dataset, the table of slips as a pandas
DataFrame, the final state and a few statistics gathered over every step. The period sweep of
Fig. 3 is :func:`stickslip.analysis.dynamics.slip_limit.period_sweep`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from stickslip.kernels.block import heun_block
from stickslip.kernels.entry import specialise_call
from stickslip.models.params import BlockParams, ParameterError, check_number, steps_for

INTEGRATOR = "heun (explicit trapezoid, fixed dt) with the start/stop rules of docs/model.md"

#: The positions of the friction law and the threshold among heun_block's arguments (compiled
#: as literals).
LAW_ARG = frozenset({8, 10})

SLIP_COLUMNS = ("t_c", "t_e", "duration", "slip", "force_at_stop", "period")


@dataclass(frozen=True)
class BlockState:
    """State of the block, eq. (1): position x, velocity v, state variable theta, stick flag.

    The default is the paper's initial condition x(0) = 0, v(0) = 0, theta(0) = 0.1, with the
    block at rest, i.e. stopped (it starts when the spring force exceeds Fs). A stopped block
    has v = 0.
    """

    x: float = 0.0
    v: float = 0.0
    theta: float = 0.1
    stopped: bool = True

    def __post_init__(self) -> None:
        object.__setattr__(self, "x", float(check_number("x", self.x)))
        object.__setattr__(self, "v", float(check_number("v", self.v)))
        object.__setattr__(self, "theta", float(check_number("theta", self.theta, low=0.0)))
        object.__setattr__(self, "stopped", bool(self.stopped))
        if self.stopped and self.v != 0.0:
            raise ParameterError(f"v must be 0 for a stopped block (got {self.v!r})")


@dataclass(frozen=True)
class BlockRun:
    """A run of eq. (1) from t = 0 to t_end (Figs. 1-3).

    - ``series``: Dataset over coordinate t with x, v, theta, f = K (V t - x) and stopped, at
      every ``every``-th step including step 0 and the last step;
    - ``slips``: one row per slip that starts and ends inside the run, columns
      t_c (start time: start of the step whose start rule fired), t_e (end time: end of the step
      whose stop rule fired), duration = t_e - t_c, slip = x(t_e) - x(t_c),
      force_at_stop = f(t_e) = K (V t_e - x(t_e)) (the spring force left when the block stops;
      in the limit V -> 0 it is the paper's Fs - K x' of eq. (3)), and period = t_c minus the
      previous slip's t_c (NaN for the first);
    - ``final``: the state at t_end; ``steps``: number of Heun steps;
    - ``v_min``, ``v_max``, ``n_stops``, ``n_starts``: over every step, stored or not
      (``n_stops`` counts every moving -> stopped transition).
    """

    params: BlockParams
    series: xr.Dataset
    slips: pd.DataFrame
    final: BlockState
    steps: int
    every: int
    v_min: float
    v_max: float
    n_stops: int
    n_starts: int
    initial: BlockState = field(default_factory=BlockState)

    @property
    def t_end(self) -> float:
        """End time t_n of the run (n = steps)."""
        return self.steps * self.params.dt

    def restart_state(self) -> BlockState:
        """The final state shifted so that a new run from t = 0 continues this one.

        A run's time starts at 0 and its spring force is f = K (V t - x); shifting x by
        -V t_end keeps f (and so the dynamics) continuous, also when the next run uses another V.
        """
        f = self.final
        return BlockState(x=f.x - self.params.V * self.t_end, v=f.v, theta=f.theta, stopped=f.stopped)

    def summary(self) -> dict[str, Any]:
        """Numbers of the run: slips, mean period, duration and force at stop (section 2).

        ``period``, ``slip_duration``, ``force_at_stop`` and ``slip`` are means over the slips
        after the first (the first starts from the initial transient); NaN when there are none.
        """
        later = self.slips.iloc[1:]
        return {
            "events": int(len(self.slips)),
            "period": _mean(later["period"]),
            "period_std": _std(later["period"]),
            "slip_duration": _mean(later["duration"]),
            "force_at_stop": _mean(later["force_at_stop"]),
            "slip": _mean(later["slip"]),
            "n_starts": self.n_starts,
            "n_stops": self.n_stops,
            "v_min": self.v_min,
            "v_max": self.v_max,
            "t_end": self.t_end,
            "steps": self.steps,
            "every": self.every,
            "dt": self.params.dt,
        }


def _mean(values: pd.Series) -> float:
    return float(values.mean()) if len(values) else math.nan


def _std(values: pd.Series) -> float:
    return float(values.std(ddof=0)) if len(values) else math.nan


def n_samples(steps: int, every: int) -> int:
    """Length of a series that keeps steps 0, every, 2 every, ... and the last step."""
    return steps // every + 1 + (1 if steps % every else 0)


def simulate_block(
    params: BlockParams,
    t_end: float,
    *,
    initial: BlockState | None = None,
    every: int = 1,
) -> BlockRun:
    """Integrate eq. (1) from t = 0 to t_end with Heun's method and the start/stop rules.

    The paper's run (Fig. 1) is ``simulate_block(BlockParams(), t_end)``: K = 10, V = 0.001,
    Fs = 3, dt = 0.005 from x = v = 0, theta = 0.1. The number of steps is t_end / dt rounded to
    the nearest integer; ``every`` > 1 keeps every ``every``-th state in ``series`` (the
    statistics and the slip table still see every step). To go on from a run with another V,
    pass ``initial=run.restart_state()``.

    Parameters
    ----------
    params : BlockParams
        The block's parameters (the paper's by default).
    t_end : float
        End time, in the model's time units.
    initial : BlockState, optional
        The start (default x = v = 0, theta = 0.1, stuck).
    every : int
        Keep every ``every``-th state in ``series``.

    Returns
    -------
    BlockRun
        ``series`` (x, v, theta, f over t), ``slips`` (one row per slip: t_c, t_e, duration,
        slip, force_at_stop, period), ``final`` and counts.

    Examples
    --------
    >>> from stickslip import BlockParams, simulate_block
    >>> run = simulate_block(BlockParams(), 5000.0, every=100)
    >>> len(run.slips), round(float(run.slips["period"].iloc[-1]), 3)
    (14, 344.14)
    """
    if not isinstance(params, BlockParams):
        raise TypeError("params must be a BlockParams")
    initial = BlockState() if initial is None else initial
    every = int(check_number("every", every, low=1, integer=True))
    steps = steps_for(t_end, params.dt, "t_end")
    n_out = n_samples(steps, every)

    out_t = np.empty(n_out)
    out_x = np.empty(n_out)
    out_v = np.empty(n_out)
    out_theta = np.empty(n_out)
    out_stopped = np.empty(n_out, dtype=np.bool_)

    # A slip takes at least one step; start with room for one per 1000 steps and run again
    # with exact room in the rare case (fast chatter) that this is not enough.
    capacity = max(16, steps // 1000)
    while True:
        slip_start = np.empty(capacity, dtype=np.int64)
        slip_end = np.empty(capacity, dtype=np.int64)
        slip_x_start = np.empty(capacity)
        slip_x_end = np.empty(capacity)
        law, thr = params.friction_piece, params.threshold_piece
        args = (
            initial.x, initial.v, initial.theta, initial.stopped, steps, every,
            params.K, params.V, law.module, law.kernel_params(params), thr.module, thr.kernel_params(params),
            params.M, params.sigma, params.dt,
            out_t, out_x, out_v, out_theta, out_stopped,
            slip_start, slip_end, slip_x_start, slip_x_end,
        )  # fmt: skip
        (x, v, theta, stopped, n_slips, n_starts, n_stops, v_min, v_max) = specialise_call(heun_block, args, LAW_ARG)
        if n_slips <= capacity:
            break
        capacity = n_slips
    if not (np.isfinite(x) and np.isfinite(v) and np.isfinite(theta)):
        _blow_up(params, out_t, out_x, out_v, out_theta, steps)

    series = _series(params, out_t, out_x, out_v, out_theta, out_stopped, every)
    slips = _slip_table(params, slip_start[:n_slips], slip_end[:n_slips], slip_x_start[:n_slips], slip_x_end[:n_slips])
    final = BlockState(x=x, v=v, theta=theta, stopped=bool(stopped))
    return BlockRun(
        params=params,
        series=series,
        slips=slips,
        final=final,
        steps=steps,
        every=every,
        v_min=float(v_min),
        v_max=float(v_max),
        n_stops=int(n_stops),
        n_starts=int(n_starts),
        initial=initial,
    )


def _blow_up(p: BlockParams, t, x, v, theta, steps: int) -> None:
    """Raise NonFiniteBlock naming the first stored time with a non-finite state."""
    from stickslip.run.errors import NonFiniteBlock

    bad = ~(np.isfinite(x) & np.isfinite(v) & np.isfinite(theta))
    when = f"t = {float(t[np.argmax(bad)]):.6g}" if bad.any() else f"t <= {steps * p.dt:.6g}"
    raise NonFiniteBlock(
        f"the block's state became non-finite by {when} (blow-up; a smaller dt may help, "
        f"dt = {p.dt:g}, K/M = {p.K / p.M:g})"
    )


def _series(p: BlockParams, t, x, v, theta, stopped, every: int) -> xr.Dataset:
    f = p.K * (p.V * t - x)
    attrs = {f"param_{k}": val if isinstance(val, str) else float(val) for k, val in p.to_dict().items()}
    attrs.update(integrator=INTEGRATOR, every=int(every), model="eq. (1), single block")
    return xr.Dataset(
        {
            "x": ("t", x, {"long_name": "block position x"}),
            "v": ("t", v, {"long_name": "block velocity v = dx/dt"}),
            "theta": ("t", theta, {"long_name": "state variable theta"}),
            "f": ("t", f, {"long_name": "spring force f = K (V t - x)"}),
            "stopped": ("t", stopped, {"long_name": "block stopped (sticking)"}),
        },
        coords={"t": ("t", t, {"long_name": "time t_n = n dt"})},
        attrs=attrs,
    )


def _slip_table(p: BlockParams, n_c, n_e, x_c, x_e) -> pd.DataFrame:
    t_c = n_c * p.dt
    t_e = n_e * p.dt
    period = np.full(len(t_c), np.nan)
    period[1:] = np.diff(t_c)
    return pd.DataFrame(
        {
            "t_c": t_c,
            "t_e": t_e,
            "duration": t_e - t_c,
            "slip": x_e - x_c,
            "force_at_stop": p.K * (p.V * t_e - x_e),
            "period": period,
        },
        columns=list(SLIP_COLUMNS),
    )


def first_start_time(params: BlockParams, initial: BlockState | None = None) -> float:
    """Time at which the spring force of a stopped block reaches Fs: (Fs/K + x0) / V (section 2)."""
    initial = BlockState() if initial is None else initial
    if params.V <= 0.0:
        return math.inf
    return max(0.0, (params.Fs / params.K + initial.x) / params.V)
