"""`stickslip lyapunov --decorrelation`: slip sequences of a reference and its twins, compared.

The options and the handler of the mode (:func:`stickslip.analysis.dynamics.decorrelation.sequence_decorrelation`);
the subcommand itself is :mod:`stickslip.cli.lyapunov`.
"""

from __future__ import annotations

import argparse
import sys

from stickslip.cli._common import CommandError, Result, float_arg
from stickslip.models.params import check_number, steps_for

#: The default deltas of ``--deltas``.
DEFAULT_DELTAS = "1e-12,1e-10,1e-8,1e-6"


def add_options(p: argparse.ArgumentParser) -> None:
    """The options only ``--decorrelation`` reads (all default to None: given or not)."""
    p.add_argument(
        "--perturb",
        choices=("state", "Fs", "V"),
        default=None,
        help="--decorrelation: what the twin differs in: its state, moved by delta along a seeded "
        "direction (default), or Fs or V, changed by delta relative",
    )
    p.add_argument(
        "--deltas",
        default=None,
        metavar="D1,D2,...",
        help=f"--decorrelation: the perturbations delta (default {DEFAULT_DELTAS})",
    )
    p.add_argument(
        "--events",
        type=int,
        default=None,
        metavar="N_EV",
        help="--decorrelation: compare until N_EV slips of the reference have passed (default 1000)",
    )
    p.add_argument(
        "--seeds",
        type=int,
        default=None,
        metavar="K",
        help="--decorrelation: K windows, one after the other, each with its own direction (default 1)",
    )
    p.add_argument(
        "--rtol",
        type=float_arg("rtol"),
        default=None,
        metavar="R",
        help="--decorrelation: slips with the same start block and number of blocks disagree when "
        "their sizes differ by more than R of the larger (default 0.1)",
    )
    p.add_argument(
        "--state-cache",
        default=None,
        metavar="DIR",
        help="--decorrelation on the grid: keep the engine's state at --transient in DIR (checksummed, "
        "named by the model, start and transient) and start from it when it is there, so that "
        "several commands share one transient",
    )


#: (option, attribute) of :func:`add_options`, refused without ``--decorrelation``.
OPTIONS = (
    ("--perturb", "perturb"),
    ("--deltas", "deltas"),
    ("--events", "events"),
    ("--seeds", "seeds"),
    ("--rtol", "rtol"),
    ("--state-cache", "state_cache"),
)


def deltas_arg(text: str) -> list[float]:
    """The comma-separated deltas, each a number >= 0 (one-line error otherwise)."""
    try:
        values = [float(s) for s in text.split(",") if s.strip()]
    except ValueError:
        raise CommandError(f"--deltas must be a comma-separated list of numbers >= 0 (got {text!r})") from None
    if not values:
        raise CommandError(f"--deltas must be a comma-separated list of numbers >= 0 (got {text!r})")
    for d in values:
        check_number("delta", d, low=0.0, high=1.0)
    return values


def run(params, args: argparse.Namespace) -> Result:
    """`--decorrelation` with either switch rule, from the state at ``--transient``: a window of
    ``--events`` reference slips (cut at ``--t-end`` when given), ``--seeds`` windows."""
    from stickslip.analysis.dynamics.decorrelation import (
        EVENTS,
        SIZE_RTOL,
        GridSequences,
        LocatedSequences,
        check_slips,
        sequence_decorrelation,
    )

    deltas = deltas_arg(args.deltas if args.deltas is not None else DEFAULT_DELTAS)
    events = int(check_number("events", args.events if args.events is not None else EVENTS, low=1, integer=True))
    seeds = int(check_number("seeds", args.seeds if args.seeds is not None else 1, low=1, integer=True))
    rtol = float(check_number("rtol", args.rtol if args.rtol is not None else SIZE_RTOL, low=0.0, low_open=True))
    check_slips(events, seeds, len(deltas))  # before the transient is run
    perturb = args.perturb or "state"
    steps_for(args.transient, params.dt, "transient")  # before any work, named as given
    t_max = None
    if args.t_end is not None:
        if not args.t_end > args.transient:
            raise CommandError(f"--t-end must exceed --transient (got {args.t_end:g} and {args.transient:g})")
        t_max = args.t_end - args.transient
    located = args.switches == "located"
    if located and args.state_cache is not None:
        raise CommandError("--state-cache keeps the engine's state: it needs --switches grid")
    if args.state_cache is not None:
        from stickslip.run.loaded import check_cache_folder

        check_cache_folder(args.state_cache, "--state-cache")
    from stickslip.models.lattice.params import LatticeParams

    if isinstance(params, LatticeParams):
        source, start, loading = _lattice_start(params, args)
    else:
        source = LocatedSequences(params) if located else GridSequences(params)
        start, loading = _start(params, args, located)
    say = None
    if not args.no_progress and sys.stderr.isatty():

        def say(line: str) -> None:
            sys.stderr.write(f"decorrelation: {line}\n")

    res = sequence_decorrelation(
        source,
        start,
        deltas,
        perturbation=perturb,
        events=events,
        t_max=t_max,
        rtol=rtol,
        direction_seed=args.direction_seed,
        seeds=seeds,
        progress=say,
    )
    data = {"params": params.to_dict(), "switches": args.switches, "transient": args.transient, **res.to_dict()}
    if loading is not None:
        data["loading"] = loading
    lines = [f"{'delta':>8} {'seed':>4} {'slips agreeing':>15} {'t decorrelated':>15}"]
    for r in res.rows:
        n = f"{r['events']}" if r["decorrelated"] else f"all {r['events']}"
        t = f"{r['t_decorrelated']:.6g}" if r["decorrelated"] else "-"
        lines.append(f"{r['delta']:>8.0e} {r['seed']:>4d} {n:>15} {t:>15}")
    windows = ", ".join(f"{w['reference_events']} slips in {w['t_window']:.6g}" for w in res.windows)
    lines.append(f"perturbed: {perturb}; reference windows: {windows}")
    lines.append(f"slips disagree: other start block, other number of blocks, or sizes beyond rtol {rtol:g}")
    if loading is not None:
        first = loading["first_slip_reaching_block_N"]
        reach = (
            "no slip moved block N" if first is None else f"the first slip that moved block N started at {first:.6g}"
        )
        verdict = "loaded" if loading["loaded"] else "NOT loaded"
        lines.append(f"transient {args.transient:g}: {reach}; {verdict} ({loading['loaded_rule']})")
    return Result(data, "\n".join(lines))


def _lattice_start(params, args):
    """A lattice's slip sequences (:class:`stickslip.analysis.dynamics.lyapunov_lattice.LatticeSequences`)
    and the state at ``--transient`` from ``--start``; no loading check."""
    from stickslip.analysis.dynamics.lyapunov_lattice import LatticeSequences
    from stickslip.run.lattice import LatticeStepper, initial_state

    ref = initial_state(params, args.start, amplitude=args.perturbation, seed=args.seed)
    ref, _ = LatticeStepper(params).advance(ref, steps_for(args.transient, params.dt, "transient"))
    return LatticeSequences(params), ref, None


def _start(params, args, located: bool):
    """The state at ``--transient`` from ``--start`` and, on the grid, the transient's loading
    check (:func:`stickslip.run.loaded.loaded_state`, kept in ``--state-cache``): the engine's
    state (grid) or the located integrator's (located, as before; no check)."""

    if located:
        from stickslip.run.located import LocatedStepper, start_state

        ref = start_state(params, args.start, perturbation=args.perturbation, seed=args.seed)
        ref, _ = LocatedStepper(params).advance(ref, steps_for(args.transient, params.dt, "transient"))
        return ref, None
    from stickslip.run.loaded import loaded_state
    from stickslip.run.state import initial_state

    if args.transient > 0:
        loaded = loaded_state(
            params,
            args.transient,
            start=args.start,
            perturbation=args.perturbation,
            seed=args.seed,
            cache=args.state_cache,
        )
        return loaded.state, loaded.info
    return initial_state(params, args.start, amplitude=args.perturbation, seed=args.seed), None
