"""`stickslip plot RUN_DIR`: every figure a chain run's data supports, as PNG and PDF."""

from __future__ import annotations

import argparse
from pathlib import Path

from stickslip.cli._common import (
    CommandError,
    Result,
    add_json_option,
    add_overwrite_option,
    owned_out_dir,
)
from stickslip.cli._reading import reading_run_dir

# The figures `plot` draws (stickslip.plotting.run.run_figures); its --out may hold only these.


def register(sub) -> None:
    """Add the `plot` subcommand."""
    p = sub.add_parser(
        "plot",
        help="draw every figure a chain or lattice run directory supports (PNG and PDF)",
        description="Draw L(t), the final state and stored snapshots against steady sliding, the slip-size "
        "distribution with its fit and the rupture fronts of the largest events, as far as the "
        "run's data allow, from a directory written by `stickslip chain --out`. On a lattice run: the final "
        "state and the last snapshot as images, and the slip maps and rupture fronts of the largest events "
        "recorded with --slip-maps (docs/lattice.md).",
    )
    p.add_argument("run_dir", metavar="RUN_DIR", help="a run directory (run.json, state.nc, events.parquet)")
    p.add_argument("--out", metavar="DIR", default=None, help="where the figures go (default RUN_DIR/figures)")
    p.add_argument(
        "--format",
        action="append",
        choices=("png", "pdf", "svg"),
        default=None,
        help="file format (repeatable; default png and pdf)",
    )
    add_overwrite_option(p)
    add_json_option(p)
    p.set_defaults(handler=run_plot_command)


def run_plot_command(args: argparse.Namespace) -> Result:
    """Handler of `stickslip plot`."""
    from stickslip.plotting.run import draw_run_figures
    from stickslip.run.ownership import PLOT_FILE as _FIGURE
    from stickslip.run.ownership import PLOT_FOLDER
    from stickslip.run.rundir import RunDirDamaged, load_run

    run_dir = Path(args.run_dir)
    if not (run_dir / "run.json").is_file() or not (run_dir / "state.nc").is_file():
        raise CommandError(f"{run_dir} is not a finished chain run directory (no run.json or state.nc)")
    out = Path(args.out) if args.out else run_dir / PLOT_FOLDER
    if out.resolve() == run_dir.resolve():
        raise CommandError(
            f"--out {out} is the run directory itself; the figures go into a folder of "
            "their own (default RUN_DIR/figures)"
        )
    formats = tuple(dict.fromkeys(args.format or ("png", "pdf")))
    from stickslip.run.lattice_dir import is_lattice_run_dir

    if is_lattice_run_dir(run_dir):
        from stickslip.plotting.lattice import draw_lattice_figures
        from stickslip.run.lattice_dir import load_lattice_run

        run = load_lattice_run(run_dir)
        with owned_out_dir(out, _FIGURE.fullmatch, "stickslip plot", overwrite=args.overwrite) as out:
            records = draw_lattice_figures(run, out, formats=formats)
        return Result({"out": str(out), "figures": records}, _lines(records))
    with reading_run_dir(run_dir):  # a run writing into it (chain --resume) and the figures exclude each other
        try:
            run = load_run(run_dir)
        except RunDirDamaged as exc:
            raise CommandError(f"cannot plot {run_dir}: {exc}") from None
        with owned_out_dir(out, _FIGURE.fullmatch, "stickslip plot", overwrite=args.overwrite) as out:
            records = draw_run_figures(run, out, formats=formats)
    return Result({"out": str(out), "figures": records}, _lines(records))


def _lines(records: list[dict]) -> str:
    """One line per figure: its files, or why it was not drawn."""
    lines = []
    for r in records:
        if "files" in r:
            lines.append(f"{r['figure']:<16} {', '.join(r['files'])}")
        else:
            lines.append(f"{r['figure']:<16} not drawn: {r['skipped']}")
    return "\n".join(lines)
