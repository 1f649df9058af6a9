"""`stickslip sweep`: run the chain (eq. 4) or the single block (eq. 1) over a grid of parameters.

    stickslip sweep chain --grid beta=0.8,0.9,1.0 --grid N=99,199 --set K=10 --t-end 1e5 --out DIR
    stickslip sweep chain --lattice square --shape 16x16 --grid beta=0.6,1.2 --t-end 1e4 --out DIR

Every combination of the ``--grid`` values is one point, run as an independent Dask task (a
local cluster, one worker per core, unless ``--scheduler ADDRESS``). ``--set NAME=VALUE`` fixes
a parameter or run option for every point. Results: one directory per point under DIR plus
``summary.parquet`` and ``summary.csv``; points already done are skipped on a second call.
"""

from __future__ import annotations

import argparse
import dataclasses
import itertools
from pathlib import Path
from typing import Any

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
from stickslip.models.params import MAX_STEPS, BlockParams, ChainParams, check_number

# Run options a point may carry besides the model parameters, with their value types.
_OPTIONS: dict[str, dict[str, type]] = {
    "chain": {
        "t_end": float,
        "integrator": str,
        "start": str,
        "sample_interval": float,
        "average_from": float,
        "profile_window": float,
        "profile_min_blocks": int,
    },
    "block": {"t_end": float, "every": int},
    # the chain on --lattice square (stickslip.experiments.sweep_lattice)
    "lattice": {
        "t_end": float,
        "integrator": str,
        "start": str,
        "perturbation": float,
        "seed": int,
        "sample_interval": float,
        "average_from": float,
        "shape": str,
    },
}
_PARAMS: dict[str, type] = {"chain": ChainParams, "block": BlockParams, "lattice": ChainParams}
# Lower ends of the numeric run options (their upper ends depend on dt: RunOptions.validated).
_OPTION_RANGES: dict[str, dict[str, Any]] = {
    "sample_interval": {"low": 0.0, "low_open": True},
    "average_from": {"low": 0.0},
    "profile_window": {"low": 0.0, "low_open": True},
    "profile_min_blocks": {"low": 0},
    "every": {"low": 1},
    "perturbation": {"low": 0.0},
    "seed": {"low": 0},
}


def register(sub) -> None:
    """Add the ``sweep`` subcommand."""
    parser = sub.add_parser(
        "sweep",
        help="run the chain or the block over a grid of parameters on Dask",
        description=(
            "Run the chain (eq. 4) or the single block (eq. 1) at every point of a parameter "
            "grid, each point an independent task on a Dask cluster. One directory per point "
            "under --out, a summary table (summary.parquet, summary.csv); finished points are "
            "skipped when the command is run again; a failed point is reported and the others go on. "
            "With --lattice square --shape RxC the chain's model runs on the square (docs/lattice.md)."
        ),
        epilog=(
            "example: stickslip sweep chain --grid beta=0.2,0.6,1.0,1.2 --set N=49 "
            "--t-end 3e5 --set average_from=1.5e5 --out sweeps/L-beta (N = 49 loads until "
            "L_ss / V ~ 1.2e5: run and average beyond that)"
        ),
    )
    parser.add_argument("model", choices=("chain", "block"), help="which system to run")
    parser.add_argument(
        "--grid",
        action="append",
        default=[],
        metavar="NAME=V1,V2,...",
        help="a parameter and its values; repeat for more parameters (all combinations are run)",
    )
    parser.add_argument(
        "--set",
        action="append",
        default=[],
        dest="fixed",
        metavar="NAME=VALUE",
        help="a parameter or run option fixed for every point; repeatable",
    )
    parser.add_argument("--t-end", type=str, required=True, metavar="T", help="run length of every point")
    parser.add_argument("--out", required=True, metavar="DIR", help="output directory of the sweep")
    from stickslip.cli.lattice import add_lattice_options

    add_lattice_options(parser, run=False)
    add_dask_options(parser)
    add_overwrite_option(parser)
    add_json_option(parser)
    parser.set_defaults(handler=run)


def _value(model: str, name: str, text: str) -> Any:
    """Convert one value by the type of the parameter or option it belongs to."""
    options = _OPTIONS[model]
    if name in options:
        kind = options[name]
        allowed = _OPTION_RANGES.get(name, {})
    else:
        fields = {f.name: f for f in dataclasses.fields(_PARAMS[model])}
        meta = fields[name].metadata
        if "choices" in meta:  # a model name or a piece
            return text.strip()
        kind = int if meta.get("integer") else float
        allowed = {k: meta[k] for k in ("low", "high", "low_open", "high_open") if k in meta}
    if kind is str:
        return text
    # The range goes into the message, as for the options of the other commands.
    return check_number(name, text.strip(), integer=kind is int, **allowed)


def _check_name(model: str, name: str) -> None:
    if model == "lattice":
        from stickslip.experiments.sweep_lattice import NOT_ON_LATTICE

        if name in NOT_ON_LATTICE:
            raise CommandError(f"{name} does not go with --lattice square ({NOT_ON_LATTICE[name]})")
    allowed = [f.name for f in dataclasses.fields(_PARAMS[model])] + list(_OPTIONS[model])
    if name not in allowed:
        raise CommandError(f"unknown parameter {name!r} for {model} (allowed: {', '.join(allowed)})")


def _split_assignment(text: str, option: str) -> tuple[str, str]:
    name, sep, values = text.partition("=")
    name = name.strip()
    if not sep or not name or not values.strip():
        raise CommandError(f"{option} expects NAME=VALUE (got {text!r})")
    return name, values


def parse_grid(
    model: str, grid: list[str], fixed: list[str], t_end: str, lattice: dict[str, Any] | None = None
) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """The points (one dict per combination of ``--grid`` values) and the settings common to all.

    ``model`` ``lattice`` is the chain on the lattice ``lattice`` (its name, and shape and edges
    where given), which goes into the common settings. Every point is validated by building its
    parameter dataclass, so a bad value is reported before anything is written.
    """
    axes: dict[str, list[Any]] = {}
    for text in grid:
        name, values = _split_assignment(text, "--grid")
        _check_name(model, name)
        if name in axes:
            raise CommandError(f"--grid gives {name} twice")
        items = [v.strip() for v in values.split(",")]
        if any(not v for v in items):
            raise CommandError(f"--grid {name}: empty value in {values!r}")
        converted = [_value(model, name, v) for v in items]
        if len(set(map(repr, converted))) != len(converted):
            raise CommandError(f"--grid {name}: repeated value in {values!r}")
        axes[name] = converted
    common: dict[str, Any] = dict(lattice or {})
    clash = sorted(set(axes) & set(common))  # --shape and --grid shape=...
    if clash:
        raise CommandError(f"{clash[0]} is given more than once (--{clash[0]}/--grid)")
    for text in fixed:
        name, value = _split_assignment(text, "--set")
        _check_name(model, name)
        if name in axes or name in common:
            raise CommandError(f"{name} is given more than once (--grid/--set)")
        if name == "t_end":
            raise CommandError("give the run length with --t-end, not --set t_end")
        common[name] = _value(model, name, value)
    if "t_end" in axes:
        raise CommandError("give the run length with --t-end, not --grid t_end")
    common["t_end"] = check_number("t_end", t_end, low=0.0, low_open=True)

    names = list(axes)
    points = [dict(zip(names, combo, strict=False)) for combo in itertools.product(*axes.values())] if names else [{}]
    from stickslip.experiments.sweep_points import point_params

    if model == "lattice":
        from stickslip.experiments.sweep_lattice import lattice_run_args

        if "shape" not in common and "shape" not in axes:
            raise CommandError(f"--lattice {common['lattice']} needs --shape ROWSxCOLS (e.g. 64x64)")
        for point in points:
            lattice_run_args({**common, **point})  # raises ParameterError
        return points, common
    for point in points:
        settings = {**common, **point}
        params = point_params(model, settings)  # raises ParameterError
        _check_options(model, params, settings)
    return points, common


def _check_options(model: str, params, settings: dict[str, Any]) -> None:
    """Validate a point's run options as the point's run will (so nothing fails later)."""
    from stickslip.models.params import ParameterError, steps_for

    if model == "block":  # the system swept (single block or chain), not a model piece
        steps_for(settings["t_end"], params.dt, "t_end")
        check_number("every", settings.get("every", 1), low=1, high=MAX_STEPS, integer=True)
        return
    from stickslip.run.driver import INTEGRATORS, STARTS, RunOptions

    for name, allowed in (("integrator", INTEGRATORS), ("start", STARTS)):
        if name in settings and settings[name] not in allowed:
            raise ParameterError(f"{name} must be one of {', '.join(allowed)} (got {settings[name]!r})")
    RunOptions(
        t_end=settings["t_end"],
        sample_interval=settings.get("sample_interval", 10.0),
        average_from=settings.get("average_from"),
        profile_window=settings.get("profile_window"),
        profile_min_blocks=settings.get("profile_min_blocks", 0),
    ).validated(params.dt)


def run(args: argparse.Namespace) -> Result:
    """Handler of ``stickslip sweep``."""
    from stickslip.cli.lattice import wants_lattice
    from stickslip.experiments.sweep import STOP_WAIT_SECONDS, block_task, chain_task, run_sweep

    kind, lattice = args.model, None
    if wants_lattice(args):
        if args.model != "chain":
            raise CommandError(f"--lattice {args.lattice} goes with stickslip sweep chain, not sweep {args.model}")
        kind = "lattice"
        lattice = {"lattice": args.lattice, "shape": args.shape, "edges": args.edges}
        lattice = {k: v for k, v in lattice.items() if v is not None}
    points, common = parse_grid(kind, args.grid, args.fixed, args.t_end, lattice)
    _, workers = dask_options(args)
    own = _sweep_files(args.out)
    # Not a model piece: the user's choice of system (chain, chain on a lattice or single block) picks the task.
    if kind == "lattice":
        from stickslip.experiments.sweep_lattice import lattice_run_task as task
    else:
        task = chain_task if args.model == "chain" else block_task
    with owned_out_dir(args.out, own, "stickslip sweep", overwrite=args.overwrite) as out:
        try:
            with sigterm_as_interrupt():
                result = run_sweep(
                    task,
                    points,
                    out,
                    common=common,
                    scheduler=args.scheduler,
                    n_workers=workers,
                    dashboard=args.dashboard,
                    progress=not args.no_progress,
                    stop_wait=0.0 if task is block_task else STOP_WAIT_SECONDS,  # block points keep no checkpoint
                )
        except KeyboardInterrupt:
            runs = (
                "lattice runs continue from their last checkpoint"
                if kind == "lattice"
                else "chain runs continue from their checkpoints"
            )
            return interrupted("sweep", out, f"finished points in {out} are kept, {runs}")
        except OSError as exc:  # e.g. no scheduler at the given address
            if is_disk_full(exc):
                raise
            raise CommandError(f"cannot run the sweep: {exc}") from None
    data = {"model": args.model, "common": common, **result.to_dict()}
    return Result(data=data, text=_text(result), status=1 if result.n_failed else 0)


def _sweep_files(out: str):
    """What a sweep's directory may hold: its summary tables, the folders of its points (each
    with its point.json) and the stop file of an interrupted sweep killed while it waited; a
    sweep run again into it reuses the finished points."""
    from stickslip.experiments.sweep import POINT_FILE, STOP_FILE

    return lambda name: name in OUT_FILES["sweep"] or name == STOP_FILE or (Path(out) / name / POINT_FILE).is_file()


def _text(result) -> str:
    table = result.table
    shown = [c for c in table.columns if c not in ("error", "wall_seconds")]
    lines = [
        f"{result.n_points} points in {result.out_dir}: {result.n_run} run, {result.n_reused} reused, "
        f"{result.n_failed} failed ({result.wall_seconds:.1f} s)",
        table[shown].to_string(index=False, max_colwidth=40),
    ]
    for _, row in table[table["status"] != "ok"].iterrows():
        lines.append(f"failed: {row['point_dir']}: {row['error']}")
    lines.append(f"summary: {result.out_dir / 'summary.parquet'} (and .csv)")
    return "\n".join(lines)
