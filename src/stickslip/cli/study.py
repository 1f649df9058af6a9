"""`stickslip study`: the studies the paper leaves open, with a page per study.

    stickslip study NAME [--quick | --full] [--out DIR] [--scheduler ADDRESS] [--workers N] [--json]

NAME is ``transition`` (order parameter against beta and N), ``phase-diagram`` (final state over
(alpha, beta) and (D, beta), two starts), ``exponents`` (slip-size exponent against beta, and
Carlson-Langer) or ``chaos`` (largest Lyapunov exponent against beta, two blocks, Carlson-Langer).
Every point is cached and reused; an interrupted study resumes; a failed point
is reported and retried by the next call. See docs/studies/.
"""

from __future__ import annotations

import argparse

from stickslip.cli._common import (
    CommandError,
    Result,
    add_dask_options,
    add_json_option,
    dask_options,
    interrupted,
    prepare_out_dir,
    sigterm_as_interrupt,
)

DEFAULT_OUT = "studies"


def register(sub) -> None:
    """Add the ``study`` subcommand."""
    from stickslip.experiments.studies import STUDIES

    p = sub.add_parser(
        "study",
        help="run a study the paper leaves open (transition, phase-diagram, exponents, chaos); writes a page",
        description=(
            "Run every point of a study on Dask (reusing finished points), then write its table "
            "(Parquet, CSV), figures and an HTML page under DIR/NAME/."
        ),
    )
    p.add_argument("name", choices=STUDIES, metavar="NAME", help=f"one of {', '.join(STUDIES)}")
    mode = p.add_mutually_exclusive_group()
    mode.add_argument(
        "--quick",
        dest="mode",
        action="store_const",
        const="quick",
        help="small chains, coarse grids: minutes on two cores (default)",
    )
    mode.add_argument(
        "--full",
        dest="mode",
        action="store_const",
        const="full",
        help="larger chains and finer grids: sized for a small cluster; run again to resume",
    )
    mode.add_argument("--tiny", dest="mode", action="store_const", const="tiny", help=argparse.SUPPRESS)
    p.set_defaults(mode="quick")
    p.add_argument(
        "--extra-n",
        type=int,
        action="append",
        default=[],
        metavar="N",
        help="transition only: add a chain of N blocks (both ladders), e.g. 1599; repeatable",
    )
    p.add_argument("--out", default=DEFAULT_OUT, metavar="DIR", help=f"output directory (default {DEFAULT_OUT})")
    add_dask_options(p)
    add_json_option(p)
    p.set_defaults(handler=run)


def run(args: argparse.Namespace) -> Result:
    """Handler of ``stickslip study``."""
    from stickslip.experiments.study_run import run_study

    _, workers = dask_options(args)
    if args.extra_n and (args.name != "transition" or min(args.extra_n) < 3):
        raise CommandError("--extra-n takes chains of at least 3 blocks, for the transition study only")
    out = prepare_out_dir(args.out)
    if args.name == "transition":
        return _transition(args, out, workers)
    try:
        with sigterm_as_interrupt():
            result = run_study(
                args.name, out, args.mode, scheduler=args.scheduler, n_workers=workers, progress=not args.no_progress
            )
    except KeyboardInterrupt:
        return interrupted(
            "study", out, f"finished points in {out} are kept, chain runs continue from their checkpoints"
        )
    except OSError as exc:
        raise CommandError(f"cannot run the study: {exc}") from None
    data = {k: v for k, v in result.items() if k != "figures"}
    data["figures"] = [f["image"] for f in result["figures"]]
    return Result(data, _text(result), status=1 if result["failed"] else 0)


def _transition(args: argparse.Namespace, out, workers) -> Result:
    """The transition study by continuation in beta (:mod:`stickslip.experiments.transition_study`)."""
    import shlex
    import sys

    from stickslip.experiments.transition_study import run_transition

    command = "stickslip " + " ".join(shlex.quote(a) for a in sys.argv[1:])
    try:
        with sigterm_as_interrupt():
            result = run_transition(
                out,
                args.mode,
                extra_Ns=tuple(args.extra_n),
                scheduler=args.scheduler,
                n_workers=workers,
                progress=not args.no_progress,
                command=command,
            )
    except KeyboardInterrupt:
        return interrupted("study", out, f"finished rungs in {out} are kept; the ladders continue from them")
    except OSError as exc:
        raise CommandError(f"cannot run the study: {exc}") from None
    meta = result["meta"]
    lines = [
        f"stickslip study transition --{meta['mode']}: {meta['ladders']} ladders ({meta['failed']} failed), "
        f"{meta['rungs']} rungs, {meta['wall_seconds']} s"
    ]
    lines += [f"  {s}" for s in result["statements"]]
    lines.append(f"page: {result['page']}")
    return Result(result, "\n".join(lines), status=1 if result["failed"] else 0)


def _text(result: dict) -> str:
    lines = [
        f"stickslip study {result['study']} --{result['mode']}: {result['points']} points "
        f"({result['run']} run, {result['reused']} reused, {result['failed']} failed), {result['wall_seconds']} s"
    ]
    lines += [f"  {s}" for s in result["findings"].get("statements", [])]
    for f in result["failed_points"]:
        lines.append(f"  failed: {f['point']}: {f['error']}")
    lines.append(f"page: {result['page']}")
    return "\n".join(lines)
