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

This module sets a run up, with the hooks its options ask for, and finishes it; the loop, its
hooks and the checked kernel call shared with :class:`Stepper` are :mod:`stickslip.run.loop`. It
also names the rest of the chain-run API, which lives beside it: the state
(:mod:`stickslip.run.state`), the options (:mod:`stickslip.run.options`), buffers and results
(:mod:`stickslip.run.outputs`), the checkpoint files
(:mod:`stickslip.run.checkpoint`), the run directories (:mod:`stickslip.run.rundir`) and the
errors (:mod:`stickslip.run.errors`).
"""

from __future__ import annotations

import dataclasses
import time
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from stickslip.kernels import layout
from stickslip.models.params import ChainParams, ParameterError, check_number, steps_for
from stickslip.run import rundir

# The checkpoint file helpers (read_npz, write_npz) are named here too, for checks of the files.
from stickslip.run.budget import check_run_outputs
from stickslip.run.checkpoint import (  # noqa: F401
    CHECKPOINT_FORMAT,
    Checkpointer,
    read_npz,
    remove_checkpoint,
    write_npz,
)
from stickslip.run.errors import ChainRunError, Interrupted, NonFiniteState, ShortRunWarning
from stickslip.run.loop import (  # _Kernel named here too, for tests that count its calls
    CheckedAdvance,
    Checkpoints,
    ChunkTuning,
    Hook,
    Loop,
    MovingCounts,
    ProgressHook,
    Snapshots,
    SteadyStop,
    StopRequests,
    _Kernel,  # noqa: F401
    _par,
    _scratch,
    run_loop,
)
from stickslip.run.options import INTEGRATORS, RunOptions
from stickslip.run.outputs import EVENT_COLUMNS, ChainRun, _assemble, _Outputs
from stickslip.run.progress import Progress, SignalFlag, show_progress
from stickslip.run.rundir import load_run, read_run_id, write_run
from stickslip.run.state import (
    STARTS,
    ChainState,
    check_start_draw,
    initial_state,
    loading_warnings,
    steady_deviation,
)
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

# The fields of RunOptions that run_chain also takes as keywords.
_FIELDS = tuple(f.name for f in dataclasses.fields(RunOptions) if f.name != "t_end")


def run_chain(
    params: ChainParams,
    t_end: float,
    *,
    start: str | ChainState = "paper",
    perturbation: float = 0.0,
    seed: int = 0,
    options: RunOptions | None = None,
    **overrides: Any,
) -> ChainRun:
    """Integrate the chain of eq. (4), or a relative, from ``start`` to ``t_end`` (docs/model.md, "Chain").

    Parameters
    ----------
    params : ChainParams
        The model and its parameters: :func:`stickslip.chain_params` (``'sakaguchi'``, the
        paper's chain, or another preset, with overrides).
    t_end : float
        End time, in the model's time units (the paper's runs: 2e7 at N = 399).
    start : {'paper', 'steady', 'rest'} or ChainState
        ``paper``: x = 0, v = 0.1, theta = 0.1, all moving; ``steady``: exact steady sliding
        (perturbed uniformly in [-A, A] with ``perturbation`` A and ``seed``); ``rest``: every
        block stuck at x_i = -A u_i (Carlson-Langer's); or the state of another run.
    perturbation : float
        The size A of the draw of ``steady`` and ``rest``.
    seed : int
        The seed of that draw.
    options : RunOptions, optional
        What the run records, when it stops early and how it runs
        (:class:`~stickslip.run.options.RunOptions`; its ``t_end`` is this ``t_end``): the
        sampling interval of L (Fig. 5b), the start of <L>'s average, snapshot times (Fig. 5a),
        the profile window (Fig. 6), ``until_steady``, ``sample_moving``; the integrator
        (``exact`` or ``dense``, the same bits), the run directory ``out_dir`` with its
        checkpoints, the progress bar, signals, ``stop_requested`` and the caller's own
        ``hooks`` (:class:`~stickslip.run.loop.Hook`).
    **overrides
        Fields of :class:`~stickslip.run.options.RunOptions` by name (``integrator="dense"``,
        ``sample_interval=5.0``, ``out_dir=...``): they replace those of ``options`` (or of the
        defaults).

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
    options = _options(options, overrides, float(check_number("t_end", t_end, low=0.0, low_open=True)), params.dt)
    check_run_outputs(params.N, params.dt, options)
    check_number("perturbation", perturbation, low=0.0)
    if isinstance(start, ChainState):
        check_start_state(start, params, t_end=options.t_end)
        state = start.copy()
        start_info: dict[str, Any] = {"kind": "state", "sha256": start.sha256()}
    else:
        # the defaults (0.0, 0) draw nothing: only another value is a draw the paper's start lacks
        check_start_draw(start, perturbation if perturbation != 0.0 else None, seed if seed != 0 else None)
        state = initial_state(params, start, amplitude=perturbation, seed=seed)
        start_info = {"kind": start, "perturbation": perturbation, "seed": seed}
        for message in loading_warnings(params, options.t_end, options.average_from, start):
            warnings.warn(message, ShortRunWarning, stacklevel=2)
    state.ist[layout.NEXT_SAMPLE] = state.step
    outputs = _Outputs(params.N, options.profile_window is not None)
    out_dir = options.out_dir
    with rundir.run_dir_for_run(out_dir, options.run_id) as run_id:  # owned as the command owns its --out
        options = dataclasses.replace(options, run_id=run_id)
        checkpointer = Checkpointer(Path(out_dir)) if out_dir else None
        return _drive(params, options, start_info, state, outputs, checkpointer=checkpointer, wall_before=0.0)


def _options(options: RunOptions | None, overrides: dict[str, Any], t_end: float, dt: float) -> RunOptions:
    """The run's options: ``options`` (or the defaults) with the fields in ``overrides`` replaced
    and ``t_end``, checked."""
    unknown = sorted(set(overrides) - set(_FIELDS))
    if unknown:
        raise TypeError(f"run_chain() got an unexpected keyword argument {unknown[0]!r}")
    if options is not None and not isinstance(options, RunOptions):
        raise ParameterError(
            f"options must be a RunOptions (stickslip.RunOptions(...)), or give its fields as keywords "
            f"of run_chain (got {type(options).__name__})"
        )
    options = RunOptions() if options is None else options
    if options.t_end is not None and options.t_end != t_end:
        raise ParameterError(f"options.t_end {options.t_end:g} differs from t_end {t_end:g}; give one")
    options = dataclasses.replace(options, **overrides)
    hooks = tuple(options.hooks)
    for hook in hooks:
        if not isinstance(hook, Hook):
            raise ParameterError(f"hooks must be Hook instances (stickslip.run.Hook; got {type(hook).__name__})")
    options = dataclasses.replace(options, t_end=t_end, hooks=hooks).validated(dt)  # as given, then as used
    return dataclasses.replace(
        options,
        snapshot_times=tuple(float(t) for t in options.snapshot_times),
        profile_min_blocks=int(options.profile_min_blocks),
        sample_moving=bool(options.sample_moving),
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
    hooks: Sequence[Hook] = (),
) -> ChainRun:
    """Continue the run in ``run_dir`` from its checkpoint to its t_end (or a later ``t_end``),
    ending bit for bit where an uninterrupted :func:`run_chain` ends.

    Parameters
    ----------
    run_dir : str or Path
        The run directory of an interrupted run (or one kept with ``keep_checkpoint``).
    t_end : float, optional
        A later end time than the run's own.
    checkpoint_interval : float, optional
        Wall-clock seconds between checkpoints (:class:`~stickslip.run.options.RunOptions`).
    progress : bool, optional
        The progress bar, as for :func:`run_chain`.
    handle_signals : bool
        Stop on SIGINT/SIGTERM: checkpoint, then :class:`Interrupted`.
    stop_requested : callable, optional
        Asked after each kernel call whether to stop as a signal does.
    hooks : sequence of Hook
        The caller's own concerns of the run loop (:class:`~stickslip.run.loop.Hook`).
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
        options = RunOptions.from_dict(header["options"], header["integrator"]).validated(params.dt)
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
        if steps_for(t_end, params.dt, "t_end") < state.step:
            raise ParameterError(f"t_end must be >= the checkpoint's time {state.step * params.dt:g} (got {t_end:g})")
        options = dataclasses.replace(options, t_end=t_end)
    if keep_checkpoint is None:
        keep_checkpoint = header.get("keep_checkpoint") is True
    options = _options(
        options,
        dict(
            out_dir=run_dir,
            checkpoint_interval=checkpoint_interval,
            progress=progress,
            handle_signals=handle_signals,
            run_id=run_id,
            keep_checkpoint=keep_checkpoint,
            stop_requested=stop_requested,
            hooks=hooks,
        ),
        options.t_end,
        params.dt,
    )
    check_run_outputs(params.N, params.dt, options)
    outputs = _Outputs(params.N, options.profile_window is not None)
    outputs.parts = parts
    ckpt.since = {k: len(v) for k, v in parts.items()}
    with rundir.run_dir_for_resume(run_dir):  # locked as chain --resume locks it
        wall_before = float(header.get("wall_seconds", 0.0))
        return _drive(params, options, header["start"], state, outputs, checkpointer=ckpt, wall_before=wall_before)


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
                remove_checkpoint(run_dir)  # a file of the user's there stays
        return run_chain(
            params,
            t_end,
            out_dir=run_dir,
            checkpoint_interval=checkpoint_interval,
            stop_requested=stop_requested,
            **options,
        )


def _drive(params, options, start_info, state, outputs, *, checkpointer, wall_before) -> ChainRun:
    """The run loop (:func:`stickslip.run.loop.run_loop`) with the hooks ``options`` asks for and
    the caller's own, then the results, written into ``options.out_dir`` if given."""
    n_end = steps_for(options.t_end, params.dt, "t_end")
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
    ints = (sample_every, profile_every, options.profile_min_blocks, int(stop_all_moving))
    integrator, out_dir, progress = options.integrator, options.out_dir, options.progress
    advance = CheckedAdvance(integrator, params, state, _scratch(params.N), _par(params), outputs, ints)
    header = {
        "params": params.to_dict(),
        "options": options.to_dict(),
        "integrator": integrator,
        "start": start_info,
    }
    if options.run_id is not None:
        header["run_id"] = options.run_id
    if options.keep_checkpoint:
        header["keep_checkpoint"] = True
    hooks: list[Hook] = []
    if options.snapshot_times:
        done = set(int(s) for a in outputs.parts["snap_step"] for s in a)
        steps = [steps_for(t, params.dt, "snapshot_times") for t in options.snapshot_times]
        hooks.append(Snapshots(steps, done, n_end))
    if options.sample_moving and not outputs.moving_from_kernel:
        hooks.append(MovingCounts(sample_every, last_moving))
    if options.until_steady is not None:
        hooks.append(SteadyStop(options.until_steady, sample_every, kernel_stops=stop_all_moving))
    # From Python (progress None) the bar waits a second, so that a short run shows none.
    bar = Progress(options.t_end, show_progress(progress), delay=1.0 if progress is None else 0.0)
    hooks += [*options.hooks, ChunkTuning(), ProgressHook(bar)]
    t0 = time.perf_counter()
    if out_dir is not None:
        Path(out_dir).mkdir(parents=True, exist_ok=True)
    loop = Loop(params, state, outputs, n_end)
    with SignalFlag(options.handle_signals) as flag:
        hooks.append(StopRequests(flag, options.stop_requested))
        if checkpointer is not None:
            hooks.append(Checkpoints(checkpointer, options.checkpoint_interval, header, wall_before, t0))
        run_loop(loop, advance, hooks, checkpointer.state_path if checkpointer else None)
    outputs.flush(state.ist)
    wall = wall_before + time.perf_counter() - t0
    run = _assemble(params, options.recorded(), integrator, start_info, state, outputs, wall, loop.steady_at)
    run.summary["wall_seconds_this_run"] = wall - wall_before  # wall_seconds counts every part of a resumed run
    if run.summary["event_in_progress"]:  # the unfinished event began after the last finished one
        run.summary["in_progress_since"] = float(run.events["t_end"].max()) if len(run.events) else 0.0
    if out_dir is not None:
        # The last checkpoint stands until the results are written: a kill while they are
        # written leaves a run that --resume finishes.
        if checkpointer is not None:
            checkpointer.write(state, outputs, dict(header, wall_seconds=wall))
        write_run(run, out_dir)
        if not options.keep_checkpoint:
            drop_checkpoint(out_dir)
    return run


class Stepper:
    """Advance chain states of one model to given steps with no outputs kept: the engine of
    :func:`run_chain` without its tables, for methods that restart short runs many times
    (Lyapunov exponents).

    Same kernels, parameters and arrays as :func:`run_chain`, and the same checked call
    (:class:`~stickslip.run.loop.CheckedAdvance`), so a trajectory is the one ``run_chain`` gives
    bit for bit; sampling is switched off (it decides only where a kernel pauses, never what it
    computes) and the event buffers are emptied and dropped when full.
    """

    def __init__(self, params: ChainParams, integrator: str = "exact"):
        if integrator not in INTEGRATORS:
            raise ParameterError(f"integrator must be one of {', '.join(INTEGRATORS)} (got {integrator!r})")
        self.params = params
        self.integrator = integrator
        self.par = _par(params)
        self.scratch = _scratch(params.N)
        self.outputs = _Outputs(params.N, False)
        self._advance: CheckedAdvance | None = None

    def advance(self, state: ChainState, step: int) -> tuple[ChainState, int]:
        """Advance ``state`` in place to ``step``; returns it and the slip events completed."""
        if self._advance is None:
            self._advance = CheckedAdvance(
                self.integrator, self.params, state, self.scratch, self.par, self.outputs, (1, 0, 0, 0)
            )
        events0 = int(state.ist[layout.N_EVENTS])
        state.ist[layout.NEXT_SAMPLE] = np.iinfo(np.int64).max
        while True:
            status = self._advance(state, step)
            ist = state.ist  # after a replay the state holds the copy's arrays
            ist[layout.EV_COUNT] = ist[layout.FM_COUNT] = ist[layout.S_COUNT] = ist[layout.P_COUNT] = 0
            ist[layout.EV_P_FIRST] = 0
            if status == layout.DONE:
                return state, int(ist[layout.N_EVENTS]) - events0


def drop_checkpoint(run_dir: str | Path) -> None:
    """Remove the checkpoint of a finished run (its results are in the run directory); a file
    there that is not the checkpoint's stays (:func:`~stickslip.run.checkpoint.remove_checkpoint`)."""
    remove_checkpoint(run_dir)
