"""A short line on stderr every minute or so while a long command runs off a terminal.

On a terminal the commands show progress bars; in a log file (a batch job, ``> log 2>&1``) a bar
would garble the file, and a long command would otherwise say nothing for minutes. The code that
knows how far a command is calls :func:`note` (cheap: it only keeps the text); the command line
runs :func:`heartbeat` around a command, whose thread writes the latest note every ``interval``
seconds.
"""

from __future__ import annotations

import contextlib
import sys
import threading
import time
from collections.abc import Iterator

#: Seconds between two lines.
INTERVAL = 60.0

_latest = {"text": ""}


def note(text: str) -> None:
    """Say what runs now and how far it is (shown by the next heartbeat line, if any)."""
    _latest["text"] = text


def _elapsed(seconds: float) -> str:
    minutes, s = divmod(int(seconds), 60)
    return f"{minutes} min {s:02d} s" if minutes else f"{s} s"


@contextlib.contextmanager
def heartbeat(
    command: str, *, interval: float | None = None, enabled: bool | None = None, stream=None
) -> Iterator[None]:
    """Within the block, write ``stickslip COMMAND: running for 2 min 00 s; <latest note>`` on
    ``stream`` (stderr) every ``interval`` seconds (default :data:`INTERVAL`); by default only when
    the stream is not a terminal."""
    stream = sys.stderr if stream is None else stream
    interval = INTERVAL if interval is None else interval
    if enabled is None:
        enabled = not (hasattr(stream, "isatty") and stream.isatty())
    if not enabled:
        yield
        return
    stop = threading.Event()
    t0 = time.perf_counter()
    _latest["text"] = ""

    def beat() -> None:
        while not stop.wait(interval):
            text = _latest["text"]
            line = f"stickslip {command}: running for {_elapsed(time.perf_counter() - t0)}"
            try:
                stream.write(line + (f"; {text}" if text else "") + "\n")
                stream.flush()
            except (OSError, ValueError):  # the stream went away (closed pipe): stop beating
                return

    thread = threading.Thread(target=beat, name="stickslip-heartbeat", daemon=True)
    thread.start()
    try:
        yield
    finally:
        stop.set()
        thread.join(timeout=1.0)
