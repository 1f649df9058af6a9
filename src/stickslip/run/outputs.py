"""What a chain run (eq. 4) returns: :class:`ChainRun`, and the output buffers (what a run records
is asked for by :class:`~stickslip.run.options.RunOptions`, also importable from here).

The kernels fill fixed-size buffers (:class:`_Outputs`) that are flushed into Python-side parts;
:func:`_assemble` turns the parts into the event table (docs/model.md, "Slip events"), the first moves
(rupture fronts, Fig. 6), L(t) (Fig. 5b), the snapshots (Fig. 5a), the displacement profiles
(Fig. 6) and the run's summary.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from stickslip.kernels import layout
from stickslip.models import physics
from stickslip.models.params import ChainParams, steps_for
from stickslip.run.options import RunOptions
from stickslip.run.state import ChainState, closed_form

EVENT_COLUMNS = [
    "event",
    "step_start",
    "step_end",
    "t_start",
    "t_end",
    "duration",
    "S",
    "start_block",
    "max_block",
    "n_blocks",
]


@dataclass(repr=False)
class ChainRun:
    """The result of a chain run (eq. 4 or a relative): its slip events, L(t), snapshots,
    displacement profiles and final state, with methods to plot and to save them.

    Made by :func:`~stickslip.run.driver.run_chain` (or read back from a run directory by
    :func:`~stickslip.run.rundir.load_run`). Times are in the model's units (eq. 4 scaled to
    M = sigma = 1, docs/model.md); blocks are numbered 1 (pulled end) to N.

    Attributes
    ----------
    params : ChainParams
        The model and its parameters.
    options : RunOptions
        What the run recorded (t_end, sampling interval, snapshot times, profile window) and its
        integrator (:meth:`RunOptions.recorded`: not where it was written, nor its hooks).
    integrator : str
        ``'exact'`` or ``'dense'`` (the same result bit for bit).
    start : dict
        The start state: its kind (``'paper'``, ``'steady'``, ``'rest'`` or ``'state'``) and draw.
    state : ChainState
        The final state: x_i, v_i, theta_i, which blocks are stuck, the step count.
    events : pandas.DataFrame
        One row per slip event (docs/model.md, "Slip events"), columns:

        ============  =================================================================
        event         event number, 0-based, in order of start
        step_start    first step n in which a block moved (t = n dt)
        step_end      first step that ended with every block stopped again
        t_start       start time, step_start dt (model time units)
        t_end         end time, (step_end + 1) dt (model time units)
        duration      t_end - t_start (model time units)
        S             slip size S = sum_i (x_i(end) - x_i(start)) (model length units; Figs. 7, 8)
        start_block   block that moved first (1..N)
        max_block     farthest block that moved (1..N)
        n_blocks      number of blocks that moved
        ============  =================================================================
    first_move : pandas.DataFrame
        When each block first moved in each event (rupture fronts, Fig. 6): columns ``event``,
        ``block`` (1..N), ``step`` and ``t_first`` = step dt (model time units).
    samples : xarray.Dataset
        ``L`` = x_1 - x_N (model length units) over ``t``, sampled every ``sample_interval``
        (Fig. 5b); with ``sample_moving``, ``n_moving`` over ``t_moving``.
    snapshots : xarray.DataArray
        ``snapshot_x``: x_i (model length units) over (``snapshot_time``, ``block``), at the
        ``snapshot_times`` and the end.
    profiles : xarray.Dataset
        ``profile_dx`` over (``profile_row``, ``block``): x_i(t + W) - x_i(t) over each stored
        window of an event (Fig. 6), with ``profile_event`` (the event's number in ``events``),
        ``profile_t`` (window start) and ``profile_t_next`` (window end) per row.

    Every array has the name it has in the run directory's state.nc (docs/chain.md, "A run directory").
    summary : dict
        Numbers of the run: ``n_events``, ``L_mean``, ``L_steady``, ``t_end``, ``steps``,
        ``wall_seconds``, ``state_sha256`` (the final state's SHA-256), ...

    Examples
    --------
    >>> import stickslip
    >>> run = stickslip.run_chain(stickslip.chain_params(N=10), 2e4)
    >>> run  # doctest: +ELLIPSIS
    ChainRun(eq. (4): N=10, K=10, V=0.001, dt=0.005, beta=1, alpha=1, D=5, Fs=3
             t_end=20000 (4000000 steps, exact), 69 events, L_mean=4.69194
             state sha256 ef0a3122809af663...)
    >>> list(run.events.columns[:4])
    ['event', 'step_start', 'step_end', 't_start']
    """

    params: ChainParams
    options: RunOptions
    integrator: str
    start: dict[str, Any]
    state: ChainState
    events: pd.DataFrame
    first_move: pd.DataFrame
    samples: xr.Dataset
    snapshots: xr.DataArray
    profiles: xr.Dataset
    summary: dict[str, Any]

    @property
    def t_end(self) -> float:
        """The end time the run was asked for (model time units)."""
        return self.options.t_end

    @property
    def steps(self) -> int:
        """Time steps taken (t = steps dt)."""
        return self.state.step

    def __repr__(self) -> str:
        from stickslip.models.presets import model_name

        p = self.params
        values = ", ".join(f"{k}={getattr(p, k):g}" for k in p.used())
        s = self.summary
        return (
            f"ChainRun({model_name(p)}: {values}\n"
            f"         t_end={s['t_end']:g} ({s['steps']} steps, {self.integrator}), {s['n_events']} events, "
            f"L_mean={s['L_mean']:.6g}\n"
            f"         state sha256 {s['state_sha256'][:16]}...)"
        )

    def save(self, out_dir: str | Path, *, overwrite: bool = False) -> Path:
        """Write the run directory ``stickslip chain --out DIR`` writes (run.json, state.nc,
        events and first_move as Parquet and CSV), for :func:`~stickslip.run.rundir.load_run`
        and ``stickslip plot`` to read.

        The folder is owned as the command owns it: a folder holding files a chain run does not
        write, or a run already, is refused with ParameterError; it is locked while written.

        Parameters
        ----------
        out_dir : str or Path
            The run directory; created if missing.
        overwrite : bool
            Replace a run already there (as ``stickslip chain --overwrite``): its files are
            removed first; other files in the folder stay.

        Returns
        -------
        Path
            ``out_dir``.

        Examples
        --------
        >>> import stickslip, tempfile, pathlib
        >>> run = stickslip.run_chain(stickslip.chain_params(N=10), 2e4)
        >>> folder = run.save(pathlib.Path(tempfile.mkdtemp()) / "run1")
        >>> stickslip.load_run(folder).summary["state_sha256"] == run.summary["state_sha256"]
        True
        """
        from stickslip.run.ownership import run_dir_for_run
        from stickslip.run.runfiles import write_run

        with run_dir_for_run(out_dir, overwrite=overwrite):
            return write_run(self, out_dir)

    @property
    def plot(self):
        """This run's figures (:class:`stickslip.plotting.run.RunPlots`): ``run.plot.length()``,
        ``.snapshot(t)``, ``.sizes()``, ``.fronts()``, each returning the Figure drawn in."""
        from stickslip import accessors

        return accessors.accessor("plot", self)

    def plot_length(self, *, ax=None):
        """L(t) against steady sliding: :func:`stickslip.plotting.length`; returns the Figure
        (the Axes ``ax`` when given)."""
        return _drawn(self.plot.length(ax=ax), ax)

    def plot_snapshot(self, t: float | None = None, *, ax=None):
        """The final state (or the snapshot at ``t``) against steady sliding:
        :func:`stickslip.plotting.snapshot`; returns the Figure (the Axes ``ax`` when given)."""
        return _drawn(self.plot.snapshot(t, ax=ax), ax)

    def plot_sizes(self, *, ax=None, bins: int = 30):
        """The slip-size distribution with its fit: :func:`stickslip.plotting.sizes`; returns the
        Figure (the Axes ``ax`` when given)."""
        return _drawn(self.plot.sizes(ax=ax, bins=bins), ax)

    def plot_fronts(self, *, ax=None):
        """The rupture fronts of the largest events: :func:`stickslip.plotting.fronts`; returns the
        Figure (the Axes ``ax`` when given)."""
        return _drawn(self.plot.fronts(ax=ax), ax)


def _drawn(fig, ax):
    """What a ``plot_*`` method returns: the Axes it was given, else the new Figure (as pandas'
    and seaborn's plots on an ``ax`` do)."""
    return fig if ax is None else ax


class _Outputs:
    """Output buffers shared with the kernels, and what has been flushed from them."""

    def __init__(self, N: int, profiling: bool):
        self.ev_int = np.zeros((4096, layout.EV_INT_COLS), dtype=np.int64)
        self.ev_S = np.zeros(4096)
        self.fm = np.zeros((max(65536, 4 * (N + 1)), 3), dtype=np.int64)
        self.samp_L = np.zeros(65536)
        self.samp_step = np.zeros(65536, dtype=np.int64)
        self.samp_moving = np.zeros(65536, dtype=np.int64)
        # The kernels count the moving blocks at each sample of L; kept where the run samples
        # them (set by the driver).
        self.moving_from_kernel = False
        rows = 256 if profiling else 2
        self.prof_x = np.zeros((rows, N))
        self.prof_meta = np.zeros((rows, 2), dtype=np.int64)
        self.parts: dict[str, list[np.ndarray]] = {k: [] for k in PART_KEYS}

    def kernel_args(self):
        return (
            self.ev_int,
            self.ev_S,
            self.fm,
            self.samp_L,
            self.samp_step,
            self.samp_moving,
            self.prof_x,
            self.prof_meta,
        )

    def flush(self, ist: np.ndarray) -> None:
        """Move filled buffer rows into Python-side lists and reset the counts."""
        ne, nf, ns, npr = (
            int(ist[layout.EV_COUNT]),
            int(ist[layout.FM_COUNT]),
            int(ist[layout.S_COUNT]),
            int(ist[layout.P_COUNT]),
        )
        if ne:
            self.parts["ev_int"].append(self.ev_int[:ne].copy())
            self.parts["ev_S"].append(self.ev_S[:ne].copy())
        if nf:
            self.parts["fm"].append(self.fm[:nf].copy())
        if ns:
            self.parts["samp_L"].append(self.samp_L[:ns].copy())
            self.parts["samp_step"].append(self.samp_step[:ns].copy())
            if self.moving_from_kernel:
                self.parts["moving"].append(np.column_stack((self.samp_step[:ns], self.samp_moving[:ns])))
        if npr:
            self.parts["prof_x"].append(self.prof_x[:npr].copy())
            self.parts["prof_meta"].append(self.prof_meta[:npr].copy())
        ist[layout.EV_COUNT] = ist[layout.FM_COUNT] = ist[layout.S_COUNT] = ist[layout.P_COUNT] = 0
        ist[layout.EV_P_FIRST] = 0

    def add_snapshot(self, step: int, x: np.ndarray) -> None:
        """Keep x_1..x_N (``state.x``, no ghost cells) at ``step``."""
        self.parts["snap_step"].append(np.array([step], dtype=np.int64))
        self.parts["snap_x"].append(np.array(x, dtype=np.float64)[None, :])

    def add_moving(self, step: int, n_moving: int) -> None:
        self.parts["moving"].append(np.array([[step, n_moving]], dtype=np.int64))

    def take_new(self, since: dict[str, int]) -> dict[str, np.ndarray]:
        """Concatenate the parts added since ``since`` (counts per key); updates ``since``."""
        out = {}
        for key in PART_KEYS:
            new = self.parts[key][since.get(key, 0) :]
            since[key] = len(self.parts[key])
            out[key] = _concat(key, new)
        return out

    def all(self) -> dict[str, np.ndarray]:
        return {key: _concat(key, self.parts[key]) for key in PART_KEYS}


PART_KEYS = ("ev_int", "ev_S", "fm", "samp_L", "samp_step", "prof_x", "prof_meta", "snap_step", "snap_x", "moving")
_PART_SHAPES = {
    "moving": (0, 2),
    "ev_int": (0, layout.EV_INT_COLS),
    "ev_S": (0,),
    "fm": (0, 3),
    "samp_L": (0,),
    "samp_step": (0,),
    "prof_x": None,
    "prof_meta": (0, 2),
    "snap_step": (0,),
    "snap_x": None,
}
_PART_DTYPES = {
    "moving": np.int64,
    "ev_int": np.int64,
    "fm": np.int64,
    "samp_step": np.int64,
    "prof_meta": np.int64,
    "snap_step": np.int64,
}


def _concat(key: str, arrays: list[np.ndarray]) -> np.ndarray:
    if arrays:
        return np.concatenate(arrays, axis=0)
    shape = _PART_SHAPES[key] or (0, 0)
    return np.zeros(shape, dtype=_PART_DTYPES.get(key, np.float64))


def _assemble(params, options, integrator, start_info, state, outputs, wall, steady_at=None) -> ChainRun:
    dt = params.dt
    state.of(params)  # the final state belongs to the run's model
    parts = outputs.all()
    ev = parts["ev_int"]
    events = pd.DataFrame(
        {
            "event": ev[:, layout.E_ID],
            "step_start": ev[:, layout.E_START_STEP],
            "step_end": ev[:, layout.E_END_STEP],
            "t_start": ev[:, layout.E_START_STEP] * dt,
            "t_end": (ev[:, layout.E_END_STEP] + 1) * dt,
            "duration": (ev[:, layout.E_END_STEP] + 1 - ev[:, layout.E_START_STEP]) * dt,
            "S": parts["ev_S"],
            "start_block": ev[:, layout.E_START_BLOCK],
            "max_block": ev[:, layout.E_MAX_BLOCK],
            "n_blocks": ev[:, layout.E_N_BLOCKS],
        },
        columns=EVENT_COLUMNS,
    )
    fm = parts["fm"]
    first_move = pd.DataFrame({"event": fm[:, 0], "block": fm[:, 1], "step": fm[:, 2], "t_first": fm[:, 2] * dt})
    t_samples = parts["samp_step"] * dt
    samples = xr.Dataset(
        {"L": ("t", parts["samp_L"], {"long_name": "total length x_1 - x_N"})},
        coords={"t": ("t", t_samples, {"long_name": "time t (dimensionless model units)", "units": "1"})},
    )
    if options.sample_moving:
        mv = parts["moving"]
        samples["n_moving"] = xr.DataArray(mv[:, 1], dims="t_moving", attrs={"long_name": "blocks moving"})
        time_attrs = {"long_name": "time t (dimensionless model units)", "units": "1"}
        samples = samples.assign_coords(t_moving=("t_moving", mv[:, 0] * dt, time_attrs))
    blocks = np.arange(1, params.N + 1)
    snap_steps = list(parts["snap_step"]) + [state.step]
    snap_x = np.vstack([parts["snap_x"].reshape(-1, params.N), state.x[None, :]])
    order = np.argsort(snap_steps, kind="stable")
    snapshots = xr.DataArray(
        snap_x[order],
        dims=("snapshot_time", "block"),
        coords={"snapshot_time": np.asarray(snap_steps)[order] * dt, "block": blocks},
        name="snapshot_x",
        attrs={"long_name": "block positions x_i"},
    )
    profiles = _profiles(parts, events, options, params)
    L_final = float(state.x[0] - state.x[-1])
    avg_from = options.average_from if options.average_from is not None else options.t_end / 2
    sel = t_samples >= avg_from - 0.5 * dt
    L_values = parts["samp_L"][sel]
    early: dict[str, Any] = {"stopped_early": False}
    if steady_at:
        # From the stop on, the chain is taken to slide steadily: L = L_ss at the remaining samples.
        L_ss = closed_form(physics.chain_steady_length, params)
        sample_every = int(round(options.sample_interval / dt))
        n_end = steps_for(options.t_end, dt, "t_end")
        later = np.arange((state.step // sample_every + 1) * sample_every, n_end + 1, sample_every) * dt
        n_virtual = int(np.count_nonzero(later >= avg_from - 0.5 * dt))
        L_values = np.concatenate([L_values, np.full(n_virtual, L_ss)])
        L_final = L_ss
        early = {
            "stopped_early": True,
            "reason": (
                f"steady sliding reached at t = {steady_at['t_steady']:g}: every block slides "
                f"within {options.until_steady:g} of the steady state (deviation "
                f"{steady_at['deviation']:.3g}); L taken from the steady solution from then on"
            ),
            "t_steady": steady_at["t_steady"],
            "steady_deviation": steady_at["deviation"],
            "until_steady": options.until_steady,
            "L_final_simulated": float(state.x[0] - state.x[-1]),
        }
    L_mean = float(np.mean(L_values)) if len(L_values) else float("nan")
    summary = {
        "model": params.model,
        **params.pieces,
        **_model_note(params),
        "n_events": int(len(events)),
        "event_in_progress": bool(state.ist[layout.EV_ACTIVE]),
        "L_final": L_final,
        "L_mean": L_mean,
        "L_mean_from": avg_from,
        "L_steady": closed_form(physics.chain_steady_length, params),
        "t_end": options.t_end if steady_at else state.step * dt,
        "t_reached": state.step * dt,
        "steps": state.step,
        "steps_computed": int(state.ist[layout.STEPS_COMPUTED]),
        "block_updates": int(state.ist[layout.BLOCK_UPDATES]),
        "full_block_updates": int(state.ist[layout.FULL_UPDATES])
        if integrator == "exact"
        else int(state.ist[layout.BLOCK_UPDATES]),
        "n_moving": int(state.ist[layout.N_MOVING]),
        "wall_seconds": wall,
        "integrator": integrator,
        "state_sha256": state.sha256(),
        **early,
    }
    return ChainRun(
        params, options, integrator, start_info, state, events, first_move, samples, snapshots, profiles, summary
    )


def _model_note(params) -> dict[str, str]:
    """The preset's caveat (Batista-Carlson: the paper's reading; train: one member), if any."""
    from stickslip.models.presets import PRESETS

    preset = PRESETS[params.model]
    return {"model_note": preset.note} if preset.note and preset.note_in_runs else {}


def _profiles(parts, events, options, params) -> xr.Dataset:
    """Displacements dx_i = x_i(t + W) - x_i(t) over the stored windows of each event (Fig. 6)."""
    px, pm = parts["prof_x"].reshape(-1, params.N), parts["prof_meta"]
    keep_ids = set(events.loc[events["n_blocks"] >= options.profile_min_blocks, "event"].tolist())
    rows_dx, rows_ev, rows_t0, rows_t1 = [], [], [], []
    for eid in sorted(set(pm[:, 0].tolist()) & keep_ids) if len(pm) else []:
        idx = np.flatnonzero(pm[:, 0] == eid)
        idx = idx[np.argsort(pm[idx, 1], kind="stable")]
        for a, b in zip(idx[:-1], idx[1:], strict=False):
            rows_dx.append(px[b] - px[a])
            rows_ev.append(eid)
            rows_t0.append(pm[a, 1] * params.dt)
            rows_t1.append(pm[b, 1] * params.dt)
    dx = np.array(rows_dx).reshape(-1, params.N)
    return xr.Dataset(
        {"profile_dx": (("profile_row", "block"), dx, {"long_name": "displacement over the window"})},
        coords={
            "profile_event": ("profile_row", np.array(rows_ev, dtype=np.int64)),
            "profile_t": ("profile_row", np.array(rows_t0, dtype=np.float64)),
            "profile_t_next": ("profile_row", np.array(rows_t1, dtype=np.float64)),
            "block": np.arange(1, params.N + 1),
        },
        attrs={"window": options.profile_window if options.profile_window else 0.0},
    )
