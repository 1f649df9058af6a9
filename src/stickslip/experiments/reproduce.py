"""Reproduce the paper: run its studies, draw every figure, compare every stated number.

:func:`reproduce` runs each of the paper's studies (:data:`stickslip.experiments.studies.PAPER`)
with :func:`stickslip.experiments.study_run.run_study`, the runner of every study (points on Dask,
cache, resume; its docstring gives the layout of the runs and the pages), and gathers their rows
of stated numbers and their figures into ``report.json`` and ``report.html`` in the same folder
(:mod:`stickslip.report.writer`). A second call with the same mode finds every ``done.json`` and
only redraws; an interrupted chain run continues from its last checkpoint; adding a value of beta
to a study only runs the new point.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Any

from stickslip import heartbeat
from stickslip.experiments.studies import PAPER, study
from stickslip.experiments.study_run import run_study
from stickslip.report.writer import ReportFigure, ReportRow, write_report

__all__ = ["reproduce", "ReproduceError"]


class ReproduceError(RuntimeError):
    """An experiment could not be completed (e.g. a chain run failed); the message says which."""


def _log(enabled: bool, t0: float, text: str) -> None:
    heartbeat.note(text)
    if enabled:
        sys.stderr.write(f"[reproduce {time.perf_counter() - t0:6.1f} s] {text}\n")
        sys.stderr.flush()


def _figure(study: str, entry: dict[str, Any]) -> ReportFigure:
    """A figure of a study's page as the report shows it (paths relative to the report)."""
    return ReportFigure(
        figure=entry["figure"],
        image=f"{study}/{entry['image']}",
        caption=entry["caption"],
        pdf=f"{study}/{entry['pdf']}",
        data=tuple(f"{study}/{name}" for name in entry["data"]),
        command=entry["command"],
    )


def reproduce(
    out_dir: str | Path,
    mode: str = "quick",
    *,
    scheduler: str | None = None,
    n_workers: int | None = None,
    progress: bool = True,
) -> dict[str, Any]:
    """Reproduce the paper's Figs. 1-8 and stated numbers into ``out_dir`` (``stickslip reproduce``).

    Runs (or reuses) every point of each study of :data:`~stickslip.experiments.studies.PAPER`
    in ``mode`` (one of :data:`~stickslip.experiments.studies.MODES`) on a local Dask cluster
    (``n_workers`` processes, default one per core) or on the cluster at ``scheduler``; each
    study draws its figures (PNG, PDF and their data) and writes its page; then ``report.json``
    and ``report.html`` get one row per number of docs/model.md's last table and every figure.
    Progress goes to stderr when ``progress`` and stderr is a terminal. Raises
    :class:`ReproduceError`, after every study ran, when a point failed. Returns what the command
    prints: mode, paths, the rows, the figures, and per study its counts and times.
    """
    start = time.perf_counter()
    out = Path(out_dir)
    results = []
    for name in PAPER:
        r = run_study(study(name, mode), out, scheduler=scheduler, n_workers=n_workers, progress=progress)
        results.append(r)
        _log(
            progress,
            start,
            f"{name}: {r['points']} points ({r['reused']} reused, {r['damaged']} damaged and run again, "
            f"{r['run']} run, {r['failed']} failed; {r['compute_seconds']:.1f} s of point runs); page {r['page']}",
        )
    failed = [f"{r['study']}/{p['point']}: {p['error']}" for r in results for p in r["failed_points"]]
    if failed:
        raise ReproduceError(f"{len(failed)} run(s) failed ({'; '.join(failed)}); run again to retry them")
    rows = [ReportRow.from_dict(row) for r in results for row in r["findings"]["rows"]]
    figures = [_figure(r["study"], f) for r in results for f in r["figures"]]
    not_drawn = {k: v for r in results for k, v in r["figures_not_drawn"].items()}
    wall = time.perf_counter() - start
    keys = ("study", "runs", "page", "points", "run", "reused", "damaged", "failed", "compute_seconds")
    studies = [{key: r[key] for key in keys} for r in results]
    meta = {
        "mode": mode,
        "command": f"stickslip reproduce --{mode} --out {out}",
        "wall_seconds": round(wall, 1),
        "compute_seconds": round(sum(r["compute_seconds"] for r in results), 1),
        "studies": [
            f"{r['study']}: {r['points']} points in {Path(r['runs']).relative_to(out).as_posix()}, "
            f"{r['reused']} reused, {r['run']} run ({r['compute_seconds']:.1f} s); page {r['study']}/index.html"
            for r in results
        ],
        "notes": [r["note"] for r in results if r["note"]],
    }
    if not_drawn:
        meta["figures_not_drawn"] = not_drawn
    paths = write_report(out, rows, figures, meta)
    _log(progress, start, f"report: {paths['html']}")
    return {
        "mode": mode,
        "out": str(out),
        "report_json": str(paths["json"]),
        "report_html": str(paths["html"]),
        "wall_seconds": wall,
        "rows": [r.to_dict() for r in rows],
        "figures": [f.to_dict() for f in figures],
        "figures_not_drawn": not_drawn,
        "studies": studies,
    }
