"""`stickslip reproduce`: every figure and stated number of the paper, with a report.

    stickslip reproduce [--quick | --full] [--out DIR] [--scheduler ADDRESS] [--workers N]

``--quick`` (default) runs the pipeline on shorter chain runs in minutes; ``--full`` uses the
paper's N = 399 and t = 2e7 (hours; resumable: run the same command again). Results already
computed for the same spec and package version are reused, so a second call only redraws.
Writes one page folder per study of the paper (DIR/figs1-4, DIR/figs5-8: PNG, PDF and data per
figure), DIR/runs (the experiments), report.json and report.html. See docs/reproduce.md.
"""

from __future__ import annotations

import argparse

from stickslip.cli._common import (
    OUT_FILES,
    CommandError,
    Result,
    add_dask_options,
    add_json_option,
    add_overwrite_option,
    dask_options,
    interrupted,
    is_disk_full,
    owned_out_dir,
    sigterm_as_interrupt,
)

DEFAULT_OUT = "paper-reproduction"


def register(sub) -> None:
    """Add the ``reproduce`` subcommand."""
    p = sub.add_parser(
        "reproduce",
        help="reproduce every figure and stated number of the paper; writes report.html",
        description=(
            "Run the experiment behind each of the paper's figures (section 2: Figs. 1-3, the Hopf "
            "point, the inverse transition; Fig. 4; section 3: chain runs on Dask for Figs. 5-8), draw "
            "each figure (PNG, PDF and its data), and write report.json and report.html with one row "
            "per number the paper states. Stored results of the same spec are reused."
        ),
    )
    mode = p.add_mutually_exclusive_group()
    mode.add_argument(
        "--quick",
        dest="mode",
        action="store_const",
        const="quick",
        help="shorter chain runs (N = 99 and 199, t = 2e6 and 4e6): minutes on two cores (default)",
    )
    mode.add_argument(
        "--full",
        dest="mode",
        action="store_const",
        const="full",
        help="the paper's chains (N = 399, t = 2e7): hours; run again to resume",
    )
    # A tiny spec set that exercises the whole pipeline in seconds (the tests'); --smoke, its old name.
    for flag in ("--tiny", "--smoke"):
        mode.add_argument(flag, dest="mode", action="store_const", const="tiny", help=argparse.SUPPRESS)
    p.set_defaults(mode="quick")
    p.add_argument(
        "--out",
        default=DEFAULT_OUT,
        metavar="DIR",
        help=f"output directory (default {DEFAULT_OUT}); stored results in it are reused",
    )
    add_dask_options(p, what=" for the chain runs", dashboard=False)
    add_overwrite_option(p)
    add_json_option(p)
    p.set_defaults(handler=run)


def run(args: argparse.Namespace) -> Result:
    """Handler of ``stickslip reproduce``."""
    _, workers = dask_options(args)
    own = OUT_FILES["reproduce"]
    with owned_out_dir(args.out, own, "stickslip reproduce", overwrite=args.overwrite) as out:
        return _run(out, args, workers)


def _run(out, args: argparse.Namespace, workers: int | None) -> Result:
    """The pipeline into the claimed directory ``out``; its errors as results."""
    from stickslip.experiments.reproduce import ReproduceError, reproduce

    try:
        with sigterm_as_interrupt():
            result = reproduce(
                out, args.mode, scheduler=args.scheduler, n_workers=workers, progress=not args.no_progress
            )
    except ReproduceError as exc:
        return Result({"error": str(exc)}, f"stickslip reproduce: {exc}", status=1)
    except KeyboardInterrupt:
        return interrupted(
            "reproduce", out, f"finished results in {out} are kept, chain runs continue from their last checkpoint"
        )
    except OSError as exc:  # e.g. no scheduler at the given address
        if is_disk_full(exc):
            raise
        raise CommandError(f"cannot run the chain runs: {exc}") from None
    return Result(result, _text(result))


#: Width of the agreement column of the summary table (its text wraps, whole words, below).
AGREEMENT_WIDTH = 60


def _text(result: dict) -> str:
    """The summary on stdout: a row per stated number, its agreement in full (wrapped at word
    boundaries, never cut), the studies, the figures and the report."""
    import textwrap

    lines = [f"stickslip reproduce --{result['mode']}: {result['wall_seconds']:.1f} s"]
    width = max(len(r["where"]) for r in result["rows"]) if result["rows"] else 0
    for r in result["rows"]:
        first, *more = textwrap.wrap(str(r["agreement"]), AGREEMENT_WIDTH, break_long_words=False) or [""]
        lines.append(f"  {r['where']:<{width}}  {first:<{AGREEMENT_WIDTH}}  {r['quantity']}")
        lines += [f"  {'':<{width}}  {line}" for line in more]
    for s in result["studies"]:
        lines.append(f"  {s['study']}: {s['points']} points ({s['reused']} reused); page {s['page']}")
    lines.append(f"figures: {len(result['figures'])}")
    for name, why in result["figures_not_drawn"].items():
        lines.append(f"  not drawn: {name}: {why}")
    lines.append(f"report: {result['report_html']}")
    return "\n".join(lines)
