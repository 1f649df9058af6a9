"""`stickslip chain --lattice square --shape RxC [--edges ...]`: a model on a lattice
(docs/lattice.md), on the lattice reference integrator."""

from __future__ import annotations

import argparse
from pathlib import Path

from stickslip.cli._common import CommandError, Result, float_arg, int_arg

#: Options of `stickslip chain` that do not yet go with a lattice, as the command spells them.
_NOT_YET = {
    "from_dir": "--from",
    "resume": "--resume",
    "average_from": "--average-from",
    "snapshot": "--snapshot",
    "profile_window": "--profile-window",
    "profile_min_blocks": "--profile-min-blocks",
    "until_steady": "--until-steady",
    "checkpoint_interval": "--checkpoint-interval",
    "keep_checkpoint": "--keep-checkpoint",
    "until_periodic": "--until-periodic",
}


def add_lattice_options(p: argparse.ArgumentParser, *, bench: bool = False, run: bool = True):
    """``--lattice``, ``--shape``, ``--edges`` and ``--snapshot-every`` of `stickslip chain`
    (``--t-prepare`` in its place for `stickslip bench`; neither where ``run`` is false: the
    other commands that take a model). Returns the option group."""
    from stickslip.models.lattice import EDGE_KINDS, LATTICES, SIDES

    g = p.add_argument_group("lattice (docs/lattice.md)")
    g.add_argument("--lattice", choices=LATTICES, default=None, help="chain (default: eq. 4's line) or square")
    g.add_argument("--shape", default=None, metavar="RxC", help="rows x cols of the square, e.g. 64x64")
    g.add_argument(
        "--edges",
        default=None,
        metavar="EDGES",
        help=f"the square's sides ({', '.join(SIDES)}): one kind for all, or SIDE=KIND,... with kinds "
        f"{', '.join(EDGE_KINDS)} (default: the ends piece's kind; an edge drive pulls the left side)",
    )
    if not run:
        return g
    if bench:
        g.add_argument(
            "--t-prepare",
            type=float_arg("t-prepare", ">= 0"),
            default=None,
            metavar="T",
            help="with --lattice square: run exact from rest to T first, then time both over --t-end "
            "(default: two loading times 2 / V for a plate drive, at V = 0.001 unless given; else 0)",
        )
        g.add_argument(
            "--sizes",
            default=None,
            metavar="L,L,...",
            help="with --workload events: the sizes L of the L x L squares (default 64,128,256)",
        )
        return g
    g.add_argument(
        "--snapshot-every",
        dest="lattice_snapshot_every",
        type=float_arg("snapshot-every", "> 0"),
        default=None,
        metavar="T",
        help="with --lattice square: snapshots of x, v, theta and stopped over (row, col) every T, in state.nc",
    )
    g.add_argument(
        "--slip-maps",
        type=int_arg("slip-maps", "in [0, 256]"),
        default=None,
        metavar="K",
        help="with --lattice square: the slip field and first-move steps of the K largest events, in event_fields.nc",
    )
    g.add_argument(
        "--slip-min-area",
        type=int_arg("slip-min-area", ">= 1"),
        default=None,
        metavar="A",
        help="with --slip-maps: only events of at least A blocks",
    )
    return g


def refuse_lattice(args: argparse.Namespace, command: str) -> None:
    """The one-line refusal of a command that does not yet run on a lattice: ``--lattice square``
    (and ``--shape``, ``--edges`` without it, as :func:`wants_lattice` refuses them)."""
    if wants_lattice(args):
        raise CommandError(f"--lattice {args.lattice} is not yet available with stickslip {command} (docs/lattice.md)")


def refuse_on_lattice(args: argparse.Namespace) -> None:
    """The one-line refusal of what `stickslip lyapunov --lattice square` does not yet do: the
    exponent of the flow and its modes (``--switches located``), the tables against d0 or beta,
    the lifetimes, the chain's centred frame, a shared transient's cache and a twin that differs
    in a parameter."""
    perturb = getattr(args, "perturb", None)
    for option, given in (
        ("--switches located", args.switches == "located"),
        ("--convergence", args.convergence),
        ("--betas", args.betas is not None),
        ("--lifetimes", args.lifetimes is not None),
        ("--finite-size", args.finite_size),
        ("--fronts", args.fronts),
        ("--frame centred", args.frame == "centred"),
        ("--state-cache", getattr(args, "state_cache", None) is not None),
        (f"--perturb {perturb}", perturb not in (None, "state")),
    ):
        if given:
            raise CommandError(
                f"{option} is not yet available with stickslip lyapunov --lattice {args.lattice} (docs/lattice.md)"
            )


def wants_lattice(args: argparse.Namespace) -> bool:
    """Whether the command line asks for a lattice other than the chain."""
    if getattr(args, "lattice", None) in (None, "chain"):
        for option, value in (("--shape", getattr(args, "shape", None)), ("--edges", getattr(args, "edges", None))):
            if value is not None:
                raise CommandError(f"{option} goes with --lattice square")
        if getattr(args, "t_prepare", None) is not None:
            raise CommandError("--t-prepare goes with --lattice square")
        if getattr(args, "lattice_snapshot_every", None) is not None:
            raise CommandError("--snapshot-every goes with --lattice square (the chain has --snapshot)")
        for option, name in (("--slip-maps", "slip_maps"), ("--slip-min-area", "slip_min_area")):
            if getattr(args, name, None) is not None:
                raise CommandError(f"{option} goes with --lattice square")
        return False
    return True


def lattice_params_from_args(args: argparse.Namespace, **overrides):
    """The model of the command line on ``--lattice square --shape RxC --edges ...``: the chain's
    options (pieces, parameters, per-block values and ``--disorder-seed``, ``--history``) for
    N = rows cols blocks, a per-block ``file:`` table of rows x cols read row by row
    (docs/lattice.md); ``overrides`` are the command's own defaults, as for
    :func:`~stickslip.cli._common.chain_params_from_args`."""
    import dataclasses

    from stickslip.cli._common import chain_params_from_args
    from stickslip.models.lattice import parse_shape
    from stickslip.models.lattice.params import on_lattice, row_major
    from stickslip.models.params import ChainParams
    from stickslip.models.presets import on_square

    if args.shape is None:
        raise CommandError(f"--lattice {args.lattice} needs --shape ROWSxCOLS (e.g. 64x64)")
    if getattr(args, "param_N", None) is not None:
        raise CommandError("--N goes with the chain; the square's size is --shape")
    N = on_square({}, args.shape)["N"]  # a bad shape: ParameterError, one line
    shape = parse_shape(args.shape)
    given = argparse.Namespace(**vars(args))
    for f in dataclasses.fields(ChainParams):
        value = getattr(given, f"param_{f.name}", None)
        if value is not None:
            setattr(given, f"param_{f.name}", row_major(f"--{f.name}", value, shape))
    given.param_N = N
    return on_lattice(chain_params_from_args(given, **overrides), args.lattice, args.shape, args.edges)


def run_lattice_command(args: argparse.Namespace) -> Result:
    """`stickslip chain --lattice square`: run the model on the square, print its summary."""
    from stickslip.run.lattice import run_lattice, start_defaults

    for name, option in _NOT_YET.items():
        if getattr(args, name, None) not in (None, False):
            raise CommandError(f"{option} is not yet available with --lattice {args.lattice}")
    if args.integrator not in (None, "dense", "exact"):
        raise CommandError(f"--integrator {args.integrator}: a lattice runs on exact or dense")
    from stickslip.run.lattice_fields import MAX_SLIP_MAPS

    if args.slip_maps is not None and not 0 <= args.slip_maps <= MAX_SLIP_MAPS:
        raise CommandError(f"--slip-maps must be in [0, {MAX_SLIP_MAPS}] (got {args.slip_maps})")
    if args.slip_min_area is not None and (args.slip_min_area < 1 or not args.slip_maps):
        raise CommandError(f"--slip-min-area must be >= 1 and goes with --slip-maps (got {args.slip_min_area})")
    params = lattice_params_from_args(args)
    t_end = 1000.0 if args.t_end is None else args.t_end
    start, amplitude = start_defaults(params, args.start, args.perturbation)
    if start == "paper" and (args.perturbation is not None or args.seed is not None):
        raise CommandError("--perturbation and --seed go with --start steady or --start rest")
    run = run_lattice(
        params,
        t_end,
        start=start,
        perturbation=amplitude,
        seed=args.seed or 0,
        snapshot_every=args.lattice_snapshot_every,
        integrator=args.integrator or "exact",
        sample_every=args.sample_interval,
        slip_maps=args.slip_maps or 0,
        slip_min_area=args.slip_min_area or 1,
    )
    out = Path(args.out) if args.out else None
    if out is not None:
        run.write(out)
    ev = run.events
    summary = dict(run.summary)
    summary.update(
        {
            "start": start,
            "largest_area": int(ev["area"].max()) if len(ev) else 0,
            "largest_moment": float(ev["moment"].max()) if len(ev) else 0.0,
            "out": str(out) if out else None,
        }
    )
    pieces = ", ".join(f"{k} {v}" for k, v in params.pieces.items() if k != "ends")
    text = [
        f"{summary['lattice']}: {params.model} ({pieces})",
        f"t_end {summary['t_end']:g} ({summary['steps']} steps), start {start}: {summary['events']} events, "
        f"largest area {summary['largest_area']} blocks, largest moment {summary['largest_moment']:.4g}",
        f"moving at the end: {summary['moving_at_end']} of {params.lattice.n_blocks}; "
        f"state sha256 {summary['state_sha256'][:16]}...",
    ]
    if out is not None:
        text.append(
            f"written: {out}/run.json, events.csv, state.nc"
            + (", samples.csv" if run.samples is not None else "")
            + (", event_fields.nc" if run.event_fields is not None else "")
        )
    return Result(summary, "\n".join(text))


def run_lattice_bench_command(args: argparse.Namespace) -> Result:
    """`stickslip bench --lattice square --shape RxC`: dense against exact on the square, from the
    model's state at --t-prepare, timed over --t-end. A model pulled by a leaf spring
    (Carlson-Langer) runs the slow-loading workload :data:`~stickslip.run.lattice.SLOW_LOADING`
    (V = 0.001 unless --V or --nu is given; --t-prepare 2 / V, --t-end 20); another from t = 0
    over 100."""
    from stickslip.run.lattice import SLOW_LOADING, bench_lattice

    if args.workload == "events":
        return _event_cost(args)
    if args.sizes is not None:
        raise CommandError("--sizes goes with --workload events")
    for name, option in (("profile", "--profile"), ("workload", "--workload"), ("switches", "--switches")):
        if getattr(args, name, None) not in (None, False, "default", "grid"):
            raise CommandError(f"{option} is not yet available with --lattice {args.lattice}")
    params = lattice_params_from_args(args)
    slow = params.drive_piece.leaf_spring
    if slow and getattr(args, "param_V", None) is None and getattr(args, "param_nu", None) is None:
        params = lattice_params_from_args(args, V=SLOW_LOADING["V"])
    if args.t_prepare is not None:
        t_prepare = args.t_prepare
    else:
        t_prepare = SLOW_LOADING["loading_times"] / params.V if slow and params.V > 0 else 0.0
    t_timed = args.t_end if args.t_end is not None else (SLOW_LOADING["t_timed"] if slow else 100.0)
    result = bench_lattice(params, t_timed, t_prepare=t_prepare, repeat=args.repeat or (3 if slow else 1))
    r = result
    text = (
        f"{r['lattice']}, {r['model']} (V = {r['V']:g}): from t = {r['t_prepare']:g} over {r['t_timed']:g}: "
        f"dense {r['dense_seconds']:.3g} s, exact {r['exact_seconds']:.3g} s ({r['speedup']:.1f}x; processor "
        f"time {r['cpu_speedup']:.1f}x; exact path {r['exact_integrator']}), identical {r['identical']}\n"
        f"block updates {r['exact_block_updates']:.3g} against {r['dense_block_updates']:.3g}, "
        f"{r['exact_ns_per_block_update']:.3g} ns each against {r['dense_ns_per_block_update']:.3g}"
    )
    if r["exact_moving_block_updates"]:
        text += (
            f"; of exact's, {r['exact_moving_block_updates']:.3g} of blocks that moved ({r['moving_fraction']:.2%} "
            f"of the block-steps), {r['exact_ns_per_moving_update']:.3g} ns of exact each"
        )
    text += f"\n{r['events']} events, mean area {r['event_area_mean']:.4g} blocks"
    return Result(result, text)


def _event_cost(args: argparse.Namespace) -> Result:
    """`stickslip bench --lattice square --workload events`: the exact path's cost per slip event
    against its area on L x L squares (:func:`stickslip.run.lattice_bench.event_cost`); the model's
    V (--V, --nu) is the plate's at L = 64, unless given :data:`~stickslip.run.lattice_bench.EVENTS`'s."""
    import sys

    from stickslip.run.lattice_bench import EVENTS, event_cost, format_event_cost

    for name, option in (("shape", "--shape"), ("t_prepare", "--t-prepare"), ("t_end", "--t-end")):
        if getattr(args, name, None) is not None:
            raise CommandError(f"{option} is not read by --workload events (it sets its own; --sizes sets L)")
    for name, option in (("profile", "--profile"), ("switches", "--switches"), ("start", "--start")):
        if getattr(args, name, None) not in (None, False, "grid"):
            raise CommandError(f"{option} is not available with --workload events")
    try:
        sizes = [int(text) for text in (args.sizes or ",".join(map(str, EVENTS["sizes"]))).split(",")]
    except ValueError:
        raise CommandError(f"--sizes must be sizes L in [4, 4096] separated by commas (got {args.sizes!r})") from None
    if not sizes or not all(4 <= L <= 4096 for L in sizes):
        raise CommandError(f"--sizes must be sizes L in [4, 4096] separated by commas (got {args.sizes!r})")
    given_v = getattr(args, "param_V", None) is not None or getattr(args, "param_nu", None) is not None
    args = argparse.Namespace(**{**vars(args), "shape": f"{sizes[0]}x{sizes[0]}"})
    params = lattice_params_from_args(args)
    v64 = params.V if given_v else EVENTS["V64"]

    def say(line: str) -> None:
        sys.stderr.write(f"stickslip bench: {line}\n")
        sys.stderr.flush()

    result = event_cost(params, sizes, v64=v64, repeat=args.repeat or EVENTS["repeat"], say=say)
    return Result(result, format_event_cost(result))


def run_stability_lattice(args: argparse.Namespace) -> Result:
    """`stickslip stability chain --lattice square --shape RxC`: steady sliding on the square
    against its normal modes (eq. 5 with the lattice's Laplacian eigenvalues; docs/lattice.md,
    "Steady sliding and its stability")."""
    from stickslip.analysis.dynamics.lattice_stability import lattice_critical_beta, lattice_stability
    from stickslip.run.lattice import steady_fields

    for name in ("Fs", "dt"):
        if getattr(args, f"param_{name}", None) is not None:
            raise CommandError(f"--{name} is not read by the linear stability of steady sliding")
    if args.out is not None:
        raise CommandError(f"--out is not yet available with stickslip stability chain --lattice {args.lattice}")
    p = lattice_params_from_args(args)
    if p.per_block():
        raise CommandError(
            f"stickslip stability chain --lattice {args.lattice}: per-block parameters "
            f"({', '.join(p.per_block())}) are not yet covered (one number each)"
        )
    if not p.friction_piece.eq5:
        raise CommandError(
            f"stickslip stability chain --lattice {args.lattice}: friction {p.friction} is not yet covered "
            "(eq. 5's law, friction state)"
        )
    steady_fields(p)  # a ParameterError of one line where there is no steady sliding (a fixed side)
    s = lattice_stability(p)
    data = {
        "params": {k: v for k, v in p.to_dict().items() if k in ("K", "D", "V", "beta", "alpha", "shape", "edges")},
        "lattice": p.lattice.describe(),
        **s,
        "q_min": float(p.lattice.eigenvalues()[p.lattice.eigenvalues() > 1e-12].min()),
        "critical_beta_lattice": lattice_critical_beta(p),
    }
    text = "\n".join(
        [
            f"{data['lattice']}: K = {p.K:g}, D = {p.D:g}, V = {p.V:g}, alpha = {p.alpha:g}, beta = {p.beta:g}",
            f"largest growth rate {s['max_growth_rate']:.6g} (mode q = {s['q_at_max']:.4g}): "
            f"{'unstable' if s['unstable'] else 'stable'}",
            f"critical beta of this lattice {data['critical_beta_lattice']:.6g} (long waves: {s['critical_beta']:g}; "
            f"smallest q {data['q_min']:.4g})",
        ]
    )
    return Result(data, text)
