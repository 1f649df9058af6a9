"""`stickslip study`: the studies the paper leaves open, with a page per study.

    stickslip study NAME [--quick | --full] [--out DIR] [--scheduler ADDRESS] [--workers N] [--json]

NAME is ``transition`` (order parameter against beta and N), ``phase-diagram`` (final state over
(alpha, beta) and (D, beta), two starts), ``exponents`` (slip-size exponent against beta, and
Carlson-Langer) or ``chaos`` (the flow's exponent, slip decorrelation and its threshold delta*
against N at beta = 0.5, 0.9, 1, and the verdict; two blocks, Carlson-Langer).
Every point is cached and reused (only if its files are whole: a damaged point runs again); an
interrupted study resumes; a failed point is reported and retried by the next call. DIR is owned
as a chain's run directory is: no foreign files (``--overwrite`` removes this study's own files
only), one writer at a time. See docs/studies/ and docs/limits.md.
"""

from __future__ import annotations

import argparse
import contextlib
from collections.abc import Iterator
from pathlib import Path

from stickslip.cli._common import (
    CommandError,
    Result,
    add_dask_options,
    add_json_option,
    add_overwrite_option,
    check_out_dir,
    dask_options,
    interrupted,
    is_disk_full,
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
    add_overwrite_option(p)
    add_dask_options(p)
    add_json_option(p)
    p.set_defaults(handler=run)


def run(args: argparse.Namespace) -> Result:
    """Handler of ``stickslip study``: the output folder is checked and locked before the first
    point starts (:func:`_claim`)."""
    from stickslip.experiments.study_run import run_study

    _, workers = dask_options(args)
    if args.extra_n and (args.name != "transition" or min(args.extra_n) < 3):
        raise CommandError("--extra-n takes chains of at least 3 blocks, for the transition study only")
    from stickslip.models.params import MAX_BLOCKS, check_number

    for n in args.extra_n or ():  # before any ladder runs
        check_number("extra-n", n, low=3, high=MAX_BLOCKS, integer=True)
    spec = _spec(args)
    with _claim(args.out, spec, overwrite=args.overwrite) as out:
        if args.name == "transition":
            return _transition(args, out, workers)
        try:
            with sigterm_as_interrupt():
                result = run_study(
                    spec,
                    out,
                    scheduler=args.scheduler,
                    n_workers=workers,
                    progress=not args.no_progress,
                    dashboard=args.dashboard,
                )
        except KeyboardInterrupt:
            return interrupted(
                "study", out, f"finished points in {out} are kept, chain runs continue from their checkpoints"
            )
        except OSError as exc:
            if is_disk_full(exc):
                raise
            raise CommandError(f"cannot run the study: {exc}") from None
    data = {k: v for k, v in result.items() if k != "figures"}
    data["figures"] = [f["image"] for f in result["figures"]]
    return Result(data, _text(result), status=1 if result["failed"] else 0)


@contextlib.contextmanager
def _claim(path: str, spec, *, overwrite: bool) -> Iterator[Path]:
    """Own the study's output folder as a chain run owns its directory: refuse it if it holds
    files no study of this package wrote (:func:`~stickslip.experiments.study_run.foreign_files`;
    with ``overwrite`` only those where this study writes: its page and runs folders), hold its
    lock for the whole study (a second writer is refused at once, naming the holder) and, with
    ``overwrite``, remove this study's own files first. Every output path is checked here,
    before the first point starts."""
    from stickslip.experiments.study_run import MANIFEST, foreign_files, remove_study_files
    from stickslip.run.rundir import RunDirBusy, owned_run_dir

    out = check_out_dir(path)
    foreign = foreign_files(out, spec)
    if overwrite:  # other files may stay, but nothing of somebody else's where this study writes
        mine = (f"{spec.name}/", f"runs/{spec.dirname}/")
        foreign = [f for f in foreign if f.startswith(mine)]
    if foreign:
        shown = ", ".join(foreign[:3]) + (", ..." if len(foreign) > 3 else "")
        hint = "" if overwrite else ", or --overwrite to replace this study's own files there"
        raise CommandError(
            f"--out {out} holds files that `stickslip study` did not write ({shown}); choose an empty directory{hint}"
        )
    try:
        with owned_run_dir(out, run_id=False, keep={MANIFEST}):  # it names the page files kept
            if foreign_files(out, spec) and not overwrite:  # put there while the lock was taken
                raise CommandError(f"--out {out} changed while the study started; run it again")
            if overwrite:
                remove_study_files(out, spec)
            yield out
    except RunDirBusy as exc:
        raise CommandError(str(exc)) from None
    except OSError as exc:
        if is_disk_full(exc) or out.is_dir():
            raise
        raise CommandError(f"cannot create output directory {out}: {exc.strerror}") from None


def _spec(args: argparse.Namespace):
    """The spec whose folder the study owns: the study's, or for ``transition`` (run by
    continuation in beta) its name and runs folder."""
    from stickslip.experiments.studies import study

    if args.name == "transition":
        from stickslip.experiments.transition_study import study_folder

        return study_folder(args.mode, tuple(args.extra_n))
    return study(args.name, args.mode)


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
                dashboard=args.dashboard,
            )
    except KeyboardInterrupt:
        return interrupted("study", out, f"finished rungs in {out} are kept; the ladders continue from them")
    except OSError as exc:
        if is_disk_full(exc):
            raise
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
    if result.get("damaged"):
        lines.append(f"  {result['damaged']} cached points ran again: their files were damaged (see the page)")
    lines += [f"  {s}" for s in result["findings"].get("statements", [])]
    for f in result["failed_points"]:
        lines.append(f"  failed: {f['point']}: {f['error']}")
    lines.append(f"page: {result['page']}")
    return "\n".join(lines)
