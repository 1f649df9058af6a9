"""The options of a chain run (eq. 4): :class:`RunOptions`, what a run records and how it runs.

Each field that ``stickslip chain`` takes as an option carries its command-line spelling, metavar
and help as metadata (``cli``), from which the command line is built
(:func:`stickslip.cli._common.add_run_options`), as the model parameters' options are built from
:class:`~stickslip.models.params.ChainParams`. The fields marked ``control`` say how a run runs
(where it writes, progress, signals, hooks) and are not part of what it records.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from stickslip.models.params import MAX_STEPS, ParameterError, check_number, steps_for

if TYPE_CHECKING:
    from stickslip.run.loop import Hook

#: The chain's integrators: ``exact`` (fast) and ``dense`` (the reference), the same bits.
INTEGRATORS = ("exact", "dense")


def _option(default: Any, option: str, metavar: str | None, help: str, *, control: bool = False, **more: Any):
    """A field of :class:`RunOptions` with its command-line option (``stickslip chain --OPTION``):
    name, metavar and help, and where they apply ``integer``, ``allowed`` (the range named when
    the text is no number), ``append`` (repeatable), ``choices``, ``text`` (a string) and ``flag``
    (no value: the field gets this value when the option is given)."""
    metadata = {"cli": {"option": option, "metavar": metavar, "help": help, **more}, "control": control}
    return field(default=default, metadata=metadata)


def _control(default: Any):
    """A field of :class:`RunOptions` that says how a run runs, with no command-line option."""
    return field(default=default, metadata={"control": True})


@dataclass(frozen=True)
class RunOptions:
    """What a chain run (eq. 4) records besides its state, when it stops early, and how it runs.
    Times are in the model's time units. Given to :func:`~stickslip.run.driver.run_chain` as
    ``options=``; the fields with a command-line spelling are the options of ``stickslip chain``
    (their metadata ``cli``: spelling, metavar and help), from which the command line is built.
    The fields from ``integrator`` on say how the run runs; all but ``integrator`` are marked
    ``control`` and are not part of what a run records (:meth:`recorded`).

    Attributes
    ----------
    t_end : float or None
        The end time (given to :func:`~stickslip.run.driver.run_chain` as its own argument, which
        fills it in here).
    sample_interval : float
        L = x_1 - x_N is sampled every this long (Fig. 5b).
    average_from : float or None
        <L> is the mean of the samples with t >= average_from (default t_end / 2).
    snapshot_times : tuple of float
        Times at which all x_i are stored (Fig. 5a); the final state is always kept.
    profile_window : float or None
        If set, x_i is stored every this long during each event, for the displacement over
        windows of Fig. 6.
    profile_min_blocks : int
        Profiles are kept of the events with at least this many moved blocks.
    until_steady : float or None
        If set, the run stops at the first sampling time at which every block slides and the
        state is within this tolerance of steady sliding
        (:func:`~stickslip.run.state.steady_deviation`).
    sample_moving : bool
        If set, the number of moving blocks is sampled at the multiples of sample_interval
        (``samples["n_moving"]`` over ``t_moving``: the fraction of time with some block stuck);
        these are the times of L for a run that starts on one.
    integrator : {'exact', 'dense'}
        ``exact`` (fast) or ``dense`` (the reference); the same result bit for bit.
    out_dir : str or Path or None
        A run directory, owned as ``stickslip chain --out`` owns it (locked; foreign files and an
        earlier run refused): checkpoints every ``checkpoint_interval`` wall-clock seconds and on
        SIGINT/SIGTERM (``handle_signals``), the results at the end. Without it nothing is
        written; :meth:`~stickslip.run.outputs.ChainRun.save` writes the same folder afterwards.
    checkpoint_interval : float or None
        Wall-clock seconds between checkpoints in ``out_dir`` (None: only on a stop).
    keep_checkpoint : bool
        Keep the checkpoint at the end, to continue to a later t_end with
        :func:`~stickslip.run.driver.resume_chain`.
    progress : bool or None
        Show a progress bar: None where the session is interactive (a Jupyter notebook, the
        interpreter on a terminal), True on any terminal, False never.
    handle_signals : bool
        Stop on SIGINT/SIGTERM as on a stop request: checkpoint, then
        :class:`~stickslip.run.errors.Interrupted`.
    run_id : str or None
        The run directory's id, written into every checkpoint.
    stop_requested : callable or None
        Asked after each kernel call (about four times a second) whether to stop as a signal
        does (checkpoint, then :class:`~stickslip.run.errors.Interrupted`).
    hooks : tuple of Hook
        The caller's own concerns of the run loop (:class:`~stickslip.run.loop.Hook`), served
        after the run's own recording hooks; they change no bit of the run.

    Examples
    --------
    >>> from stickslip import RunOptions
    >>> options = RunOptions(sample_interval=5.0, integrator="dense", out_dir="runs/a", progress=False)
    >>> kept = options.recorded()  # what the run's ChainRun keeps
    >>> kept.sample_interval, kept.integrator, kept.out_dir, kept.progress
    (5.0, 'dense', None, None)
    """

    t_end: float | None = None
    sample_interval: float = _option(
        10.0, "sample-interval", "T", "sample L = x_1 - x_N every T time units (default 10)"
    )
    average_from: float | None = _option(
        None, "average-from", "T", "<L> averages the samples with t >= T (default t_end / 2)"
    )
    snapshot_times: tuple[float, ...] = _option(
        (), "snapshot", "T", "store all x_i at time T (repeatable; Fig. 5a)", append=True
    )
    profile_window: float | None = _option(
        None, "profile-window", "W", "store the displacement over windows of W during events (Fig. 6 uses 20)"
    )
    profile_min_blocks: int = _option(
        0,
        "profile-min-blocks",
        "M",
        "keep profiles only of events with at least M moved blocks",
        integer=True,
        allowed=">= 0",
    )
    until_steady: float | None = _option(
        None,
        "until-steady",
        "TOL",
        "stop once every block slides within TOL of steady sliding (velocities, state "
        "variables, spring extensions); L is taken from the steady solution from then on",
    )
    sample_moving: bool = False
    integrator: str = _option(
        "exact",
        "integrator",
        None,
        "exact (default, fast) or dense (reference); both give the same answer bit for bit",
        choices=INTEGRATORS,
    )
    out_dir: str | Path | None = _option(
        None, "out", "DIR", "run directory: results, checkpoints, run.json", control=True, text=True
    )
    checkpoint_interval: float | None = _option(
        None,
        "checkpoint-interval",
        "SECONDS",
        "wall-clock seconds between checkpoints (default 300; needs --out)",
        control=True,
        allowed="> 0",
    )
    keep_checkpoint: bool = _option(
        False,
        "keep-checkpoint",
        None,
        "keep the checkpoint (tens of MB for long chains) when the run finishes, so that "
        "--resume can continue it to a later --t-end (default: removed)",
        control=True,
        flag=True,
    )
    progress: bool | None = _option(None, "no-progress", None, "no progress bar on stderr", control=True, flag=False)
    handle_signals: bool = _control(False)
    run_id: str | None = _control(None)
    stop_requested: Callable[[], bool] | None = _control(None)
    hooks: Sequence[Hook] = _control(())

    def validated(self, dt: float, spell: Callable[[str], str] | None = None) -> RunOptions:
        """Check every option against the time step (ranges in docs/limits.md); returns self.

        The one place where a run's options are checked, for :func:`~stickslip.run.driver.run_chain`
        and ``stickslip chain`` alike; ``spell`` names a field as the caller's user gave it
        (``--sample-interval`` on the command line; default the field's own name).
        """
        name = spell if spell is not None else (lambda field_name: field_name)
        if self.t_end is None:
            raise ParameterError("t_end must be given (run_chain's own argument)")
        steps_for(self.t_end, dt, "t_end")
        longest = MAX_STEPS * dt
        check_number(name("sample_interval"), self.sample_interval, low=0.0, low_open=True, high=longest)
        if round(self.sample_interval / dt) < 1:
            raise ParameterError(f"{name('sample_interval')} must be >= dt = {dt:g} (got {self.sample_interval!r})")
        if self.average_from is not None:
            check_number(name("average_from"), self.average_from, low=0.0, high=self.t_end)
        if isinstance(self.snapshot_times, (str, bytes)) or not isinstance(self.snapshot_times, Iterable):
            raise ParameterError(
                f"{name('snapshot_times')} must be a sequence of times, e.g. (10.0,) (got {self.snapshot_times!r})"
            )
        for t in self.snapshot_times:
            check_number(name("snapshot_times"), t, low=0.0, high=self.t_end)
        if self.profile_window is not None:
            check_number(name("profile_window"), self.profile_window, low=0.0, low_open=True, high=longest)
            if round(self.profile_window / dt) < 1:
                raise ParameterError(f"{name('profile_window')} must be >= dt = {dt:g} (got {self.profile_window!r})")
        check_number(name("profile_min_blocks"), self.profile_min_blocks, low=0, integer=True)
        if self.until_steady is not None:
            check_number(name("until_steady"), self.until_steady, low=0.0, low_open=True)
        if self.integrator not in INTEGRATORS:
            raise ParameterError(
                f"{name('integrator')} must be one of {', '.join(INTEGRATORS)} (got {self.integrator!r})"
            )
        if self.out_dir is not None and not str(self.out_dir).strip():
            raise ParameterError(f"{name('out_dir')} must name a directory (got '')")
        if self.checkpoint_interval is not None:
            check_number(name("checkpoint_interval"), self.checkpoint_interval, low=0.0, low_open=True)
        for field_name in ("checkpoint_interval", "keep_checkpoint"):
            if self.out_dir is None and getattr(self, field_name) not in (None, False):
                raise ParameterError(
                    f"{name(field_name)} needs {name('out_dir')} (a run without a run directory writes no checkpoints)"
                )
        return self

    def recorded(self) -> RunOptions:
        """These options less how the run ran: the ``control`` fields at their defaults (what a
        :class:`~stickslip.run.outputs.ChainRun` keeps, read back the same from its run directory)."""
        return dataclasses.replace(
            self, **{f.name: f.default for f in dataclasses.fields(self) if f.metadata.get("control")}
        )

    def to_dict(self) -> dict[str, Any]:
        """What a run directory and a checkpoint keep of the options (``options`` in run.json;
        the integrator is kept beside them)."""
        return {
            "t_end": self.t_end,
            "sample_interval": self.sample_interval,
            "average_from": self.average_from,
            "snapshot_times": list(self.snapshot_times),
            "profile_window": self.profile_window,
            "profile_min_blocks": self.profile_min_blocks,
            "until_steady": self.until_steady,
            "sample_moving": bool(self.sample_moving),
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any], integrator: str = "exact") -> RunOptions:
        """The options :meth:`to_dict` wrote, run with ``integrator``."""
        d = dict(d)
        d["snapshot_times"] = tuple(d.get("snapshot_times", ()))
        return cls(**d, integrator=integrator)
