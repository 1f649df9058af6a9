"""`stickslip lyapunov`: the largest Lyapunov exponent of the chain of eq. (4) (eq. (1) at N = 1).

Benettin et al. (1980) two-trajectory method (:mod:`stickslip.analysis.dynamics.lyapunov`). ``--convergence``
tabulates the exponent against d0, the renormalisation interval and the run length;
``--betas`` tabulates it against beta, and ``--plot FILE`` draws that table. ``--switches located``
measures the exponent of the flow instead (:mod:`stickslip.analysis.dynamics.lyapunov_flow`): located
switches, the time-shift direction removed, at dt, dt/2, dt/4 and extrapolated to dt -> 0.
``--decorrelation`` compares slip sequences of perturbed twins (:mod:`stickslip.cli.decorrelation`).
``--lattice square --shape RxC`` measures the exponent and the decorrelation of the model on the
square (:mod:`stickslip.analysis.dynamics.lyapunov_lattice`; docs/lattice.md).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from stickslip.cli import decorrelation
from stickslip.cli._common import (
    CommandError,
    Result,
    add_json_option,
    add_model_options,
    chain_params_from_args,
    float_arg,
)
from stickslip.models.params import MAX_PERTURBATION, MAX_STEPS, ParameterError, check_number


def register(sub) -> None:
    """Add the `lyapunov` subcommand."""
    p = sub.add_parser(
        "lyapunov",
        help="largest Lyapunov exponent of the chain (eq. 4; eq. 1 with --N 1)",
        description=(
            "Largest Lyapunov exponent of the chain of eq. (4) by the two-trajectory method of "
            "Benettin et al. (1980): a reference run and a twin d0 away, renormalised every "
            "interval; the exponent is the mean of ln(d/d0) per unit time after the transient, "
            "with the standard error of the means of M segments. See docs/lyapunov.md."
        ),
    )
    add_model_options(p)
    from stickslip.cli.lattice import add_lattice_options

    add_lattice_options(p, run=False)
    p.add_argument(
        "--start",
        choices=("paper", "steady", "rest"),
        default=None,
        help="initial state (default: the model's; the paper's for sakaguchi, rest for the plate drive)",
    )
    p.add_argument(
        "--perturbation",
        type=float_arg("perturbation"),
        default=None,
        metavar="A",
        help="with --start steady: uniform perturbation of x and v in [-A, A] (default 0); with "
        "--start rest: x_i = -A u_i (default the model's, 0.01 for Carlson-Langer)",
    )
    p.add_argument("--seed", type=int, default=None, help="seed of the perturbation (default the model's, 0)")
    p.add_argument(
        "--t-end",
        type=float_arg("t-end"),
        default=None,
        metavar="T",
        help="end time (default 2e4; with --decorrelation the latest end of a window, none by default)",
    )
    p.add_argument(
        "--interval",
        type=float_arg("interval"),
        default=10.0,
        metavar="TAU",
        help="time between renormalisations (default 10)",
    )
    p.add_argument(
        "--d0", type=float_arg("d0"), default=1e-10, metavar="D0", help="initial separation of the twin (default 1e-10)"
    )
    p.add_argument(
        "--transient",
        type=float_arg("transient"),
        default=0.0,
        metavar="T0",
        help="the reference runs alone up to T0 before the twin is placed (default 0)",
    )
    p.add_argument(
        "--align",
        type=float_arg("align"),
        default=None,
        metavar="TA",
        help="renormalisations ending before T0 + TA are not counted (default (T - T0) / 10)",
    )
    p.add_argument(
        "--segments", type=int, default=10, metavar="M", help="independent segments for the error bar (default 10)"
    )
    p.add_argument("--direction-seed", type=int, default=0, help="seed of the twin's first direction (default 0)")
    p.add_argument(
        "--frame",
        choices=("centred", "absolute"),
        default=None,
        help="the grid's twin runs in a frame moved back along the drive (centred, the chain's default) or "
        "beside the reference itself (absolute, the only one on a lattice); docs/lyapunov.md",
    )
    p.add_argument(
        "--convergence",
        action="store_true",
        help="tabulate the exponent against d0 (1e-8, 1e-10, 1e-12), the interval (TAU/2, TAU, 2 TAU) "
        "and the run length",
    )
    p.add_argument(
        "--betas", default=None, metavar="B1,B2,...", help="tabulate the exponent against these values of beta"
    )
    p.add_argument(
        "--plot",
        default=None,
        metavar="FILE",
        help="with --betas: draw lambda(beta) as FILE.png and FILE.pdf (a suffix .png or .pdf is dropped)",
    )
    p.add_argument(
        "--switches",
        choices=("grid", "located"),
        default="grid",
        help="grid: the engine's map, starts and stops on the time grid (default); located: the flow, "
        "switches located inside the step, at dt, dt/2, dt/4 extrapolated to dt -> 0",
    )
    p.add_argument(
        "--neutral",
        choices=("remove", "keep"),
        default="remove",
        help="with --switches located: remove the separation's component along the flow (a shift in "
        "time, neutral) before measuring and renormalising (default), or keep it",
    )
    p.add_argument(
        "--levels", type=int, default=3, metavar="L", help="with --switches located: rungs dt .. dt/2^(L-1) (default 3)"
    )
    p.add_argument(
        "--finite-size",
        action="store_true",
        help="with --switches located: finite-size exponents, the mean time for a separation to grow "
        "from delta to 2 delta, delta from --delta-min to --delta-max (JSON key fsle)",
    )
    p.add_argument(
        "--decorrelation",
        action="store_true",
        help="the number of slips after which a reference and twins perturbed by each delta (--perturb, "
        "--deltas) stop agreeing, over --events slips from the state at --transient, with either "
        "--switches (JSON key decorrelation)",
    )
    p.add_argument(
        "--fronts",
        action="store_true",
        help="with --switches located: how far along the chain perturbations of one block's position "
        "by delta = 1e-10, 1e-6, 1e-3, 1e-2 spread (blocks differing by more than 1e-2 delta) over "
        "--t-end minus --transient, from the engine's state at --transient (JSON key fronts)",
    )
    p.add_argument(
        "--front-block", type=int, default=None, metavar="B", help="--fronts: the block moved (0-based, default 0)"
    )
    p.add_argument(
        "--lifetimes",
        default=None,
        metavar="N,N,...",
        help="the time from the paper's start until every block slides steadily, for each N, at most "
        "--loads loading times (JSON key lifetimes)",
    )
    p.add_argument("--loads", type=float_arg("loads"), default=None, metavar="L", help="--lifetimes: cap (default 8)")
    p.add_argument(
        "--delta-min", type=float_arg("delta-min"), default=None, metavar="D", help="--finite-size (default 1e-10)"
    )
    p.add_argument(
        "--delta-max", type=float_arg("delta-max"), default=None, metavar="D", help="--finite-size (default 0.1)"
    )
    p.add_argument("--cycles", type=int, default=None, metavar="C", help="finite-size cycles counted (default 20)")
    p.add_argument(
        "--check",
        type=float_arg("check"),
        default=None,
        metavar="TAU",
        help="finite-size: time between distance checks (default 0.1)",
    )
    decorrelation.add_options(p)
    p.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    add_json_option(p)
    p.set_defaults(handler=run_lyapunov_command)


def _betas(text: str) -> list[float]:
    try:
        values = [float(s) for s in text.split(",") if s.strip()]
    except ValueError:
        raise ParameterError(f"betas must be a comma-separated list of numbers >= 0 (got {text!r})") from None
    if not values:
        raise ParameterError(f"betas must be a comma-separated list of numbers >= 0 (got {text!r})")
    for b in values:
        check_number("beta", b, low=0.0)
    return values


def _result_text(d: dict) -> str:
    return "\n".join(
        [
            f"lyapunov          {d['lyapunov']:.6g} +- {d['lyapunov_err']:.2g}   (per unit time)",
            f"renormalisations  {d['renormalisations']} counted, interval {d['interval']:g}, d0 {d['d0']:g}",
            f"window            t = {d['transient'] + d['align']:g} .. {d['t_end']:g}  (transient {d['transient']:g}, "
            f"align {d['align']:g}); {d['events']} events in it",
            f"segments          {d['segments']} (error bar: standard error of their means)",
            f"max ln(d/d0)      {d['max_log_growth']:.3g} in one interval",
            f"reference sha256  {d['reference_sha256']}",
            f"wall time         {d['wall_seconds']:.3g} s",
        ]
    )


def run_lyapunov_command(args: argparse.Namespace) -> Result:
    """Handler of `stickslip lyapunov`."""
    from stickslip.analysis.dynamics import lyapunov as ly
    from stickslip.analysis.dynamics.benettin import check_run
    from stickslip.cli.lattice import lattice_params_from_args, refuse_on_lattice, wants_lattice
    from stickslip.models.presets import PRESETS

    lattice = wants_lattice(args)
    if lattice:
        refuse_on_lattice(args)
    params = lattice_params_from_args(args) if lattice else chain_params_from_args(args)
    preset = PRESETS[params.model]
    if args.start is None:
        args.start = preset.start
    from stickslip.run.state import check_start_draw

    check_start_draw(args.start, args.perturbation, args.seed, cli=True)  # as `chain` and run_chain check it
    if args.perturbation is None:
        args.perturbation = preset.start_options.get("amplitude", 0.0) if args.start == "rest" else 0.0
    if args.seed is None:
        args.seed = preset.start_options.get("seed", 0)
    check_number("perturbation", args.perturbation, low=0.0, high=MAX_PERTURBATION)
    check_number("seed", args.seed, low=0, integer=True)
    check_number("direction-seed", args.direction_seed, low=0, integer=True)
    if args.betas is not None:
        _betas(args.betas)  # refused before any run, '' included
    if args.plot and args.betas is None:
        raise CommandError("--plot needs --betas")
    if args.convergence and args.betas is not None:
        raise CommandError("give either --convergence or --betas, not both")
    kw = dict(
        interval=args.interval,
        d0=args.d0,
        transient=args.transient,
        align=args.align,
        start=args.start,
        perturbation=args.perturbation,
        seed=args.seed,
        direction_seed=args.direction_seed,
        segments=args.segments,
    )
    _refuse_ignored(args)
    if args.decorrelation:
        return _decorrelation(params, args)
    if args.t_end is None:
        args.t_end = 2e4
    # Validate every option before the first (possibly long) run.
    check_run(params, args.t_end, args.interval, args.d0, args.transient, args.align, args.segments)
    if args.lifetimes is not None:
        return _lifetimes(params, args)
    if args.switches == "located":
        return _located(params, args, kw)
    for flag, given in (("--finite-size", args.finite_size), ("--fronts", args.fronts)):
        if given:
            raise CommandError(f"{flag} goes with --switches located")
    if lattice:
        from stickslip.analysis.dynamics.lyapunov_lattice import lattice_lyapunov

        return _exponent(lattice_lyapunov(params, args.t_end, **kw), args)
    kw["frame"] = args.frame or "centred"
    if args.convergence:
        table = ly.lyapunov_convergence(params, args.t_end, **kw)
        data = {
            "params": params.to_dict(),
            "convergence": table.to_dict(orient="records"),
            "method": "Benettin et al. (1980) two-trajectory method",
            "norm": ly.NORM,
        }
        return Result(data, table.to_string(index=False))
    if args.betas is not None:
        betas = _betas(args.betas)
        table = ly.lyapunov_vs_beta(params, betas, args.t_end, progress=not args.no_progress, **kw)
        data = {
            "params": params.to_dict(),
            "t_end": args.t_end,
            "table": table.to_dict(orient="records"),
            "method": "Benettin et al. (1980) two-trajectory method",
            "norm": ly.NORM,
        }
        text = table.to_string(index=False)
        if args.plot:
            from stickslip.io import disk_full
            from stickslip.plotting.lyapunov import plot_lyapunov_beta
            from stickslip.plotting.style import FIGURE_FORMATS, save_figure

            fig = plot_lyapunov_beta(table, params)
            stem = Path(args.plot)
            if stem.suffix.lower().lstrip(".") in FIGURE_FORMATS:
                stem = stem.with_suffix("")
            try:
                written = save_figure(fig, stem)
            except (OSError, ValueError) as exc:
                if disk_full(exc) is not None:
                    raise
                raise CommandError(f"cannot write plot {args.plot}: {exc}") from None
            data["plot"] = str(stem)
            data["outputs"] = [str(p) for p in written]
            text += f"\nplot written to {', '.join(data['outputs'])}"
        return Result(data, text)
    return _exponent(ly.largest_lyapunov(params, args.t_end, progress=not args.no_progress, **kw), args)


def _exponent(res, args) -> Result:
    """The result of one exponent (the chain's or a lattice's), a warning where the twin merged."""
    data = res.to_dict()
    if data["merges"]:
        import sys

        sys.stderr.write(
            f"stickslip lyapunov: warning: the twin fell onto the reference {data['merges']} times "
            f"(d0 = {args.d0:g} at the rounding floor, or sticking contracts to a point); "
            "try a larger --d0\n"
        )
    return Result(data, _result_text(data))


def _ladder_text(d: dict) -> str:
    lines = [f"{'dt':>10} {'lyapunov':>12} {'err':>9} {'renorm':>7} {'events':>7} {'wall s':>7}"]
    for r in d["ladder"]:
        lines.append(
            f"{r['dt']:>10.6g} {r['lyapunov']:>12.6g} {r['lyapunov_err']:>9.2g} {r['renormalisations']:>7d} "
            f"{r['events']:>7d} {r['wall_seconds']:>7.3g}"
        )
    lines.append(
        f"dt -> 0      {d['lyapunov_dt0']:.6g} +- {d['lyapunov_dt0_err']:.2g}   (per unit time; {d['extrapolation']})"
    )
    lines.append(f"neutral      {d['neutral']} (the time-shift direction along the flow)")
    return "\n".join(lines)


def _located(params, args, kw) -> Result:
    """`--switches located`: the ladder of :func:`stickslip.analysis.dynamics.lyapunov_flow.flow_ladder`."""
    from stickslip.analysis.dynamics.lyapunov_flow import flow_ladder

    if args.convergence or args.betas is not None:
        raise CommandError("--switches located runs one ladder; --convergence and --betas go with --switches grid")
    if args.finite_size and args.fronts:
        raise CommandError("give one of --finite-size, --decorrelation and --fronts")
    if args.fronts:
        return _fronts(params, args)
    if args.finite_size:
        return _finite_size(params, args)
    check_number("levels", args.levels, low=2, high=6, integer=True)
    import numpy as np

    try:
        ladder = flow_ladder(params, args.t_end, levels=args.levels, neutral=args.neutral, **kw)
    except (ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
        if isinstance(exc, ParameterError):
            raise
        # an extreme dt or d0: the ladder's numbers are not finite, or its fit has no answer
        raise CommandError(f"--switches located at dt = {params.dt:g}, d0 = {args.d0:g}: {exc}") from None
    data = ladder.to_dict()
    return Result(data, _ladder_text(data))


def _finite_size(params, args) -> Result:
    """`--switches located --finite-size`: :func:`stickslip.analysis.dynamics.fsle.finite_size_exponents`."""
    from stickslip.analysis.dynamics.fsle import LocatedPair, finite_size_exponents, thresholds
    from stickslip.models.params import steps_for
    from stickslip.run.located import LocatedStepper, start_state

    for name, default in (("delta_min", 1e-10), ("delta_max", 0.1), ("cycles", 20), ("check", 0.1)):
        if getattr(args, name) is None:
            setattr(args, name, default)
    deltas = thresholds(args.delta_min, args.delta_max)
    check_number("cycles", args.cycles, low=1, integer=True)
    # A check further apart than the longest cycle (--t-end) would never look at the distance.
    check = max(1, int(round(check_number("check", args.check, low=params.dt, high=args.t_end) / params.dt)))
    ref = start_state(params, args.start, perturbation=args.perturbation, seed=args.seed)
    ref, _ = LocatedStepper(params).advance(ref, steps_for(args.transient, params.dt, "transient"))
    pair = LocatedPair(params, ref, neutral=args.neutral, direction_seed=args.direction_seed)
    res = finite_size_exponents(
        pair, deltas, cycles=args.cycles, check_steps=check, max_cycle_time=args.t_end, pooled_below=1e-6
    )
    data = {"params": params.to_dict(), "switches": "located", "neutral": args.neutral, "transient": args.transient}
    data.update(res.to_dict())
    lines = [f"{'delta':>10} {'rate':>10} {'err':>9} {'cycles':>6}"]
    for r in res.rows:
        lines.append(f"{r['delta']:>10.3g} {r['rate']:>10.4g} {r['rate_err']:>9.2g} {r['cycles']:>6d}")
    if "pooled_rate" in res.extra:
        e = res.extra
        lines.append(f"pooled up to {e['pooled_below']:.3g}: {e['pooled_rate']:.4g} +- {e['pooled_rate_err']:.2g}")
    if res.unfinished:
        lines.append(f"{res.unfinished} cycles did not reach {deltas[-1]:g} within t = {args.t_end:g}")
    return Result(data, "\n".join(lines))


def _decorrelation(params, args) -> Result:
    """`--decorrelation` (either switch rule): :func:`stickslip.cli.decorrelation.run`."""
    for option, given in (
        ("--convergence", args.convergence),
        ("--betas", args.betas is not None),
        ("--finite-size", args.finite_size),
        ("--fronts", args.fronts),
    ):
        if given:
            raise CommandError(f"{option} does not go with --decorrelation")
    check_number("transient", args.transient, low=0.0)
    return decorrelation.run(params, args)


def _fronts(params, args) -> Result:
    """`--switches located --fronts`: :func:`stickslip.analysis.dynamics.stable_chaos.perturbation_front`."""
    from stickslip.analysis.dynamics.stable_chaos import perturbation_front
    from stickslip.run.loaded import located_start

    if not args.t_end > args.transient:
        raise CommandError(f"--t-end must exceed --transient (got {args.t_end:g} and {args.transient:g})")
    if args.front_block is None:
        args.front_block = 0
    check_number("front-block", args.front_block, low=0, high=params.N - 1, integer=True)
    if params.ends_piece.wall and args.transient > 0:
        raise CommandError("--fronts restarts the clock after --transient: fixed ends (which read t) are refused")
    start = located_start(params, args.transient, start=args.start, perturbation=args.perturbation, seed=args.seed)
    res = perturbation_front(
        params, start, (1e-10, 1e-6, 1e-3, 1e-2), t_max=args.t_end - args.transient, block=args.front_block
    )
    data = {"params": params.to_dict(), "switches": "located", "transient": args.transient, **res.to_dict()}
    lines = [f"{'delta':>8} {'blocks reached':>15} {'at t':>9} {'speed':>10} {'ln(max diff/delta)':>19}"]
    for r in res.rows:
        lines.append(
            f"{r['delta']:>8.0e} {r['reach']:>15d} {r['t_reach']:>9.4g} {r['speed']:>10.3g} {r['log_growth']:>19.3g}"
        )
    lines.append(f"block {res.block} moved; threshold {res.rel:g} delta; t after the transient")
    return Result(data, "\n".join(lines))


#: Options that only one mode reads: (option, its attribute, the mode's flag, whether the mode is on).
_MODE_OPTIONS = (
    ("--front-block", "front_block", "--fronts", lambda a: a.fronts),
    ("--delta-min", "delta_min", "--finite-size", lambda a: a.finite_size),
    ("--delta-max", "delta_max", "--finite-size", lambda a: a.finite_size),
    ("--cycles", "cycles", "--finite-size", lambda a: a.finite_size),
    ("--check", "check", "--finite-size", lambda a: a.finite_size),
    ("--loads", "loads", "--lifetimes", lambda a: a.lifetimes is not None),
    *((option, name, "--decorrelation", lambda a: a.decorrelation) for option, name in decorrelation.OPTIONS),
)


def _refuse_ignored(args) -> None:
    """Refuse an option the chosen mode would ignore: one of another mode's (``--front-block``
    without ``--fronts``), or beside ``--lifetimes`` one of the exponents' (``--betas``,
    ``--switches located``)."""
    for option, name, mode, on in _MODE_OPTIONS:
        if getattr(args, name) is not None and not on(args):
            raise CommandError(f"{option} goes with {mode}")
    if args.frame is not None and (args.switches == "located" or args.decorrelation or args.lifetimes is not None):
        raise CommandError(
            "--frame goes with the grid's exponent (--switches grid, without --decorrelation or --lifetimes)"
        )
    if args.lifetimes is None:
        return
    for option, given in (
        ("--betas", args.betas is not None),
        ("--convergence", args.convergence),
        ("--switches located", args.switches == "located"),
        ("--plot", bool(args.plot)),
    ):
        if given:
            raise CommandError(f"{option} does not go with --lifetimes (it measures no exponent)")


def _lifetimes(params, args) -> Result:
    """`--lifetimes`: :func:`stickslip.analysis.dynamics.stable_chaos.steady_lifetime` at each N."""
    from stickslip.analysis.dynamics.stable_chaos import steady_lifetime
    from stickslip.experiments.studies.chain_point import loading_time

    try:
        Ns = [int(s) for s in args.lifetimes.split(",") if s.strip()]
    except ValueError:
        raise CommandError(
            f"--lifetimes must be a comma-separated list of block numbers (got {args.lifetimes!r})"
        ) from None
    if not Ns:
        raise CommandError("--lifetimes needs at least one N")
    for n in Ns:
        check_number("N", n, low=1, integer=True)
    if args.loads is None:
        args.loads = 8.0
    check_number("loads", args.loads, low=0.0, low_open=True)
    for n in Ns:  # every run's length, before the first runs
        cap = max(loading_time(n, params.K, params.V), 1.0)
        if args.loads * cap / params.dt > MAX_STEPS:
            raise CommandError(
                f"--loads must be <= {MAX_STEPS * params.dt / cap:.3g} at N = {n} (a run of at most "
                f"{MAX_STEPS:.0e} steps of dt = {params.dt:g}, its loading time {cap:.3g}; got {args.loads:g})"
            )
    rows = []
    for n in Ns:
        p = params.replace(N=n)
        load = loading_time(n, p.K, p.V)
        out = steady_lifetime(p, args.loads * max(load, 1.0))
        out["loading_time"] = load
        out["t_steady_loads"] = out["t_steady"] / load if out["t_steady"] is not None and load > 0 else None
        rows.append(out)
    # each row has its own N
    data = {"params": {k: v for k, v in params.to_dict().items() if k != "N"}, "loads": args.loads, "lifetimes": rows}
    lines = [f"{'N':>6} {'t_steady':>12} {'loading times':>14} {'events':>8} {'wall s':>8}"]
    for r in rows:
        ts = f"{r['t_steady']:.6g}" if r["t_steady"] is not None else f"> {r['t_max']:.3g}"
        tl = f"{r['t_steady_loads']:.3g}" if r["t_steady_loads"] is not None else "-"
        lines.append(f"{r['N']:>6d} {ts:>12} {tl:>14} {r['events']:>8d} {r['wall_seconds']:>8.3g}")
    return Result(data, "\n".join(lines))
