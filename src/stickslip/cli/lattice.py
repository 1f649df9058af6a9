"""`stickslip chain --lattice square --shape RxC [--edges ...]`: a model on a lattice
(docs/lattice.md), on the lattice reference integrator."""

from __future__ import annotations

import argparse
from pathlib import Path

from stickslip.cli._common import CommandError, Result, float_arg

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
            help="with --lattice square: run exact from rest to T first, then time both over --t-end",
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
    return g


def refuse_lattice(args: argparse.Namespace, command: str) -> None:
    """The one-line refusal of a command that does not yet run on a lattice: ``--lattice square``
    (and ``--shape``, ``--edges`` without it, as :func:`wants_lattice` refuses them)."""
    if wants_lattice(args):
        raise CommandError(f"--lattice {args.lattice} is not yet available with stickslip {command} (docs/lattice.md)")


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
        return False
    return True


def lattice_params_from_args(args: argparse.Namespace):
    """The model of the command line on ``--lattice square --shape RxC --edges ...``: the chain's
    options (pieces, parameters, per-block values and ``--disorder-seed``, ``--history``) for
    N = rows cols blocks, a per-block ``file:`` table of rows x cols read row by row
    (docs/lattice.md)."""
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
    return on_lattice(chain_params_from_args(given), args.lattice, args.shape, args.edges)


def run_lattice_command(args: argparse.Namespace) -> Result:
    """`stickslip chain --lattice square`: run the model on the square, print its summary."""
    from stickslip.run.lattice import run_lattice

    for name, option in _NOT_YET.items():
        if getattr(args, name, None) not in (None, False):
            raise CommandError(f"{option} is not yet available with --lattice {args.lattice}")
    if args.integrator not in (None, "dense", "exact"):
        raise CommandError(f"--integrator {args.integrator}: a lattice runs on exact or dense")
    params = lattice_params_from_args(args)
    t_end = 1000.0 if args.t_end is None else args.t_end
    start = args.start or ("rest" if params.drive_piece.leaf_spring else "paper")
    if start == "paper" and (args.perturbation is not None or args.seed is not None):
        raise CommandError("--perturbation and --seed go with --start steady or --start rest")
    amplitude = args.perturbation if args.perturbation is not None else (0.01 if start == "rest" else 0.0)
    run = run_lattice(
        params,
        t_end,
        start=start,
        perturbation=amplitude,
        seed=args.seed or 0,
        snapshot_every=args.lattice_snapshot_every,
        integrator=args.integrator or "exact",
        sample_every=args.sample_interval,
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
            f"written: {out}/run.json, events.csv, state.nc" + (", samples.csv" if run.samples is not None else "")
        )
    return Result(summary, "\n".join(text))


def run_lattice_bench_command(args: argparse.Namespace) -> Result:
    """`stickslip bench --lattice square --shape RxC`: dense against exact on the square, from the
    model's state at --t-prepare (default 0), timed over --t-end (default 100)."""
    from stickslip.run.lattice import bench_lattice

    for name, option in (("profile", "--profile"), ("workload", "--workload"), ("switches", "--switches")):
        if getattr(args, name, None) not in (None, False, "default", "grid"):
            raise CommandError(f"{option} is not yet available with --lattice {args.lattice}")
    params = lattice_params_from_args(args)
    t_prepare = 0.0 if args.t_prepare is None else args.t_prepare
    result = bench_lattice(
        params, 100.0 if args.t_end is None else args.t_end, t_prepare=t_prepare, repeat=args.repeat or 1
    )
    text = (
        f"{result['lattice']}, {result['model']}: from t = {result['t_prepare']:g} over {result['t_timed']:g}: "
        f"dense {result['dense_seconds']:.3g} s, exact {result['exact_seconds']:.3g} s "
        f"({result['speedup']:.2f}x; exact path {result['exact_integrator']}), identical {result['identical']}; "
        f"block updates {result['exact_block_updates']:.3g} against {result['dense_block_updates']:.3g}, "
        f"{result['events']} events"
    )
    return Result(result, text)


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
