"""Signals to the worker processes of a local Dask cluster.

SIGTERM (a batch system stopping a job) and SIGINT (Ctrl-C) reach the driver and its Dask workers
alike; left to their default, the workers would die at once, losing the work since the point's
last checkpoint. Each worker of a local cluster therefore turns either signal into a stop request
(:class:`StopOnSignal`): its running point writes its checkpoint and stops, as when the driver asks
(:func:`stickslip.experiments.sweep.stop_requested`).
"""

from __future__ import annotations

import signal

from distributed.diagnostics.plugin import WorkerPlugin

from stickslip.run.progress import in_main_thread

_signalled = False


def signalled() -> bool:
    """Whether this process got SIGINT or SIGTERM since :class:`StopOnSignal` was set up in it."""
    return _signalled


def _stop(signum, frame) -> None:
    global _signalled
    _signalled = True


class StopOnSignal(WorkerPlugin):
    """Worker plugin: SIGINT and SIGTERM set the stop request of the worker's points."""

    name = "stickslip-stop-on-signal"

    def setup(self, worker) -> None:
        if in_main_thread():
            for sig in (signal.SIGINT, signal.SIGTERM):
                signal.signal(sig, _stop)
