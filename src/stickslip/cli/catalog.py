"""`stickslip catalog RUN_DIR`: a run's slip catalogue, as seismologists read it."""

from __future__ import annotations

import argparse
import shlex
from pathlib import Path

from stickslip.cli._common import (
    CommandError,
    Result,
    add_json_option,
    add_overwrite_option,
    float_arg,
    int_arg,
    owned_out_dir,
)
from stickslip.cli._reading import reading_run_dir, staged_writes


def register(sub) -> None:
    """Add the `catalog` subcommand."""
    p = sub.add_parser(
        "catalog",
        help="a chain run's slip catalogue: magnitudes, b-value, which distribution, recurrence, moment rate",
        description="Read the slips of a run directory (written by `stickslip chain --out`) in its stationary "
        "window (the run's <L> window, default the second half; the same slips `plot` and `reproduce` fit) "
        "as a catalogue: per slip its time, duration, size S, magnitude M = (2/3) log10 S, epicentre, extent "
        "and whether it spans the system; the b-value with its completeness magnitude, the size exponent "
        "tau, the power law against lognormal, exponential, stretched exponential and exponential cut-off "
        "(Vuong) with a KS-bootstrap goodness of fit, the inter-event times with renewal fits, and the moment "
        "rate of the largest slips where the run kept profiles. Tables, figures (PNG and PDF), catalog.json "
        "and a page index.html go to RUN_DIR/catalog (or --out DIR). See docs/statistics.md. On a lattice run "
        "directory (`stickslip chain --lattice square ... --out`): magnitudes M = (2/3) log10 moment, the b-value, "
        "tau of the moments and the recurrence, from the events of the run's second half (docs/lattice.md).",
    )
    p.add_argument("run_dir", metavar="RUN_DIR", help="a chain run directory (run.json, state.nc, events.parquet)")
    p.add_argument("--out", metavar="DIR", default=None, help="where the catalogue goes (default RUN_DIR/catalog)")
    p.add_argument(
        "--dm",
        type=float_arg("dm", "in [0, 1]"),
        default=0.1,
        help="magnitude bin of the b-value (default 0.1; 0: continuous magnitudes)",
    )
    p.add_argument(
        "--bootstrap",
        type=int_arg("bootstrap", ">= 0"),
        default=200,
        help="bootstrap resamples of the errors of tau and b (default 200)",
    )
    p.add_argument(
        "--gof-sims",
        type=int_arg("gof-sims", ">= 0"),
        default=100,
        help="synthetic catalogues of the KS goodness of fit (default 100: p to about ±0.05; 0: none)",
    )
    p.add_argument("--seed", type=int_arg("seed", ">= 0"), default=0, help="seed of the resampling (default 0)")
    add_overwrite_option(p)
    add_json_option(p)
    p.set_defaults(handler=run_catalog_command)


def run_catalog_command(args: argparse.Namespace) -> Result:
    """Handler of `stickslip catalog`."""
    from stickslip.analysis.stats.catalog import check_catalog_options, check_counts

    check_catalog_options(args.dm, args.bootstrap, args.gof_sims, args.seed, spell=lambda n: n.replace("_", "-"))
    check_counts(args.bootstrap, args.gof_sims, ("bootstrap", "gof-sims"))  # before the run is read: refused at once
    run_dir = Path(args.run_dir)
    out = Path(args.out) if args.out else run_dir / "catalog"
    if out.resolve() == run_dir.resolve():
        raise CommandError(
            f"--out {out} is the run directory itself; the catalogue goes into a folder of its own "
            "(default RUN_DIR/catalog)"
        )
    from stickslip.run.lattice_dir import is_lattice_run_dir

    if is_lattice_run_dir(run_dir):
        return _lattice_catalog(args, run_dir, out)
    with reading_run_dir(run_dir):  # a run writing into it (chain --resume) and the catalogue exclude each other
        return _catalog(args, run_dir, out)


def _lattice_catalog(args: argparse.Namespace, run_dir: Path, out: Path) -> Result:
    """The catalogue of a lattice run directory into ``out``: catalog.csv, catalog.json and the
    frequency-magnitude figure (docs/lattice.md, "The catalogue")."""
    from stickslip import io
    from stickslip.analysis.stats.lattice_catalog import lattice_catalog_analysis
    from stickslip.plotting.catalog import frequency_magnitude_figure
    from stickslip.plotting.style import save_figure
    from stickslip.report.catalog_page import CATALOG_FILES

    cat = lattice_catalog_analysis(run_dir, dm=args.dm, bootstrap=args.bootstrap, seed=args.seed)
    formats = ("png", "pdf")
    with owned_out_dir(out, CATALOG_FILES, "stickslip catalog", overwrite=args.overwrite) as out:
        with staged_writes(out, CATALOG_FILES.__contains__) as stage:
            io.write_csv(stage / "catalog.csv", cat.table)
            io.write_json(stage / "catalog.json", cat.summary)
            fig = frequency_magnitude_figure(cat)
            figures = [p.name for p in save_figure(fig, stage / "frequency_magnitude", formats=formats)] if fig else []
    s = cat.summary
    fm = s["frequency_magnitude"]
    bv = fm.get("b_value")
    lines = [f"{s['lattice']}: {s['n_events']} events at t >= {s['window']['t_from']:g} ({s['n_positive']} with M)"]
    lines.append(
        f"- b = {bv['b']:.3f} ± {bv['b_err_shi_bolt']:.3f} above Mc = {bv['mc']:.3g} ({bv['n']} events)"
        if bv
        else f"- {fm.get('reason', 'no b-value')}"
    )
    if "tau" in s["moments"]:
        lines.append(f"- tau of the moments {s['moments']['tau']:.3f}: b = (3/2)(tau - 1) = {fm['b_from_tau']:.3f}")
    else:
        lines.append(f"- moments: {s['moments']['reason']}")
    lines.append(f"written to {out}: catalog.csv, catalog.json" + (", " + ", ".join(figures) if figures else ""))
    data = {
        "out": str(out),
        "run_dir": str(run_dir),
        **s,
        "outputs": [str(out / n) for n in ["catalog.csv", "catalog.json", *figures]],
    }
    return Result(data, "\n".join(lines))


def _catalog(args: argparse.Namespace, run_dir: Path, out: Path) -> Result:
    """The catalogue of ``run_dir`` into ``out``, the run directory held."""
    from stickslip.analysis.stats.catalog import catalog_analysis, load_catalog_run
    from stickslip.report.catalog_page import CATALOG_FILES, write_catalog

    run = load_catalog_run(run_dir)
    cat = catalog_analysis(run, dm=args.dm, bootstrap=args.bootstrap, gof_sims=args.gof_sims, seed=args.seed)
    command = "stickslip catalog " + shlex.join(
        [str(run_dir)]
        + (["--out", str(args.out)] if args.out else [])
        + [
            f"--{k}={v}"
            for k, v in (
                ("dm", args.dm),
                ("bootstrap", args.bootstrap),
                ("gof-sims", args.gof_sims),
                ("seed", args.seed),
            )
        ]
    )
    with owned_out_dir(out, CATALOG_FILES, "stickslip catalog", overwrite=args.overwrite) as out:
        # written whole or not at all: a stop (SIGINT, SIGTERM, an error) leaves no half catalogue
        with staged_writes(out, CATALOG_FILES.__contains__) as stage:
            written = write_catalog(cat, stage, run_dir=run_dir, command=command)
    data = {"out": str(out), "run_dir": str(run_dir), **cat.summary, **written}
    data["outputs"] = [str(out / name) for name in written["outputs"]]
    lines = [f"{cat.summary['n_events']} slips at t >= {cat.summary['window']['t_from']:g} (stationary window)"]
    lines += [f"- {s}" for s in written["statements"]]
    lines += [
        f"{f['figure']:<20} " + (", ".join(f["files"]) if "files" in f else f"not drawn: {f['skipped']}")
        for f in written["figures"]
    ]
    lines.append(f"written to {out} (page: {out / 'index.html'})")
    return Result(data, "\n".join(lines))
