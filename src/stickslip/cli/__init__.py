"""The ``stickslip`` command line.

Each subcommand lives in a module of this package with a ``register(subparsers)`` function.
A handler returns a :class:`Result`; with ``--json`` its ``data`` is printed as one JSON
document on stdout and nothing else goes to stdout, otherwise its ``text``.
Bad input gives one line on stderr naming the parameter and exit status 2.
"""

from __future__ import annotations

import argparse
import sys

from stickslip.cli._common import CommandError, Result, emit
from stickslip.models.params import ParameterError

__all__ = ["main", "build_parser", "Result", "CommandError"]


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are one line and exit with status 2."""

    def error(self, message: str):  # type: ignore[override]
        sys.stderr.write(f"{self.prog}: error: {message}\n")
        raise SystemExit(2)


def build_parser() -> argparse.ArgumentParser:
    """The full parser with every subcommand registered."""
    from stickslip.cli import block, chain, lyapunov, models, reproduce, stability, study, sweep

    parser = _Parser(
        prog="stickslip",
        description="Stick-slip friction in block-spring systems (Sakaguchi's model).",
    )
    from stickslip import __version__

    parser.add_argument("--version", action="version", version=f"stickslip {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for module in (block, stability, chain, models, sweep, reproduce, study, lyapunov):
        module.register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``stickslip`` command; returns the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        result = args.handler(args)
    except (ParameterError, CommandError) as exc:
        sys.stderr.write(f"stickslip {args.command}: error: {exc}\n")
        return 2
    except KeyboardInterrupt:
        sys.stderr.write("stickslip: interrupted\n")
        return 130
    return emit(result, as_json=getattr(args, "json", False))


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
