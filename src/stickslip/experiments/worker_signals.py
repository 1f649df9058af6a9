"""Signals to the worker processes of a local Dask cluster.

A batch system stopping a job sends SIGTERM to every process of it, and Ctrl-C in a terminal sends
SIGINT to the whole foreground process group: the command's driver and its Dask workers alike.
Left to their default, the workers die at once (losing the work since the point's last
checkpoint, printing a traceback) and the driver waits in vain for its points to stop. On a
local cluster each worker therefore turns either signal into a stop request
(:class:`StopOnSignal`): its running point writes its checkpoint and stops, as when the driver
asks (:func:`stickslip.experiments.sweep.stop_requested`), and the driver, which got the signal
too, closes the cluster.
"""

from __future__ import annotations

import signal
import threading

from distributed.diagnostics.plugin import WorkerPlugin

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
        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGINT, signal.SIGTERM):
                signal.signal(sig, _stop)
