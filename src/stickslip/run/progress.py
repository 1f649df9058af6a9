"""What a long chain run shows and hears while it goes: its progress bar and the signals it ends on.

The bar (:class:`Progress`) goes to a terminal's stderr, or into a Jupyter notebook's output
(a widget where ipywidgets is installed, else text); :func:`show_progress` decides where it is
shown. :class:`SignalFlag` turns SIGINT/SIGTERM into a flag the driver checks between chunks.
"""

from __future__ import annotations

import signal
import sys
import threading
from dataclasses import dataclass
from typing import Any

from stickslip import heartbeat


def in_notebook() -> bool:
    """Whether this runs in a Jupyter kernel (IPython loaded with a kernel app)."""
    ipython = sys.modules.get("IPython")
    if ipython is None:
        return False
    try:
        shell = ipython.get_ipython()
    except AttributeError:
        return False
    return shell is not None and "IPKernelApp" in getattr(shell, "config", {})


def show_progress(progress: bool | None) -> bool:
    """Whether a run shows its bar: ``False`` never; ``True`` on a terminal or in a notebook;
    ``None`` (the default from Python) only in an interactive session: a notebook, or the
    interactive interpreter on a terminal (a script or a worker stays quiet)."""
    if progress is False:
        return False
    terminal = sys.stderr.isatty()
    if progress is None:
        return in_notebook() or (terminal and (hasattr(sys, "ps1") or bool(sys.flags.interactive)))
    return terminal or in_notebook()


def _bar_class():
    """tqdm's notebook widget in a Jupyter kernel with ipywidgets, else the text bar."""
    if in_notebook():
        try:
            import ipywidgets  # noqa: F401
            from tqdm.notebook import tqdm

            return tqdm, {}
        except ImportError:
            pass
    from tqdm import tqdm

    return tqdm, {"file": sys.stderr, "dynamic_ncols": True}


@dataclass
class Progress:
    """Progress of a chain run: time reached, events so far, speed, time left. ``delay``: seconds
    before the bar appears (a short run shows none)."""

    t_end: float
    enabled: bool
    delay: float = 0.0
    bar: Any = None
    t_last: float = 0.0

    def __post_init__(self):
        if self.enabled:
            tqdm, extra = _bar_class()
            self.bar = tqdm(
                total=self.t_end,
                unit=" time units",
                unit_scale=False,
                desc="chain",
                smoothing=0.1,
                delay=self.delay,
                bar_format="{l_bar}{bar}| t = {n:.4g}/{total:.4g} [{elapsed}<{remaining}, {rate_fmt}{postfix}]",
                **extra,
            )

    def update(self, t: float, n_events: int) -> None:
        heartbeat.note(f"chain t = {t:.4g} of {self.t_end:.4g}, {n_events} events")
        if self.bar is not None:
            self.bar.update(t - self.t_last)
            self.bar.set_postfix(events=n_events, refresh=False)
            self.t_last = t

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


class SignalFlag:
    """Turns SIGINT/SIGTERM into a flag checked between chunks (main thread only)."""

    def __init__(self, enabled: bool):
        self.set = False
        self.enabled = enabled and in_main_thread()
        self.previous: dict[int, Any] = {}

    def __enter__(self):
        if self.enabled:
            for sig in (signal.SIGINT, signal.SIGTERM):
                self.previous[sig] = signal.signal(sig, self._handler)
        return self

    def _handler(self, signum, frame):
        self.set = True

    def __exit__(self, *exc):
        for sig, handler in self.previous.items():
            signal.signal(sig, handler)
        return False


def in_main_thread() -> bool:
    """Whether this is the main thread (the only one that may install signal handlers)."""
    return threading.current_thread() is threading.main_thread()
