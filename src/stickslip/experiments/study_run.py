"""Running a study (``stickslip study NAME``): its points on Dask, its table, figures and page.

:func:`run_study` takes a :class:`~stickslip.experiments.studies.Study`, runs its points through
:func:`stickslip.experiments.sweep.run_sweep` (each point reused if done, failed points recorded
and retried next time, interrupted chain runs continued from their checkpoints), builds the
study's table (:mod:`stickslip.analysis.order` for the conclusions drawn from it), draws its
figures (:mod:`stickslip.plotting.studies`) and writes its page. Layout::

    OUT/runs/<name>-<key>/points/<point>/   one chain run and its analysis per point
    OUT/<name>/table.parquet, table.csv     the study's table, one row per point
    OUT/<name>/<figure>.png|.pdf            its figures
    OUT/<name>/study.json, index.html       the conclusions, the commands, the page
"""

from __future__ import annotations

import re
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from stickslip import __version__, io
from stickslip.experiments.studies import Study, study, study_command, study_point_task
from stickslip.jsonable import to_jsonable
from stickslip.pages import image_src, write_page

__all__ = ["run_study", "study_command", "TABLE_COLUMNS"]

#: The leading columns of each study's table (the rest follow).
TABLE_COLUMNS = {
    "phase-diagram": [
        "N",
        "alpha",
        "D",
        "beta",
        "start",
        "final_state",
        "order_parameter",
        "order_parameter_err",
        "stuck_fraction",
        "t_steady",
        "t_end",
    ],
    "exponents": [
        "model",
        "N",
        "beta",
        "tau",
        "tau_err",
        "s_min",
        "s_max",
        "n_fit",
        "n_events",
        "excess",
        "observed",
        "expected",
        "n_spanning",
        "S_max",
        "t_end",
    ],
    "chaos": [
        "model",
        "N",
        "beta",
        "verdict",
        "verdict_text",
        "lyapunov_dt0",
        "lyapunov_dt0_err",
        "flow_slips",
        "window",
        "delta_star_state",
        "delta_star_state_err_log10",
        "delta_star_state_low",
        "delta_star_state_high",
        "delta_star_state_censored",
        "delta_star_Fs",
        "delta_star_Fs_err_log10",
        "delta_star_Fs_low",
        "delta_star_Fs_high",
        "delta_star_Fs_censored",
        "delta_star_V",
        "delta_star_V_err_log10",
        "delta_star_V_low",
        "delta_star_V_high",
        "delta_star_V_censored",
        "threshold_below",
        "threshold_low",
        "windows_decorrelated",
        "windows",
        "transient",
        "loaded",
        "first_slip_reaching_block_N",
        "flow_t",
        "seeds",
        "n_deltas",
    ],
}


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

    ``spec`` is a :class:`Study` or a study name (then ``mode`` picks its spec set). Points run
    on a local Dask cluster of ``n_workers`` processes or on the cluster at ``scheduler``.
    Progress goes to stderr when ``progress`` and stderr is a terminal; ``dashboard`` serves the
    local cluster's dashboard on 127.0.0.1 (its address on stderr). Returns the table as
    records, the conclusions, failed points with their errors, paths and times.
    """
    from stickslip.experiments.sweep import STOP_WAIT_SECONDS, _on_terminal, run_sweep

    t0 = time.perf_counter()
    spec = study(spec, mode) if isinstance(spec, str) else spec
    out = Path(out_dir)
    run_dir = out / "runs" / spec.dirname
    page_dir = out / spec.name
    show = progress and _on_terminal()
    from stickslip.experiments.studies import check_point

    for p in spec.points:  # validate every point before any work starts
        check_point({**spec.common, **p})
    _log(
        show,
        t0,
        f"{spec.name} --{spec.mode}: {len(spec.points)} points in {run_dir} "
        f"({'scheduler ' + scheduler if scheduler else 'local cluster'}); finished points are reused",
    )
    io.write_json(run_dir / "study-spec.json", spec.spec())
    result = run_sweep(
        study_point_task,
        [dict(p) for p in spec.points],
        run_dir / "points",
        common=dict(spec.common),
        scheduler=scheduler,
        n_workers=n_workers,
        progress=show,
        stop_wait=STOP_WAIT_SECONDS,
        dashboard=dashboard,
    )
    table = _study_table(spec, result.table)
    failed = table[table["status"] != "ok"]
    page_dir.mkdir(parents=True, exist_ok=True)
    record_outputs(out, [page_dir / name for name in PAGE_FILES])
    io.write_table_files(page_dir / "table", table)
    ok = table[table["status"] == "ok"]
    from stickslip.experiments import study_findings

    findings = study_findings.conclusions(spec, ok)
    figures = study_findings.draw(spec, ok, page_dir)
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
        "points": len(table),
        "run": result.n_run,
        "reused": result.n_reused,
        "damaged": result.n_damaged,
        "failed": int(len(failed)),
        "wall_seconds": round(wall, 1),
        "compute_seconds": round(float(np.nansum(table["wall_seconds"].to_numpy(dtype=float))), 1),
        "runs": str(run_dir),
    }
    records = _records(table)
    io.write_json(page_dir / "study.json", {"meta": meta, "findings": findings, "figures": figures, "rows": records})
    _write_page(page_dir / "index.html", spec, meta, findings, figures, table)
    _log(show, t0, f"page: {page_dir / 'index.html'} ({wall:.1f} s)")
    return {
        **meta,
        "out": str(out),
        "page": str(page_dir / "index.html"),
        "table_file": str(page_dir / "table.parquet"),
        "findings": findings,
        "figures": figures,
        "failed_points": [{"point": r.point_dir, "error": r.error} for r in failed.itertuples()],
        "rows": records,
    }


def _study_table(spec: Study, sweep_table: pd.DataFrame) -> pd.DataFrame:
    """The sweep's table with the shared settings filled in and the study's columns first."""
    table = sweep_table.copy()
    for key in ("N", "alpha", "D", "beta", "model"):
        if key not in table.columns and key in spec.common:
            table[key] = spec.common[key]
    if "model" in table.columns:
        table["model"] = table["model"].fillna(spec.common.get("model", "sakaguchi"))
    if "N" in table.columns and "model" in table.columns:
        # a relative run at its preset's N carries no N in its point
        from stickslip.models.presets import PRESETS

        missing = table["N"].isna()
        if missing.any():
            table.loc[missing, "N"] = [PRESETS[m].params["N"] for m in table.loc[missing, "model"]]
            table["N"] = table["N"].astype("int64")
    if "beta" in table.columns and "model" in table.columns:
        # models whose friction reads no beta (velocity weakening) have none
        from stickslip.models.presets import PRESETS

        no_beta = [m for m in table["model"].unique() if "beta" not in PRESETS[m].reads()]
        table.loc[table["model"].isin(no_beta), "beta"] = np.nan
    if "final_state" in table.columns:
        table.loc[table["status"] != "ok", "final_state"] = "failed"
    lead = [c for c in TABLE_COLUMNS[spec.name] if c in table.columns]
    rest = [c for c in table.columns if c not in lead]
    return table[lead + rest].reset_index(drop=True)


def _records(table: pd.DataFrame) -> list[dict[str, Any]]:
    return to_jsonable(table.astype(object).where(table.notna(), None).to_dict(orient="records"))


# ---------------------------------------------------------------------------------------------
# The page: stickslip/templates/study.html.j2


def _write_page(
    path: Path,
    spec: Study,
    meta: dict[str, Any],
    findings: dict[str, Any],
    figures: list[dict[str, Any]],
    table: pd.DataFrame,
) -> None:
    """Write the study's ``index.html``: the command, the counts, what the data say, the figures
    (embedded) and the table, failed points marked."""
    damaged = []
    if "note" in table.columns and table["note"].notna().any():
        damaged = [f"{r.point_dir}: {r.note}" for r in table.itertuples() if isinstance(r.note, str)]
    cols = [c for c in TABLE_COLUMNS[spec.name] if c in table.columns] + ["status", "error"]
    rows = [{**r, "_class": "failed" if r.get("status") != "ok" else ""} for r in table.to_dict(orient="records")]
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
        cols=cols,
        rows=rows,
    )


# ---------------------------------------------------------------------------------------------
# The study's folder: what it owns

#: The record, at the top of a study's output folder, of every page file its studies wrote.
MANIFEST = ".stickslip-study.json"
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


def foreign_files(out: str | Path, spec: Study) -> list[str]:
    """The entries of the output folder ``out`` that no study of this package wrote (relative
    paths): at its top anything but the runs folder, the study pages and the manifest; in a page
    folder anything not in the manifest; in the runs folder anything but the folders of studies
    (``<name>-<key>``) holding their spec, their points (each with its point.json) and the sweep's
    summary; in a transition study's ladder anything but its bookkeeping and its rungs' files.
    ``spec`` is the study about to run (its page names are checked even before the page folder
    exists)."""
    from stickslip.experiments.cache import BOOKKEEPING
    from stickslip.experiments.ladders import RUNG_FILES
    from stickslip.experiments.studies import STUDIES
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

    def page(path: Path, rel: str):
        return rel in own and path.is_file()

    def points(path: Path, rel: str):
        summary = {f"{SUMMARY_NAME}.parquet", f"{SUMMARY_NAME}.csv", STOP_FILE}
        return (path.is_file() and path.name in summary) or (path / POINT_FILE).is_file()

    def rung(path: Path, rel: str):
        return path.is_file() and path.name in ("rung.json", *RUNG_FILES)

    def rungs(path: Path, rel: str):
        return rung if path.is_dir() and re.fullmatch(r"\d{2,}-beta[^/]+", path.name) else False

    def ladder(path: Path, rel: str):  # a ladder's folder: the sweep's bookkeeping and its rungs
        if path.name == "rungs" and path.is_dir():
            return rungs
        return path.is_file() and path.name in BOOKKEEPING

    def ladders(path: Path, rel: str):
        return ladder if path.is_dir() and (path / POINT_FILE).is_file() else points(path, rel)

    def study_runs(path: Path, rel: str):
        if path.name == "ladders" and path.is_dir():  # a transition study's points are ladders
            return ladders
        if path.name == "points" and path.is_dir():
            return points
        return path.name == "study-spec.json" and path.is_file()

    def runs(path: Path, rel: str):
        ok = path.is_dir() and any(path.name.startswith(f"{name}-") for name in STUDIES)
        return study_runs if ok else False

    def top(path: Path, rel: str):
        if path.name in LOCK_FILES or (path.name == MANIFEST and path.is_file()):
            return True
        if path.name == "runs" and path.is_dir():
            return runs
        if path.name in STUDIES and path.is_dir():
            return page
        return False

    walk(out, top)
    return foreign


def remove_study_files(out: str | Path, spec: Study) -> None:
    """``--overwrite``: remove what this study wrote under ``out`` (its page files and its runs
    folder); every other file stays."""
    import shutil

    out = Path(out)
    own = read_manifest(out)
    page_dir = out / spec.name
    for rel in sorted(own):
        path = out / rel
        if path.parent == page_dir and path.is_file():
            path.unlink()
    shutil.rmtree(out / "runs" / spec.dirname, ignore_errors=True)
    if own:
        io.write_json(out / MANIFEST, {"files": sorted(p for p in own if (out / p).exists())})
