"""The single block and spring of section 2: runs of eq. (1) and their slips.

A run starts at t = 0 from a :class:`BlockState` and advances eq. (1) as the chain of eq. (4) at
N = 1 (docs/model.md): the chain's reference kernel :func:`stickslip.kernels.dense.run_dense`
with the drive ``end`` (the pulling point V t and the spring K), the block's friction and threshold
pieces (with eq. (1)'s sigma), its mass M and free ends, so the block, the chain and every law
share one Heun step and one pair of start and stop rules. The chain's events are the slips; the
kernel's trace keeps the series. It returns a
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

from stickslip.kernels import layout
from stickslip.kernels.dense import run_dense
from stickslip.kernels.entry import specialise
from stickslip.models.params import BlockParams, ParameterError, check_number, steps_for
from stickslip.models.pieces import piece

INTEGRATOR = "heun (explicit trapezoid, fixed dt) with the start/stop rules of docs/model.md"

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
    chain = _Chain1(params, initial, steps, every)
    chain.run()
    x, v, theta, stopped = chain.state()
    if not (np.isfinite(x) and np.isfinite(v) and np.isfinite(theta)):
        _blow_up(params, chain.bad_step())
    t, xs, vs, ths, stops = chain.series(steps)
    series = _series(params, t, xs, vs, ths, stops, every)
    n_c, n_e, x_c, x_e = chain.slips()
    slips = _slip_table(params, n_c, n_e, x_c, x_e)
    v_min, v_max = chain.trace.v_range
    return BlockRun(
        params=params,
        series=series,
        slips=slips,
        final=BlockState(x=x, v=v, theta=theta, stopped=stopped),
        steps=steps,
        every=every,
        v_min=float(v_min),
        v_max=float(v_max),
        n_stops=chain.n_stops(),
        n_starts=chain.n_starts(),
        initial=initial,
    )


def chain_pieces(p: BlockParams) -> tuple[str, str, str, str]:
    """eq. (1) as the chain of eq. (4) at N = 1: what the chain's kernels are compiled for (drive,
    friction, threshold, ends; :func:`stickslip.models.pieces.code`). The pulling point V t is
    joined to the block by the spring K (drive ``end``), no spring beyond it (ends ``free``), and
    the block's friction and threshold are the chain's pieces."""
    from stickslip.models.pieces import code

    return (code("drive", "end"), p.friction_piece.module, p.threshold_piece.module, code("ends", "free"))


def _sigma(kernel_params: tuple, sigma: float) -> tuple:
    """A piece's kernel parameters with eq. (1)'s sigma where the piece reads one (its optional
    field: sigma theta + beta v, and the threshold sigma theta)."""
    return kernel_params._replace(sigma=float(sigma)) if "sigma" in kernel_params._fields else kernel_params


class _Chain1:
    """The arrays of one run of the chain's reference kernel at N = 1 for eq. (1)
    (:func:`stickslip.kernels.dense.run_dense`, its ``trace`` keeping the series): its events are
    the slips, their first and last profile rows the block's position at t_c and t_e."""

    def __init__(self, p: BlockParams, s: BlockState, steps: int, every: int):
        self.p, self.initial, self.steps = p, s, steps
        # A slip takes at least one step: room for one per 1000 steps, emptied when full.
        cap = max(16, steps // 1000)
        ist = np.zeros(layout.IST_SIZE, dtype=np.int64)
        ist[layout.N_MOVING] = 0 if s.stopped else 1
        ist[layout.NEXT_SAMPLE] = layout._NEVER
        ist[layout.NEXT_PROFILE] = layout._NEVER
        self.ist = ist
        rows = steps // every
        self.trace = layout.Trace(
            np.int64(every),
            np.empty((rows, 1)),
            np.empty((rows, 1)),
            np.empty((rows, 1)),
            np.empty((rows, 1)),
            np.empty(rows, dtype=np.int64),
            np.array([0, every], dtype=np.int64),
            np.array([s.v, s.v]),
        )
        state = [np.array([0.0, value, 0.0]) for value in (s.x, s.v, s.theta, 0.0 if s.stopped else 1.0)]
        law, thr = p.friction_piece, p.threshold_piece
        self.args = layout.ChainArgs(
            *state,
            *(np.zeros(3) for _ in range(6)),
            np.zeros(3, dtype=np.int64),
            np.full(3, -1, dtype=np.int64),
            np.zeros(3),
            ist,
            np.array([p.K, p.V, p.dt]),
            piece("drive", "end").kernel_params(p),
            _sigma(thr.kernel_params(p), p.sigma),
            _sigma(law.kernel_params(p), p.sigma),
            None,
            float(p.M),  # a / M, as eq. (1) reads it (a / 1.0 is a): one kernel for every M
            np.zeros((cap, layout.EV_INT_COLS), dtype=np.int64),
            np.zeros(cap),
            np.zeros((cap + 1, 3), dtype=np.int64),
            np.zeros(1),
            np.zeros(1, dtype=np.int64),
            np.zeros(1, dtype=np.int64),
            np.zeros((2 * cap + 2, 1)),
            np.zeros((2 * cap + 2, 2), dtype=np.int64),
            np.int64(steps),
            np.int64(1),
            np.int64(1) << np.int64(62),  # profile rows at an event's start and end only
            np.int64(1),
            np.int64(0),
            self.trace,
        )
        self.pieces = chain_pieces(p)
        self.events: list[np.ndarray] = []
        self.rows: list[tuple[np.ndarray, np.ndarray]] = []

    def run(self) -> None:
        """Run the kernel to the last step, emptying the event and profile buffers when full."""
        entry_point = specialise(run_dense, self.args, self.pieces)
        while True:
            status = entry_point(self.args, *self.pieces)
            if status in (layout.EVENTS_FULL, layout.FIRST_MOVES_FULL, layout.PROFILES_FULL):
                self._drain()
                continue
            if status not in (layout.DONE, layout.NONFINITE):
                raise RuntimeError(f"unexpected status {status} of the chain kernel")
            self._drain()
            return

    def _drain(self) -> None:
        a, ist = self.args, self.ist
        self.events.append(a.ev_int[: ist[layout.EV_COUNT]].copy())
        p = ist[layout.P_COUNT]
        self.rows.append((a.prof_x[:p, 0].copy(), a.prof_meta[:p, 0].copy()))
        ist[layout.EV_COUNT] = ist[layout.FM_COUNT] = ist[layout.P_COUNT] = 0

    def state(self) -> tuple[float, float, float, bool]:
        a = self.args
        return float(a.x[1]), float(a.v[1]), float(a.th[1]), bool(a.mov[1] == 0.0)

    def bad_step(self) -> int:
        """The step after which the state was found non-finite."""
        return int(self.ist[layout.STEP])

    def series(self, steps: int):
        """t, x, v, theta and the stop flag at step 0, every ``every``-th step and the last."""
        tr = self.trace
        k = int(tr.count[0])
        x0 = self.initial
        last = [] if k and tr.step[k - 1] == steps or not steps else [steps]
        n = np.concatenate([[0], tr.step[:k], last]).astype(np.int64)
        xf, vf, thf, stf = self.state()

        def column(values, first, final):
            return np.concatenate([[first], values[:k, 0], [final] if last else []])

        mov = column(tr.mov, 0.0 if x0.stopped else 1.0, 0.0 if stf else 1.0)
        t = n * self.p.dt
        return (t, column(tr.x, x0.x, xf), column(tr.v, x0.v, vf), column(tr.th, x0.theta, thf), mov == 0.0)

    def slips(self):
        """Start and end step of each complete slip (the chain's events; t_e = (end + 1) dt) and the
        block's position then (the event's first and last profile rows)."""
        ev = np.concatenate(self.events) if self.events else np.zeros((0, layout.EV_INT_COLS), dtype=np.int64)
        x = np.concatenate([r[0] for r in self.rows]) if self.rows else np.zeros(0)
        eid = np.concatenate([r[1] for r in self.rows]) if self.rows else np.zeros(0, dtype=np.int64)
        first = {}
        last = {}
        for j, e in enumerate(eid.tolist()):
            first.setdefault(e, x[j])
            last[e] = x[j]
        ids = ev[:, layout.E_ID].tolist()
        x_c = np.array([first[e] for e in ids], dtype=float)
        x_e = np.array([last[e] for e in ids], dtype=float)
        return ev[:, layout.E_START_STEP], ev[:, layout.E_END_STEP] + 1, x_c, x_e

    def n_starts(self) -> int:
        """Starts: every event opened (each start of the block's slips)."""
        return int(self.ist[layout.N_EVENTS] + self.ist[layout.EV_ACTIVE])

    def n_stops(self) -> int:
        """Stops: each complete event, and the end of a slip under way at step 0."""
        first = not self.initial.stopped and (self.state()[3] or self.n_starts() > 0)
        return int(self.ist[layout.N_EVENTS]) + int(first)


def _blow_up(p: BlockParams, step: int) -> None:
    """Raise NonFiniteBlock naming the time at which the state was found non-finite."""
    from stickslip.run.errors import NonFiniteBlock

    raise NonFiniteBlock(
        f"the block's state became non-finite by t = {step * p.dt:.6g} (blow-up; a smaller dt may "
        f"help, dt = {p.dt:g}, K/M = {p.K / p.M:g})"
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
