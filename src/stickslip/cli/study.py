"""`stickslip study`: the studies the paper leaves open, and the paper's own, with a page per study.

    stickslip study NAME [--quick | --full] [--out DIR] [--scheduler ADDRESS] [--workers N] [--json]

NAME is one of :data:`stickslip.experiments.studies.STUDIES` or of
:data:`~stickslip.experiments.studies.PAPER` (the two studies ``stickslip reproduce`` runs and
gathers into its report); ``stickslip study NAME --help``
prints what the study's module says of it (its grid, its cost, its outputs).
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
    """Add the ``study`` subcommand, with one subcommand per study whose ``--help`` is its
    module's description (:class:`~stickslip.experiments.studies.Design`)."""
    from stickslip.experiments.studies import PAPER, STUDIES, design

    p = sub.add_parser(
        "study",
        help="run a study the paper leaves open (transition, phase-diagram, exponents, chaos, lifetimes, disorder, "
        "lattice) or one of "
        "the paper's own (figs1-4, figs5-8); writes a page",
        description=(
            "Run every point of a study on Dask (reusing finished points), then write its table "
            "(Parquet, CSV), figures and an HTML page under DIR/NAME/. "
            "`stickslip study NAME --help` describes one study: its grid, its cost and its outputs."
        ),
    )
    names = p.add_subparsers(
        dest="name",
        metavar="NAME",
        required=True,
        title="studies",
        parser_class=type("StudyParser", (_LazyDescription, type(p)), {}),
    )
    for name in STUDIES + PAPER:
        plan = design(name)
        q = names.add_parser(name, help=plan.summary)
        q.describe = plan.describe
        _options(q, plan)
        q.set_defaults(handler=run, study_options=[o.dest for o in plan.options])


class _LazyDescription:
    """Mixed into a study's parser: its description (its module's text, made from the study's
    specs in every mode: a second or so) is made only when its help is asked for."""

    describe = None

    def format_help(self) -> str:
        if self.description is None and self.describe is not None:
            self.description = self.describe()
        return super().format_help()


def _options(p: argparse.ArgumentParser, plan) -> None:
    """The options every study takes, then the study's own."""
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
    for o in plan.options:
        p.add_argument(o.flag, dest=o.dest, type=int, action="append", default=[], metavar=o.metavar, help=o.help)
    p.add_argument("--out", default=DEFAULT_OUT, metavar="DIR", help=f"output directory (default {DEFAULT_OUT})")
    add_overwrite_option(p)
    add_dask_options(p)
    add_json_option(p)


def run(args: argparse.Namespace) -> Result:
    """Handler of ``stickslip study NAME``: the output folder is checked and locked before the
    first point starts (:func:`_claim`)."""
    from stickslip.experiments.studies import study
    from stickslip.experiments.study_run import run_study

    _, workers = dask_options(args)
    spec = study(args.name, args.mode, **{d: tuple(getattr(args, d)) for d in args.study_options})
    with _claim(args.out, spec, overwrite=args.overwrite) as out:
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
            kept = f"finished points in {out} are kept, chain runs continue from their checkpoints"
            return interrupted("study", out, kept)
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
    foreign = foreign_files(out)
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
            if foreign_files(out) and not overwrite:  # put there while the lock was taken
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
