"""Running a study (``stickslip study NAME``): its points on Dask, its table, figures and page.

:func:`run_study` takes a :class:`~stickslip.experiments.studies.Study` and the
:class:`~stickslip.experiments.studies.Design` of its module, runs its points through
:func:`stickslip.experiments.sweep.run_sweep` (each point reused if done, failed points recorded
and retried next time, interrupted points continued from their checkpoints), builds the study's
table, asks its module for the findings and figures and writes its page. It names no study.
Layout::

    OUT/runs/<name>-<key>/points/<point>/   one point (a chain run and its analysis, a ladder, ...)
    OUT/<name>/table.parquet, table.csv     the study's table
    OUT/<name>/<figure>.png|.pdf            its figures
    OUT/<name>/study.json, index.html       the findings, the commands, the page
"""

from __future__ import annotations

import contextlib
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from stickslip import __version__, io
from stickslip.experiments.studies import MANIFEST, Design, Study, design, study, study_command
from stickslip.jsonable import table_records
from stickslip.pages import image_src, write_page

__all__ = ["run_study", "foreign_files", "remove_study_files", "MANIFEST"]


def _log(enabled: bool, t0: float, text: str) -> None:
    if enabled:
        sys.stderr.write(f"[study {time.perf_counter() - t0:6.1f} s] {text}\n")
        sys.stderr.flush()


def run_study(
    spec: Study | str,
    out_dir: str | Path,
    mode: str = "quick",
    *,
    scheduler: str | None = None,
    n_workers: int | None = None,
    progress: bool = True,
    dashboard: bool = False,
) -> dict[str, Any]:
    """Run (or reuse) every point of a study and write its table, figures and page under ``out_dir``.

    Parameters
    ----------
    spec : Study or str
        The study, or a study's name (then ``mode`` picks its spec set).
    out_dir : str or Path
        The output folder: ``runs/<name>-<key>/`` and the page folder ``<name>/``.
    scheduler, n_workers, progress, dashboard
        As for :func:`stickslip.experiments.sweep.run_sweep` (``progress`` also: the study's own
        lines on stderr, where it is a terminal).

    Returns
    -------
    dict
        The counts and times (``points``, ``run``, ``reused``, ``damaged``, ``failed``,
        ``wall_seconds``, ``compute_seconds``), the ``findings``, the ``figures`` (and in
        ``figures_not_drawn`` why a figure could not be drawn), the ``rows`` of the table, the
        failed points with their errors and the paths.
    """
    from stickslip.experiments.sweep import STOP_WAIT_SECONDS, _on_terminal, run_sweep

    t0 = time.perf_counter()
    spec = study(spec, mode) if isinstance(spec, str) else spec
    plan = design(spec.name)
    out = Path(out_dir)
    run_dir = spec.runs_dir(out)
    page_dir = out / spec.name
    show = progress and _on_terminal()
    for p in spec.points:  # validate every point before any work starts
        plan.check({**spec.common, **p})
    where = "scheduler " + scheduler if scheduler else "local cluster"
    _log(show, t0, f"{spec.name} --{spec.mode}: {len(spec.points)} points in {run_dir} ({where}); reusing finished")
    io.write_json(run_dir / "study-spec.json", spec.spec())
    result = run_sweep(
        plan.task,
        [dict(p) for p in spec.points],
        run_dir / "points",
        common=dict(spec.common),
        scheduler=scheduler,
        n_workers=n_workers,
        progress=show,
        stop_wait=STOP_WAIT_SECONDS,
        dashboard=dashboard,
        names=[plan.point_name(p) for p in spec.points] if plan.point_name else None,
    )
    points = _points_table(spec, plan, result.table)
    failed = points[points["status"] != "ok"]
    table = plan.rows(points) if plan.rows else points
    page_dir.mkdir(parents=True, exist_ok=True)
    record_outputs(out, [page_dir / name for name in PAGE_FILES])
    io.write_table_files(page_dir / "table", table)
    ok = table[table["status"] == "ok"] if "status" in table else table
    data = plan.load(spec, ok, run_dir / "points") if plan.load and len(ok) else ok
    findings = plan.findings(spec, data) if len(ok) else {"statements": ["no finished points"]}
    figures, not_drawn = _draw(spec, plan, data, page_dir) if len(ok) else ([], {})
    # the page folder held only the manifest's files when the study began (foreign_files)
    record_outputs(out, [p for p in page_dir.iterdir() if p.is_file() and not p.name.startswith(".")])
    wall = time.perf_counter() - t0
    meta = {
        "study": spec.name,
        "mode": spec.mode,
        "key": spec.key(),
        "version": __version__,
        "command": study_command(spec.name, spec.mode),
        "note": spec.note,
        "points": len(points),
        "run": result.n_run,
        "reused": result.n_reused,
        "damaged": result.n_damaged,
        "failed": int(len(failed)),
        "wall_seconds": round(wall, 1),
        "compute_seconds": round(float(np.nansum(points["wall_seconds"].to_numpy(dtype=float))), 1),
        "runs": str(run_dir),
    }
    records = table_records(table)
    if not_drawn:
        meta["figures_not_drawn"] = not_drawn
    io.write_json(page_dir / "study.json", {"meta": meta, "findings": findings, "figures": figures, "rows": records})
    _write_page(page_dir / "index.html", spec, plan, meta, findings, figures, points, table)
    _log(show, t0, f"page: {page_dir / 'index.html'} ({wall:.1f} s)")
    return {
        **meta,
        "out": str(out),
        "page": str(page_dir / "index.html"),
        "table_file": str(page_dir / "table.parquet"),
        "findings": findings,
        "figures": figures,
        "figures_not_drawn": not_drawn,
        "failed_points": [{"point": r.point_dir, "error": r.error} for r in failed.itertuples()],
        "rows": records,
    }


def _points_table(spec: Study, plan: Design, sweep_table: pd.DataFrame) -> pd.DataFrame:
    """The sweep's table with the shared settings filled in and the study's columns first."""
    from stickslip.models.presets import PRESETS

    table = sweep_table.copy()
    for key in ("N", "alpha", "D", "beta", "model"):
        if key not in table.columns and key in spec.common:
            table[key] = spec.common[key]
    if "model" in table.columns:
        table["model"] = table["model"].fillna(spec.common.get("model", "sakaguchi"))
        if "N" in table.columns and table["N"].isna().any():
            # a relative run at its preset's N carries no N in its point
            missing = table["N"].isna()
            table.loc[missing, "N"] = [PRESETS[m].params["N"] for m in table.loc[missing, "model"]]
            table["N"] = table["N"].astype("int64")
        if "beta" in table.columns:
            # models whose friction reads no beta (velocity weakening) have none
            no_beta = [m for m in table["model"].unique() if "beta" not in PRESETS[m].reads()]
            table.loc[table["model"].isin(no_beta), "beta"] = np.nan
    if "final_state" in table.columns:
        table.loc[table["status"] != "ok", "final_state"] = "failed"
    lead = [c for c in plan.columns if c in table.columns]
    return table[lead + [c for c in table.columns if c not in lead]].reset_index(drop=True)


def _draw(spec: Study, plan: Design, data: Any, page_dir: Path) -> tuple[list[dict[str, Any]], dict[str, str]]:
    """Draw the study's figures into ``page_dir`` (PNG and PDF); returns their descriptions and,
    for each figure the results cannot give, why."""
    from stickslip.plotting.style import save_figure

    out, not_drawn = [], {}
    for name, fig, caption, *extra in plan.figures(spec, data, page_dir):
        if fig is None:
            not_drawn[name] = caption
            continue
        save_figure(fig, page_dir / name)  # atomic: a full disk leaves no half-written image
        command = study_command(spec.name, spec.mode)
        entry = {"name": name, "image": f"{name}.png", "pdf": f"{name}.pdf", "caption": caption, "command": command}
        out.append({**entry, **(extra[0] if extra else {})})
    return out, not_drawn


# ---------------------------------------------------------------------------------------------
# The page: stickslip/templates/study.html.j2


def _write_page(
    path: Path,
    spec: Study,
    plan: Design,
    meta: dict[str, Any],
    findings: dict[str, Any],
    figures: list[dict[str, Any]],
    points: pd.DataFrame,
    table: pd.DataFrame,
) -> None:
    """Write the study's ``index.html``: the command, the counts, what the data say, the figures
    (embedded), the study's further tables and its table, failed points and undecided rows marked,
    and the cached points (or the rows within them) that ran again because their files were damaged."""
    damaged = [f"{r.point_dir}: {r.note}" for r in points.itertuples() if isinstance(getattr(r, "note", None), str)]
    if plan.rows and "note" in table:
        damaged += [f"row {k}: {note}" for k, note in enumerate(table["note"]) if isinstance(note, str)]
    cols = [c for c in plan.columns if c in table.columns] + [c for c in ("status", "error") if c in table.columns]

    def mark(r: dict[str, Any]) -> str:
        return "failed" if r.get("status", "ok") != "ok" else "undecided" if r.get("final_state") == "undecided" else ""

    tables = [{"title": t, "cols": c, "rows": rows} for t, c, rows in (plan.tables(findings) if plan.tables else [])]
    write_page(
        path,
        "study.html.j2",
        name=spec.name,
        mode=spec.mode,
        note=spec.note,
        meta=meta,
        damaged=damaged,
        statements=findings.get("statements", []),
        figures=[{**fig, "src": image_src(fig["image"], path.parent)} for fig in figures],
        tables=tables,
        cols=cols,
        rows=[{**r, "_class": mark(r)} for r in table.to_dict(orient="records")],
    )


# ---------------------------------------------------------------------------------------------
# The study's folder: what it owns

#: The files of a study's page besides its figures.
PAGE_FILES = ("table.parquet", "table.csv", "study.json", "index.html")


def read_manifest(out: Path) -> set[str]:
    """The paths (relative to ``out``, with ``/``) that studies recorded as written there."""
    try:
        data = io.read_json(Path(out) / MANIFEST)
        return {str(p) for p in data["files"]}
    except (OSError, ValueError, KeyError, TypeError):
        return set()


def record_outputs(out: Path, paths: list[Path]) -> None:
    """Add ``paths`` (under ``out``) to the manifest, before they are written: a file at an output
    path not in the manifest is somebody else's and is never written over."""
    out = Path(out)
    files = read_manifest(out) | {p.relative_to(out).as_posix() for p in paths}
    io.write_json(out / MANIFEST, {"files": sorted(files)})


def foreign_files(out: str | Path) -> list[str]:
    """The entries of the output folder ``out`` that no study of this package wrote (relative
    paths): at its top anything but the runs folder, the study pages and the manifest; in a page
    folder anything not in the manifest; in the runs folder anything but the folders of studies
    (``<name>-<key>``) holding their spec, their points (each with its point.json, holding what
    the study's :attr:`~stickslip.experiments.studies.Design.point_entry` allows) and the sweep's
    summary."""
    from stickslip.experiments.studies import PAPER, STUDIES
    from stickslip.experiments.sweep import POINT_FILE, STOP_FILE, SUMMARY_NAME
    from stickslip.run.rundir import LOCK_FILES, is_temporary

    out = Path(out)
    if not out.is_dir():
        return []
    own = read_manifest(out)
    foreign: list[str] = []

    def walk(folder: Path, test) -> None:
        for path in sorted(folder.iterdir()):
            rel = path.relative_to(out).as_posix()
            if is_temporary(path.name):
                continue
            sub = test(path, rel)
            if sub is False:
                foreign.append(rel)
            elif callable(sub):
                walk(path, sub)

    def runs(path: Path, rel: str):
        names = [name for name in STUDIES + PAPER if path.name.startswith(f"{name}-")]
        if not (path.is_dir() and names):
            return False
        entry = design(names[0]).point_entry or True

        def points(path: Path, rel: str):
            if path.is_file():
                return path.name in {f"{SUMMARY_NAME}.parquet", f"{SUMMARY_NAME}.csv", STOP_FILE}
            if not (path / POINT_FILE).is_file():
                # a point stopped at its first write (a full disk) left its folder with nothing in it
                return path.is_dir() and all(is_temporary(p.name) or p.name in LOCK_FILES for p in path.iterdir())
            return _point_entry(path) if entry is True else entry

        def study_runs(path: Path, rel: str):
            if path.name == "points" and path.is_dir():
                return points
            return path.name == "study-spec.json" and path.is_file()

        return study_runs

    def top(path: Path, rel: str):
        if path.name in LOCK_FILES or (path.name == MANIFEST and path.is_file()):
            return True
        if path.name == "runs" and path.is_dir():
            return runs
        if path.name in STUDIES + PAPER and path.is_dir():
            return lambda path, rel: rel in own and path.is_file()  # a page's files
        return False

    walk(out, top)
    return foreign


def _point_entry(point: Path):
    """The test of a point's entries (the walk of :func:`foreign_files`) for a study without a
    ``point_entry``: the sweep's bookkeeping and the run's lock and id; in its checkpoint only a
    checkpoint's files (:data:`~stickslip.run.checkpoint.CHECKPOINT_FILE`); in a finished point
    (its done.json records its files) only those; in one still running, what its task writes."""
    from stickslip.experiments.cache import BOOKKEEPING
    from stickslip.run.checkpoint import CHECKPOINT_FILE
    from stickslip.run.rundir import LOCK_FILES, RUN_ID_FILE

    try:
        files = io.read_json(point / "done.json").get("files")
    except (OSError, ValueError, AttributeError):
        files = None
    recorded = set(files) if isinstance(files, dict) else None

    def checkpoint(path: Path, rel: str) -> bool:
        return path.is_file() and CHECKPOINT_FILE.fullmatch(path.name) is not None

    def inside(path: Path, rel: str):
        if recorded is None:
            return True
        return inside if path.is_dir() else path.relative_to(point).as_posix() in recorded

    def top(path: Path, rel: str):
        if path.name in BOOKKEEPING or path.name in LOCK_FILES or path.name == RUN_ID_FILE:
            return True
        if path.name == "checkpoint" and path.is_dir():
            return checkpoint
        return inside(path, rel)

    return top


def remove_study_files(out: str | Path, spec: Study) -> None:
    """``--overwrite``: remove what this study wrote under ``out`` (its page files and its runs
    folder); every other file stays (:func:`foreign_files`: a file of the user's in a point's
    folder or checkpoint too)."""
    out = Path(out)
    own = read_manifest(out)
    page_dir = out / spec.name
    for rel in sorted(own):
        path = out / rel
        if path.parent == page_dir and path.is_file():
            path.unlink()
    runs = spec.runs_dir(out)
    foreign = {out / rel for rel in foreign_files(out)}
    if runs.is_dir():
        for path in sorted(runs.rglob("*"), key=lambda p: len(p.parts), reverse=True):  # deepest first
            if path in foreign or foreign & set(path.parents):
                continue
            if path.is_dir() and not path.is_symlink():
                with contextlib.suppress(OSError):
                    path.rmdir()  # a folder still holding a foreign file stays
            else:
                path.unlink()
        with contextlib.suppress(OSError):
            runs.rmdir()
    if own:
        io.write_json(out / MANIFEST, {"files": sorted(p for p in own if (out / p).exists())})
