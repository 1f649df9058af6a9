"""`stickslip chain` (run the chain of eq. 4) and `stickslip bench` (dense against exact, and the
located integrator's dense against its fast form)."""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

from stickslip.cli._common import (
    CommandError,
    Result,
    add_json_option,
    add_model_options,
    add_run_options,
    chain_params_from_args,
    check_out_owned,
    float_arg,
    int_arg,
    owned_out_dir,
    run_option_dests,
    run_option_spelling,
    run_options_from_args,
)
from stickslip.cli.lattice import add_lattice_options, run_lattice_bench_command, run_lattice_command, wants_lattice
from stickslip.models.params import MAX_PERTURBATION, check_number, steps_for


def register(sub) -> None:
    """Add the `chain` and `bench` subcommands."""
    p = sub.add_parser(
        "chain",
        help="run the chain of eq. (4) or any model of its family (--model)",
        description="Integrate the chain of eq. (4) (docs/model.md), or a relative chosen with --model or "
        "composed with --drive/--friction/--threshold/--ends, and record its slip events.",
    )
    add_model_options(
        p, helps={"N": "number of blocks N (default the preset's: 399 for the paper's chain; 49 without --t-end)"}
    )
    add_lattice_options(p)
    _add_run_options(p)
    _add_from_option(p)
    p.add_argument("--resume", metavar="DIR", help="continue the run in DIR from its checkpoint")
    p.add_argument(
        "--overwrite",
        action="store_true",
        help="replace this package's files in --out (other files there are left alone)",
    )
    # What the run records, its integrator, --out, checkpoints, progress: RunOptions' fields.
    add_run_options(p)
    p.add_argument(
        "--until-periodic",
        action="store_true",
        help="stop once the slip sequence is periodic (the rule of `stickslip period`, its defaults); "
        "prints the period and the slip and time from which the sequence repeats",
    )
    add_json_option(p)
    p.set_defaults(handler=run_chain_command)

    b = sub.add_parser(
        "bench",
        help="time dense against exact on the same workload, in one process",
        description="Run the same chain workload with the dense and the exact integrator and compare.",
    )
    add_model_options(b)
    add_lattice_options(b, bench=True)
    b.add_argument(
        "--t-end",
        type=float_arg("t-end"),
        default=None,
        help="end time (default 2e5 for the paper's chain, 2e4 for the plate-driven models)",
    )
    b.add_argument(
        "--start",
        choices=("paper", "steady", "rest"),
        default=None,
        help="initial state (default: the model's; the paper's x=0, v=0.1, theta=0.1 for sakaguchi)",
    )
    b.add_argument(
        "--repeat",
        type=int_arg("repeat", ">= 1"),
        default=None,
        help="time each integrator this many times, alternated, keep the fastest (default 1; 3 with "
        "--workload partly-stuck or disordered, whose exact runs last a fraction of a second)",
    )
    b.add_argument(
        "--workload",
        choices=("default", "partly-stuck", "disordered", "events"),
        default="default",
        help="partly-stuck: the paper's chain loading at beta = 1.3 with part of its blocks stuck "
        "(N, beta and t-end as given, else 199, 1.3 and 1e4 after a prepared 4e5); disordered: the "
        "chain with per-block values (as given, else Fs uniform(2.5, 3.5) and beta 10%% normal) "
        "against the same chain with their means, time per block update (N 199, t-end 2e4); events "
        "(with --lattice square): the exact path's cost per slip event against its area on L x L "
        "squares of --sizes, under a plate slow enough to keep the events apart",
    )
    b.add_argument(
        "--profile", action="store_true", help="instead: where the exact integrator spends its time on this workload"
    )
    b.add_argument(
        "--switches",
        choices=("grid", "located"),
        default="grid",
        help="located: the located integrator's dense against its fast form, from the engine's "
        "state at t = 5e5 (N = 99; scaled with N^2) from the paper's start, timed over --t-end "
        "(default 5000); N and beta as given, else 99 and 0.5",
    )
    add_json_option(b)
    b.set_defaults(handler=run_bench_command)


def _add_run_options(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--t-end",
        type=float_arg("t-end"),
        default=None,
        metavar="T",
        help="end time; without it a first look: a chain loaded from one end from x_i = 0 gets "
        "N = 49 (unless --N) and runs for four loading times L_ss / V, rounded up (5e5 for N = 49), other "
        "chains to 2e4. The paper's runs: --t-end 2e7 (N = 399, the preset's)",
    )
    p.add_argument(
        "--start",
        choices=("paper", "steady", "rest"),
        default=None,
        help="initial state: the paper's (x=0, v=0.1, theta=0.1; default for sakaguchi), exact "
        "steady sliding, or every block stuck at x_i = -A u_i (Carlson-Langer's; default for "
        "the plate-driven models)",
    )
    p.add_argument(
        "--perturbation",
        type=float_arg("perturbation"),
        default=None,
        metavar="A",
        help="size A of the start's perturbation: with --start steady uniform in [-A, A] on x and v (default 0); "
        "with --start rest x_i = -A u_i, u_i uniform in [0, 1) (default the model's, 0.01 for CL)",
    )
    # The former name of --perturbation with --start rest; kept so that old scripts run.
    p.add_argument("--amplitude", dest="perturbation", type=float_arg("perturbation"), help=argparse.SUPPRESS)
    p.add_argument(
        "--seed", type=int_arg("seed", ">= 0"), default=None, help="seed of the perturbation or of u_i (default 0)"
    )


def _add_from_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--from",
        dest="from_dir",
        default=None,
        metavar="DIR",
        help="start from the final state of another run: a run directory or a rung of the transition "
        "study (DIR/state.npz); its time goes on, so --t-end is the end time, not a duration",
    )


def _events_text(summary: dict, N: int | None) -> str:
    """The events line; a chain with every block moving in an unfinished event is said to slide."""
    text = f"events         {summary['n_events']}"
    if summary.get("stopped_early") and summary.get("t_steady") is not None:
        return text + f"  (then steady sliding from t = {summary['t_steady']:g})"
    if N is not None and summary["n_moving"] == N:
        since = summary.get("in_progress_since") if summary["event_in_progress"] else None
        when = f" since t = {since:g}" if since is not None else ""
        return text + (
            f"  (every block moving{when}: the chain slides; --until-steady TOL stops a run once the sliding is steady)"
        )
    return text + ("  (one in progress)" if summary["event_in_progress"] else "")


def _summary_text(summary: dict, out: Path | None, N: int | None = None) -> str:
    wall = f"wall time      {summary['wall_seconds']:.3g} s"
    this_run = summary.get("wall_seconds_this_run", summary["wall_seconds"])
    if this_run < summary["wall_seconds"] - 1e-9:
        wall = (
            f"wall time      {summary['wall_seconds_this_run']:.3g} s this run, "
            f"{summary['wall_seconds']:.3g} s in all (resumed)"
        )
    lines = [
        f"t_end          {summary['t_end']:g}  ({summary['steps']} steps, {summary['integrator']})",
        _events_text(summary, N),
        f"L_final        {summary['L_final']:.6g}   (steady sliding {summary['L_steady']:.6g})",
        f"L_mean         {summary['L_mean']:.6g}   (t >= {summary['L_mean_from']:g})",
        f"moving blocks  {summary['n_moving']}",
        wall,
        f"state sha256   {summary['state_sha256']}",
    ]
    if summary.get("stopped_early"):
        lines.append(f"stopped early  {summary['reason']}")
    if out is not None:
        lines.append(f"written to     {out}")
    else:
        lines.append("not written    nothing was saved; give --out DIR to keep the run (events, L(t), state)")
    return "\n".join(lines)


def _json_summary(summary: dict, out: Path | None) -> dict:
    from stickslip.run.rundir import RUN_FILES

    data = dict(summary)
    data["events"] = summary["n_events"]
    if out is not None:
        data["out"] = str(out)
        data["outputs"] = [str(out / name) for name in RUN_FILES if (out / name).exists()]
    return data


_FIXED_BY_CHECKPOINT = ("from_dir", "start", "perturbation", "seed", *run_option_dests())


def run_chain_command(args: argparse.Namespace) -> Result:
    """Handler of `stickslip chain`."""
    if wants_lattice(args):
        return run_lattice_command(args)
    progress = not args.no_progress
    periodic = _periodic_hook(args)
    if args.resume is not None:
        from stickslip.run import driver as chain
        from stickslip.run.rundir import RunDirBusy, owned_run_dir

        if not args.resume.strip():
            raise CommandError("--resume must name a run directory (got '')")
        if not Path(args.resume).is_dir():
            raise CommandError(f"--resume {args.resume}: no such run directory")
        if args.out and Path(args.out) != Path(args.resume):
            raise CommandError("--out and --resume name different directories; give only --resume")
        fixed = [
            f"--{k.removeprefix('param_').replace('_', '-')}"
            for k, v in vars(args).items()
            if v is not None and (k.startswith("param_") or k in _FIXED_BY_CHECKPOINT)
        ]
        if fixed:
            raise CommandError(
                f"{', '.join(fixed)} cannot be combined with --resume: a resumed run keeps the "
                "parameters and options it was started with (only --t-end may be raised)"
            )
        interval = 300.0 if args.checkpoint_interval is None else args.checkpoint_interval
        check_number("checkpoint-interval", interval, low=0.0, low_open=True)
        if args.overwrite:
            raise CommandError("--overwrite cannot be combined with --resume")
        if args.t_end is not None:
            check_number("t-end", args.t_end, low=0.0, low_open=True)
        try:
            with owned_run_dir(args.resume, new_id=False):
                run = chain.resume_chain(
                    args.resume,
                    t_end=args.t_end,
                    checkpoint_interval=interval,
                    progress=progress,
                    handle_signals=True,
                    keep_checkpoint=args.keep_checkpoint,
                    hooks=periodic,
                )
        except RunDirBusy as exc:
            raise CommandError(str(exc)) from None
        except chain.NonFiniteState as exc:
            sys.stderr.write(f"stickslip chain: error: {exc}\n")
            return Result({"error": str(exc)}, "", status=1)
        except chain.ChainRunError as exc:
            raise CommandError(str(exc)) from None
        except chain.Interrupted as exc:
            return _interrupted(exc, Path(args.resume))
        return _with_period(
            Result(
                _json_summary(run.summary, Path(args.resume)),
                _summary_text(run.summary, Path(args.resume), run.params.N),
            ),
            periodic,
        )

    # a bad parameter is refused before the engine loads
    params = _inherit_per_block(chain_params_from_args(args), args)
    from stickslip.run import driver as chain
    from stickslip.run.rundir import RunDirBusy, read_run_id

    from_state = _from_state(params, args)
    start, amplitude, seed = _start_of(params, args)
    params, t_end = _first_look(params, args, start) if args.t_end is None else (params, args.t_end)
    args.start, args.perturbation, args.seed = start, amplitude, seed
    for name, default in (
        ("integrator", "exact"),
        ("start", "paper"),
        ("perturbation", 0.0),
        ("seed", 0),
    ):
        if getattr(args, name) is None:
            setattr(args, name, default)
    check_number("t-end", t_end, low=0.0, low_open=True)
    steps_for(t_end, params.dt, "t-end")
    if args.out is None and args.overwrite:
        raise CommandError("--overwrite needs --out (a run without a run directory writes nothing to replace)")
    interval = 300.0 if args.checkpoint_interval is None else args.checkpoint_interval
    options = run_options_from_args(args, t_end)
    # Validate every option before anything is written, where run_chain does (one place), and
    # refuse outputs no machine can hold.
    options.validated(params.dt, spell=run_option_spelling)
    from stickslip.run.budget import check_run_outputs

    check_run_outputs(params.N, params.dt, options)
    check_number("perturbation", args.perturbation, low=0.0, high=MAX_PERTURBATION)
    own = _own_files(args.out)
    out = check_out_owned(args.out, own, "stickslip chain", overwrite=args.overwrite)
    if out is not None and out.is_dir():
        if (out / "checkpoint" / "state.npz").exists() and not args.overwrite:
            raise CommandError(
                f"{out} already holds a run; continue it with --resume {out}, choose another --out or give --overwrite"
            )
        if (out / "run.json").exists() and not args.overwrite:
            raise CommandError(f"{out} already holds a finished run; choose another --out or give --overwrite")
    try:
        with owned_out_dir(out, own, "stickslip chain", overwrite=args.overwrite, run_id=True) as out:
            if args.overwrite:
                _remove_derived(out)
            # The command's own defaults: a progress bar on any terminal, checkpoints every
            # `interval` and on signals where it writes, into the folder it owns.
            options = dataclasses.replace(
                options,
                out_dir=out,
                checkpoint_interval=interval if out else None,
                progress=progress,
                handle_signals=out is not None,
                run_id=read_run_id(out) if out else None,
                hooks=periodic,
            )
            run = chain.run_chain(
                params,
                t_end,
                start=args.start if from_state is None else from_state,
                perturbation=args.perturbation,
                seed=args.seed,
                options=options,
            )
    except chain.ChainRunError as exc:
        sys.stderr.write(f"stickslip chain: error: {exc}\n")
        return Result({"error": str(exc)}, "", status=1)
    except chain.Interrupted as exc:
        return _interrupted(exc, out)
    text = _summary_text(run.summary, out, params.N)
    if args.t_end is None:
        text = f"N              {params.N}  (without --t-end a first look; the paper's run is --t-end 2e7)\n" + text
    return _with_period(Result(_json_summary(run.summary, out), text), periodic)


def _periodic_hook(args: argparse.Namespace) -> list:
    """With ``--until-periodic``, the hook that ends the run once its slips repeat
    (:class:`~stickslip.analysis.stats.periodicity.PeriodicStop`); else none."""
    if not getattr(args, "until_periodic", False):
        return []
    from stickslip.analysis.stats.periodicity import PeriodicStop

    return [PeriodicStop()]


def _with_period(result: Result, periodic: list) -> Result:
    """The command's result with the periodicity found by ``--until-periodic`` (its ``periodicity``
    in JSON, and lines of text)."""
    if not periodic:
        return result
    hook = periodic[0]
    found = hook.result if hook.result is not None else hook.finish()
    result.data["periodicity"] = found.to_dict()
    stop = "stopped: " if hook.result is not None else "ran to the end: "
    result.text += "\n" + stop + found.text().replace("\n", "\n  ")
    return result


def _own_files(out: str | None):
    """What `chain` treats as its own in ``--out``: a run's files, the figures `stickslip plot`
    drew from that run into RUN_DIR/figures and the catalogue `stickslip catalog` wrote into
    RUN_DIR/catalog (``--overwrite`` removes them with the run they were read from; either folder
    holding other files too is left alone)."""
    from stickslip.run.ownership import CATALOG_FOLDER, PLOT_FOLDER, only_catalog_files, only_plot_files
    from stickslip.run.rundir import OWN_FILES

    if out is None:
        return OWN_FILES
    figures, catalog = Path(out) / PLOT_FOLDER, Path(out) / CATALOG_FOLDER
    return lambda name: (
        name in OWN_FILES
        or (name == PLOT_FOLDER and only_plot_files(figures))
        or (name == CATALOG_FOLDER and only_catalog_files(catalog))
    )


def _remove_derived(out: Path) -> None:
    """With ``--overwrite``: the figures and catalogue of the replaced run that a folder of them
    holding other files too still had (those other files stay)."""
    from stickslip.run.ownership import CATALOG_FILES, CATALOG_FOLDER, PLOT_FILE, PLOT_FOLDER, remove_own_files

    for folder, own in ((PLOT_FOLDER, PLOT_FILE.fullmatch), (CATALOG_FOLDER, CATALOG_FILES.__contains__)):
        if (out / folder).is_dir():
            remove_own_files(out / folder, own)


def _first_look(params, args, start: str):
    """Without ``--t-end``, a first look that shows the stick-slip state within seconds: a chain
    loaded from one end from x_i = 0 gets N = 49 blocks (unless ``--N`` is given) and runs for a
    few of its loading times (:func:`stickslip.models.physics.first_look_t_end`); other chains
    run to t = 2e4. The paper's run (N = 399 to t = 2e7) is ``--t-end 2e7``."""
    from stickslip.models import physics

    if start in ("paper", "rest") and not params.drive_piece.leaf_spring:  # loaded from one end
        looked = params if args.param_N is not None else chain_params_from_args(args, N=physics.FIRST_LOOK_N)
        t_end = physics.first_look_t_end(looked)
        if t_end == t_end:
            return looked, t_end
    return params, 2e4


def _inherit_per_block(params, args):
    """With --from, the per-block parameters of the run named there (docs/model.md, "Per-block
    parameters") that the command line does not give: the continued chain is the same medium."""
    if getattr(args, "from_dir", None) is None or not (Path(args.from_dir) / "run.json").is_file():
        return params
    from stickslip import io
    from stickslip.models.params import ChainParams
    from stickslip.run.rundir import LatticeRunDir, refuse_lattice_run

    try:
        refuse_lattice_run(args.from_dir, "--from")
    except LatticeRunDir as exc:
        raise CommandError(f"--from: {exc}") from None
    try:
        before = ChainParams(**io.read_json(Path(args.from_dir) / "run.json")["params"])
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise CommandError(f"--from: {exc}") from None
    keep = {k: v for k, v in before.per_block().items() if getattr(args, f"param_{k}", None) is None}
    if keep and before.N == params.N:
        params = params.replace(**keep)
    return params


def _from_state(params, args):
    """The state named by --from, checked against the run's N and --t-end; None without --from."""
    if getattr(args, "from_dir", None) is None:
        return None
    from stickslip.run.rundir import final_state

    for flag, value in (
        ("--start", args.start),
        ("--perturbation", args.perturbation),
    ):
        if value is not None:
            raise CommandError(f"{flag} cannot be combined with --from (the state of the run named there is the start)")
    from stickslip.run.validate import check_start_state

    try:
        state = final_state(args.from_dir)
    except (OSError, ValueError, KeyError) as exc:
        raise CommandError(f"--from: {exc}") from None
    n_state = state.xg.shape[0] - 2 if getattr(state.xg, "ndim", 0) == 1 else None
    if n_state is not None and n_state != params.N:
        raise CommandError(f"--from: the state there has {n_state} blocks, the run N = {params.N} (give --N {n_state})")
    check_start_state(state, params, where=f"--from: the state in {args.from_dir}")
    t0 = state.step * params.dt
    if args.t_end is not None and args.t_end <= t0:
        raise CommandError(f"--t-end must be after the start state's time {t0:g} (got {args.t_end:g})")
    if args.t_end is None:
        args.t_end = t0 + 2e4
    return state


def _start_of(params, args) -> tuple[str, float, int]:
    """The initial state: the option, else the model's preset; its amplitude and seed."""
    from stickslip.models.presets import PRESETS

    preset = PRESETS[params.model]
    start = args.start or preset.start
    from stickslip.run.state import check_start_draw

    check_start_draw(start, args.perturbation, args.seed, cli=True)  # None: not given
    if start == "rest":
        amplitude = args.perturbation if args.perturbation is not None else preset.start_options.get("amplitude", 0.0)
        check_number("perturbation", amplitude, low=0.0, high=MAX_PERTURBATION)
    else:
        amplitude = args.perturbation if args.perturbation is not None else 0.0
    seed = args.seed if args.seed is not None else preset.start_options.get("seed", 0)
    check_number("seed", seed, low=0, integer=True)
    if start == "steady":
        from stickslip.models import physics

        if not physics.has_steady_state(params):
            raise CommandError(f"--start steady: the chain with ends {params.ends} has no steady sliding state")
    return start, float(amplitude), int(seed)


def _interrupted(exc, out: Path | None) -> Result:
    sys.stderr.write(f"stickslip chain: {exc}; continue with: stickslip chain --resume {out}\n")
    return Result({"interrupted": True, "t": exc.t, "checkpoint": str(exc.checkpoint)}, "", status=130)


def run_bench_command(args: argparse.Namespace) -> Result:
    """Handler of `stickslip bench`: the same workload with dense and exact, one process."""
    from stickslip.run import bench

    if wants_lattice(args):
        return run_lattice_bench_command(args)
    if args.workload == "events" or args.sizes is not None:
        raise CommandError("--workload events and --sizes go with --lattice square")
    if args.repeat is None:
        # A short timing is the noisier one: the partly stuck workload's exact run takes about 0.25 s.
        args.repeat = 3 if args.workload in ("partly-stuck", "disordered") else 1
    check_number("repeat", args.repeat, low=1, integer=True)
    if args.switches == "located":
        return _located(args)
    if args.workload == "partly-stuck":
        return _partly_stuck(args)
    if args.workload == "disordered":
        return _disordered(args)
    params = chain_params_from_args(args)
    t_end = args.t_end if args.t_end is not None else (2e4 if params.drive_piece.leaf_spring else 2e5)
    check_number("t-end", t_end, low=0.0, low_open=True)
    steps_for(t_end, params.dt, "t-end")
    args.perturbation = getattr(args, "perturbation", None)
    args.seed = None
    start, amplitude, seed = _start_of(params, args)
    if args.profile:
        result = bench.profile(params, t_end, start=start, perturbation=amplitude, seed=seed)
        return Result(result, bench.format_profile(result))
    _say(bench.expected_cost(params, t_end, args.repeat))  # up front: the default runs for a minute or more
    result = bench.compare(params, t_end, start=start, repeat=args.repeat, perturbation=amplitude, seed=seed, say=_say)
    return Result(result, bench.format_result(result))


def _say(line: str) -> None:
    """A line of `stickslip bench` on stderr (stdout keeps the result, and --json its document)."""
    sys.stderr.write(f"stickslip bench: {line}\n")
    sys.stderr.flush()


def _partly_stuck(args: argparse.Namespace) -> Result:
    """`stickslip bench --workload partly-stuck`: exact per block update against dense per block-step."""
    from stickslip.run import bench

    if args.profile or args.start is not None:
        raise CommandError("--workload partly-stuck prepares its own start and has no --profile")
    params, t_prepare, t_timed = _workload(args, bench.PARTLY_STUCK)
    result = bench.partly_stuck(params, t_prepare=t_prepare, t_timed=t_timed, repeat=args.repeat)
    return Result(result, bench.format_partly_stuck(result))


def _disordered(args: argparse.Namespace) -> Result:
    """`stickslip bench --workload disordered`: a disordered chain's time per block update against
    the uniform chain's (docs/model.md, "Per-block parameters")."""
    from stickslip.run import bench

    if args.profile or args.start is not None:
        raise CommandError("--workload disordered starts from the paper's start and has no --profile")
    w = bench.DISORDERED
    params = chain_params_from_args(args, **({"N": w["N"]} if args.param_N is None else {}))
    t_end = args.t_end if args.t_end is not None else w["t_timed"]
    check_number("t-end", t_end, low=0.0, low_open=True)
    result = bench.disordered(params, t_end, repeat=args.repeat, seed=args.disorder_seed)
    return Result(result, bench.format_disordered(result))


def _workload(args: argparse.Namespace, w: dict):
    """The parameters, preparation time and timed span of a bench workload ``w``, the preparation
    scaled with the loading time L_ss / V ~ N^2. The workload's N and beta are the paper's chain's
    (unless given); another model keeps its own, and a parameter it does not read is not set."""
    paper = (args.model or "sakaguchi") == "sakaguchi"
    overrides = {k: w[k] for k in ("N", "beta") if paper and getattr(args, f"param_{k}", None) is None}
    params = chain_params_from_args(args, **overrides)
    t_timed = args.t_end if args.t_end is not None else w["t_timed"]
    check_number("t-end", t_timed, low=0.0, low_open=True)
    return params, w["t_prepare"] * (params.N / w["N"]) ** 2, t_timed


def _located(args: argparse.Namespace) -> Result:
    """`stickslip bench --switches located`: the located integrator's dense form against its fast form."""
    from stickslip.run import bench

    if args.profile or args.start is not None or args.workload != "default":
        raise CommandError("--switches located prepares its own start and has no --profile or --workload")
    params, t_prepare, t_timed = _workload(args, bench.LOCATED)
    result = bench.located(params, t_prepare=t_prepare, t_timed=t_timed, repeat=args.repeat)
    return Result(result, bench.format_located(result))
