"""`stickslip period RUN_DIR`: whether a run's slip sequence settled on a periodic orbit (a chain
run's, or a lattice run's: docs/lattice.md)."""

from __future__ import annotations

import argparse
from pathlib import Path

from stickslip.cli._common import CommandError, Result, add_json_option, float_arg, int_arg


def add_rule_options(p: argparse.ArgumentParser, prefix: str = "") -> None:
    """The options of the matching rule (:func:`stickslip.analysis.stats.periodicity.find_period`),
    named ``--{prefix}rtol``, ``--{prefix}max-period`` and ``--{prefix}repeats``."""
    from stickslip.analysis.stats.period_rule import MAX_PERIOD, REPEATS, RTOL

    p.add_argument(
        f"--{prefix}rtol",
        dest="period_rtol",
        type=float_arg(f"{prefix}rtol", "in [0, 1]"),
        default=RTOL,
        help=f"relative tolerance on the slip size S of matching slips (default {RTOL:g})",
    )
    p.add_argument(
        f"--{prefix}max-period",
        dest="period_max",
        type=int_arg(f"{prefix}max-period", ">= 1"),
        default=MAX_PERIOD,
        help=f"longest period searched, in slips (default {MAX_PERIOD})",
    )
    p.add_argument(
        f"--{prefix}repeats",
        dest="period_repeats",
        type=int_arg(f"{prefix}repeats", ">= 2"),
        default=REPEATS,
        help=f"periods the periodic stretch must hold (default {REPEATS})",
    )


def rule_from_args(args: argparse.Namespace) -> dict:
    """The rule's keywords from :func:`add_rule_options`' options, checked."""
    from stickslip.models.params import check_number

    check_number("rtol", args.period_rtol, low=0.0, high=1.0)
    check_number("max-period", args.period_max, low=1, integer=True)
    check_number("repeats", args.period_repeats, low=2, integer=True)
    return {"rtol": args.period_rtol, "max_period": args.period_max, "repeats": args.period_repeats}


def register(sub) -> None:
    """Add the `period` subcommand."""
    p = sub.add_parser(
        "period",
        help="whether a run's slip sequence settled on a periodic orbit: its period and from when",
        description="Read the slips of a run directory (written by `stickslip chain --out`) and find the "
        "smallest period of the slip sequence and the first slip from which it repeats: slips match when "
        "the same block starts them, as many blocks move and their sizes S agree within a relative "
        "tolerance; the periodic stretch must hold a few periods. Prints period_slips (and its duration "
        "in time), settled_from_slip and settled_from_t (null where the sequence does not repeat within "
        "the run), the rule and the longest period searched. On a lattice run (stickslip chain --lattice "
        "square --out) a slip is its epicentre, area and moment. See docs/statistics.md, 'Periodic orbits', "
        "and docs/lattice.md.",
    )
    p.add_argument(
        "run_dir",
        metavar="RUN_DIR",
        help="a chain run directory (run.json, events.parquet) or a lattice run's (run.json, events.csv, state.nc)",
    )
    add_rule_options(p)
    add_json_option(p)
    p.set_defaults(handler=run_period_command)


def run_period_command(args: argparse.Namespace) -> Result:
    """Handler of `stickslip period`."""
    from stickslip.analysis.stats.periodicity import periodicity
    from stickslip.run.lattice_dir import is_lattice_run_dir
    from stickslip.run.rundir import RunDirDamaged, load_run

    rule = rule_from_args(args)
    run_dir = Path(args.run_dir)
    if not (run_dir / "run.json").is_file():
        raise CommandError(f"{run_dir} is not a finished chain run directory (no run.json)")
    if is_lattice_run_dir(run_dir):
        return _lattice(run_dir, rule)
    try:
        run = load_run(run_dir)
    except RunDirDamaged as exc:
        raise CommandError(f"cannot read {run_dir}: {exc}") from None
    found = periodicity(run.events, **rule)
    data = {"run_dir": str(run_dir), "t_reached": run.summary["t_reached"], **found.to_dict()}
    text = f"{found.text()}\nrun reached t = {run.summary['t_reached']:g}"
    return Result(data, text)


def _lattice(run_dir: Path, rule: dict) -> Result:
    """`stickslip period` on a lattice run directory:
    :func:`stickslip.analysis.stats.periodicity.lattice_periodicity` of its events."""
    from stickslip.analysis.stats.periodicity import lattice_periodicity
    from stickslip.run.lattice_dir import load_lattice_run

    run = load_lattice_run(run_dir)  # a folder without state.nc: ParameterError, one line
    found = lattice_periodicity(run.events, run.params.lattice, **rule)
    t_end = run.summary["t_end"]
    data = {"run_dir": str(run_dir), "lattice": run.params.lattice.describe(), "t_reached": t_end, **found.to_dict()}
    return Result(data, f"{found.text()}\n{data['lattice']}: run reached t = {t_end:g}")
