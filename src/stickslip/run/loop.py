"""The run loop of the chain of eq. (4): checked kernel calls, and the hooks that stop them.

A run advances its state by calls to a compiled kernel (:mod:`stickslip.kernels`), each to a
target step. Between calls the loop serves its concerns, each a :class:`Hook`: snapshots (Fig.
5a), moving counts, the steady stop, chunk tuning, progress, stop requests (signals, a caller's
callable) and checkpoints. A hook says at which step it next needs the kernel to stop
(:meth:`Hook.stop_at`) and acts there (:meth:`Hook.at`) or after each call (:meth:`Hook.after`);
the kernel is called to the nearest of these steps. Where a kernel stops decides only when the
hooks act, never what the kernel computes, so the hooks leave every bit of a run as it is.

Every call goes through :class:`CheckedAdvance`, which :func:`~stickslip.run.driver.run_chain`
and :class:`~stickslip.run.driver.Stepper` share: the fast integrator does not look for
non-finite values, so the state is checked after each call and, if anything is non-finite, the
call is replayed from a copy with the reference (``dense``), which checks each step and names the
step and the block (docs/chain.md, "Non-finite values").
"""

from __future__ import annotations

import bisect
import numbers
import time
import warnings
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from stickslip.kernels import dense, entry, exact, layout, plate
from stickslip.models.params import ChainParams
from stickslip.models.pieces import stopped_blocks_still
from stickslip.run.errors import DenseStepsWarning, HookError, Interrupted, NonFiniteState
from stickslip.run.state import ChainState, line_aligned, steady_deviation

NEVER = np.iinfo(np.int64).max  # a hook that needs no stop

_KERNELS = {"dense": dense.run_dense, "exact": exact.run_exact, "sparse": plate.run_sparse}


def _finite(state: ChainState) -> bool:
    return bool(np.isfinite(state.xg).all() and np.isfinite(state.vg).all() and np.isfinite(state.thg).all())


def _par(p: ChainParams) -> np.ndarray:
    """The kernels' parameter vector: K, V and dt (the pieces' parameters travel as their named
    tuples, :meth:`~stickslip.models.piece.Piece.kernel_params`). V is the velocity of the pull point
    p = V t_n, the drive's (:meth:`~stickslip.models.piece.Piece.kernel_velocity`: a force ramp's r)."""
    par = np.zeros(layout.PAR_SIZE)
    par[layout.P_K] = p.K if isinstance(p.K, float) else float(p.K.values[0])
    par[layout.P_V], par[layout.P_DT] = p.drive_piece.kernel_velocity(p), p.dt
    return par


def chain_extras(p: ChainParams) -> tuple:
    """The springs per bond and the masses as the kernels read them (``ChainArgs.kb``,
    ``ChainArgs.mass``): None for one spring K (in ``par``) and for unit masses."""
    from stickslip.models.disorder import PerBlock

    # Springs all alike take the uniform expression K ((x_{i-1} - x_i) - (x_i - x_{i+1})), whose
    # rounding differs from the per-bond one's.
    bonds = isinstance(p.K, PerBlock) and bool((p.K.values != p.K.values[0]).any())
    kb = p.K.bonds(ring=p.ends_piece.ring) if bonds else None
    if isinstance(p.M, PerBlock):
        mass = p.M.padded()
    else:
        mass = None if p.M == 1.0 else float(p.M)
    return kb, mass


def _scratch(N: int) -> list[np.ndarray]:
    """The kernels' scratch arrays (predictors, mask, stage-1 rates; ``trig``), the float ones
    with block 1 at a line's start like the state's (:func:`~stickslip.run.state.line_aligned`)."""
    return [line_aligned(np.zeros(N + 2)) for _ in range(6)] + [np.zeros(N + 2, dtype=np.int64)]


class _Kernel:
    """One integrator compiled for one model: ``kernel(state, target)`` advances the state.

    The model's pieces are compile-time constants of the kernels (:func:`stickslip.kernels.entry.specialise`).
    Where stopped blocks keep every bit, ``exact`` is the sparse path (:mod:`stickslip.kernels.plate`),
    so only the kernel a run uses is compiled.
    """

    def __init__(self, name, params, state, scratch, par, outputs, ints):
        monotone = params.drive_piece.monotone
        if name == "exact" and monotone is not None and not monotone(params):
            # The start searches of the fast paths need a load point that never moves back.
            warnings.warn(
                "the load point moves back: the exact integrator's start search needs one that never "
                "does, so this run takes the dense integrator's plain steps (the same bits as dense)",
                DenseStepsWarning,
                stacklevel=2,
            )
            name = "dense"
        if name == "exact" and stopped_blocks_still(params.drive_piece, params.friction_piece):
            name = "sparse"
        self.scratch = tuple(scratch)
        pieces_p = tuple(
            pc.kernel_params(params) for pc in (params.drive_piece, params.threshold_piece, params.friction_piece)
        )
        self.rest = (par, *pieces_p, *chain_extras(params), *outputs.kernel_args())
        # sample_every, profile_every, profile_min_blocks, stop_all_moving (layout.ChainArgs)
        self.tail = tuple(np.int64(t) for t in ints)
        self.pieces = params.codes
        self.entry = entry.specialise(_KERNELS[name], self._args(state, 0), self.pieces)

    def _args(self, state, target):
        return layout.ChainArgs(
            state.xg,
            state.vg,
            state.thg,
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


class CheckedAdvance:
    """One kernel call of the chain of eq. (4), checked for non-finite values.

    ``advance(state, target)`` runs the integrator's kernel (:class:`_Kernel`) to ``target`` and
    returns its status (:mod:`stickslip.kernels.layout`). The ``exact`` kernel does not look for
    non-finite values; if the state holds one after its call, the call is replayed from a copy
    with ``dense``, which follows the same arithmetic and checks each step. A non-finite state
    raises :class:`~stickslip.run.errors.NonFiniteState` naming the time, step and block.
    ``state`` is updated in place (before a replay its arrays get the copy's values back).
    """

    def __init__(self, integrator: str, params: ChainParams, state: ChainState, scratch, par, outputs, ints):
        self.params = params
        self._build = (params, state, scratch, par, outputs, ints)
        self.kernel = _Kernel(integrator, *self._build)
        self.check = integrator == "exact"
        self._reference: _Kernel | None = None

    def __call__(self, state: ChainState, target: int) -> int:
        before = state.copy() if self.check else None
        status = self.kernel(state, target)
        if before is not None and not _finite(state):
            state.restore(before)
            if self._reference is None:
                self._reference = _Kernel("dense", *self._build)
            status = self._reference(state, target)
        if status == layout.NONFINITE:
            raise NonFiniteState(
                f"state became non-finite at t = {state.step * self.params.dt:.6g} (step {state.step}) "
                f"in block {int(state.ist[layout.BAD_BLOCK])}"
            )
        return status


class Loop:
    """What the hooks of one run of the chain of eq. (4) see (:class:`Hook`).

    Attributes
    ----------
    params : ChainParams
        The run's model and parameters (``params.dt``: the step).
    state : ChainState
        The state, at step ``state.step`` (t = step dt). A hook reads it and never changes it:
        it is the run's own state, and a changed bit changes the run.
    outputs : object
        The run's output buffers (the hooks of :mod:`stickslip.run.loop` add to them).
    n_end : int
        The step the run ends at.
    stopping : bool
        Set by a hook's :meth:`Hook.after` to stop the run as a signal does (checkpoint, then
        :class:`~stickslip.run.errors.Interrupted`).
    steady_at : dict
        Where the steady stop ended the run (``t_steady``, ``deviation``), else empty.
    """

    def __init__(self, params: ChainParams, state: ChainState, outputs, n_end: int):
        self.params = params
        self.state = state
        self.outputs = outputs
        self.n_end = n_end
        self.stopping = False  # a stop was asked for: checkpoint, then Interrupted
        self.steady_at: dict[str, float] = {}


class Hook:
    """One concern of the run loop of the chain of eq. (4): a base class for the caller's own,
    given to :func:`~stickslip.run.driver.run_chain` as ``hooks=[...]`` (a field of
    :class:`~stickslip.run.options.RunOptions`) or to :func:`~stickslip.run.driver.resume_chain`.

    The loop calls the kernel to the nearest step any hook asks for, and between calls serves
    every hook. The contract, each method optional:

    * ``stop_at(n)``: the next step after ``n`` (an integer > n) at which this hook needs the
      kernel to stop (:attr:`NEVER` if none). The kernel stops at every step asked for that is
      not after the run's end.
    * ``at(loop, n)``: act at step ``n`` (``loop.state.step``), before the next call. It is
      called at the run's first step, at every step any hook asked for, at the last step, and
      wherever else the kernel stopped (its buffers filled), so a hook checks ``n`` itself.
      True ends the run there (a short run, as ``until_steady`` ends one); False or None go on.
    * ``after(loop, status, elapsed, now)``: act after each kernel call, given its status,
      its wall-clock seconds and the clock (:func:`time.perf_counter`); setting
      ``loop.stopping = True`` stops the run as a signal does (no later hook clears it).
    * ``close()``: release what the hook holds, once, however the run ends.

    The loop checks what ``stop_at`` and ``at`` return where it calls them and raises
    :class:`~stickslip.run.errors.HookError`, naming the hook, for anything else.

    A hook reads ``loop.state`` and ``loop.params`` (:class:`Loop`) and never changes the state;
    where the kernel stops decides only when the hooks act, never what it computes, so a hook
    changes no bit of a run.

    Attributes
    ----------
    NEVER : int
        What :meth:`stop_at` returns for no stop (the largest int64).

    Examples
    --------
    >>> import stickslip
    >>> from stickslip.run import Hook
    >>> class EveryThousand(Hook):
    ...     def __init__(self):
    ...         self.steps = []
    ...     def stop_at(self, n):
    ...         return (n // 1000 + 1) * 1000
    ...     def at(self, loop, n):
    ...         if n % 1000 == 0:
    ...             self.steps.append(n)
    ...         return False
    >>> hook = EveryThousand()
    >>> run = stickslip.run_chain(stickslip.chain_params(N=10), 20.0, start="steady", hooks=[hook])
    >>> hook.steps
    [0, 1000, 2000, 3000, 4000]
    """

    NEVER = NEVER

    def stop_at(self, n: int) -> int:
        """The next step after ``n`` at which the kernel must stop for this hook."""
        return NEVER

    def at(self, loop: Loop, n: int) -> bool:
        """Act at step ``n``, before the next call; True ends the run here."""
        return False

    def after(self, loop: Loop, status: int, elapsed: float, now: float) -> None:
        """Act after a call that returned ``status`` in ``elapsed`` seconds (``now``: the clock)."""

    def close(self) -> None:
        """Release what the hook holds, however the run ends."""


class Snapshots(Hook):
    """Every x_i at the given steps (Fig. 5a); the end's is the final state, kept apart."""

    def __init__(self, steps: Sequence[int], done: set[int], n_end: int):
        self.wanted = set(steps) - {n_end}
        self.steps = sorted(self.wanted)
        self.done = done

    def stop_at(self, n):
        # a search, not a scan: a run may ask for many thousands of snapshots
        k = bisect.bisect_right(self.steps, n)
        return self.steps[k] if k < len(self.steps) else NEVER

    def at(self, loop, n):
        if n in self.wanted and n not in self.done:
            loop.outputs.add_snapshot(n, loop.state.x)
            self.done.add(n)
        return False


def _next_multiple(n: int, every: int) -> int:
    return (n // every + 1) * every


class MovingCounts(Hook):
    """The number of moving blocks at the multiples of the sampling interval, counted here where
    the kernel does not count them with L (a start off L's grid, or a checkpoint without them)."""

    def __init__(self, sample_every: int, last: int):
        self.every, self.last = sample_every, last

    def stop_at(self, n):
        return _next_multiple(n, self.every)

    def at(self, loop, n):
        if n % self.every == 0 and n > self.last:
            loop.outputs.add_moving(n, int(np.count_nonzero(loop.state.mov[1:-1])))
            self.last = n
        return False


class SteadyStop(Hook):
    """End the run at the first multiple of the sampling interval at which every block slides
    within ``tol`` of steady sliding (:func:`~stickslip.run.state.steady_deviation`). On L's grid
    the kernel stops by itself at the samples with every block moving (only there can the chain
    slide steadily); off it, the kernel is stopped at each multiple."""

    def __init__(self, tol: float, sample_every: int, kernel_stops: bool):
        self.tol, self.every, self.kernel_stops = tol, sample_every, kernel_stops

    def stop_at(self, n):
        return NEVER if self.kernel_stops else _next_multiple(n, self.every)

    def at(self, loop, n):
        if n % self.every == 0:
            dev = steady_deviation(loop.state, loop.params)
            if dev <= self.tol:
                loop.steady_at = {"t_steady": n * loop.params.dt, "deviation": dev}
                return True
        return False


class ChunkTuning(Hook):
    """Calls of about a quarter second, so that signals and progress are answered promptly."""

    def __init__(self, chunk: int = 200_000):
        self.chunk = chunk

    def stop_at(self, n):
        return n + self.chunk

    def after(self, loop, status, elapsed, now):
        if status == layout.DONE and elapsed > 0:
            self.chunk = int(min(max(self.chunk * 0.25 / elapsed, 10_000), 50_000_000))


class ProgressHook(Hook):
    """The progress bar (:class:`~stickslip.run.progress.Progress`): time reached and events."""

    def __init__(self, bar):
        self.bar = bar

    def after(self, loop, status, elapsed, now):
        self.bar.update(loop.state.step * loop.params.dt, int(loop.state.ist[layout.N_EVENTS]))

    def close(self):
        self.bar.close()


class StopRequests(Hook):
    """A stop asked for by SIGINT/SIGTERM (a :class:`~stickslip.run.progress.SignalFlag`) or by
    the caller's ``stop_requested()``, looked at after each call: the run checkpoints and raises
    :class:`~stickslip.run.errors.Interrupted`."""

    def __init__(self, flag, stop_requested: Callable[[], bool] | None):
        self.flag, self.stop_requested = flag, stop_requested

    def after(self, loop, status, elapsed, now):
        # only ever sets the stop: a caller's hook may have asked for one before this one
        if self.flag.set or (self.stop_requested is not None and self.stop_requested()):
            loop.stopping = True


class Checkpoints(Hook):
    """A checkpoint (:class:`~stickslip.run.checkpoint.Checkpointer`) every ``interval`` wall-clock
    seconds and when a stop is asked for (after :class:`StopRequests`)."""

    def __init__(self, checkpointer, interval: float | None, header: dict[str, Any], wall_before: float, t0: float):
        self.checkpointer, self.interval, self.header = checkpointer, interval, header
        self.wall_before, self.t0, self.last = wall_before, t0, t0

    def after(self, loop, status, elapsed, now):
        if loop.stopping or (self.interval is not None and now - self.last >= self.interval):
            self.write(loop, now)

    def write(self, loop, now: float) -> None:
        loop.outputs.flush(loop.state.ist)
        wall = self.wall_before + now - self.t0
        self.checkpointer.write(loop.state, loop.outputs, dict(self.header, wall_seconds=wall))
        self.last = now


def _hook_name(hook: Hook) -> str:
    return type(hook).__qualname__


def _checked_stop(hook: Hook, n: int) -> int:
    """``hook.stop_at(n)``, checked: an integer step after ``n`` (a step at or before ``n`` would
    call the kernel for nothing, again and again)."""
    step = hook.stop_at(n)
    if not isinstance(step, numbers.Integral) or isinstance(step, bool):
        raise HookError(
            f"hook {_hook_name(hook)}.stop_at({n}) returned {step!r} ({type(step).__name__}): "
            "it must return an integer step after n, or Hook.NEVER"
        )
    if step <= n:
        raise HookError(
            f"hook {_hook_name(hook)}.stop_at({n}) returned {int(step)}: it must return a step after n "
            f"(> {n}), or Hook.NEVER; a step at or before n would stop the run where it stands forever"
        )
    return int(step)


def _checked_at(hook: Hook, loop: Loop, n: int) -> bool:
    """``hook.at(loop, n)``, checked: True, False (or None, nothing to say)."""
    ended = hook.at(loop, n)
    if ended is None or isinstance(ended, (bool, np.bool_)):
        return bool(ended)
    raise HookError(
        f"hook {_hook_name(hook)}.at(loop, {n}) returned {ended!r} ({type(ended).__name__}): "
        "it must return True (end the run here) or False"
    )


def run_loop(loop: Loop, advance: CheckedAdvance, hooks: Sequence[Hook], checkpoint_path=None) -> None:
    """Advance ``loop.state`` to ``loop.n_end`` (or until a hook ends the run), calling the kernel
    to the nearest step a hook needs and letting each hook act there; a stop asked for raises
    :class:`~stickslip.run.errors.Interrupted` (after the hooks have checkpointed). A hook that
    breaks its contract (:class:`Hook`) raises :class:`~stickslip.run.errors.HookError` naming it."""
    state, outputs, n_end = loop.state, loop.outputs, loop.n_end
    try:
        while True:
            n = state.step
            ended = [_checked_at(hook, loop, n) for hook in hooks]  # every hook acts before the run ends
            if any(ended):
                break
            if n >= n_end:
                # One more call services outputs due at the final step (its sample).
                status = advance.kernel(state, n_end)
                if status != layout.DONE and status != layout.NONFINITE:
                    outputs.flush(state.ist)
                    continue
                break
            target = min(n_end, min((_checked_stop(hook, n) for hook in hooks), default=NEVER))
            c0 = time.perf_counter()
            status = advance(state, target)
            elapsed = time.perf_counter() - c0
            if status != layout.DONE:
                outputs.flush(state.ist)
            now = time.perf_counter()
            for hook in hooks:
                hook.after(loop, status, elapsed, now)
            if loop.stopping:
                raise Interrupted(checkpoint_path, state.step * loop.params.dt)
    finally:
        for hook in hooks:
            hook.close()
