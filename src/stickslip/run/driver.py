"""The chain of eq. (4): running it, its slip events, and long resumable runs.

:func:`run_chain` integrates the chain of N blocks pulled at one end (docs/model.md, section
"Chain") with one of two integrators that give the same answer bit for bit:

* ``dense``: the reference, Heun over every block at every step;
* ``exact`` (default): the same arithmetic, skipping only work whose result is known in
  advance (see :mod:`stickslip.kernels.laws` and :mod:`stickslip.kernels.exact`).

A run returns a :class:`ChainRun`: the slip-event table (docs/model.md, "Slip events"), the time
each block first moved in each event (rupture fronts, Fig. 6), L(t) = x_1 - x_N sampled at a
fixed interval (Fig. 5b), snapshots of x_i (Fig. 5a), optional displacement profiles over
windows (Fig. 6), and the final state with its SHA-256.

Long runs write checkpoints into their run directory (atomically, with checksums) at a
wall-clock interval and on SIGINT/SIGTERM; :func:`resume_chain` continues from one and ends
bit for bit where an uninterrupted run does.

This module holds the driver loop, the progress bar and the signal handling; it also names the
rest of the chain-run API, which lives beside it: the state (:mod:`stickslip.run.state`), the
options, buffers and results (:mod:`stickslip.run.outputs`), the checkpoint files
(:mod:`stickslip.run.checkpoint`), the run directories (:mod:`stickslip.run.rundir`) and the
errors (:mod:`stickslip.run.errors`).
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from stickslip.kernels import dense, entry, exact, layout, plate
from stickslip.models.params import ChainParams, ParameterError, check_number, steps_for
from stickslip.models.pieces import stopped_blocks_still
from stickslip.run import rundir

# The checkpoint file helpers (_read_npz, _write_npz) are named here too, for checks of the files.
from stickslip.run.checkpoint import CHECKPOINT_FORMAT, Checkpointer, _read_npz, _write_npz  # noqa: F401
from stickslip.run.errors import ChainRunError, Interrupted, NonFiniteState, ShortRunWarning
from stickslip.run.outputs import EVENT_COLUMNS, ChainRun, RunOptions, _assemble, _Outputs
from stickslip.run.progress import Progress, SignalFlag, show_progress
from stickslip.run.rundir import load_run, read_run_id, write_run
from stickslip.run.state import STARTS, ChainState, initial_state, line_aligned, loading_warnings, steady_deviation
from stickslip.run.validate import check_chain_params, check_checkpoint_state, check_start_state

__all__ = [
    "run_chain",
    "resume_chain",
    "load_run",
    "write_run",
    "ChainState",
    "ChainRun",
    "RunOptions",
    "initial_state",
    "steady_deviation",
    "Checkpointer",
    "ChainRunError",
    "NonFiniteState",
    "ShortRunWarning",
    "Interrupted",
    "CHECKPOINT_FORMAT",
    "EVENT_COLUMNS",
    "INTEGRATORS",
    "STARTS",
]

INTEGRATORS = ("exact", "dense")

_KERNELS = {"dense": dense.run_dense, "exact": exact.run_exact, "sparse": plate.run_sparse}


def _finite(state: ChainState) -> bool:
    return bool(np.isfinite(state.x).all() and np.isfinite(state.v).all() and np.isfinite(state.th).all())


def _par(p: ChainParams) -> np.ndarray:
    """The kernels' parameter vector: K, V and dt (the pieces' parameters travel as their named
    tuples, :meth:`~stickslip.models.piece.Piece.kernel_params`)."""
    par = np.zeros(layout.PAR_SIZE)
    par[layout.P_K], par[layout.P_V], par[layout.P_DT] = p.K, p.V, p.dt
    return par


class _Kernel:
    """One integrator compiled for one model: ``kernel(state, target)`` advances the state.

    The model's pieces are compile-time constants of the kernels (:func:`stickslip.kernels.entry.specialise`).
    Where stopped blocks keep every bit, ``exact`` is the sparse path (:mod:`stickslip.kernels.plate`),
    so only the kernel a run uses is compiled.
    """

    def __init__(self, name, params, state, scratch, par, outputs, ints):
        if name == "exact" and stopped_blocks_still(params.drive_piece, params.friction_piece):
            name = "sparse"
        self.scratch = tuple(scratch)
        pieces_p = tuple(
            pc.kernel_params(params) for pc in (params.drive_piece, params.threshold_piece, params.friction_piece)
        )
        self.rest = (par, *pieces_p, *outputs.kernel_args())
        # sample_every, profile_every, profile_min_blocks, stop_all_moving (layout.ChainArgs)
        self.tail = tuple(np.int64(t) for t in ints)
        self.pieces = params.codes
        self.entry = entry.specialise(_KERNELS[name], self._args(state, 0), self.pieces)

    def _args(self, state, target):
        return layout.ChainArgs(
            state.x,
            state.v,
            state.th,
            state.mov,
            *self.scratch,
            state.first_step,
            state.x0ev,
            state.ist,
            *self.rest,
            np.int64(target),
            *self.tail,
        )

    def __call__(self, state, target):
        return self.entry(self._args(state, target), *self.pieces)


def _scratch(N: int) -> list[np.ndarray]:
    """The kernels' scratch arrays (predictors, mask, stage-1 rates; ``trig``), the float ones
    with block 1 at a line's start like the state's (:func:`~stickslip.run.state.line_aligned`)."""
    return [line_aligned(np.zeros(N + 2)) for _ in range(6)] + [np.zeros(N + 2, dtype=np.int64)]


def run_chain(
    params: ChainParams,
    t_end: float,
    *,
    integrator: str = "exact",
    start: str | ChainState = "paper",
    perturbation: float = 0.0,
    seed: int = 0,
    sample_interval: float = 10.0,
    average_from: float | None = None,
    snapshot_times: Sequence[float] = (),
    profile_window: float | None = None,
    profile_min_blocks: int = 0,
    until_steady: float | None = None,
    sample_moving: bool = False,
    out_dir: str | Path | None = None,
    checkpoint_interval: float | None = None,
    progress: bool | None = None,
    handle_signals: bool = False,
    run_id: str | None = None,
    keep_checkpoint: bool = False,
    stop_requested: Callable[[], bool] | None = None,
) -> ChainRun:
    """Integrate the chain of eq. (4), or a relative, from ``start`` to ``t_end`` (docs/model.md, "Chain").

    Parameters
    ----------
    params : ChainParams
        The model and its parameters: :func:`stickslip.chain_params` (``'sakaguchi'``, the
        paper's chain, or another preset, with overrides).
    t_end : float
        End time, in the model's time units (the paper's runs: 2e7 at N = 399).
    integrator : {'exact', 'dense'}
        ``exact`` (fast) or ``dense`` (the reference); the same result bit for bit.
    start : {'paper', 'steady', 'rest'} or ChainState
        ``paper``: x = 0, v = 0.1, theta = 0.1, all moving; ``steady``: exact steady sliding
        (perturbed uniformly in [-A, A] with ``perturbation`` A and ``seed``); ``rest``: every
        block stuck at x_i = -A u_i (Carlson-Langer's); or the state of another run.
    perturbation, seed : float, int
        The draw of ``steady`` and ``rest``.
    sample_interval : float
        L = x_1 - x_N is sampled every this long (Fig. 5b).
    average_from : float, optional
        <L> (``summary['L_mean']``) averages the samples from this time (default t_end / 2).
    snapshot_times : sequence of float
        Times at which every x_i is kept (Fig. 5a); the end is always kept.
    profile_window, profile_min_blocks : float, int, optional
        Keep x_i every ``profile_window`` during events of at least ``profile_min_blocks``
        blocks: the rupture fronts of Fig. 6 (the paper's window is 20).
    until_steady : float, optional
        Stop at the first sampling time at which every block slides within this tolerance of
        steady sliding; L is then taken from the steady solution up to t_end.
    sample_moving : bool
        Also sample the number of moving blocks (``samples['n_moving']``).
    out_dir : str or Path, optional
        A run directory, owned as ``stickslip chain --out`` owns it (locked; foreign files and an
        earlier run refused): checkpoints every ``checkpoint_interval`` wall-clock seconds and on
        SIGINT/SIGTERM (``handle_signals``), the results at the end. Without it nothing is
        written; :meth:`ChainRun.save` writes the same folder afterwards.
    progress : bool, optional
        Show a progress bar: ``None`` (default) where the session is interactive (a Jupyter
        notebook, the interpreter on a terminal), ``True`` on any terminal, ``False`` never.
    run_id, keep_checkpoint, stop_requested
        The run directory's id in every checkpoint; keep the checkpoint at the end (to continue
        to a later t_end with :func:`resume_chain`); a callable asked between chunks of about
        a quarter second whether to stop as a signal does (checkpoint, then :class:`Interrupted`).

    Returns
    -------
    ChainRun
        Events, first moves, L(t), snapshots, profiles, final state and summary.

    Raises
    ------
    ParameterError
        A bad value (one line naming it); :class:`NonFiniteState` if the state blows up.

    Examples
    --------
    >>> import stickslip
    >>> run = stickslip.run_chain(stickslip.chain_params(N=10, beta=0.5), 2e4)
    >>> run.summary["n_events"], len(run.events), run.summary["steps"]
    (65, 65, 4000000)
    """
    check_chain_params(params)
    if integrator not in INTEGRATORS:
        raise ParameterError(f"integrator must be one of {', '.join(INTEGRATORS)} (got {integrator!r})")
    options = RunOptions(
        t_end=float(check_number("t_end", t_end, low=0.0, low_open=True)),
        sample_interval=sample_interval,
        average_from=average_from,
        snapshot_times=tuple(float(t) for t in snapshot_times),
        profile_window=profile_window,
        profile_min_blocks=int(profile_min_blocks),
        until_steady=until_steady,
        sample_moving=bool(sample_moving),
    ).validated(params.dt)
    if checkpoint_interval is not None:
        check_number("checkpoint_interval", checkpoint_interval, low=0.0, low_open=True)
    check_number("perturbation", perturbation, low=0.0)
    if isinstance(start, ChainState):
        check_start_state(start, params, t_end=options.t_end)
        state = start.copy()
        start_info: dict[str, Any] = {"kind": "state", "sha256": start.sha256()}
    else:
        state = initial_state(params, start, amplitude=perturbation, seed=seed)
        start_info = {"kind": start, "perturbation": perturbation, "seed": seed}
        for message in loading_warnings(params, options.t_end, options.average_from, start):
            warnings.warn(message, ShortRunWarning, stacklevel=2)
    state.ist[layout.NEXT_SAMPLE] = state.step
    outputs = _Outputs(params.N, options.profile_window is not None)
    with rundir.run_dir_for_run(out_dir, run_id) as run_id:  # owned as the command owns its --out
        return _drive(
            params,
            options,
            integrator,
            start_info,
            state,
            outputs,
            run_id=run_id,
            out_dir=out_dir,
            checkpointer=Checkpointer(Path(out_dir)) if out_dir else None,
            checkpoint_interval=checkpoint_interval,
            progress=progress,
            handle_signals=handle_signals,
            wall_before=0.0,
            keep_checkpoint=keep_checkpoint,
            stop_requested=stop_requested,
        )


def resume_chain(
    run_dir: str | Path,
    *,
    t_end: float | None = None,
    checkpoint_interval: float | None = None,
    progress: bool | None = None,
    handle_signals: bool = False,
    expect_params: ChainParams | None = None,
    keep_checkpoint: bool | None = None,
    stop_requested: Callable[[], bool] | None = None,
) -> ChainRun:
    """Continue the run in ``run_dir`` from its checkpoint to its t_end (or a later ``t_end``),
    ending bit for bit where an uninterrupted :func:`run_chain` ends.

    Parameters
    ----------
    run_dir : str or Path
        The run directory of an interrupted run (or one kept with ``keep_checkpoint``).
    t_end : float, optional
        A later end time than the run's own.
    checkpoint_interval, progress, handle_signals, stop_requested
        As for :func:`run_chain`.
    expect_params : ChainParams, optional
        Refuse a checkpoint made with other parameters.
    keep_checkpoint : bool, optional
        Keep the checkpoint at the end; ``None``: if the run was started keeping it.

    Returns
    -------
    ChainRun
        The whole run, written into ``run_dir``. A corrupt checkpoint, one of another format or
        of other parameters raises :class:`ChainRunError`.
    """
    run_dir = Path(run_dir)
    ckpt = Checkpointer(run_dir)
    if not ckpt.state_path.exists() and (run_dir / "run.json").exists():
        raise ChainRunError(
            f"the run in {run_dir} is finished and kept no checkpoint to continue from "
            "(a run started with --keep-checkpoint can be continued to a later --t-end)"
        )
    state, header, parts = ckpt.load()
    try:
        params = ChainParams(**header["params"])
        options = RunOptions.from_dict(header["options"]).validated(params.dt)
        integrator = header["integrator"]
        if integrator not in INTEGRATORS:
            raise ParameterError(f"integrator must be one of {', '.join(INTEGRATORS)} (got {integrator!r})")
    except (KeyError, TypeError, ValueError, AttributeError) as exc:
        raise ChainRunError(f"checkpoint in {run_dir} has an unusable header ({exc})") from None
    run_id = header.get("run_id")
    if run_id != read_run_id(run_dir):
        raise ChainRunError(
            f"the checkpoint in {run_dir} belongs to another run (run id {run_id}, the directory's "
            f"{read_run_id(run_dir)}); resume the directory it was written in"
        )
    check_checkpoint_state(state, params, options, parts, run_dir)
    if expect_params is not None and expect_params != params:
        raise ChainRunError(
            f"checkpoint in {run_dir} was made with other parameters: {params.to_dict()} != {expect_params.to_dict()}"
        )
    if t_end is not None:
        t_end = float(check_number("t_end", t_end, low=0.0))
        if steps_for(t_end, params.dt) < state.step:
            raise ParameterError(f"t_end must be >= the checkpoint's time {state.step * params.dt:g} (got {t_end:g})")
        options = RunOptions(**{**options.__dict__, "t_end": t_end})
    outputs = _Outputs(params.N, options.profile_window is not None)
    outputs.parts = parts
    ckpt.since = {k: len(v) for k, v in parts.items()}
    if keep_checkpoint is None:
        keep_checkpoint = header.get("keep_checkpoint") is True
    with rundir.run_dir_for_resume(run_dir):  # locked as chain --resume locks it
        return _drive(
            params,
            options,
            integrator,
            header["start"],
            state,
            outputs,
            run_id=run_id,
            out_dir=run_dir,
            checkpointer=ckpt,
            checkpoint_interval=checkpoint_interval,
            progress=progress,
            handle_signals=handle_signals,
            wall_before=float(header.get("wall_seconds", 0.0)),
            keep_checkpoint=keep_checkpoint,
            stop_requested=stop_requested,
        )


def continue_or_run(
    params: ChainParams,
    t_end: float,
    run_dir: str | Path,
    *,
    checkpoint_interval: float,
    stop_requested: Callable[[], bool] | None = None,
    **options: Any,
) -> ChainRun:
    """The chain of eq. (4) (or a relative) into ``run_dir``, continued from the checkpoint there
    when one is usable (:func:`resume_chain` with ``expect_params``), else run afresh
    (:func:`run_chain` with ``options``); an unusable checkpoint is removed. A point of a study
    or reproduction that is killed so loses at most ``checkpoint_interval`` seconds; one stopped
    through ``stop_requested`` loses nothing."""
    import shutil

    ckpt = Checkpointer(Path(run_dir))
    with rundir.owned_by_caller(run_dir):  # a point's folder: the study or sweep owns it
        if ckpt.state_path.is_file():
            try:
                return resume_chain(
                    run_dir,
                    checkpoint_interval=checkpoint_interval,
                    expect_params=params,
                    stop_requested=stop_requested,
                )
            except ChainRunError:
                shutil.rmtree(ckpt.dir, ignore_errors=True)
        return run_chain(
            params,
            t_end,
            out_dir=run_dir,
            checkpoint_interval=checkpoint_interval,
            stop_requested=stop_requested,
            **options,
        )


def _drive(
    params,
    options,
    integrator,
    start_info,
    state,
    outputs,
    *,
    out_dir,
    checkpointer,
    checkpoint_interval,
    progress,
    handle_signals,
    wall_before,
    run_id=None,
    keep_checkpoint=False,
    stop_requested=None,
) -> ChainRun:
    par = _par(params)
    N = params.N
    scratch = _scratch(N)
    n_end = steps_for(options.t_end, params.dt)
    sample_every = int(round(options.sample_interval / params.dt))
    profile_every = int(round(options.profile_window / params.dt)) if options.profile_window else 0
    last_moving = max((int(a[-1, 0]) for a in outputs.parts["moving"] if len(a)), default=-1)
    last_sample = max((int(a[-1]) for a in outputs.parts["samp_step"] if len(a)), default=-1)
    # Moving blocks are counted, and steady sliding looked for, at the multiples of sample_every.
    # Where those are L's sampling steps, the kernel counts them with L (unless a count is missing:
    # a checkpoint of an earlier version) and stops only at a sample with every block moving
    # (steady sliding needs it); otherwise (a start off the grid) the kernel stops at each one.
    on_l_grid = state.ist[layout.NEXT_SAMPLE] % sample_every == 0
    outputs.moving_from_kernel = options.sample_moving and on_l_grid and last_moving == last_sample
    stop_all_moving = options.until_steady is not None and on_l_grid
    on_grid = (options.until_steady is not None and not stop_all_moving) or (
        options.sample_moving and not outputs.moving_from_kernel
    )
    ints = (sample_every, profile_every, options.profile_min_blocks, int(stop_all_moving))
    kernel = _Kernel(integrator, params, state, scratch, par, outputs, ints)
    stops = sorted({steps_for(t, params.dt) for t in options.snapshot_times} | {n_end})
    done_snaps = set(int(s) for a in outputs.parts["snap_step"] for s in a)
    steady_at: dict[str, float] = {}
    header = {
        "params": params.to_dict(),
        "options": options.to_dict(),
        "integrator": integrator,
        "start": start_info,
    }
    if run_id is not None:
        header["run_id"] = run_id
    if keep_checkpoint:
        header["keep_checkpoint"] = True
    # From Python (progress None) the bar waits a second, so that a short run shows none.
    bar = Progress(options.t_end, show_progress(progress), delay=1.0 if progress is None else 0.0)
    t0 = time.perf_counter()
    last_ckpt = t0
    chunk = 200_000
    if out_dir is not None:
        Path(out_dir).mkdir(parents=True, exist_ok=True)
    with SignalFlag(handle_signals) as flag:
        try:
            while True:
                n = state.step
                if n in stops and n not in done_snaps and n != n_end:
                    outputs.add_snapshot(n, state.x)
                    done_snaps.add(n)
                moving_due = options.sample_moving and not outputs.moving_from_kernel and n % sample_every == 0
                if moving_due and n > last_moving:
                    outputs.add_moving(n, int(np.count_nonzero(state.mov[1:-1])))
                    last_moving = n
                if options.until_steady is not None and n % sample_every == 0:
                    dev = steady_deviation(state, params)
                    if dev <= options.until_steady:
                        steady_at = {"t_steady": n * params.dt, "deviation": dev}
                        break
                next_stop = min((s for s in stops if s > n), default=n_end)
                if on_grid:
                    # Check on a fixed grid of steps, so the stop does not depend on timing.
                    next_stop = min(next_stop, (n // sample_every + 1) * sample_every)
                if n >= n_end:
                    # One more call services outputs due at the final step (its sample).
                    status = kernel(state, n_end)
                    if status != layout.DONE and status != layout.NONFINITE:
                        outputs.flush(state.ist)
                        continue
                    break
                target = min(next_stop, n + chunk)
                before = state.copy() if integrator == "exact" else None
                c0 = time.perf_counter()
                status = kernel(state, target)
                elapsed = time.perf_counter() - c0
                if before is not None and not _finite(state):
                    # The fast kernel does not look for non-finite values; replay this call
                    # with the reference, which follows the same arithmetic and checks each step.
                    state = before
                    reference = _Kernel("dense", params, state, scratch, par, outputs, ints)
                    status = reference(state, target)
                if status == layout.NONFINITE:
                    bad = int(state.ist[layout.BAD_BLOCK])
                    raise NonFiniteState(
                        f"state became non-finite at t = {state.step * params.dt:.6g} (step {state.step}) "
                        f"in block {bad}"
                    )
                if status != layout.DONE:
                    outputs.flush(state.ist)
                # Aim at about a quarter second per call: responsive to signals and progress.
                if status == layout.DONE and elapsed > 0:
                    chunk = int(min(max(chunk * 0.25 / elapsed, 10_000), 50_000_000))
                now = time.perf_counter()
                bar.update(state.step * params.dt, int(state.ist[layout.N_EVENTS]))
                stop = flag.set or (stop_requested is not None and stop_requested())
                if checkpointer is not None and (
                    stop or (checkpoint_interval is not None and now - last_ckpt >= checkpoint_interval)
                ):
                    outputs.flush(state.ist)
                    checkpointer.write(state, outputs, dict(header, wall_seconds=wall_before + now - t0))
                    last_ckpt = now
                if stop:
                    raise Interrupted(checkpointer.state_path if checkpointer else None, state.step * params.dt)
        finally:
            bar.close()
    outputs.flush(state.ist)
    wall = wall_before + time.perf_counter() - t0
    run = _assemble(params, options, integrator, start_info, state, outputs, wall, steady_at)
    run.summary["wall_seconds_this_run"] = wall - wall_before  # wall_seconds counts every part of a resumed run
    if run.summary["event_in_progress"]:  # the unfinished event began after the last finished one
        run.summary["in_progress_since"] = float(run.events["t_end"].max()) if len(run.events) else 0.0
    if out_dir is not None:
        # The last checkpoint stands until the results are written: a kill while they are
        # written leaves a run that --resume finishes.
        if checkpointer is not None:
            checkpointer.write(state, outputs, dict(header, wall_seconds=wall))
        write_run(run, out_dir)
        if not keep_checkpoint:
            drop_checkpoint(out_dir)
    return run


class Stepper:
    """Advance chain states of one model to given steps with no outputs kept: the engine of
    :func:`run_chain` without its tables, for methods that restart short runs many times
    (Lyapunov exponents).

    Same kernels, parameters and arrays as :func:`run_chain`, so a trajectory is the one
    ``run_chain`` gives bit for bit; sampling is switched off (it decides only where a kernel
    pauses, never what it computes) and the event buffers are emptied and dropped when full.
    """

    def __init__(self, params: ChainParams, integrator: str = "exact"):
        if integrator not in INTEGRATORS:
            raise ParameterError(f"integrator must be one of {', '.join(INTEGRATORS)} (got {integrator!r})")
        self.params = params
        self.integrator = integrator
        self.par = _par(params)
        self.scratch = _scratch(params.N)
        self.outputs = _Outputs(params.N, False)
        self._kernels: dict[str, _Kernel] = {}

    def _kernel(self, name: str, state: ChainState) -> _Kernel:
        if name not in self._kernels:
            self._kernels[name] = _Kernel(name, self.params, state, self.scratch, self.par, self.outputs, (1, 0, 0, 0))
        return self._kernels[name]

    def advance(self, state: ChainState, step: int) -> tuple[ChainState, int]:
        """Advance ``state`` in place to ``step``; returns it and the slip events completed."""
        ist = state.ist
        events0 = int(ist[layout.N_EVENTS])
        ist[layout.NEXT_SAMPLE] = np.iinfo(np.int64).max
        while True:
            before = state.copy() if self.integrator == "exact" else None
            status = self._kernel(self.integrator, state)(state, step)
            if before is not None and not _finite(state):
                state.__dict__.update(before.__dict__)
                status = self._kernel("dense", state)(state, step)
            if status == layout.NONFINITE:
                raise NonFiniteState(
                    f"state became non-finite at t = {state.step * self.params.dt:.6g} "
                    f"(step {state.step}) in block {int(ist[layout.BAD_BLOCK])}"
                )
            ist[layout.EV_COUNT] = ist[layout.FM_COUNT] = ist[layout.S_COUNT] = ist[layout.P_COUNT] = 0
            ist[layout.EV_P_FIRST] = 0
            if status == layout.DONE:
                return state, int(ist[layout.N_EVENTS]) - events0


def drop_checkpoint(run_dir: str | Path) -> None:
    """Remove the checkpoint of a finished run (its results are in the run directory)."""
    import shutil

    path = Path(run_dir) / "checkpoint"
    # The state file first: a kill part way leaves no checkpoint that lists missing parts.
    (path / "state.npz").unlink(missing_ok=True)
    if path.is_dir():
        shutil.rmtree(path)
