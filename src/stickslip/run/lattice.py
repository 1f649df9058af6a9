"""Runs of a model on a lattice (docs/lattice.md): the state, its starts, the reference
integrator's loop and the results (events with area, moment, epicentre and extent; the final
state and snapshots as fields over (row, col)).

:func:`run_lattice` integrates a :class:`~stickslip.models.lattice.params.LatticeParams` with
:func:`stickslip.kernels.lattice.run_lattice_dense`. On the chain lattice its steps are those of
:func:`stickslip.run.driver.run_chain` with the dense integrator, bit for bit.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from stickslip.kernels import layout
from stickslip.models.lattice import module_of
from stickslip.models.lattice.params import LatticeParams
from stickslip.models.lattice.samples import SAMPLES, sample
from stickslip.models.params import MAX_PERTURBATION, ParameterError, check_number, steps_for
from stickslip.run.errors import NonFiniteState

STARTS = ("paper", "steady", "rest")
#: Rows of the event buffer between two drains.
EVENT_ROWS = 4096


@dataclass
class LatticeState:
    """The state of a model on a lattice: flat padded arrays of the lattice's layout, ghost cells
    included (xg, vg, thg: x, v, theta; the moving mask 1.0/0.0, the event bookkeeping) and the
    kernels' int64 vector ``ist``; :meth:`fields` gives the blocks over (row, col)."""

    xg: np.ndarray
    vg: np.ndarray
    thg: np.ndarray
    mov: np.ndarray
    first_step: np.ndarray
    x0ev: np.ndarray
    ist: np.ndarray

    @classmethod
    def from_blocks(cls, lat, x, v, theta, stopped) -> LatticeState:
        """A state from per-block values (arrays of the lattice's (rows, cols), or scalars)."""
        stopped = np.broadcast_to(np.asarray(stopped, dtype=bool), lat.shape)
        x = lat.padded(np.broadcast_to(np.asarray(x, dtype=float), lat.shape)) + 0.0
        v = lat.padded(np.where(stopped, 0.0, np.broadcast_to(np.asarray(v, dtype=float), lat.shape))) + 0.0
        th = lat.padded(np.broadcast_to(np.asarray(theta, dtype=float), lat.shape)) + 0.0
        mov = lat.padded(np.where(stopped, 0.0, 1.0))
        ist = np.zeros(layout.IST_SIZE, dtype=np.int64)
        ist[layout.N_MOVING] = int(np.count_nonzero(~stopped))
        first = np.full(lat.size, -1, dtype=np.int64)
        return cls(x, v, th, mov, first, np.zeros(lat.size), ist)

    @property
    def step(self) -> int:
        return int(self.ist[layout.STEP])

    def copy(self) -> LatticeState:
        """A copy of every array."""
        return LatticeState(**{k: np.array(getattr(self, k)) for k in self.__dataclass_fields__})

    def sha256(self, lat) -> str:
        """SHA-256 of x, v, theta (float64 little-endian, the blocks in row-major order) then
        stopped (1 byte each): on the chain lattice, :meth:`stickslip.run.state.ChainState.sha256`."""
        h = hashlib.sha256()
        for a in (self.xg, self.vg, self.thg):
            h.update(np.ascontiguousarray(lat.grid(a).ravel(), dtype="<f8").tobytes())
        h.update((lat.grid(self.mov).ravel() == 0.0).astype(np.uint8).tobytes())
        return h.hexdigest()

    def fields(self, lat) -> dict[str, np.ndarray]:
        """x, v, theta and stopped over (row, col)."""
        return {
            "x": lat.grid(self.xg),
            "v": lat.grid(self.vg),
            "theta": lat.grid(self.thg),
            "stopped": lat.grid(self.mov) == 0.0,
        }


def steady_fields(p: LatticeParams) -> dict[str, np.ndarray]:
    """Steady sliding on the lattice at t = 0 (docs/lattice.md): every block at v = V with
    theta_0 and friction c of the law's steady sliding, and x solving the force balance
    K lap(x) + (the drive's term) = c with the lattice's ghost cells (the load point at 0),
    a sparse linear solve. Edge drives and the plate drive; a fixed side (a wall that the load
    point leaves behind) has none."""
    from scipy.sparse import identity
    from scipy.sparse.linalg import spsolve

    if p.per_block():
        raise ParameterError("start steady with per-block parameters is not yet available on a lattice")
    lat = p.lattice
    edges = lat.edges if lat.name == "square" else (lat.left, lat.right)
    if "fixed" in edges:
        raise ParameterError("start steady: a fixed edge has no steady sliding (the wall stays behind the load)")
    if (
        p.drive_piece.applied is not None
        or p.drive_piece.pull_velocity is not None
        or not p.drive_piece.steady_sliding
        or p.friction_piece.steady is None
    ):
        raise ParameterError(
            f"start steady needs a drive at the velocity V and a law with steady sliding (got {p.drive}, {p.friction})"
        )
    c, theta0 = p.friction_piece.steady(p.chain)
    A = p.K * lat.laplacian_matrix() - p.leaf() * identity(lat.n_blocks, format="csr")
    x = spsolve(A.tocsc(), np.full(lat.n_blocks, c)).reshape(lat.shape)
    return {"x": x, "v": np.full(lat.shape, p.V), "theta": np.full(lat.shape, theta0)}


def initial_state(p: LatticeParams, start: str = "paper", *, amplitude: float = 0.0, seed: int = 0) -> LatticeState:
    """``paper``: x = 0, v = 0.1, theta = the law's start, all moving (section 3); ``rest``: all
    stuck at x = -A u, u = ``default_rng(seed).random`` in row-major order (Carlson-Langer's);
    ``steady``: :func:`steady_fields`, x and v of every block shifted by uniform numbers in
    [-A, A] (all of x's, then all of v's, as the chain's ``steady``)."""
    amplitude = check_number("perturbation", amplitude, low=0.0, high=MAX_PERTURBATION)
    lat, n = p.lattice, p.lattice.n_blocks
    theta = p.friction_piece.start_theta(p.chain)
    if start == "paper":
        return LatticeState.from_blocks(lat, 0.0, 0.1, theta, False)
    if start == "rest":
        u = np.random.default_rng(seed).random(n) if amplitude > 0 else np.zeros(n)
        return LatticeState.from_blocks(lat, (-amplitude * u).reshape(lat.shape), 0.0, theta, True)
    if start == "steady":
        s = steady_fields(p)
        if amplitude > 0:
            rng = np.random.default_rng(seed)
            s["x"] = s["x"] + rng.uniform(-amplitude, amplitude, n).reshape(lat.shape)
            s["v"] = s["v"] + rng.uniform(-amplitude, amplitude, n).reshape(lat.shape)
        return LatticeState.from_blocks(lat, s["x"], s["v"], s["theta"], False)
    raise ParameterError(f"start must be one of {', '.join(STARTS)} (got {start!r})")


def start_defaults(p: LatticeParams, start: str | None = None, perturbation: float | None = None) -> tuple[str, float]:
    """The start of a run of ``p`` where none is given, and its size A (:func:`initial_state`):
    ``rest`` for a drive with a leaf spring (Carlson-Langer's, A = 0.01), else the paper's
    (section 3, never perturbed); a ``rest`` start with no A given gets 0.01, another 0."""
    start = start or ("rest" if p.drive_piece.leaf_spring else "paper")
    if perturbation is None:
        perturbation = 0.01 if start == "rest" else 0.0
    return start, perturbation


@dataclass
class LatticeRun:
    """A run on a lattice: ``events`` (one row per slip event: steps and times, epicentre row and
    column, area, moment, bounding box), the final ``state``, ``snapshots`` of x, v, theta and
    stopped over (time, row, col) (None unless asked for) and a ``summary``."""

    params: LatticeParams
    events: pd.DataFrame
    state: LatticeState
    snapshots: xr.Dataset | None
    summary: dict[str, Any] = field(default_factory=dict)
    #: samples every ``sample_every``: t and the declared reductions of
    #: :data:`~stickslip.models.lattice.samples.SAMPLES` (the mean slip deficit, the mean velocity,
    #: the number of moving blocks, the mean stress); None unless asked for
    samples: pd.DataFrame | None = None
    #: the slip field and the first-move step of each block over (event, row, col) of the events
    #: asked for (``slip_maps`` of :func:`run_lattice`); None unless asked for
    event_fields: xr.Dataset | None = None

    def __repr__(self) -> str:
        return (
            f"LatticeRun({self.params.lattice.describe()}, {self.params.model}, "
            f"t_end={self.summary.get('t_end')}, events={len(self.events)})"
        )

    @property
    def plot(self):
        """This run's figures (:class:`stickslip.plotting.lattice.LatticePlots`), lent to it by
        :mod:`stickslip.accessors`: ``run.plot.snapshot()``, ``.event()``, ``.rupture()``."""
        from stickslip import accessors

        return accessors.accessor("lattice_plot", self)

    def plot_snapshot(self, t: float | None = None, *, fields=("x", "v", "stopped")):
        """x, v and stopped over (row, col) as images, at the end or at the snapshot nearest ``t``:
        :func:`stickslip.plotting.lattice.snapshot_images`; returns the Figure."""
        return self.plot.snapshot(t, fields=fields)

    def plot_event(self, event: int | None = None):
        """The slip map of a recorded event (the largest by default) with its rupture front's
        contours: :func:`stickslip.plotting.lattice.slip_map`; returns the Figure."""
        return self.plot.event(event)

    def plot_rupture(self, event: int | None = None, *, frames: int = 6):
        """The rupture front of a recorded event as a sequence of ``frames`` images:
        :func:`stickslip.plotting.lattice.rupture_frames`; returns the Figure."""
        return self.plot.rupture(event, frames=frames)

    def final(self) -> xr.Dataset:
        """The final state as fields over (row, col)."""
        f = self.state.fields(self.params.lattice)
        return _dataset(f, self.params)

    def write(self, out: str | Path) -> Path:
        """Write run.json (parameters, summary), events.csv and state.nc (the final state and the
        per-block parameters over (row, col), the snapshots over (time, row, col)) into the
        directory ``out``, and event_fields.nc where events' fields were recorded."""
        from stickslip import io

        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        io.write_json(out / "run.json", {"params": self.params.to_dict(), "summary": self.summary})
        io.write_csv(out / "events.csv", self.events)
        if self.samples is not None:
            io.write_csv(out / "samples.csv", self.samples)
        ds = self.final()
        for name, pb in self.params.per_block().items():
            # the per-block parameters over (row, col), as the chain's state.nc holds them over block
            ds[f"param_{name}"] = (("row", "col"), np.reshape(pb.values, self.params.lattice.shape))
            ds[f"param_{name}"].attrs.update({"spec": pb.spec_text, "sha256": pb.sha256})
        if self.snapshots is not None:
            ds = ds.merge(self.snapshots.rename({k: f"snapshot_{k}" for k in self.snapshots.data_vars}))
        io.write_dataset(out / "state.nc", ds)
        if self.event_fields is not None:
            io.write_dataset(out / "event_fields.nc", self.event_fields)
        return out


def _dataset(f: dict[str, np.ndarray], p: LatticeParams, time=None) -> xr.Dataset:
    rows, cols = p.lattice.shape
    dims = ("row", "col") if time is None else ("time", "row", "col")
    coords = {"row": np.arange(1, rows + 1), "col": np.arange(1, cols + 1)}
    if time is not None:
        coords["time"] = np.asarray(time)
    data = {k: (dims, np.asarray(v)) for k, v in f.items()}
    attrs = {k: str(v) for k, v in p.to_dict().items()}
    return xr.Dataset(data, coords=coords, attrs=attrs)


def _kernel(p: LatticeParams, args, sparse):
    """The compiled integrator for the model: the active-set path where ``sparse`` is given, else
    the dense reference; called with the current LatticeArgs."""
    from stickslip.kernels import entry
    from stickslip.kernels.lattice import run_lattice_dense
    from stickslip.kernels.lattice_sparse import run_lattice_sparse

    pieces = (p.drive_piece.module, p.friction_piece.module, p.threshold_piece.module, module_of(p.lattice.name))
    if sparse is None:
        fn = entry.specialise(run_lattice_dense, args, pieces)
        return lambda a: fn(a, *pieces)
    fn = entry.specialised(run_lattice_sparse, (args, sparse, *pieces), literal=(2, 3, 4, 5))
    return lambda a: fn(a, sparse, *pieces)


def sparse_path(p: LatticeParams) -> bool:
    """Whether the active-set exact path applies (:mod:`stickslip.kernels.lattice_sparse`): the
    model's stopped blocks keep every bit until a neighbour moves or the drive starts them."""
    from stickslip.models.pieces import stopped_blocks_still

    return stopped_blocks_still(p.drive_piece, p.friction_piece)


def _sparse_args(p: LatticeParams):
    from stickslip.kernels.lattice_sparse import B_FRESH, BOOK_SIZE, SparseArgs
    from stickslip.kernels.layout import _NEVER

    size = p.lattice.size
    book = np.zeros(BOOK_SIZE, dtype=np.int64)
    book[B_FRESH] = 1
    ints = lambda: np.zeros(size, dtype=np.int64)  # noqa: E731
    return SparseArgs(
        ints(), ints(), ints(), np.full(size, -1, dtype=np.int64), np.full(size, _NEVER, dtype=np.int64),
        np.zeros(2 * size + 16, dtype=np.int64), np.zeros(2 * size + 16, dtype=np.int64), ints(),
        np.zeros((size, 5), dtype=np.int32), book,
    )  # fmt: skip


def _sparse_counts(sparse) -> dict[str, int]:
    """The active-set path's own counts of this run: block updates of blocks that moved, and
    triggers computed (blocks that left the candidates); none for the dense path."""
    from stickslip.kernels.lattice_sparse import B_MOVING_UPDATES, B_TRIGGERS

    if sparse is None:
        return {}
    return {"moving_block_updates": int(sparse.book[B_MOVING_UPDATES]), "triggers": int(sparse.book[B_TRIGGERS])}


def _args(p: LatticeParams, s: LatticeState, scratch, ev_int, ev_moment, n_end: int):
    from stickslip.kernels.lattice import LatticeArgs
    from stickslip.run.loop import _par

    mass = p.kernel_mass()
    tp, lp = p.kernel_params(p.threshold_piece), p.kernel_params(p.friction_piece)
    dp = p.kernel_params(p.drive_piece)
    geo = p.lattice.geometry()
    return LatticeArgs(
        s.xg, s.vg, s.thg, s.mov, *scratch, s.first_step, s.x0ev, geo, s.ist, _par(p.chain), dp, tp, lp, mass,
        ev_int, ev_moment, np.int64(n_end),
    )  # fmt: skip


def _event_table(p: LatticeParams, ev_int: np.ndarray, moment: np.ndarray) -> pd.DataFrame:
    from stickslip.kernels import lattice as kl

    W = p.lattice.width
    epi = ev_int[:, kl.L_EPICENTRE]
    chain = p.lattice.name == "chain"
    return pd.DataFrame(
        {
            "event": ev_int[:, kl.L_ID],
            "step_start": ev_int[:, kl.L_START_STEP],
            "step_end": ev_int[:, kl.L_END_STEP],
            "t_start": ev_int[:, kl.L_START_STEP] * p.dt,
            "t_end": (ev_int[:, kl.L_END_STEP] + 1) * p.dt,
            "epicentre_row": np.ones_like(epi) if chain else epi // W,
            "epicentre_col": epi if chain else epi % W,
            "area": ev_int[:, kl.L_AREA],
            "moment": moment,
            "row_min": ev_int[:, kl.L_ROW_MIN],
            "row_max": ev_int[:, kl.L_ROW_MAX],
            "col_min": ev_int[:, kl.L_COL_MIN],
            "col_max": ev_int[:, kl.L_COL_MAX],
        }
    )


def epicentre_index(events: pd.DataFrame, lat) -> np.ndarray:
    """The epicentres of a lattice's event table as row-major indices over its blocks, 0-based:
    (epicentre_row - 1) cols + epicentre_col - 1 (the chain lattice's block i - 1)."""
    cols = lat.shape[1]
    return ((np.asarray(events["epicentre_row"]) - 1) * cols + np.asarray(events["epicentre_col"]) - 1).astype(np.int64)


def run_lattice(
    p: LatticeParams,
    t_end: float,
    *,
    start: str | LatticeState = "paper",
    perturbation: float = 0.0,
    seed: int = 0,
    snapshot_every: float | None = None,
    sample_every: float | None = None,
    integrator: str = "exact",
    slip_maps: int = 0,
    slip_min_area: int = 1,
) -> LatticeRun:
    """Integrate the model ``p`` on its lattice to ``t_end`` (docs/lattice.md): with the
    active-set exact path where it applies, else with the reference integrator
    (:func:`stickslip.kernels.lattice.run_lattice_dense`); both give the same bits.

    Parameters
    ----------
    p : LatticeParams
        The model on its lattice (:func:`stickslip.chain_params` with ``lattice``, ``shape``).
    t_end : float
        End time; the steps are n = 0 .. round(t_end / dt).
    start : {'paper', 'steady', 'rest'} or LatticeState
        The start (:func:`initial_state`), or a state to continue (copied).
    perturbation, seed : float, int
        The size A and the seed of the draws of ``steady`` and ``rest``.
    snapshot_every : float, optional
        Time between snapshots of x, v, theta and stopped over (row, col), from t = 0.
    sample_every : float, optional
        Time between samples of the declared reductions (:attr:`LatticeRun.samples`).
    integrator : {'exact', 'dense'}
        ``exact``: the active-set path (:mod:`stickslip.kernels.lattice_sparse`) where the model's
        stopped blocks keep every bit (a drive on every block, a friction without theta), the
        dense reference otherwise; ``dense``: the reference. Both give the same bits.
    slip_maps : int
        Record the slip field and each block's first-move step of the ``slip_maps`` largest
        events by moment (:attr:`LatticeRun.event_fields`, :mod:`stickslip.run.lattice_fields`;
        at most :data:`~stickslip.run.lattice_fields.MAX_SLIP_MAPS`). 0 (the default) records none
        and leaves the run as it is; with it the kernel returns after every event.
    slip_min_area : int
        Only events of at least this area (blocks) are recorded.

    Returns
    -------
    LatticeRun
        Events with area, moment, epicentre and extent; the final state; snapshots.
    """
    if not isinstance(p, LatticeParams):
        raise ParameterError("run_lattice needs a model on a lattice (chain_params(..., lattice=..., shape=...))")
    if integrator not in ("exact", "dense"):
        raise ParameterError(f"integrator must be exact or dense (got {integrator!r})")
    n_end = steps_for(t_end, p.dt, "t_end")
    if isinstance(start, LatticeState):
        if start.xg.shape != (p.lattice.size,):
            raise ParameterError(f"start holds {start.xg.size} cells, the lattice's layout {p.lattice.size}")
        s = start.copy()
    else:
        s = initial_state(p, start, amplitude=perturbation, seed=seed)
    every = _every(p, snapshot_every, "snapshot_every")
    every_sample = _every(p, sample_every, "sample_every")
    size = p.lattice.size
    scratch = [np.zeros(size) for _ in range(6)]
    ev_int = np.zeros((EVENT_ROWS, 9), dtype=np.int64)
    ev_moment = np.zeros(EVENT_ROWS)
    from stickslip.run.lattice_fields import EventFields

    maps = EventFields(p, slip_maps, slip_min_area)  # checked whether asked for or not
    if maps.largest:
        ev_int, ev_moment = ev_int[:1], ev_moment[:1]  # the kernel returns after each event
    else:
        maps = None
    sparse = _sparse_args(p) if integrator == "exact" and sparse_path(p) else None
    call = _kernel(p, _args(p, s, scratch, ev_int, ev_moment, n_end), sparse)
    rows, moments, snaps, times, samples = [], [], [], [], []
    while True:
        _record(p, s, every, snaps, times, every_sample, samples)
        target = min(n_end, _next(s.step, every), _next(s.step, every_sample))
        pre = s.copy() if maps is not None else None
        status = call(_args(p, s, scratch, ev_int, ev_moment, target))
        k = int(s.ist[layout.EV_COUNT])
        rows.append(ev_int[:k].copy())
        moments.append(ev_moment[:k].copy())
        if maps is not None and k:
            maps.offer(pre, ev_int[0], float(ev_moment[0]))
        s.ist[layout.EV_COUNT] = 0
        if status == layout.NONFINITE:
            raise NonFiniteState(f"the run became non-finite at step {s.step} (flat index {s.ist[layout.BAD_BLOCK]})")
        if status == layout.DONE and s.step >= n_end:
            break
    _record(p, s, every, snaps, times, every_sample, samples)
    events = _event_table(p, np.concatenate(rows), np.concatenate(moments))
    snapshots = None
    if snaps:
        stacked = {k: np.stack([f[k] for f in snaps]) for k in snaps[0]}
        snapshots = _dataset(stacked, p, time=np.asarray(times) * p.dt)
    sample_table = pd.DataFrame(samples, columns=["t", *(r.name for r in SAMPLES)]) if samples else None
    summary = {
        "integrator": "dense" if sparse is None else "exact",
        "steps_computed": int(s.ist[layout.STEPS_COMPUTED]),
        "block_updates": int(s.ist[layout.BLOCK_UPDATES]),
        "lattice": p.lattice.describe(),
        "t_end": n_end * p.dt,
        "steps": n_end,
        "events": len(events),
        "moving_at_end": int(s.ist[layout.N_MOVING]),
        **_sparse_counts(sparse),
        "state_sha256": s.sha256(p.lattice),
    }
    fields = maps.dataset(_replay) if maps is not None else None
    return LatticeRun(p, events, s, snapshots, summary, sample_table, fields)


def _replay(p: LatticeParams, pre: LatticeState, step_end: int) -> tuple[LatticeState, np.ndarray, float]:
    """The event that closes in step ``step_end``, run again by the dense reference from ``pre``
    (a state before its end, whatever the integrator that made it: both give the same bits):
    (the state after it, each block's first-move step in it (-1: none), its moment)."""
    s = pre.copy()
    scratch = [np.zeros(p.lattice.size) for _ in range(6)]
    ev_int, ev_moment = np.zeros((1, 9), dtype=np.int64), np.zeros(1)
    call = _kernel(p, _args(p, s, scratch, ev_int, ev_moment, step_end), None)
    call(_args(p, s, scratch, ev_int, ev_moment, step_end))
    first = s.first_step.copy()  # reset by the event's end, so read before its last step
    s.x0ev[first < 0] = np.nan
    call(_args(p, s, scratch, ev_int, ev_moment, step_end + 1))
    from stickslip.kernels.lattice import L_END_STEP

    if int(s.ist[layout.EV_COUNT]) != 1 or int(ev_int[0, L_END_STEP]) != step_end:
        raise RuntimeError(f"the replay of the event ending at step {step_end} did not end there")
    first[(first < 0) & ~np.isnan(s.x0ev)] = step_end  # blocks whose first move was the last step
    return s, first, float(ev_moment[0])


class LatticeStepper:
    """Advance lattice states of one model to given steps with no outputs kept: the loop of
    :func:`run_lattice` without its tables, for methods that restart short runs many times
    (:mod:`stickslip.analysis.dynamics.lyapunov_lattice`). It runs the dense reference, which
    gives the bits of either integrator and keeps no bookkeeping of its own between calls, so
    any number of states (a reference and its twins) share one stepper."""

    def __init__(self, p: LatticeParams):
        self.p = p
        self.scratch = [np.zeros(p.lattice.size) for _ in range(6)]
        self.ev_int = np.zeros((EVENT_ROWS, 9), dtype=np.int64)
        self.ev_moment = np.zeros(EVENT_ROWS)
        self._call = None

    def advance(self, s: LatticeState, step: int) -> tuple[LatticeState, int]:
        """Advance ``s`` in place to ``step``; returns it and the slip events completed."""
        events0 = int(s.ist[layout.N_EVENTS])
        while True:
            args = _args(self.p, s, self.scratch, self.ev_int, self.ev_moment, step)
            if self._call is None:
                self._call = _kernel(self.p, args, None)
            status = self._call(args)
            s.ist[layout.EV_COUNT] = 0
            if status == layout.NONFINITE:
                raise NonFiniteState(
                    f"the run became non-finite at step {s.step} (flat index {s.ist[layout.BAD_BLOCK]})"
                )
            if status == layout.DONE:
                return s, int(s.ist[layout.N_EVENTS]) - events0


def _every(p: LatticeParams, interval: float | None, name: str) -> int:
    """An output interval in steps (0: none)."""
    if interval is None:
        return 0
    return max(1, int(round(check_number(name, interval, low=0.0, low_open=True) / p.dt)))


def _next(step: int, every: int) -> int:
    """The next multiple of ``every`` after ``step`` (a huge number for no output)."""
    return (step // every + 1) * every if every else np.iinfo(np.int64).max


def _record(p: LatticeParams, s: LatticeState, every: int, snaps, times, every_sample: int, samples) -> None:
    """The snapshot and the sample due at the state's step, once each."""
    n = s.step
    if every and n % every == 0 and (not times or times[-1] != n):
        snaps.append(s.fields(p.lattice))
        times.append(n)
    if every_sample and n % every_sample == 0 and (not samples or samples[-1][0] != n * p.dt):
        samples.append(sample(p, s, n))


#: The lattice bench's workload for a model whose drive pulls every block by a leaf spring
#: (Carlson-Langer, Burridge-Knopoff; docs/lattice.md, "Speed"): slow loading, V = 0.001 unless
#: given, prepared over two loading times 2 / V from rest, then timed over 20 time units.
SLOW_LOADING = {"V": 1e-3, "loading_times": 2.0, "t_timed": 20.0}


def bench_lattice(p: LatticeParams, t_timed: float, *, t_prepare: float = 0.0, repeat: int = 1) -> dict[str, Any]:
    """Dense against exact on one workload, in one process (docs/lattice.md, "Speed"): the model
    run by exact from ``rest`` (Carlson-Langer's start, A = 0.01) to ``t_prepare``, then continued
    for ``t_timed`` by each integrator (both compiled first), alternated ``repeat`` times, the
    fastest kept (wall-clock and processor seconds); whether their states and events are
    identical, the work each did and its cost per block update, the exact path's block updates
    per update of a block that moved, and the events' mean area (the cost per event against
    its size, at any L)."""
    import time

    repeat = int(check_number("repeat", repeat, low=1, integer=True))
    prep = run_lattice(p, t_prepare, start="rest", perturbation=0.01, integrator="exact")
    t0_end = prep.summary["t_end"]
    t_end = t0_end + check_number("t-end", t_timed, low=0.0, low_open=True)
    for integrator in ("dense", "exact"):  # compile both outside the timings
        run_lattice(p, t0_end + 2 * p.dt, start=prep.state, integrator=integrator)
    best: dict[str, float] = {}
    cpu: dict[str, float] = {}
    runs: dict[str, LatticeRun] = {}
    for _ in range(repeat):
        for integrator in ("dense", "exact"):
            t0, c0 = time.perf_counter(), time.process_time()
            runs[integrator] = run_lattice(p, t_end, start=prep.state, integrator=integrator)
            best[integrator] = min(best.get(integrator, np.inf), time.perf_counter() - t0)
            cpu[integrator] = min(cpu.get(integrator, np.inf), time.process_time() - c0)
    dense, exact = runs["dense"], runs["exact"]
    before = prep.summary["block_updates"]
    du = dense.summary["block_updates"] - before
    eu = exact.summary["block_updates"] - before
    moving = exact.summary.get("moving_block_updates")
    steps = exact.summary["steps"] - prep.summary["steps"]
    ev = exact.events
    return {
        "lattice": p.lattice.describe(),
        "model": p.model,
        "V": p.V,
        "blocks": p.lattice.n_blocks,
        "t_prepare": t0_end,
        "t_timed": t_end - t0_end,
        "steps": steps,
        "dense_seconds": best["dense"],
        "exact_seconds": best["exact"],
        "speedup": best["dense"] / best["exact"],
        "dense_cpu_seconds": cpu["dense"],
        "exact_cpu_seconds": cpu["exact"],
        "cpu_speedup": cpu["dense"] / cpu["exact"],
        "identical": dense.summary["state_sha256"] == exact.summary["state_sha256"] and dense.events.equals(ev),
        "exact_integrator": exact.summary["integrator"],
        "events": len(ev),
        "event_area_mean": float(ev["area"].mean()) if len(ev) else 0.0,
        "dense_block_updates": du,
        "exact_block_updates": eu,
        "dense_ns_per_block_update": 1e9 * cpu["dense"] / max(du, 1),
        "exact_ns_per_block_update": 1e9 * cpu["exact"] / max(eu, 1),
        "exact_moving_block_updates": moving,
        "exact_updates_per_moving_update": eu / moving if moving else None,
        "exact_ns_per_moving_update": 1e9 * cpu["exact"] / moving if moving else None,
        "moving_fraction": moving / (p.lattice.n_blocks * steps) if moving and steps else None,
        "state_sha256": exact.summary["state_sha256"],
    }
