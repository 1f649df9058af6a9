"""The ``stickslip`` command line.

Each subcommand lives in a module of this package with a ``register(subparsers)`` function.
A handler returns a :class:`Result`; with ``--json`` its ``data`` is printed as one JSON
document on stdout and nothing else goes to stdout, otherwise its ``text``.
Bad input gives one line on stderr naming the parameter and exit status 2.
"""

from __future__ import annotations

import argparse
import re
import shlex
import sys
import warnings

from stickslip.cli._common import CommandError, Result, emit
from stickslip.heartbeat import heartbeat
from stickslip.models.params import ParameterError

__all__ = ["main", "build_parser", "Result", "CommandError"]


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are argparse's usage line and one line of error (with a
    "did you mean" for a misspelt choice or option), exit status 2. A word that starts with a minus
    and a digit is a value (``--history -1:20``, ``--V -1,10``, ``--rs-a -1e-3``), so that the
    value's own check names what is wrong with it."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        # argparse takes only plain numbers such as -1 or -.5 for values; no option here starts
        # with a digit, so every such word is one.
        self._negative_number_matcher = re.compile(r"^-\.?\d")

    def error(self, message: str):  # type: ignore[override]
        self.print_usage(sys.stderr)
        sys.stderr.write(f"{self.prog}: error: {message}{_did_you_mean(self, message)}\n")
        raise SystemExit(2)


def _did_you_mean(parser: argparse.ArgumentParser, message: str) -> str:
    """``; did you mean 'chain'?`` for an invalid choice or an unrecognised option close to a valid one."""
    import difflib

    choice = re.search(r"invalid choice: '([^']*)' \(choose from (.*)\)$", message)
    if choice:
        word, options = choice.group(1), re.findall(r"'([^']*)'", choice.group(2))
    else:
        unknown = re.search(r"unrecognized arguments?:? (--?[\w-]+)", message)
        if not unknown:
            return ""
        word = unknown.group(1)
        options = [s for action in parser._actions for s in action.option_strings]
    close = difflib.get_close_matches(word, options, n=1, cutoff=0.6)
    return f"; did you mean '{close[0]}'?" if close else ""


def build_parser() -> argparse.ArgumentParser:
    """The full parser with every subcommand registered."""
    from stickslip.cli import (
        block,
        catalog,
        chain,
        compile,
        lab,
        lyapunov,
        models,
        period,
        plot,
        reproduce,
        stability,
        study,
        sweep,
    )

    parser = _Parser(
        prog="stickslip",
        description="Stick-slip friction in block-spring systems (Sakaguchi's model).",
    )
    from stickslip import __version__

    parser.add_argument("--version", action="version", version=f"stickslip {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for module in (
        block,
        stability,
        chain,
        models,
        sweep,
        reproduce,
        study,
        lyapunov,
        plot,
        catalog,
        period,
        compile,
        lab,
    ):
        module.register(sub)
    parser.commands = sub.choices
    return parser


def _one_line_warning(command: str):
    """A ``warnings.showwarning`` that writes ``stickslip COMMAND: warning: MESSAGE`` on stderr."""

    def show(message, category, filename, lineno, file=None, line=None):
        sys.stderr.write(f"stickslip {command}: warning: {message}\n")

    return show


def _beats(args: argparse.Namespace) -> bool:
    """Heartbeat lines (every minute, what runs and how far) when stderr is not a terminal and
    progress is not switched off; a short command ends before the first."""
    return not sys.stderr.isatty() and not getattr(args, "no_progress", False)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``stickslip`` command; returns the exit status."""
    from stickslip.run.errors import NonFiniteBlock

    parser = build_parser()
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv and argv[0].startswith("-") and argv[0] not in ("-h", "--help", "--version"):
        parser.error(f"unrecognized argument {argv[0]} (options follow a COMMAND; see stickslip --help)")
    args, extra = parser.parse_known_args(argv)
    if extra:  # refused by the command's own parser: its usage line, and its options to suggest from
        parser.commands[args.command].error(f"unrecognized arguments: {' '.join(extra)}")
    args.command_line = "stickslip " + shlex.join(argv)  # quoted on the pages a command writes
    sub_command = getattr(args, "stability_command", None) or getattr(args, "lab_command", None)
    name = " ".join(v for v in (args.command, sub_command) if v)
    try:
        with warnings.catch_warnings(), heartbeat(name, enabled=_beats(args)):
            warnings.showwarning = _one_line_warning(args.command)
            result = args.handler(args)
    except (ParameterError, CommandError) as exc:
        sys.stderr.write(f"stickslip {name}: error: {exc}\n")
        return 2
    except NonFiniteBlock as exc:
        sys.stderr.write(f"stickslip {name}: error: {exc}\n")
        return 1
    except KeyboardInterrupt:
        sys.stderr.write("stickslip: interrupted\n")
        return 130
    except Exception as exc:
        full = _full_disk_line(exc, args)
        if full is None:
            raise
        sys.stderr.write(f"stickslip {name}: error: {full}\n")
        return 1
    return emit(result, as_json=getattr(args, "json", False))


def _full_disk_line(exc: BaseException, args: argparse.Namespace) -> str | None:
    """The one line for a write that met a full disk (:func:`stickslip.io.disk_full`), naming the
    file, or the output directory where the error names none; None for any other error."""
    from stickslip.io import disk_full

    full = disk_full(exc)
    if full is None:
        return None
    from pathlib import Path

    run_dir = getattr(args, "resume", None) or getattr(args, "out", None)
    where = full.filename or run_dir or "."
    if args.command == "chain" and run_dir and (Path(run_dir) / "checkpoint" / "state.npz").is_file():
        then = f"continue with: stickslip chain --resume {run_dir} (its last checkpoint is kept)"
    else:
        then = "run the same command again (nothing half-written was kept)"
    return f"the disk is full: no space left to write {where}; free some space and {then}"


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
