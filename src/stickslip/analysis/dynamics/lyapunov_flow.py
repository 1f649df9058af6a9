"""The largest Lyapunov exponent of the flow: the equations with switches, dt -> 0.

:mod:`stickslip.analysis.dynamics.lyapunov` measures the exponent of the gridded map the engine integrates
(starts tested at the beginning of a step, stops at its end, docs/model.md). Here the same
two-trajectory method (Benettin, Galgani, Giorgilli and Strelcyn, Meccanica 15, 9, 1980) runs on
the integrator with located switches (:mod:`stickslip.run.located`): reference and twin each
start and stop their blocks at the times their own forces and velocities say, so a perturbation
that shifts a switch is carried across it as the saltation of the flow carries it (no tangent
equations and no saltation matrices are formed: the two trajectories are the method). The
exponent is measured at dt, dt/2, dt/4 and extrapolated to dt -> 0 (:func:`flow_ladder`).

Separation. As in the gridded method, y = (sqrt(K) e_i, v_i, theta_i) with e_i = u_{i-1} - u_i,
u = x - V t and u_0 = 0 (end drive), or y = (sqrt(Kp) u_i, v_i, theta_i) (plate drive); theta
counts only for the state friction. Positions relative to the drive keep their precision however
long the run.

The neutral direction. In the frame of the drive the equations are autonomous (fixed ends
apart), so a perturbation along the flow, F(y), is a shift in time: it neither grows nor decays
on average, and it makes d swing with the norm of F between sticking (about V) and slipping (about 1).
With ``neutral='remove'`` (the default) the separation is measured and renormalised after its
component along F(y_ref) is removed: d is the distance of the twin from the reference's orbit,
not from the reference's point. The exponent is then the largest one transverse to the flow; the
flow's own spectrum adds the zero of the time shift, so the largest exponent of the flow is
max(0, lambda) on an attractor other than a fixed point. A periodic orbit gives lambda < 0,
a chaotic attractor lambda > 0. Near a fixed point (steady sliding) F(y) -> 0 and its direction
carries no time shift; the removal is skipped where the norm of F is below ``flow_floor``.

Renormalisation waits until both trajectories have the same blocks stuck (at most
``max_wait`` steps past the planned time), so the twin is always rebuilt on the reference's
branch: its stuck blocks have v = 0 and the separation no velocity on them.
"""

from __future__ import annotations

import hashlib
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from stickslip.analysis.dynamics.benettin import LyapunovResult, check_run, two_trajectory_exponent
from stickslip.models.lattice import norm
from stickslip.models.params import ChainParams, ParameterError, check_number, steps_for
from stickslip.run.located import LocatedState, LocatedStepper, rates, start_state
from stickslip.run.state import ChainState

NORM = "Euclidean norm of (sqrt(K) e_i, v_i, theta_i), e_i = u_{i-1} - u_i, u = x - V t, u_0 = 0"
NEUTRAL = ("remove", "keep")
METHOD = (
    "Benettin et al. (1980) two-trajectory method on Heun with located switches "
    "(each trajectory locates its own starts and stops)"
)


#: The flow's result is the method's one result class (``extra`` holds ``neutral``).
FlowLyapunovResult = LyapunovResult


def separation(ref: LocatedState, twin: LocatedState, params: ChainParams) -> np.ndarray:
    """twin - ref in y coordinates (module docstring), length 3N: the lattice's norm
    (:func:`stickslip.models.lattice.norm.coordinates`)."""
    du = twin.u[1:-1] - ref.u[1:-1]
    dv = twin.v[1:-1] - ref.v[1:-1]
    dth = twin.th[1:-1] - ref.th[1:-1]
    if not params.friction_piece.has_state:
        dth = np.zeros_like(dth)
    return norm.coordinates(norm.lattice_of(params), du, dv, dth, params)


def flow_direction(state: LocatedState, params: ChainParams) -> np.ndarray:
    """F(y) = dy/dt at ``state`` in y coordinates: the direction of a shift in time."""
    N = state.N
    du, dv, dth = rates(state, params)
    fth = dth[1:-1] if params.friction_piece.has_state else np.zeros(N)
    return norm.coordinates(norm.lattice_of(params), du[1:-1], dv[1:-1], fth, params)


def _on_branch(dy: np.ndarray, stopped: np.ndarray, params: ChainParams) -> np.ndarray:
    """No velocity on the reference's stuck blocks; no theta without a state variable."""
    return norm.on_branch(dy, stopped, params.friction_piece.has_state)


def twin_state(ref: LocatedState, direction: np.ndarray, d0: float, params: ChainParams) -> LocatedState:
    """ref + d0 * direction (y coordinates), on the reference's branch (same stuck blocks).

    Moving blocks keep v >= 0 (a stop is a switch, not a perturbation).
    """
    stopped = ref.stopped
    N = ref.N
    u = _on_branch(direction, stopped, params)
    size = float(np.linalg.norm(u))
    if not size > 0.0:
        raise ValueError("the separation vanished on the reference's branch; cannot renormalise")
    u = u * (d0 / size)
    du = norm.displacement(norm.lattice_of(params), u[:N], params)
    twin = ref.copy()
    twin.u[1:-1] += du
    twin.v[1:-1] = np.where(stopped, 0.0, np.maximum(ref.v[1:-1] + u[N : 2 * N], 0.0))
    twin.th[1:-1] += u[2 * N :]
    return twin


class LocatedEngine:
    """The equations with located switches (:class:`stickslip.run.located.LocatedStepper`) for
    :func:`stickslip.analysis.dynamics.benettin.two_trajectory_exponent`.

    Separations in y (:func:`separation`), twins by :func:`twin_state`; the neutral direction is
    the flow F(y_ref) with ``neutral='remove'`` (none where its norm is not above ``flow_floor``,
    or with 'keep'); a renormalisation waits up to ``max_wait`` steps for both to have the same
    blocks stuck.
    """

    method = METHOD
    norm = NORM

    def __init__(self, params: ChainParams, *, neutral: str = "remove", flow_floor: float = 1e-9, max_wait: int = 0):
        if neutral not in NEUTRAL:
            raise ParameterError(f"neutral must be one of {', '.join(NEUTRAL)} (got {neutral!r})")
        self.params = params
        self.stepper = LocatedStepper(params)
        self.remove = neutral == "remove"
        self.flow_floor = flow_floor
        self.max_wait = max_wait

    def advance(self, ref: LocatedState, twin: LocatedState, step: int) -> tuple[LocatedState, LocatedState, int]:
        """Both to grid ``step``; the reference's slip events on the way."""
        ref, ev = self.stepper.advance(ref, step)
        twin, _ = self.stepper.advance(twin, step)
        return ref, twin, len(ev)

    def step(self, ref: LocatedState) -> int:
        """The reference's grid step."""
        return ref.step

    def separation(self, ref: LocatedState, twin: LocatedState) -> np.ndarray:
        """:func:`separation`."""
        return separation(ref, twin, self.params)

    def twin(self, ref: LocatedState, direction: np.ndarray, d0: float) -> LocatedState:
        """:func:`twin_state`."""
        return twin_state(ref, direction, d0, self.params)

    def on_branch(self, dy: np.ndarray, ref: LocatedState) -> np.ndarray:
        """No velocity on the reference's stuck blocks, no theta without a state variable."""
        return _on_branch(dy, ref.stopped, self.params)

    def same_branch(self, ref: LocatedState, twin: LocatedState) -> bool:
        """Whether both have the same blocks stuck."""
        return bool(np.array_equal(ref.mov, twin.mov))

    def neutral(self, ref: LocatedState) -> np.ndarray | None:
        """F(y_ref) (:func:`flow_direction`) with neutral 'remove' where its norm is above the floor."""
        if not self.remove:
            return None
        flow = flow_direction(ref, self.params)
        return flow if float(np.linalg.norm(flow)) > self.flow_floor else None

    def fingerprint(self, ref: LocatedState) -> str:
        """SHA-256 of u, v, theta (float64 little-endian, block order) then the stuck flags (1 byte each)."""
        h = hashlib.sha256()
        for a in (ref.u, ref.v, ref.th):
            h.update(np.ascontiguousarray(a[1:-1], dtype="<f8").tobytes())
        h.update(ref.stopped.astype(np.uint8).tobytes())
        return h.hexdigest()


def flow_lyapunov(
    params: ChainParams,
    t_end: float,
    *,
    interval: float = 10.0,
    d0: float = 1e-10,
    transient: float = 0.0,
    align: float | None = None,
    start: str | ChainState | LocatedState = "paper",
    perturbation: float = 0.0,
    seed: int = 0,
    direction_seed: int = 0,
    segments: int = 10,
    neutral: str = "remove",
    flow_floor: float = 1e-9,
    max_wait: int | None = None,
    progress: bool = False,
    stop_requested=None,
) -> LyapunovResult:
    """Largest Lyapunov exponent of the equations with switches at the step ``params.dt``.

    The reference runs with located switches (:func:`stickslip.run.located.run_located`) from
    ``start`` to ``transient``; a twin is placed d0 away in a random direction
    (``default_rng(direction_seed)``); both advance by ``interval`` (then step by step until they
    have the same stuck blocks, at most ``max_wait`` steps, default one interval); the separation
    (less its component along the flow with ``neutral='remove'``, module docstring) gives
    ln(d / d0) and the twin is put back d0 away along it. Counted and averaged as in
    :func:`stickslip.analysis.dynamics.lyapunov.largest_lyapunov`: one loop,
    :func:`stickslip.analysis.dynamics.benettin.two_trajectory_exponent` with :class:`LocatedEngine`
    (``stop_requested``: asked now and then whether to stop, as there).
    """
    t_end, interval, d0, transient, align, segments = check_run(params, t_end, interval, d0, transient, align, segments)
    dt = params.dt
    m = int(round(interval / dt))
    engine = LocatedEngine(params, neutral=neutral, flow_floor=flow_floor, max_wait=m if max_wait is None else max_wait)
    wall0 = time.perf_counter()
    ref = start_state(params, start, perturbation=perturbation, seed=seed)
    ref, _ = engine.stepper.advance(ref, steps_for(transient, dt, "transient"))
    return two_trajectory_exponent(
        engine,
        ref,
        t_end,
        interval=interval,
        d0=d0,
        transient=transient,
        align=align,
        segments=segments,
        direction_seed=direction_seed,
        start=start if isinstance(start, str) else "state",
        extra={"neutral": neutral},
        progress=progress,
        wall0=wall0,
        stop_requested=stop_requested,
    )


def extrapolate(dts, values, errors, order: int = 2) -> tuple[float, float, float]:
    """Weighted least-squares fit of lambda(dt) = lambda_0 + c dt^order (Richardson's model).

    Returns (lambda_0, its error, c). The error is the fit's standard error, scaled up by
    sqrt(chi^2 / dof) when the points scatter more than their error bars say (dof = points - 2);
    with two points, the propagated error bars. Raises ValueError (one line) where an exponent is
    not finite or the steps do not differ (the fit's matrix would be singular).
    """
    h = np.asarray(dts, dtype=float) ** order
    y = np.asarray(values, dtype=float)
    e = np.asarray(errors, dtype=float)
    if not np.all(np.isfinite(y)):
        bad = ", ".join(f"{d:g}" for d, v in zip(dts, y, strict=True) if not math.isfinite(v))
        raise ValueError(f"no extrapolation: the exponent at dt = {bad} is not finite")
    if np.unique(h).size < 2:
        raise ValueError("no extrapolation: it needs two different steps")
    floor = 1e-12 * max(1.0, float(np.max(np.abs(y))))
    e = np.where(np.isfinite(e) & (e > floor), e, floor)
    A = np.column_stack((np.ones_like(h), h)) / e[:, None]
    b = y / e
    coef, *_ = np.linalg.lstsq(A, b, rcond=None)
    cov = np.linalg.inv(A.T @ A)
    dof = len(y) - 2
    scale = 1.0
    if dof > 0:
        chi2 = float(np.sum((A @ coef - b) ** 2))
        scale = max(1.0, math.sqrt(chi2 / dof))
    return float(coef[0]), float(math.sqrt(cov[0, 0]) * scale), float(coef[1])


#: What each rung of a ladder has for itself (its rows), not the ladder's settings.
_PER_RUNG = (
    "lyapunov",
    "lyapunov_err",
    "dt",
    "renormalisations",
    "merges",
    "segment_means",
    "events",
    "waits",
    "max_log_growth",
    "reference_sha256",
)

LADDER_COLUMNS = ["dt", "lyapunov", "lyapunov_err", "renormalisations", "events", "waits", "wall_seconds"]


@dataclass(frozen=True)
class FlowLadder:
    """The exponent of the flow at dt, dt/2, ... and its extrapolation to dt -> 0."""

    rows: list[dict[str, Any]]
    lyapunov_dt0: float
    lyapunov_dt0_err: float
    slope: float
    results: list[LyapunovResult] = field(repr=False)

    def to_dict(self) -> dict[str, Any]:
        """``lyapunov_dt0``, ``lyapunov_dt0_err``, ``ladder`` rows and the run's settings."""
        first = self.results[0]
        d = first.to_dict()
        for k in _PER_RUNG:
            d.pop(k)
        d["wall_seconds"] = float(sum(r.wall_seconds for r in self.results))
        d.update(
            {
                "switches": "located",
                "lyapunov_dt0": self.lyapunov_dt0,
                "lyapunov_dt0_err": self.lyapunov_dt0_err,
                "dt2_slope": self.slope,
                "extrapolation": "weighted least squares of lambda = lambda_0 + c dt^2 (Heun's order)",
                "ladder": self.rows,
            }
        )
        return d


def flow_ladder(params: ChainParams, t_end: float, *, levels: int = 3, **kwargs: Any) -> FlowLadder:
    """:func:`flow_lyapunov` at dt = params.dt, dt/2, ..., dt/2^(levels-1), extrapolated to dt -> 0.

    The same start, transient, interval (in time) and twin direction at every rung; the
    extrapolation assumes lambda(dt) = lambda_0 + c dt^2, the order of the integrator.
    """
    levels = int(check_number("levels", levels, low=2, integer=True))
    results = []
    for k in range(levels):
        p = params.replace(dt=params.dt / 2**k)
        results.append(flow_lyapunov(p, t_end, **kwargs))
    rows = [
        {
            "dt": r.dt,
            "lyapunov": r.lyapunov,
            "lyapunov_err": r.lyapunov_err,
            "renormalisations": r.renormalisations,
            "events": r.events,
            "waits": r.waits,
            "wall_seconds": r.wall_seconds,
        }
        for r in results
    ]
    lam0, err0, slope = extrapolate(
        [r.dt for r in results], [r.lyapunov for r in results], [r.lyapunov_err for r in results]
    )
    return FlowLadder(rows, lam0, err0, slope, results)
