"""The slip in the limit V -> 0, eq. (3), and the period law of Fig. 3.

During a slip that starts after a long stick, the pulling point hardly moves, the spring force
starts at Fs and the state variable has recovered to theta = 1. With x' = x - x(t_c):

    M x'' = Fs - K x' - sigma theta - beta v,   theta' = theta (1 - theta) - alpha theta v,

from x' = 0, v = 0, theta = 1 until v returns to 0 at t_e (the paper's eq. (3) has
M = sigma = alpha = 1). The block then sticks with the spring force f_end = Fs - K x'(t_e),
which grows at the rate K V until it reaches Fs again, so the period is

    T(V) = (t_e - t_c) + (Fs - f_end) / (K V),

the paper's T = 1.035 + 3.432 / (K V). :func:`solve_slip_limit` integrates eq. (3) with an
adaptive high-order method and locates v = 0 as an event; :func:`heun_slip_limit` does the same
slip with the fixed-step Heun scheme and stop rule of eq. (1), to show where the paper's third
digit comes from. :func:`period_sweep` runs eq. (1) at several V and sets the simulated periods
beside the law (Fig. 3).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr
from scipy.integrate import solve_ivp

from stickslip.models.params import BlockParams, ParameterError, check_number, steps_for
from stickslip.run.block import BlockState, first_start_time, simulate_block

#: The paper's numbers for eq. (3) at K = 10, beta = 1, Fs = 3 (section 2), for comparison only.
PAPER_DURATION = 1.035
PAPER_FORCE_AT_STOP = -0.432


class NoStopError(ValueError):
    """The block of eq. (3) does not come to rest within the time allowed."""


@dataclass(frozen=True)
class SlipLimit:
    """One slip of eq. (3) and the period law T(V) = a + b / (K V) built from it (Fig. 3).

    ``duration`` = t_e - t_c (= a), ``force_at_stop`` = Fs - K x'(t_e) (the spring force when
    the block stops; b = Fs - force_at_stop), ``slip`` = x'(t_e), ``theta_at_stop`` =
    theta(t_e). ``curve`` holds x', v, theta and f on a time grid from 0 (= t_c) to t_e.
    """

    params: BlockParams
    duration: float
    force_at_stop: float
    slip: float
    theta_at_stop: float
    method: str
    curve: xr.Dataset | None = field(default=None, repr=False, compare=False)
    dense: Any = field(default=None, repr=False, compare=False)

    @property
    def law_a(self) -> float:
        """Constant term of T(V) = a + b / (K V): the slip duration."""
        return self.duration

    @property
    def law_b(self) -> float:
        """Numerator of the stick time b / (K V): the force rise Fs - force_at_stop."""
        return self.params.Fs - self.force_at_stop

    def period(self, V: float | np.ndarray) -> float | np.ndarray:
        """The period law T(V) = (t_e - t_c) + (Fs - f_end) / (K V) of section 2 (Fig. 3)."""
        return self.law_a + self.law_b / (self.params.K * np.asarray(V, dtype=float))

    def at(self, t: np.ndarray) -> dict[str, np.ndarray]:
        """x', v, theta of eq. (3) at times t - t_c in [0, duration] (accurate run only)."""
        if self.dense is None:
            raise ValueError("this SlipLimit has no dense output (solve with dense=True)")
        y = self.dense(np.asarray(t, dtype=float))
        return {"x": y[0], "v": y[1], "theta": y[2]}

    def summary(self) -> dict[str, Any]:
        """The numbers of eq. (3) and the two coefficients of T(V) = a + b / (K V)."""
        return {
            "duration": self.duration,
            "force_at_stop": self.force_at_stop,
            "slip": self.slip,
            "theta_at_stop": self.theta_at_stop,
            "period_law_a": self.law_a,
            "period_law_b": self.law_b,
            "period_law": "T(V) = a + b / (K V)",
            "method": self.method,
        }


def _check_can_slip(p: BlockParams) -> None:
    # The slip starts from v = 0, theta = 1 with M v' = Fs - sigma: it must be pushed forward.
    if not p.Fs > p.sigma:
        raise ParameterError(f"Fs must be > sigma = {p.sigma:g} for a slip of eq. (3) to start (got {p.Fs:g})")


def eq3_rhs(t: float, y: np.ndarray, K: float, beta: float, alpha: float, Fs: float, M: float, sigma: float):
    """Right-hand side of eq. (3) for y = (x', v, theta)."""
    x, v, theta = y
    return [v, (Fs - K * x - sigma * theta - beta * v) / M, theta * (1.0 - theta) - alpha * theta * v]


def solve_slip_limit(
    params: BlockParams | None = None,
    *,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    t_max: float = 1000.0,
    n_points: int = 1001,
    dense: bool = True,
) -> SlipLimit:
    """Integrate eq. (3), the slip in the limit V -> 0, accurately and locate the stop v = 0
    (section 2, Figs. 2 and 3).

    Uses scipy's DOP853 with a terminal event v = 0 crossed downwards (v starts at 0 with
    v' = (Fs - sigma)/M > 0, so the start is not a crossing). V of ``params`` is not used.

    Parameters
    ----------
    params : BlockParams, optional
        The block (default the paper's: K = 10, beta = 1, alpha = 1, Fs = 3).
    rtol, atol : float
        Tolerances of the integrator.
    t_max : float
        Longest slip looked for.
    n_points : int
        Points of the stored curve from the start of the slip to its stop.
    dense : bool
        Keep the curve (x', v, theta, f against t - t_c) and the dense output.

    Returns
    -------
    SlipLimit
        The slip's duration a, the force at the stop and b = Fs - force_at_stop, with
        ``period(V)`` = a + b / (K V), the period law of Fig. 3.

    Raises
    ------
    NoStopError
        If the block has not stopped by ``t_max``.

    Examples
    --------
    >>> from stickslip import BlockParams
    >>> from stickslip.analysis.dynamics.slip_limit import solve_slip_limit
    >>> law = solve_slip_limit(BlockParams(), dense=False)
    >>> print(f"T(V) = {law.law_a:.3f} + {law.law_b:.3f} / (K V)")  # the paper: 1.035 + 3.432 / (K V)
    T(V) = 1.037 + 3.432 / (K V)
    """
    p = BlockParams() if params is None else params
    _check_can_slip(p)
    rtol = check_number("rtol", rtol, low=0.0, low_open=True)
    atol = check_number("atol", atol, low=0.0, low_open=True)
    t_max = check_number("t_max", t_max, low=0.0, low_open=True)
    args = (p.K, p.beta, p.alpha, p.Fs, p.M, p.sigma)

    def stop(t, y, *a):
        return y[1]

    stop.terminal = True
    stop.direction = -1

    sol = solve_ivp(
        eq3_rhs, (0.0, t_max), [0.0, 0.0, 1.0], method="DOP853", args=args,
        rtol=rtol, atol=atol, events=stop, dense_output=dense,
    )  # fmt: skip
    if not sol.success:
        raise NoStopError(f"eq. (3) integration failed: {sol.message}")
    if len(sol.t_events[0]) == 0:
        raise NoStopError(f"the block of eq. (3) does not stop before t = {t_max:g}")
    t_e = float(sol.t_events[0][0])
    x_e, _, theta_e = (float(c) for c in sol.y_events[0][0])
    curve = None
    if dense:
        t = np.linspace(0.0, t_e, int(check_number("n_points", n_points, low=2, integer=True)))
        y = sol.sol(t)
        y[1, -1] = 0.0  # the event's v is zero to within the tolerance; show it as the stop
        curve = _curve(p, t, y[0], y[1], y[2], "eq. (3), DOP853 with event location")
    return SlipLimit(
        params=p,
        duration=t_e,
        force_at_stop=p.Fs - p.K * x_e,
        slip=x_e,
        theta_at_stop=theta_e,
        method=f"DOP853 rtol={rtol:g} atol={atol:g}, event v = 0",
        curve=curve,
        dense=sol.sol if dense else None,
    )


def heun_slip_limit(params: BlockParams | None = None, *, dt: float | None = None, t_max: float = 1000.0) -> SlipLimit:
    """Eq. (3) with the Heun step and stop rule of eq. (1) at step ``dt`` (default params.dt).

    This is eq. (1) at V = 0 started moving with v = 0, theta = 1 and spring force Fs
    (x = -Fs/K), run until the stop rule fires: what a fixed-step run of the paper reports for
    eq. (3). Its t_e is a whole number of steps.
    """
    p = BlockParams() if params is None else params
    _check_can_slip(p)
    if dt is not None:
        p = p.replace(dt=dt)
    t_max = check_number("t_max", t_max, low=0.0, low_open=True)
    p0 = p.replace(V=0.0)
    start = BlockState(x=-p.Fs / p.K, v=0.0, theta=1.0, stopped=False)
    # The slip lasts a few time units; grow the window until the stop is inside it.
    window = 8.0
    while True:
        run = simulate_block(p0, min(window, t_max), initial=start)
        if run.n_stops:
            break
        if window >= t_max:
            raise NoStopError(f"the block of eq. (3) does not stop before t = {t_max:g}")
        window *= 4.0
    s = run.series
    i = int(np.argmax(s["stopped"].values))
    xs = s["x"].values[: i + 1] - start.x
    f = p.Fs - p.K * xs
    curve = _curve(p, s["t"].values[: i + 1], xs, s["v"].values[: i + 1], s["theta"].values[: i + 1],
                   f"eq. (3), Heun dt={p.dt:g} with the stop rule of eq. (1)", f=f)  # fmt: skip
    return SlipLimit(
        params=p,
        duration=float(s["t"].values[i]),
        force_at_stop=float(f[-1]),
        slip=float(xs[-1]),
        theta_at_stop=float(s["theta"].values[i]),
        method=f"Heun dt={p.dt:g}, stop rule v <= 0 at the end of a step",
        curve=curve,
    )


def _curve(p: BlockParams, t, x, v, theta, method: str, f=None) -> xr.Dataset:
    f = p.Fs - p.K * np.asarray(x) if f is None else f
    return xr.Dataset(
        {
            "x": ("t", np.asarray(x), {"long_name": "x' = x - x(t_c)"}),
            "v": ("t", np.asarray(v), {"long_name": "velocity v"}),
            "theta": ("t", np.asarray(theta), {"long_name": "state variable theta"}),
            "f": ("t", np.asarray(f), {"long_name": "spring force Fs - K x'"}),
        },
        coords={"t": ("t", np.asarray(t), {"long_name": "time since the start of the slip t - t_c"})},
        attrs={
            "method": method,
            **{f"param_{k}": val if isinstance(val, str) else float(val) for k, val in p.to_dict().items()},
        },
    )


def matches_paper(params: BlockParams) -> bool:
    """Whether eq. (3) at these parameters is the paper's case (K = 10, beta = 1, Fs = 3)."""
    d = BlockParams()
    return all(math.isclose(getattr(params, k), getattr(d, k)) for k in ("K", "beta", "alpha", "Fs", "M", "sigma"))


def period_sweep(
    params: BlockParams,
    V_values: Iterable[float],
    *,
    periods: int = 4,
) -> pd.DataFrame:
    """Simulated stick-slip period of eq. (1) at several pulling velocities V (Fig. 3).

    Each V is run from the paper's initial state to the first slip plus ``periods`` + 1/2 periods
    of the law T(V) of eq. (3) (:func:`solve_slip_limit`); the period is the mean of the slip
    table's ``period`` over the slips after the first.

    Parameters
    ----------
    params : BlockParams
        The block; its V is replaced by each of ``V_values``.
    V_values : iterable of float
        Pulling velocities, each > 0.
    periods : int
        Periods of the law simulated after the first slip.

    Returns
    -------
    pandas.DataFrame
        One row per V: ``V``, the simulated ``period`` and ``period_std``, ``n_periods``
        averaged, the law's ``period_law`` T(V), ``rel_dev`` = period / T(V) - 1,
        ``slip_duration`` and ``force_at_stop``.
    """
    periods = int(check_number("periods", periods, low=1, integer=True))
    V_values = [float(check_number("V", V, low=0.0, low_open=True)) for V in V_values]
    law = solve_slip_limit(params, dense=False)
    rows = []
    for V in V_values:
        p = params.replace(V=V)
        T = law.period(V)
        t_end = first_start_time(p) + (periods + 0.5) * T
        steps = steps_for(t_end, p.dt, "t_end")
        run = simulate_block(p, t_end, every=max(1, steps))
        s = run.summary()
        rows.append(
            {
                "V": V,
                "period": s["period"],
                "period_std": s["period_std"],
                "n_periods": max(0, s["events"] - 1),
                "period_law": T,
                "rel_dev": s["period"] / T - 1.0,
                "slip_duration": s["slip_duration"],
                "force_at_stop": s["force_at_stop"],
            }
        )
    return pd.DataFrame(rows)


def paper_V_values(n: int = 13, low: float = 1e-3, high: float = 1e-1) -> np.ndarray:
    """Pulling velocities for Fig. 3: ``n`` values evenly spaced in log V from ``low`` to ``high``."""
    n = int(check_number("n", n, low=2, integer=True))
    return np.logspace(math.log10(low), math.log10(high), n)
