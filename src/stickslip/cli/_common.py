"""Pieces shared by the subcommands: parameter options, JSON output, errors."""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import json
import os
import sys
from collections.abc import Callable, Collection, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from stickslip.cli._history import add_history_option, take_history
from stickslip.cli._per_block import add_disorder_seed, may_vary, per_block_arg, seeded
from stickslip.experiments.studies import MANIFEST, PAPER
from stickslip.jsonable import to_jsonable
from stickslip.models.params import _range_text


class CommandError(Exception):
    """A user-facing error of a subcommand (one line, exit status 2)."""


@dataclass
class Result:
    """What a subcommand hands back: JSON-able ``data``, human ``text``, an exit ``status``."""

    data: dict[str, Any]
    text: str = ""
    status: int = 0
    extra: dict[str, Any] = field(default_factory=dict)


def dumps(data: Any) -> str:
    """One JSON document (strict: NaN and inf become null)."""
    return json.dumps(to_jsonable(data), indent=2, allow_nan=False)


def emit(result: Result, *, as_json: bool) -> int:
    """Print a result (JSON or text) and return its exit status."""
    if as_json:
        sys.stdout.write(dumps(result.data) + "\n")
    elif result.text:
        sys.stdout.write(result.text.rstrip("\n") + "\n")
    sys.stdout.flush()
    return result.status


def add_json_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", action="store_true", help="print one JSON document on stdout")


def add_dask_options(parser: argparse.ArgumentParser, *, what: str = "", dashboard: bool = True) -> None:
    """``--scheduler``, ``--workers``, ``--no-progress`` and (with ``dashboard``) ``--dashboard`` of
    the commands that run on Dask (sweep, study, reproduce); ``what`` says what runs there. Read
    back by :func:`dask_options`. The local cluster listens on 127.0.0.1 only."""
    parser.add_argument(
        "--scheduler",
        default=None,
        metavar="ADDRESS",
        help=f"address of an existing Dask scheduler{what} (default: a local cluster)",
    )
    parser.add_argument(
        "--workers", default=None, metavar="N", help="worker processes of the local cluster (default: one per core)"
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    if not dashboard:
        return
    parser.add_argument(
        "--dashboard",
        action="store_true",
        help="serve the local cluster's dashboard on 127.0.0.1 and print its address (default: none)",
    )


def dask_options(args: argparse.Namespace) -> tuple[str | None, int | None]:
    """The scheduler address (HOST:PORT or scheme://HOST:PORT, else refused) and the number of
    workers (a positive integer, else refused) of :func:`add_dask_options`."""
    import re

    from stickslip.models.params import check_number

    workers = None if args.workers is None else int(check_number("--workers", args.workers, low=1, integer=True))
    address = args.scheduler
    match = None if address is None else re.fullmatch(r"([a-z+]+://)?[^\s:/]+:(\d{1,5})", address.strip())
    if address is not None and match is None:
        raise CommandError(f"--scheduler must be an address HOST:PORT, e.g. tcp://127.0.0.1:8786 (got {address!r})")
    if match is not None and not 1 <= int(match.group(2)) <= 65535:
        raise CommandError(f"--scheduler port must be in [1, 65535] (got {match.group(2)})")
    if match is not None:
        _check_reachable(address.strip())
    return address, workers


def _check_reachable(address: str, timeout: float = 5.0) -> None:
    """Refuse a TCP scheduler address nobody answers at, before anything is written (Dask itself
    would wait 30 s, then fail after the command had made its folders)."""
    import socket

    scheme, _, rest = address.rpartition("://")
    if scheme not in ("", "tcp"):
        return  # tls, ucx, ...: left to Dask
    host, _, port = rest.rpartition(":")
    try:
        with socket.create_connection((host, int(port)), timeout=timeout):
            pass
    except OSError as exc:
        raise CommandError(f"--scheduler {address}: no scheduler answers there ({exc.strerror or exc})") from None


@contextlib.contextmanager
def sigterm_as_interrupt() -> Iterator[None]:
    """Within the block, SIGTERM (``kill``, a batch system's stop) raises KeyboardInterrupt, so the
    commands that run on Dask end on it as on Ctrl-C: the cluster closed, one line, status 130."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def interrupt(signum, frame):
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGTERM, interrupt)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def interrupted(command: str, out: Path | None, kept: str) -> Result:
    """What ``sweep``, ``study`` and ``reproduce`` answer to Ctrl-C or SIGTERM: one line on stderr
    (``kept``: what the next call reuses), exit status 130."""
    sys.stderr.write(f"stickslip {command}: interrupted; run the same command again to continue ({kept})\n")
    return Result({"interrupted": True, "out": str(out)}, "", status=130)


def option_name(name: str) -> str:
    """The command-line spelling of a parameter: ``--`` and the name, words joined by hyphens
    as in every other option (``rs_a`` is ``--rs-a``, ``t_end`` ``--t-end``)."""
    return "--" + name.replace("_", "-")


class _OldSpelling(argparse.Action):
    """An option's former spelling (``--rs_a``): still accepted, with one line on stderr."""

    def __init__(self, option_strings, dest, new: str = "", **kw):
        self.new = new
        super().__init__(option_strings, dest, **kw)

    def __call__(self, parser, namespace, values, option_string=None):
        sys.stderr.write(f"{parser.prog}: {option_string} is the old spelling of {self.new}; write {self.new}\n")
        setattr(namespace, self.dest, values)


def model_defaults(name: str, default: Any) -> str:
    """The default of parameter ``name`` in each preset (:mod:`stickslip.models.presets`) that
    reads it, e.g. ``10 (sakaguchi, train, batista-carlson), 100 (carlson-langer, two-blocks)``;
    a parameter no preset reads: its default and the pieces that read it."""
    from stickslip.models.pieces import PIECES
    from stickslip.models.presets import PRESETS

    by_value: dict[str, list[str]] = {}
    for pr in PRESETS.values():
        if name in ("N", "K", "V", "dt") or name in pr.reads():
            by_value.setdefault(f"{pr.params.get(name, default):g}", []).append(pr.name)
    if not by_value:
        readers = [f"{p.kind} {p.name}" for kind in PIECES.values() for p in kind if name in p.reads]
        return f"{default:g}" + (f"; read by {', '.join(readers)}" if readers else "")
    if len(by_value) == 1 and len(next(iter(by_value.values()))) == len(PRESETS):
        return next(iter(by_value))
    return ", ".join(f"{value} ({', '.join(names)})" for value, names in by_value.items())


def block_model_defaults(name: str) -> str:
    """The default of single-block parameter ``name`` in each model of ``--model``
    (:data:`~stickslip.models.presets.SINGLE_BLOCK`) that reads it, e.g. ``0.001 (sakaguchi),
    0.05 (batista-carlson)``; one value where every model has the same."""
    from stickslip.models.presets import SINGLE_BLOCK, block_params

    by_value: dict[str, list[str]] = {}
    unread = []
    for model in SINGLE_BLOCK:
        if not _block_reads(model, name):
            unread.append(model)
            continue
        by_value.setdefault(f"{getattr(block_params(model), name):g}", []).append(model)
    text = (
        next(iter(by_value))
        if len(by_value) == 1 and not unread
        else ", ".join(f"{value} ({', '.join(names)})" for value, names in by_value.items())
    )
    return text + (f"; not read by {', '.join(unread)}" if unread else "")


def _block_reads(model: str, name: str) -> bool:
    """Whether the single block of ``model`` reads ``name``: every field but the start threshold
    Fs, which only a model whose threshold reads it has (the state threshold is sigma theta)."""
    from stickslip.models.presets import PRESETS

    return name != "Fs" or "Fs" in PRESETS[model].reads()


def add_param_options(
    parser: argparse.ArgumentParser,
    params_cls: type,
    skip: tuple[str, ...] = (),
    helps: dict[str, str] | None = None,
    *,
    block_models: bool = False,
) -> None:
    """One option per field of a parameter dataclass (:func:`option_name`; the former spelling
    with underscores still accepted), its help giving the default of each model that reads it
    (ChainParams; BlockParams with ``block_models``, for a command with the block's ``--model``)
    or the dataclass's; ``helps`` replaces the help text of some."""
    from stickslip.models.params import ChainParams

    docs = params_cls.field_docs()
    group = parser.add_argument_group("model parameters")
    for f in dataclasses.fields(params_cls):
        if f.name in skip or f.name not in docs or "choices" in f.metadata:
            continue
        kind = int if f.metadata.get("integer") else float
        meta = f.metadata
        allowed = _range_text(
            meta.get("low"), meta.get("high"), meta.get("low_open", False), meta.get("high_open", False)
        )
        if params_cls is ChainParams:
            default = model_defaults(f.name, f.default)
        elif block_models:
            default = block_model_defaults(f.name)
        else:
            default = f"{f.default:g}" if isinstance(f.default, float) else f"{f.default}"
        flag = option_name(f.name)
        if params_cls is ChainParams and may_vary(f):
            convert = per_block_arg(f.name, allowed)
        else:
            convert = _number(kind, f.name, allowed)
        group.add_argument(
            flag,
            dest=f"param_{f.name}",
            type=convert,
            default=None,
            metavar=f.name,
            help=(helps or {}).get(f.name, f"{docs[f.name]} (default {default})"),
        )
        if flag != f"--{f.name}":
            group.add_argument(
                f"--{f.name}",
                dest=f"param_{f.name}",
                type=convert,
                action=_OldSpelling,
                new=flag,
                help=argparse.SUPPRESS,
            )


def _run_option_fields(control: bool | None = None):
    """The fields of :class:`~stickslip.run.options.RunOptions` with a command-line option, and
    their metadata (``control``: only those that say how a run runs, or only the others)."""
    from stickslip.run.options import RunOptions

    return [
        (f, f.metadata["cli"])
        for f in dataclasses.fields(RunOptions)
        if "cli" in f.metadata and (control is None or f.metadata["control"] == control)
    ]


def _run_option_dest(cli: dict[str, Any]) -> str:
    return cli["option"].replace("-", "_")


def add_run_options(parser: argparse.ArgumentParser) -> None:
    """One option per field of :class:`~stickslip.run.options.RunOptions` that names one (its
    metadata ``cli``: spelling, metavar, help; a number, an integer, text, a choice, a flag or
    repeatable), default None (the field's default then applies: :func:`run_options_from_args`)."""
    for _, cli in _run_option_fields():
        kwargs: dict[str, Any] = {"default": None, "help": cli["help"]}
        if "flag" in cli:
            kwargs["action"] = "store_true"
        elif "choices" in cli:
            kwargs["choices"] = cli["choices"]
        else:
            kwargs["metavar"] = cli["metavar"]
            if not cli.get("text"):
                kwargs["type"] = (int_arg if cli.get("integer") else float_arg)(cli["option"], cli.get("allowed", ""))
            if cli.get("append"):
                kwargs["action"] = "append"
        parser.add_argument(f"--{cli['option']}", dest=_run_option_dest(cli), **kwargs)


def run_option_dests(control: bool | None = False) -> tuple[str, ...]:
    """The names :func:`add_run_options` gives its options in the parsed arguments (by default
    those of what a run records and its integrator: the options a checkpoint fixes)."""
    return tuple(_run_option_dest(cli) for _, cli in _run_option_fields(control))


def run_option_spelling(field_name: str) -> str:
    """The command-line spelling of a field of :class:`~stickslip.run.options.RunOptions`
    (``out_dir`` is ``--out``, ``snapshot_times`` ``--snapshot``), for the refusals of
    :meth:`~stickslip.run.options.RunOptions.validated`, which the command and the API share."""
    for f, cli in _run_option_fields():
        if f.name == field_name:
            return "--" + cli["option"]
    return option_name(field_name)


def run_options_from_args(args: argparse.Namespace, t_end: float):
    """The :class:`~stickslip.run.options.RunOptions` of the options :func:`add_run_options`
    added (the field's default where one is not given), with ``t_end``; not yet validated."""
    from stickslip.run.options import RunOptions

    values: dict[str, Any] = {}
    for f, cli in _run_option_fields():
        value = getattr(args, _run_option_dest(cli), None)
        if value is not None and "flag" in cli:
            values[f.name] = cli["flag"] if value else f.default
        elif value is not None:
            values[f.name] = tuple(value) if cli.get("append") else value
    return RunOptions(t_end=t_end, **values)


def params_from_args(params_cls: type, args: argparse.Namespace, **overrides: Any):
    """Build (and so validate) a parameter dataclass from the ``--NAME`` options."""
    values = {}
    for f in dataclasses.fields(params_cls):
        value = getattr(args, f"param_{f.name}", None)
        if value is not None:
            values[f.name] = value
    values.update(overrides)
    return params_cls(**values)


def _number(kind: type, name: str, allowed: str = ""):
    """An argparse type that accepts any number text and leaves range checks to the dataclass;
    its error names the allowed range."""
    what = ("an integer" if kind is int else "a number") + (f" {allowed}" if allowed else "")

    def convert(text: str):
        try:
            return kind(text) if kind is int else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be {what} (got {text!r})") from None

    convert.__name__ = name
    return convert


def float_arg(name: str, allowed: str = ""):
    """An argparse type for a plain float option (range checked by the command; ``allowed``
    names the range in the message for text that is no number)."""
    return _number(float, name, allowed)


def int_arg(name: str, allowed: str = ""):
    """An argparse type for a plain integer option."""
    return _number(int, name, allowed)


def check_out_dir(path: str | Path | None, option: str = "--out") -> Path | None:
    """Refuse an output directory that could not be created or written, creating nothing."""
    if path is None:
        return None
    out = Path(path)
    if str(path).strip() == "":
        raise CommandError(f"{option} must name a directory (got '')")
    probe = out
    while not probe.exists():
        if probe.parent == probe:
            break
        probe = probe.parent
    if probe.exists() and not probe.is_dir():
        raise CommandError(f"{option} {out}: cannot create a directory there ({probe} is not a directory)")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise CommandError(f"{option} {out}: {probe} is not writable")
    return out


def _figures(*stems: str) -> frozenset[str]:
    """The files of figures saved by :func:`stickslip.plotting.style.save_figure` under these stems."""
    return frozenset(f"{stem}.{fmt}" for stem in stems for fmt in ("png", "pdf", "svg"))


#: What each command writes into its ``--out`` (a directory may hold only its command's files).
OUT_FILES: dict[str, frozenset[str]] = {
    "block": frozenset(
        {"series.nc", "slips.parquet", "slips.csv", "run.json", "fig1.nc", "fig2.nc", "fig3.parquet", "fig3.csv"}
    )
    | _figures("fig1", "fig2", "fig3"),
    "stability block": frozenset({"stability_map.nc", "stability_block.json"}) | _figures("stability_map"),
    "stability chain": frozenset({"fig4.nc", "mode_growth.nc", "stability_chain.json"})
    | _figures("fig4", "mode_growth"),
    "hysteresis": frozenset({"hysteresis.nc", "hysteresis.json"}) | _figures("hysteresis"),
    "lab step": frozenset({"step.nc", "step.json", "index.html"}) | _figures("step"),
    "lab shs": frozenset({"shs.nc", "shs.json", "index.html"}) | _figures("shs"),
    "lab fit": frozenset({"fit.nc", "fit.json", "posterior.nc", "index.html"}) | _figures("fit", "posterior"),
    "lab invert": frozenset({"invert.nc", "invert.json", "index.html"}) | _figures("invert"),
    "sweep": frozenset({"summary.parquet", "summary.csv"}),
    "reproduce": frozenset({"runs", *PAPER, "report.json", "report.html", MANIFEST}),
}


def package_files() -> frozenset[str]:
    """What any command writes into a run directory (a chain run's files included, not the
    folders of a sweep or of ``reproduce``); ``--overwrite`` removes these too, so that no
    directory mixes the results of two commands (a block's run.json beside a chain's state.nc)."""
    from stickslip.run.rundir import LOCK_FILES, OWN_FILES, RUN_ID_FILE

    files = frozenset().union(*OUT_FILES.values()) - {"runs", *PAPER}
    return files | (OWN_FILES - LOCK_FILES - {RUN_ID_FILE})


def _owner(own: Callable[[str], bool] | Collection[str]) -> Callable[[str], bool]:
    """A test of names: ``own`` itself, or membership in it; the lock and files left by a killed
    write always belong."""
    from stickslip.run.rundir import LOCK_FILES, is_temporary

    test = own if callable(own) else (lambda name: name in own)
    return lambda name: name in LOCK_FILES or is_temporary(name) or test(name)


def check_out_owned(
    path: str | Path | None, own, what: str, *, overwrite: bool = False, option: str = "--out"
) -> Path | None:
    """Refuse an output directory holding anything that ``own`` (a set of names or a test of a
    name) does not accept as written by the command ``what``; with ``overwrite`` the check is left out (the
    command then removes only this package's files, :func:`owned_out_dir`)."""
    out = check_out_dir(path, option)
    if out is None or not out.is_dir():
        return out
    names = sorted((p.name for p in out.iterdir()), key=lambda n: (n.startswith("."), n))  # hidden ones last
    own = _owner(own)
    foreign = [n for n in names if not own(n)]
    if foreign and not overwrite:
        shown = ", ".join(foreign[:3]) + (", ..." if len(foreign) > 3 else "")
        raise CommandError(
            f"{option} {out} holds files that `{what}` does not write ({shown}); choose an "
            "empty directory, or --overwrite to replace this package's files there"
        )
    return out


@contextlib.contextmanager
def owned_out_dir(
    path: str | Path | None, own, what: str, *, overwrite: bool = False, run_id: bool = False
) -> Iterator[Path | None]:
    """Claim ``--out`` for one command: refuse foreign files (:func:`check_out_owned`), create the
    directory, hold its lock while the command writes (a second writer is refused at once,
    naming the holder; :func:`stickslip.run.rundir.owned_run_dir`) and, with ``overwrite``,
    remove this command's and the package's files first. Yields the directory (None without
    ``--out``). Call it after every other check, so that bad input writes nothing."""
    from stickslip.run.rundir import RunDirBusy, owned_run_dir, remove_own_files

    out = check_out_owned(path, own, what, overwrite=overwrite)
    if out is None:
        if overwrite:
            raise CommandError("--overwrite needs --out")
        yield None
        return
    test, package = _owner(own), package_files()
    try:
        with owned_run_dir(out, run_id=run_id):
            if overwrite:
                remove_own_files(out, lambda name: test(name) or name in package)
            yield out
    except RunDirBusy as exc:
        raise CommandError(str(exc)) from None
    except OSError as exc:
        from stickslip.io import disk_full

        if disk_full(exc) is not None or out.is_dir():
            raise
        raise CommandError(f"cannot create output directory {out}: {exc.strerror}") from None


def add_overwrite_option(parser: argparse.ArgumentParser) -> None:
    """``--overwrite``: replace this package's files in ``--out``; other files there stay."""
    parser.add_argument(
        "--overwrite",
        action="store_true",
        help="replace this package's files in --out (other files there are left alone)",
    )


def add_model_options(parser: argparse.ArgumentParser, helps: dict[str, str] | None = None) -> None:
    """``--model`` (a preset), the four pieces to compose a model, CL's own symbols, and one
    ``--NAME`` per parameter of :class:`ChainParams`."""
    from stickslip.models.params import ChainParams
    from stickslip.models.pieces import names
    from stickslip.models.presets import PRESETS

    group = parser.add_argument_group("model (see `stickslip models`)")
    group.add_argument(
        "--model",
        choices=tuple(PRESETS),
        default=None,
        help="preset to start from (default sakaguchi: the paper's chain of eq. 4)",
    )
    for kind in ("drive", "friction", "threshold", "ends"):
        group.add_argument(f"--{kind}", choices=names(kind), default=None, help=f"{kind} piece (default: the preset's)")
    group.add_argument(
        "--l",
        dest="param_l",
        type=_number(float, "l"),
        default=None,
        metavar="l",
        help="Carlson-Langer's spring ratio l (sets K = l^2; default 10 for carlson-langer, two-blocks)",
    )
    group.add_argument(
        "--nu",
        dest="param_nu",
        type=_number(float, "nu"),
        default=None,
        metavar="nu",
        help="Carlson-Langer's plate velocity nu (sets V; default 0.01 for carlson-langer, two-blocks)",
    )
    add_disorder_seed(group, _number(int, "disorder-seed"))
    add_history_option(group)
    add_param_options(parser, ChainParams, helps=helps)


def chain_params_from_args(args: argparse.Namespace, **overrides: Any):
    """Validated ChainParams from ``--model``, the pieces and the parameter options.

    An option the composition does not read (``--D`` with weakening friction, say) is refused
    rather than silently ignored. ``overrides`` are the command's own defaults (a workload's N and
    beta), not the user's: those the composition does not read are left out, never refused.
    """
    from stickslip.models.params import ChainParams
    from stickslip.models.presets import build_chain_params, refuse_unread

    values: dict[str, Any] = {}
    for kind in ("drive", "friction", "threshold", "ends"):
        if getattr(args, kind, None) is not None:
            values[kind] = getattr(args, kind)
    for f in dataclasses.fields(ChainParams):
        value = seeded(getattr(args, f"param_{f.name}", None), getattr(args, "disorder_seed", 0))
        if value is not None:
            values[f.name] = value
    for name in ("l", "nu"):
        if getattr(args, f"param_{name}", None) is not None:
            values[name] = getattr(args, f"param_{name}")
    take_history(args, values)
    model = args.model or "sakaguchi"
    if overrides:
        reads = set(build_chain_params(model, **values).used())
        values.update({k: v for k, v in overrides.items() if k in reads})
    params = build_chain_params(model, **values)
    refuse_unread(params, {k: v for k, v in values.items() if k not in overrides}, prefix="--", spell=option_name)
    return params


def add_block_model_option(parser: argparse.ArgumentParser) -> None:
    """``--model`` for the single block: the paper's (default) or the Batista-Carlson reading."""
    from stickslip.models.presets import SINGLE_BLOCK

    parser.add_argument(
        "--model",
        choices=SINGLE_BLOCK,
        default=None,
        help="sakaguchi (default: eq. 1 with the constant threshold Fs) or batista-carlson "
        "(the paper's reading of Batista-Carlson: a stuck block starts when "
        "K (V t - x) > sigma theta)",
    )


def block_params_from_args(args: argparse.Namespace, **overrides: Any):
    """Validated BlockParams of ``--model`` with the ``--NAME`` options as overrides."""
    from stickslip.models.params import BlockParams
    from stickslip.models.presets import block_params

    values = {
        f.name: getattr(args, f"param_{f.name}")
        for f in dataclasses.fields(BlockParams)
        if getattr(args, f"param_{f.name}", None) is not None
    }
    values.update(overrides)
    model = getattr(args, "model", None) or "sakaguchi"
    if "Fs" in values and not _block_reads(model, "Fs"):
        from stickslip.models.params import ParameterError

        raise ParameterError(f"--Fs is not a parameter of {model} (its threshold is sigma theta)")
    return block_params(model, **values)


def is_disk_full(exc: BaseException) -> bool:
    """Whether ``exc`` comes from a full disk (:func:`stickslip.io.disk_full`); such an error goes
    on to the command line's one line and exit status 1, not to a refusal of the input."""
    from stickslip.io import disk_full

    return disk_full(exc) is not None
