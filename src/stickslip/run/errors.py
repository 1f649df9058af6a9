"""Errors of a run: a chain run (eq. 4) that cannot go on, a non-finite state of the chain or of
the single block (eq. 1), a stop by a signal."""

from __future__ import annotations

import contextlib
import warnings
from pathlib import Path


class ChainRunError(RuntimeError):
    """A chain run cannot go on (non-finite state, bad checkpoint)."""


class NonFiniteState(ChainRunError, ArithmeticError):
    """The state of the chain became non-finite; the message names the time and the block (an
    :class:`ArithmeticError`, as the single block's :class:`NonFiniteBlock` is)."""


class HookError(ChainRunError):
    """A hook of the run loop broke its contract (:class:`~stickslip.run.loop.Hook`); the message
    names the hook, the method and what it returned."""


class Interrupted(Exception):
    """A run was stopped by a signal after writing its checkpoint."""

    def __init__(self, checkpoint: Path | None, t: float):
        super().__init__(f"interrupted at t = {t:g}; checkpoint in {checkpoint}")
        self.checkpoint = checkpoint
        self.t = t


class ShortRunWarning(UserWarning):
    """A chain run with the end drive ends, or averages from, before the chain has loaded."""


class DenseStepsWarning(UserWarning):
    """An exact run whose load history moves back (drive ``history`` given positions that
    decrease) takes the dense integrator's plain steps: the exact path's start searches need a
    force that never decreases (:func:`stickslip.models.drive.history.monotone`)."""


@contextlib.contextmanager
def short_runs_expected():
    """Leave :class:`ShortRunWarning` out inside the block (or the decorated function): for runs
    that end before the chain has loaded on purpose (a benchmark's fixed workload, the transient
    before a Lyapunov exponent, sweep points already warned of)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ShortRunWarning)
        yield


class NonFiniteBlock(ArithmeticError):
    """The single block of eq. (1) blew up (a non-finite state); the message names the time."""
