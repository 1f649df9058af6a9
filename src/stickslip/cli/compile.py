"""`stickslip compile`: compile the numba kernels ahead of time."""

from __future__ import annotations

import argparse
import sys

from stickslip.cli._common import Result, add_json_option


def register(sub) -> None:
    """Add the `compile` subcommand."""
    from stickslip.models.presets import PRESETS

    p = sub.add_parser(
        "compile",
        help="compile the kernels ahead of time (first use of a model otherwise compiles them)",
        description="Compile the numba kernels of the models (both integrators of the chain, and the single "
        "block) into the on-disk cache, so that later runs, tests and sweep workers start at once. "
        "Kernels already in the cache are loaded, not compiled again.",
    )
    p.add_argument(
        "--model",
        action="append",
        choices=tuple(PRESETS),
        default=None,
        help="a preset whose kernels to compile (repeatable; default: every preset)",
    )
    add_json_option(p)
    p.set_defaults(handler=run_compile_command)


def run_compile_command(args: argparse.Namespace) -> Result:
    """Handler of `stickslip compile`."""
    from stickslip.kernels._cache import cache_dir
    from stickslip.run.compile import compile_models

    def log(text: str) -> None:
        sys.stderr.write(f"stickslip compile: {text}\n")
        sys.stderr.flush()

    took = compile_models(args.model, log=None if args.json else log)
    data = {"models": took, "cache": str(cache_dir())}
    text = f"kernels of {', '.join(took)} compiled into {cache_dir()}"
    return Result(data, text)
