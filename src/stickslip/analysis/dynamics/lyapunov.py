"""The largest Lyapunov exponent of the chain of eq. (4) (and of eq. (1) as the chain with N = 1).

Two-trajectory method of Benettin, Galgani, Giorgilli and Strelcyn (Meccanica 15, 9, 1980),
:mod:`stickslip.analysis.dynamics.benettin`, over the chain engine (:class:`GridEngine`, the map of
:func:`stickslip.run.driver.run_chain`): a reference trajectory and a twin a distance d0 away
are advanced side by side; every ``interval`` the distance d is measured and the twin is put
back at distance d0 along the current separation. The exponent is the mean of ln(d / d0) per
unit time over the renormalisations after a transient, and its error bar the standard error of
the means of M independent segments of them.

Separation. The state of block i is (x_i, v_i, theta_i, stopped_i). Forces depend on positions
only through the spring extensions e_i = x_{i-1} - x_i (x_0 = V t_n, the pulling point), so the
separation is measured in y = (sqrt(K) e_i, v_i, theta_i), i = 1..N, with the Euclidean norm.
With unit mass, ``|(sqrt(K) de, dv)|^2 / 2`` is the mechanical energy of the perturbation (springs
plus motion): a harmonic oscillation of the perturbation does not make d oscillate, which would
add noise to every ln(d / d0). The pulling point is the same for both trajectories, so the
extensions carry the whole position information (no neutral translation direction).

Stuck blocks. A stuck block lies on the constraint v_i = 0: its velocity is not a coordinate.
The twin therefore has the reference's stopped flags, and the separation vector loses its
velocity components on the blocks stuck in the reference before it is rescaled to d0 (it is
projected onto the reference's current branch). A stuck block is perturbed in x_i and theta_i
only; it starts when the start rule says so from its own force, as in the reference. The
distance itself is measured from the continuous variables alone, so a twin block that is still
sliding while the reference's has stopped counts with its velocity: flags never enter d.
See docs/lyapunov.md for what the exponent means with these switching rules.

Plate drive (Carlson-Langer, two blocks). Every block hangs on the plate by its own leaf spring
Kp, which both trajectories share: positions relative to the plate are the displacements
themselves, and y = (sqrt(Kp) dx_i, v_i, theta_i) weighs them with the leaf spring (the part of the
perturbation's energy that every block has whatever its neighbours do).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from stickslip.analysis.dynamics.benettin import METHOD, LyapunovResult, check_run, two_trajectory_exponent
from stickslip.models.lattice import norm
from stickslip.models.params import ChainParams, ParameterError, steps_for
from stickslip.run.driver import ChainState, Stepper, run_chain
from stickslip.run.errors import short_runs_expected
from stickslip.run.state import initial_state
from stickslip.run.validate import check_start_state

NORM = "Euclidean norm of (sqrt(K) e_i, v_i, theta_i), e_i = x_{i-1} - x_i, x_0 = V t"


def separation(ref: ChainState, twin: ChainState, params: ChainParams) -> np.ndarray:
    """The separation twin - ref in the coordinates y = (sqrt(K) e, v, theta) (length 3N), the
    lattice's norm (:func:`stickslip.models.lattice.norm.coordinates`).

    e_i = x_{i-1} - x_i with the same pulling point for both, so de_i = dx_{i-1} - dx_i, dx_0 = 0.
    With the plate drive y = (sqrt(Kp) dx, v, theta) (module docstring).
    """
    return norm.coordinates(norm.lattice_of(params), twin.x - ref.x, twin.v - ref.v, twin.theta - ref.theta, params)


def _project(dy: np.ndarray, stopped: np.ndarray) -> np.ndarray:
    """Drop the velocity components of blocks stuck in the reference (the constraint v = 0)."""
    return norm.on_branch(dy, stopped)


ENGINES = ("lean", "run_chain")


class _RunChainEngine:
    """Advances a state with the public :func:`stickslip.run.driver.run_chain` (one call per interval).

    Always right, but each call assembles the full run record (tables, xarray): some
    milliseconds, a hundred times the cost of a short interval of the kernel itself.
    """

    def __init__(self, params: ChainParams):
        self.params = params

    def advance(self, state: ChainState, step: int) -> tuple[ChainState, int]:
        """The state at ``step`` and the number of slip events completed on the way."""
        run = run_chain(self.params, step * self.params.dt, start=state, sample_interval=self.params.dt)
        return run.state, len(run.events)


class _LeanEngine:
    """Kernel calls to the target step with no outputs kept (:class:`stickslip.run.driver.Stepper`)."""

    def __init__(self, params: ChainParams):
        self.params = params
        self.stepper = Stepper(params)

    def advance(self, state: ChainState, step: int) -> tuple[ChainState, int]:
        """The state at ``step`` (advanced in place) and the slip events completed on the way."""
        return self.stepper.advance(state, step)


def _with_step(state: ChainState, step: int) -> ChainState:
    """``state`` (built by ChainState.from_blocks, at step 0) set to step ``step``.

    from_blocks marks every block as possibly changing, so the fast integrator continues it
    correctly; only the step count, which places the pulling point, has to be carried over.
    """
    from stickslip.kernels.layout import STEP

    state.ist[STEP] = step
    return state


def moved_back(state: ChainState, k: int, params: ChainParams) -> ChainState:
    """``state`` moved back along the drive by k steps: x -> x - V k dt at step - k (a new state).

    Eq. (4) and its relatives read positions only relative to the drive (V t), so the motion
    from it is the same (fixed ends, which read t, excepted); k = step restarts the clock.
    """
    b = state.blocks()
    moved = ChainState.from_blocks(b["x"] - params.V * (np.float64(k) * params.dt), b["v"], b["theta"], b["stopped"])
    moved.model = state.model
    return _with_step(moved, state.step - k)


def twin_state(ref: ChainState, direction: np.ndarray, d0: float, params: ChainParams) -> ChainState:
    """The twin ref + d0 * direction (direction in y coordinates, see :func:`separation`).

    The twin takes the reference's stopped flags; ``direction`` is first projected onto the
    reference's branch (no velocity on stuck blocks) and normalised. Positions follow from the
    extensions: dx_i = -(de_1 + ... + de_i).
    """
    b = ref.blocks()
    N = b["x"].shape[0]
    u = _project(direction, b["stopped"])
    if not params.friction_piece.has_state:
        u[2 * N :] = 0.0  # no state variable: theta is not a coordinate of these models
    size = float(np.linalg.norm(u))
    if not size > 0.0:
        raise ValueError("the separation vanished on the reference's branch; cannot renormalise")
    u = u * (d0 / size)
    x = b["x"] + norm.displacement(norm.lattice_of(params), u[:N], params)
    v = np.where(b["stopped"], 0.0, b["v"] + u[N : 2 * N])
    th = b["theta"] + u[2 * N :]
    return _with_step(ChainState.from_blocks(x, v, th, b["stopped"]), ref.step)


#: Frames the grid's twin runs in (:class:`GridEngine`).
FRAMES = ("centred", "absolute")


@dataclass
class FramedTwin:
    """The grid's twin, and the frame it runs in.

    ``state``: the twin; ``base``: the reference moved back by ``shift`` grid steps, x -> x - V
    shift dt (the same motion, the drive shifted in time by the symmetry of the equations), or
    None when the twin runs in the reference's own frame (``shift`` 0). Both run ``shift`` steps
    behind the reference's clock, and are moved back together every ``hop`` steps.
    """

    state: ChainState
    base: ChainState | None
    shift: int
    hop: int = 0


class GridEngine:
    """The engine's map (starts and stops on the time grid) for :func:`two_trajectory_exponent`.

    Separations in y = (sqrt(K) e, v, theta) (:func:`separation`), twins by :func:`twin_state`,
    advanced with ``engine`` 'lean' (:class:`stickslip.run.driver.Stepper`) or 'run_chain'.
    No neutral direction (the grid locks the phase of a slip to a step) and no waiting.

    ``frame`` 'centred' (default): at every renormalisation the twin is built from a copy of the
    reference moved back by the whole number of steps k that brings the pulling point and the
    positions closest to zero (x -> x - V k dt, t -> t - k dt; eq. (4) reads positions only
    relative to V t, so this copy continues the reference's motion), and the separation is
    measured against that copy, both run with the engine. Their rounding is that of positions
    of the size of the chain's own extent, not of V t: a decaying separation does not sink into
    the round-off of absolute positions (ulp(V t), 1.8e-12 at V t = 1e4) in a long run.
    'absolute': the twin runs beside the reference itself (the method before the frame). Ends
    that read t (a wall, fixed ends) always run in the reference's frame.
    """

    method = METHOD
    norm = NORM
    max_wait = 0

    def __init__(self, params: ChainParams, engine: str = "lean", frame: str = "centred"):
        if engine not in ENGINES:
            raise ParameterError(f"engine must be one of {', '.join(ENGINES)} (got {engine!r})")
        if frame not in FRAMES:
            raise ParameterError(f"frame must be one of {', '.join(FRAMES)} (got {frame!r})")
        self.params = params
        self.frame = frame
        self.stepper = _LeanEngine(params) if engine == "lean" else _RunChainEngine(params)
        self.shifts = frame == "centred" and not params.ends_piece.wall and params.V * params.dt > 0.0

    def advance(self, ref: ChainState, twin: FramedTwin, step: int) -> tuple[ChainState, FramedTwin, int]:
        """All to ``step`` of the reference's clock; the reference's slip events on the way.

        In the centred frame the twin and the reference's copy go in hops over which the drive
        moves by no more than the chain's extent (at least 1), and are moved back together after
        each (:meth:`centring_shift`), so that their positions stay of that size.
        """
        ref, n_events = self.stepper.advance(ref, step)
        if twin.base is None:
            twin.state, _ = self.stepper.advance(twin.state, step - twin.shift)
            return ref, twin, n_events
        while True:
            target = step - twin.shift
            reach = min(target, twin.base.step + twin.hop)
            twin.base, _ = self.stepper.advance(twin.base, reach)
            twin.state, _ = self.stepper.advance(twin.state, reach)
            if reach == target:
                return ref, twin, n_events
            k, twin.hop = self.centring_shift(twin.base)
            if k:
                twin.base, twin.state = moved_back(twin.base, k, self.params), moved_back(twin.state, k, self.params)
                twin.shift += k

    def step(self, ref: ChainState) -> int:
        """The reference's step."""
        return ref.step

    def separation(self, ref: ChainState, twin: FramedTwin) -> np.ndarray:
        """:func:`separation` of the twin from the reference (its copy in the twin's frame)."""
        return separation(ref if twin.base is None else twin.base, twin.state, self.params)

    def twin(self, ref: ChainState, direction: np.ndarray, d0: float) -> FramedTwin:
        """:func:`twin_state` of the reference's copy moved back by :meth:`centring_shift`
        (of the reference itself in the absolute frame)."""
        k, hop = self.centring_shift(ref) if self.shifts else (0, 0)
        base = moved_back(ref, k, self.params) if k else None
        return FramedTwin(twin_state(ref if base is None else base, direction, d0, self.params), base, k, hop)

    def centring_shift(self, state: ChainState) -> tuple[int, int]:
        """(k, hop): k steps in [0, state.step] to move ``state`` back by so that the pulling
        point and the blocks lie about zero (within +-R/2, R the extent of those positions, at
        least 1: below, positions round no worse than velocities of order one), and the hop,
        the steps over which the drive moves by R (after it, within -R/2 .. 3R/2)."""
        p = self.params
        n = state.step
        x = state.x
        drive = p.V * (np.float64(n) * p.dt)
        lo, hi = min(float(x.min()), drive), max(float(x.max()), drive)
        rate = p.V * p.dt  # drive per step
        hop = max(1, int(max(hi - lo, 1.0) / rate))
        k = int(round(0.5 * (lo + hi) / rate))
        return min(max(k, 0), n), hop

    def on_branch(self, dy: np.ndarray, ref: ChainState) -> np.ndarray:
        """No velocity on the reference's stuck blocks."""
        return _project(dy, ref.mov[1:-1] == 0.0)

    def same_branch(self, ref: ChainState, twin: FramedTwin) -> bool:
        """Whether both have the same blocks stuck."""
        return bool(np.array_equal(ref.mov, twin.state.mov))

    def neutral(self, ref: ChainState) -> None:
        """None: nothing is removed."""
        return None

    def fingerprint(self, ref: ChainState) -> str:
        """:meth:`stickslip.run.state.ChainState.sha256`."""
        return ref.sha256()


def largest_lyapunov(
    params: ChainParams,
    t_end: float,
    *,
    interval: float = 10.0,
    d0: float = 1e-10,
    transient: float = 0.0,
    align: float | None = None,
    start: str | ChainState = "paper",
    perturbation: float = 0.0,
    seed: int = 0,
    direction_seed: int = 0,
    segments: int = 10,
    engine: str = "lean",
    frame: str = "centred",
    progress: bool = False,
) -> LyapunovResult:
    """Largest Lyapunov exponent of eq. (4) (eq. (1) for N = 1) by the two-trajectory method of
    Benettin et al. (1980).

    The reference runs alone from ``start`` to ``transient``; there a twin is placed d0 away in a
    random direction. Both advance with the exact integrator of
    :func:`stickslip.run.driver.run_chain` in steps of ``interval`` up to ``t_end``; after each the
    distance d (:data:`NORM`) is recorded and the twin put back at d0 along the separation
    (:func:`twin_state`). The renormalisations ending after transient + ``align`` give the
    exponent: the sum of ln(d / d0) over their total time; its error is the standard error of the
    exponents of ``segments`` consecutive groups of them
    (:func:`stickslip.analysis.dynamics.benettin.two_trajectory_exponent` with :class:`GridEngine`). The
    reference is continued exactly as one uninterrupted run: its final state is bit for bit
    ``run_chain(params, t_end, start=start, ...).state``. d0 is the realised distance after
    rounding, so ln(d / d0) is not biased by the rounding of the twin's positions (docs/lyapunov.md).

    Parameters
    ----------
    params : ChainParams
        The chain (any model of the family).
    t_end : float
        End of the run.
    interval : float
        Time between renormalisations.
    d0 : float
        Initial separation of the twin.
    transient : float
        The reference runs alone up to here before the twin is placed.
    align : float, optional
        Renormalisations ending before transient + align are not counted (default a tenth of
        t_end - transient, for the separation to turn into the most unstable direction).
    start : str or ChainState
        ``'paper'``, ``'steady'`` (with ``perturbation`` and ``seed``) or a state.
    perturbation : float
        With ``start='steady'``: uniform perturbation of x and v in [-A, A].
    seed : int
        Seed of that perturbation.
    direction_seed : int
        Seed of the twin's first direction (numpy ``default_rng``).
    segments : int
        Groups of renormalisations for the error bar.
    engine : str
        ``'lean'``: the kernel loop without the run record, a hundred times faster for short
        intervals; ``'run_chain'``: one public call per interval. Both give the same numbers bit
        for bit.
    frame : str
        ``'centred'``: the twin and a copy of the reference run in a frame moved back along the
        drive by whole steps (:class:`GridEngine`), so that the separation is not limited by the
        rounding of positions of the size of V t; ``'absolute'``: the twin beside the reference.
    progress : bool
        A progress bar on stderr.

    Returns
    -------
    LyapunovResult
        ``lyapunov`` and ``lyapunov_err`` (per unit time), the renormalisations counted, the
        events of the reference, the reference's final state hash, and every interval's
        ln(d / d0).

    Examples
    --------
    >>> import stickslip
    >>> res = stickslip.largest_lyapunov(stickslip.chain_params(N=9), 2e4)
    >>> res.renormalisations  # (t_end - align) / interval
    1800
    >>> abs(res.lyapunov) < 1e-3  # per unit time, within 1e-3 of zero at N = 9
    True
    """
    t_end, interval, d0, transient, align, segments = check_run(params, t_end, interval, d0, transient, align, segments)
    grid = GridEngine(params, engine, frame)
    dt = params.dt
    n0 = steps_for(transient, dt, "transient")
    wall0 = time.perf_counter()

    if n0 > (start.step if isinstance(start, ChainState) else 0):
        with short_runs_expected():  # only the state at the transient's end is used, not <L>
            run = run_chain(
                params, n0 * dt, start=start, perturbation=perturbation, seed=seed, sample_interval=max(transient, dt)
            )
        ref = run.state
    elif isinstance(start, ChainState):  # no transient to run (run_chain refuses a run of no steps)
        check_start_state(start, params)
        ref = start.copy()
    else:
        ref = initial_state(params, start, amplitude=perturbation, seed=seed)
    return two_trajectory_exponent(
        grid,
        ref,
        t_end,
        interval=interval,
        d0=d0,
        transient=transient,
        align=align,
        segments=segments,
        direction_seed=direction_seed,
        start=start if isinstance(start, str) else "state",
        extra={"frame": frame},
        progress=progress,
        wall0=wall0,
    )


CONVERGENCE_COLUMNS = [
    "varied",
    "d0",
    "interval",
    "t_end",
    "lyapunov",
    "lyapunov_err",
    "renormalisations",
    "wall_seconds",
]


def lyapunov_convergence(
    params: ChainParams,
    t_end: float,
    *,
    d0s: Sequence[float] = (1e-8, 1e-10, 1e-12),
    intervals: Sequence[float] | None = None,
    t_ends: Sequence[float] | None = None,
    interval: float = 10.0,
    d0: float = 1e-10,
    **kwargs: Any,
) -> pd.DataFrame:
    """The exponent of :func:`largest_lyapunov` against d0, the interval and the run length.

    One quantity is varied at a time about (d0, interval, t_end). ``intervals`` defaults to
    interval / 2, interval, 2 interval; ``t_ends`` to the quarter, half and whole of the counted
    stretch, read off the base run (:meth:`LyapunovResult.truncated`, identical to shorter runs).
    Other keyword arguments go to :func:`largest_lyapunov`.
    """
    rows = []

    def add(varied, res, wall):
        rows.append(
            {
                "varied": varied,
                "d0": res.d0,
                "interval": res.interval,
                "t_end": res.t_end,
                "lyapunov": res.lyapunov,
                "lyapunov_err": res.lyapunov_err,
                "renormalisations": res.renormalisations,
                "wall_seconds": wall,
            }
        )

    base = largest_lyapunov(params, t_end, interval=interval, d0=d0, **kwargs)
    for value in d0s:
        res = base if value == d0 else largest_lyapunov(params, t_end, interval=interval, d0=value, **kwargs)
        add("d0", res, res.wall_seconds)
    if intervals is None:
        intervals = (interval / 2, interval, 2 * interval)
    for value in intervals:
        res = base if value == interval else largest_lyapunov(params, t_end, interval=value, d0=d0, **kwargs)
        add("interval", res, res.wall_seconds)
    if t_ends is None:
        lo = base.transient + base.align
        t_ends = [lo + f * (base.t_end - lo) for f in (0.25, 0.5, 1.0)]
    for value in t_ends:
        # Cut at the last renormalisation at or before value.
        t_cut = float(base.times[base.times <= value + 0.5 * params.dt].max())
        add("t_end", base.truncated(t_cut), float("nan"))
    return pd.DataFrame(rows, columns=CONVERGENCE_COLUMNS)


BETA_COLUMNS = ["beta", "lyapunov", "lyapunov_err", "renormalisations", "events", "max_log_growth", "wall_seconds"]


def lyapunov_vs_beta(params: ChainParams, betas: Sequence[float], t_end: float, **kwargs: Any) -> pd.DataFrame:
    """The largest exponent of eq. (4) at each beta (other parameters from ``params``).

    Keyword arguments go to :func:`largest_lyapunov`. Only a params object describes the
    model, so a model with other parameters needs nothing else here.
    """
    rows = []
    for beta in betas:
        res = largest_lyapunov(params.replace(beta=float(beta)), t_end, **kwargs)
        rows.append(
            {
                "beta": float(beta),
                "lyapunov": res.lyapunov,
                "lyapunov_err": res.lyapunov_err,
                "renormalisations": res.renormalisations,
                "events": res.events,
                "max_log_growth": res.max_log_growth,
                "wall_seconds": res.wall_seconds,
            }
        )
    return pd.DataFrame(rows, columns=BETA_COLUMNS)
