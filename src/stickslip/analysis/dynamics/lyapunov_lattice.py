"""The largest Lyapunov exponent of a model on a lattice (docs/lattice.md, docs/lyapunov.md): the
two-trajectory method of Benettin, Galgani, Giorgilli and Strelcyn (Meccanica 15, 9, 1980),
:func:`stickslip.analysis.dynamics.benettin.two_trajectory_exponent`, over the lattice's
reference integrator (:class:`stickslip.run.lattice.LatticeStepper`, the map of
:func:`stickslip.run.lattice.run_lattice`).

The separation is the lattice's norm (:mod:`stickslip.models.lattice.norm`), the one the chain's
exponents use: y = (sqrt(K) e, v, theta), e the springs' extensions along each line from the
pulled side (y = (sqrt(Kp) dx, v, theta) with the plate). The twin has the reference's stopped
flags and the separation no velocity on the reference's stuck blocks, as in
:mod:`stickslip.analysis.dynamics.lyapunov`. The twin runs beside the reference in its own
frame (the chain's ``frame='absolute'``): on a square of one row, and on the chain lattice, the
exponent is the chain's ``largest_lyapunov(..., frame='absolute')`` bit for bit.

:class:`LatticeSequences` gives the lattice's slip sequences to the decorrelation of
:func:`stickslip.analysis.dynamics.decorrelation.sequence_decorrelation`: a slip is its
epicentre (the flat row-major index of the first block to move), its area and its moment, in the
places of the chain's start block, number of blocks and size.
"""

from __future__ import annotations

import time

import numpy as np

from stickslip.analysis.dynamics.benettin import METHOD, LyapunovResult, check_run, two_trajectory_exponent
from stickslip.kernels import layout
from stickslip.models.lattice import norm
from stickslip.models.lattice.params import LatticeParams
from stickslip.models.params import ParameterError, steps_for
from stickslip.run.lattice import LatticeState, LatticeStepper, initial_state

__all__ = ["NORM", "LatticeEngine", "LatticeSequences", "lattice_lyapunov"]

NORM = (
    "Euclidean norm of (sqrt(K) e, v, theta), e the springs' extensions along each line from the pulled side "
    "(sqrt(Kp) x with a plate)"
)


class LatticeEngine:
    """The lattice's map for :func:`~stickslip.analysis.dynamics.benettin.two_trajectory_exponent`:
    states are :class:`~stickslip.run.lattice.LatticeState`, separations in the lattice's norm,
    twins on the reference's branch; no neutral direction removed and no waiting (the grid's
    map, as :class:`stickslip.analysis.dynamics.lyapunov.GridEngine`).

    Parameters
    ----------
    params : LatticeParams
        The model on its lattice; both trajectories run its dense integrator.
    """

    method = METHOD
    norm = NORM
    max_wait = 0

    def __init__(self, params: LatticeParams):
        self.params = params
        self.lat = params.lattice
        self.blocks = self.lat.blocks()
        self.stepper = LatticeStepper(params)

    def advance(self, ref: LatticeState, twin: LatticeState, step: int) -> tuple[LatticeState, LatticeState, int]:
        """Both to ``step``; the reference's slip events on the way."""
        ref, n_events = self.stepper.advance(ref, step)
        twin, _ = self.stepper.advance(twin, step)
        return ref, twin, n_events

    def step(self, ref: LatticeState) -> int:
        """The reference's step."""
        return ref.step

    def separation(self, ref: LatticeState, twin: LatticeState) -> np.ndarray:
        """twin - ref in the lattice's norm (:func:`stickslip.models.lattice.norm.coordinates`)."""
        b = self.blocks
        dx, dv, dth = twin.xg[b] - ref.xg[b], twin.vg[b] - ref.vg[b], twin.thg[b] - ref.thg[b]
        return norm.coordinates(self.lat, dx, dv, dth, self.params)

    def twin(self, ref: LatticeState, direction: np.ndarray, d0: float) -> LatticeState:
        """ref + d0 * direction (y coordinates), projected onto the reference's branch (no velocity
        on its stuck blocks, no theta without a state variable) and normalised; positions from
        the extensions (:func:`stickslip.models.lattice.norm.displacement`)."""
        b, n = self.blocks, self.blocks.size
        stopped = ref.mov[b] == 0.0
        u = norm.on_branch(direction, stopped, self.params.friction_piece.has_state)
        size = float(np.linalg.norm(u))
        if not size > 0.0:
            raise ValueError("the separation vanished on the reference's branch; cannot renormalise")
        u = u * (d0 / size)
        x = ref.xg[b] + norm.displacement(self.lat, u[:n], self.params)
        v = np.where(stopped, 0.0, ref.vg[b] + u[n : 2 * n])
        th = ref.thg[b] + u[2 * n :]
        shape = self.lat.shape
        twin = LatticeState.from_blocks(
            self.lat, x.reshape(shape), v.reshape(shape), th.reshape(shape), stopped.reshape(shape)
        )
        twin.ist[layout.STEP] = ref.step
        return twin

    def on_branch(self, dy: np.ndarray, ref: LatticeState) -> np.ndarray:
        """No velocity on the reference's stuck blocks."""
        return norm.on_branch(dy, ref.mov[self.blocks] == 0.0)

    def same_branch(self, ref: LatticeState, twin: LatticeState) -> bool:
        """Whether both have the same blocks stuck."""
        return bool(np.array_equal(ref.mov[self.blocks], twin.mov[self.blocks]))

    def neutral(self, ref: LatticeState) -> None:
        """None: nothing is removed."""
        return None

    def fingerprint(self, ref: LatticeState) -> str:
        """:meth:`stickslip.run.lattice.LatticeState.sha256`."""
        return ref.sha256(self.lat)


def lattice_lyapunov(
    params: LatticeParams,
    t_end: float,
    *,
    interval: float = 10.0,
    d0: float = 1e-10,
    transient: float = 0.0,
    align: float | None = None,
    start: str | LatticeState = "paper",
    perturbation: float = 0.0,
    seed: int = 0,
    direction_seed: int = 0,
    segments: int = 10,
) -> LyapunovResult:
    """Largest Lyapunov exponent of a model on a lattice by the two-trajectory method of
    Benettin et al. (1980), in the lattice's norm (module docstring).

    The reference runs alone from ``start`` (:func:`stickslip.run.lattice.initial_state`, or a
    state) to ``transient``; a twin is placed d0 away in a random direction
    (``default_rng(direction_seed)``); both advance by ``interval``, the distance is measured and
    the twin put back d0 away along the separation. Counted and averaged as in
    :func:`stickslip.analysis.dynamics.lyapunov.largest_lyapunov` (its parameters are these).

    Parameters
    ----------
    params : LatticeParams
        The model on its lattice.
    t_end : float
        The reference's last time.
    interval : float
        Time between two renormalisations.
    d0 : float
        The twin's distance after each renormalisation, in the lattice's norm.
    transient : float
        The reference's time alone before the twin is placed.
    align : float, optional
        Time the twin first runs without counting (as ``largest_lyapunov``'s).
    start : str or LatticeState
        The reference's start (:func:`stickslip.run.lattice.initial_state`), or a state.
    perturbation : float
        The start's perturbation amplitude.
    seed : int
        The start's seed.
    direction_seed : int
        The seed of the twin's first direction.
    segments : int
        Segments of the error estimate.

    Returns
    -------
    LyapunovResult
        The exponent per unit time and its error, the renormalisations, the reference's events
        and final state hash, every interval's ln(d / d0).

    Examples
    --------
    >>> from stickslip import chain_params
    >>> p = chain_params(lattice="square", shape=(1, 6))
    >>> res = lattice_lyapunov(p, 1000.0, interval=10.0)
    >>> res.renormalisations
    90
    """
    if not isinstance(params, LatticeParams):
        raise ParameterError("lattice_lyapunov needs a model on a lattice (chain_params(..., lattice=..., shape=...))")
    t_end, interval, d0, transient, align, segments = check_run(params, t_end, interval, d0, transient, align, segments)
    engine = LatticeEngine(params)
    wall0 = time.perf_counter()
    if isinstance(start, LatticeState):
        ref = start.copy()
    else:
        ref = initial_state(params, start, amplitude=perturbation, seed=seed)
    ref, _ = engine.stepper.advance(ref, steps_for(transient, params.dt, "transient"))
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
        extra={"frame": "absolute", "lattice": params.lattice.describe()},
        wall0=wall0,
    )


class LatticeSequences:
    """Slip sequences of a model on a lattice for
    :func:`~stickslip.analysis.dynamics.decorrelation.sequence_decorrelation` (the map of
    :func:`stickslip.run.lattice.run_lattice`): each slip a row of t_start, moment, epicentre
    (row-major index over the blocks, 0-based) and area, the chain's size, start block and blocks
    moved. The twin is :meth:`LatticeEngine.twin`, the reference's state moved by delta in the
    lattice's norm on its branch; the clock runs on (a twin differs in its state only).

    Parameters
    ----------
    params : LatticeParams
        The model on its lattice.
    """

    switches = "grid"

    def __init__(self, params: LatticeParams):
        self.params = params
        self.engine = LatticeEngine(params)

    def prepare(self, state: LatticeState) -> LatticeState:
        """A copy of the start state (the drive's clock is kept)."""
        return state.copy()

    def twin(self, params: LatticeParams, state: LatticeState, direction: np.ndarray, delta: float) -> LatticeState:
        """``state`` moved by delta along ``direction`` (y of the lattice's norm), theta kept in the
        law's range."""
        out = self.engine.twin(state, direction, delta)
        bounds = params.friction_piece.theta_range
        if bounds is not None:  # a stuck block's theta at the end of its range stays in it
            np.clip(out.thg, bounds[0], bounds[1], out=out.thg)
        return out

    def run(self, params: LatticeParams, state: LatticeState, step: int) -> tuple[LatticeState, np.ndarray]:
        """``state`` run to ``step``; its slips completed on the way as rows of t_start, moment,
        epicentre (row-major, 0-based) and area."""
        from stickslip.run.lattice import epicentre_index, run_lattice

        run = run_lattice(params, step * params.dt, start=state)
        ev = run.events
        if not len(ev):
            return run.state, np.zeros((0, 4))
        epicentre = epicentre_index(ev, params.lattice)
        return run.state, np.column_stack((ev["t_start"], ev["moment"], epicentre, ev["area"])).astype(float)
