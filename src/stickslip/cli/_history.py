"""``--history``: the load history of drive ``history`` on the command line (docs/lab.md, "Load
histories"): velocity steps ``V:T,V:T,...`` (a velocity held for a duration; V = 0 a hold) or a
lab record ``FILE.csv`` (time and load-point displacement or velocity, as
:meth:`stickslip.lab.LoadHistory.from_csv` reads it)."""

from __future__ import annotations

import argparse
from pathlib import Path

FORMS = "velocity steps V:T,V:T,... (e.g. 1:100,0:50,1:100) or a CSV file of time and load point"


def parse_history(text: str):
    """The :class:`~stickslip.lab.LoadHistory` of ``V:T,V:T,...`` or of a CSV file, or a
    ParameterError of one line naming ``--history`` and the two forms."""
    from stickslip.lab.history import LoadHistory
    from stickslip.models.params import ParameterError

    try:
        if ":" in text and not Path(text).exists():
            pairs = [part.split(":") for part in text.split(",")]
            if any(len(pair) != 2 for pair in pairs):
                raise ParameterError(f"each step is V:T (got {text!r})")
            velocities, durations = zip(*((float(v), float(t)) for v, t in pairs), strict=True)
            return LoadHistory.steps(velocities, durations)
        if not Path(text).is_file():
            raise ParameterError(f"no such file {text!r}")
        return LoadHistory.from_csv(text)
    except ValueError as exc:  # ParameterError, and float() of text that is not a number
        raise ParameterError(f"--history must be {FORMS}: {str(exc).splitlines()[0]}") from None


def add_history_option(group) -> None:
    """``--history``: the load history; it selects the drive ``history`` unless ``--drive`` is given."""
    group.add_argument(
        "--history",
        dest="history",
        default=None,
        metavar="SPEC",
        help="load history of the pulling point (selects --drive history): velocity steps V:T,V:T,... "
        "(V = 0 holds) or a CSV file of time and load-point displacement or velocity (docs/lab.md)",
    )


def take_history(args: argparse.Namespace, values: dict) -> None:
    """Put ``--history`` into the parameter ``values`` (with drive ``history`` unless ``--drive``
    names another, which then refuses it); refuse ``--drive history`` without it."""
    from stickslip.models.params import ParameterError

    if getattr(args, "history", None) is not None:
        values.update(history=parse_history(args.history), drive=values.get("drive", "history"))
    elif values.get("drive") == "history":
        raise ParameterError("--drive history needs --history V:T,V:T,... or --history FILE.csv")
