"""The subcritical transition of the single block: an adiabatic sweep of V up and down (section 2).

The paper: with beta = 1, Fs = 3, K = 10 steady sliding is linearly stable at every V > 0
(eq. 2), yet stick-slip persists up to V = 0.345 "as V is slowly increased", where the block
goes over to steady sliding. This module raises V step by step from V_min to V_max and lowers
it back, carrying the state over from one V to the next, and records at each V whether the
block still sticks and the range of its velocity: a bifurcation diagram with its hysteresis.

Carrying the state over. A run of :func:`stickslip.run.block.simulate_block` starts at t = 0 with
spring force f = K (V t - x). At the end of a segment of length t_seg the pulling point is at
V_old t_seg; the next segment starts from x_new = x - V_old t_seg (with v, theta and the stick
flag unchanged), so f, and with it the whole state, is continuous across the change of V
(:meth:`stickslip.run.block.BlockRun.restart_state`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from stickslip.models.params import BlockParams, ParameterError, check_number, steps_for

if TYPE_CHECKING:  # the engine and xarray load where a sweep runs (`stickslip --help` reads the defaults)
    import xarray as xr

    from stickslip.run.block import BlockState

#: Defaults of the sweep. The range holds the paper's V = 0.345; 400 time units per value of
#: V is about 160 stick-slip periods near V = 0.3 (T ~ 2.4), long enough for the transient
#: after each change of V to die out (see docs/stability.md for the convergence check).
DEFAULT_V_MIN = 0.25
DEFAULT_V_MAX = 0.45
DEFAULT_DV = 0.005
DEFAULT_TIME_PER_STEP = 400.0
DEFAULT_TRANSIENT = 0.5
MAX_V_STEPS = 20000


@dataclass(frozen=True)
class SweepSettings:
    """The protocol of the adiabatic sweep (section 2), validated when built.

    V goes V_min, V_min + dV, ..., V_max and back down to V_min; each value is held for
    ``time_per_step`` time units, of which the first fraction ``transient`` is discarded and the
    rest measured.
    """

    V_min: float = DEFAULT_V_MIN
    V_max: float = DEFAULT_V_MAX
    dV: float = DEFAULT_DV
    time_per_step: float = DEFAULT_TIME_PER_STEP
    transient: float = DEFAULT_TRANSIENT

    def __post_init__(self) -> None:
        for name, kw in (
            ("V_min", {"low": 0.0, "low_open": True}),
            ("V_max", {"low": 0.0, "low_open": True}),
            ("dV", {"low": 0.0, "low_open": True}),
            ("time_per_step", {"low": 0.0, "low_open": True}),
            ("transient", {"low": 0.0, "high": 1.0, "high_open": True}),
        ):
            object.__setattr__(self, name, float(check_number(name, getattr(self, name), **kw)))
        if self.V_max <= self.V_min:
            raise ParameterError(f"V_max must be > V_min (got V_min={self.V_min:g}, V_max={self.V_max:g})")
        if self.dV > self.V_max - self.V_min:
            raise ParameterError(f"dV must be <= V_max - V_min (got dV={self.dV:g})")
        if self.n_values > MAX_V_STEPS:
            raise ParameterError(f"(V_max - V_min)/dV must be <= {MAX_V_STEPS} (got {self.n_values - 1})")

    @property
    def n_values(self) -> int:
        """Number of values of V on the way up (V_min and the last grid point <= V_max)."""
        return int(math.floor((self.V_max - self.V_min) / self.dV + 1e-9)) + 1

    def V_grid(self) -> np.ndarray:
        """The values of V on the way up, V_min + j dV (rounded to 12 digits against drift)."""
        return np.round(self.V_min + self.dV * np.arange(self.n_values), 12)

    def to_dict(self) -> dict[str, float]:
        return {
            "V_min": self.V_min,
            "V_max": self.V_max,
            "dV": self.dV,
            "time_per_step": self.time_per_step,
            "transient": self.transient,
        }


@dataclass(frozen=True)
class HysteresisResult:
    """The sweep of section 2: per V and direction, whether the block sticks and its v range.

    ``data`` is a Dataset over (direction = up, down; V) with ``stuck`` (a stop in the measured
    part), ``n_stops``, ``v_min``, ``v_max`` and ``period`` (mean time between slip starts in the
    measured part, NaN without two slips). ``V_up`` is the first V going up where the block no
    longer sticks (None if it sticks all the way, or never stuck); ``V_down`` the first V going
    down where it sticks again (None if never in range).
    """

    params: BlockParams
    settings: SweepSettings
    data: xr.Dataset
    V_up: float | None
    V_down: float | None

    def summary(self) -> dict:
        """The numbers of the sweep as a plain dict (JSON-able)."""
        from stickslip.run.block import INTEGRATOR

        return {
            "V_up": self.V_up,
            "V_down": self.V_down,
            "hysteresis_width": None if self.V_up is None or self.V_down is None else self.V_up - self.V_down,
            "params": {k: v for k, v in self.params.to_dict().items() if k != "V"},
            "sweep": self.settings.to_dict(),
            "n_values": self.settings.n_values,
            "integrator": INTEGRATOR,
        }


def _no_series(p: BlockParams, t: float, name: str) -> int:
    """An ``every`` that keeps only the first and last state (the statistics see every step)."""
    return max(1, steps_for(t, p.dt, name))


def _hold(params: BlockParams, V: float, settings: SweepSettings, state: BlockState) -> tuple[dict, BlockState]:
    """Hold V for one step of the sweep: discard the transient, measure the rest."""
    from stickslip.run.block import simulate_block

    p = params.replace(V=float(V))
    t_transient = settings.transient * settings.time_per_step
    t_measure = settings.time_per_step - t_transient
    if t_transient > 0.0:
        transient = simulate_block(p, t_transient, initial=state, every=_no_series(p, t_transient, "t_transient"))
        state = transient.restart_state()
    run = simulate_block(p, t_measure, initial=state, every=_no_series(p, t_measure, "t_measure"))
    starts = run.slips["t_c"].to_numpy()
    period = float(np.mean(np.diff(starts))) if starts.size >= 2 else math.nan
    row = {
        "stuck": run.n_stops > 0 or run.final.stopped,
        "n_stops": run.n_stops,
        "v_min": run.v_min,
        "v_max": run.v_max,
        "period": period,
    }
    return row, run.restart_state()


def hysteresis_sweep(
    params: BlockParams,
    settings: SweepSettings | None = None,
    *,
    initial: BlockState | None = None,
) -> HysteresisResult:
    """Adiabatic sweep of V up and then down for the single block, eq. (1) (section 2).

    Starts from ``initial`` (default: the paper's x = v = 0, theta = 0.1, stopped) at V_min,
    where the block stick-slips, and carries the state from each V to the next (module
    docstring). ``params.V`` is not read. The paper's inverse transition, stick-slip -> steady
    sliding going up, is at V = 0.345 for beta = 1, Fs = 3, K = 10.
    """
    import pandas as pd
    import xarray as xr

    from stickslip.run.block import INTEGRATOR, BlockState

    settings = SweepSettings() if settings is None else settings
    state = BlockState() if initial is None else initial
    grid = settings.V_grid()
    rows: dict[str, list[dict]] = {"up": [], "down": []}
    for V in grid:
        row, state = _hold(params, V, settings, state)
        rows["up"].append(row)
    for V in grid[::-1]:
        row, state = _hold(params, V, settings, state)
        rows["down"].append(row)
    rows["down"].reverse()  # stored against increasing V, like the way up

    up = pd.DataFrame(rows["up"])
    down = pd.DataFrame(rows["down"])
    data = xr.Dataset(
        {
            name: (("direction", "V"), np.stack([up[name].to_numpy(), down[name].to_numpy()]))
            for name in ("stuck", "n_stops", "v_min", "v_max", "period")
        },
        coords={"direction": ["up", "down"], "V": grid},
    )
    for name, text in (
        ("stuck", "block stopped at least once in the measured part"),
        ("n_stops", "number of stops in the measured part"),
        ("v_min", "least v in the measured part"),
        ("v_max", "greatest v in the measured part"),
        ("period", "mean time between slip starts in the measured part"),
    ):
        data[name].attrs["long_name"] = text

    V_up = _first(grid, ~up["stuck"].to_numpy(), require_before=up["stuck"].to_numpy())
    down_stuck = down["stuck"].to_numpy()[::-1]
    V_down = _first(grid[::-1], down_stuck, require_before=~down_stuck)
    data.attrs.update({k: v if isinstance(v, str) else float(v) for k, v in params.to_dict().items() if k != "V"})
    data.attrs.update(settings.to_dict())
    data.attrs.update(
        V_up=math.nan if V_up is None else V_up,
        V_down=math.nan if V_down is None else V_down,
        integrator=INTEGRATOR,
        model="eq. (1), single block, adiabatic sweep of V",
    )
    return HysteresisResult(params=params, settings=settings, data=data, V_up=V_up, V_down=V_down)


def _first(V: np.ndarray, flag: np.ndarray, require_before: np.ndarray | None = None) -> float | None:
    """First V (in the order given) where ``flag`` holds, after ``require_before`` held once."""
    seen = require_before is None
    for j, value in enumerate(V):
        if flag[j] and seen:
            return float(value)
        if require_before is not None and require_before[j]:
            seen = True
    return None
