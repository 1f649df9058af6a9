"""Continuation in beta for the transition study: ladders of chain runs (eq. 4) handing states on.

A *ladder* is one Dask task of ``stickslip study transition``: for one N and one direction it
runs points ("rungs") one after the other, each starting from the final state of the one before.

* ``up``: starts in stick-slip (the loaded start below, at beta well below 1) and hands each
  rung's final state to the next larger beta, until a rung leaves stick-slip; then bisects
  between the last stick-slip beta and the first sliding one, each time from the last
  stick-slip state. beta_t(N) is the last beta where the up ladder still stick-slips.
* ``down``: starts from exact discrete steady sliding (the docs page ``docs/model.md``) plus a
  seeded perturbation above beta_t and hands each rung's final state, perturbed again by the
  same amount, to the next smaller beta, until a rung leaves steady sliding (some block sticks);
  then bisects. Linear stability puts that lower edge at beta = 1.

A rung runs in segments until its answer is known (:func:`stickslip.analysis.dynamics.adaptive.run_rung`).
Each finished rung is written to ``<ladder>/rungs/<k>-beta<b>/`` (``rung.json``, the final state
``state.npz``, the samples ``samples.npz``), and a running rung keeps its progress after each
segment there (``progress.npz``); a ladder started again replays its finished rungs and continues
the first unfinished one from its last finished segment, with the result of an uninterrupted rung.
"""

from __future__ import annotations

import re
from io import BytesIO
from pathlib import Path
from typing import Any

import numpy as np

from stickslip import io
from stickslip.analysis.dynamics.adaptive import STOP_BATCHES, run_rung
from stickslip.experiments.cache import BOOKKEEPING, canonical, file_sha256, read_done, sealed
from stickslip.experiments.sweep_points import point_params
from stickslip.jsonable import to_jsonable
from stickslip.models.params import ParameterError
from stickslip.models.presets import paper_parameters
from stickslip.run.checkpoint import read_state_npz, write_state_npz
from stickslip.run.rundir import read_state_file, write_state_file
from stickslip.run.state import ChainState
from stickslip.run.validate import check_start_state

__all__ = ["ladder_task", "ladder_entry"]

_PAPER = paper_parameters("N", "beta")
#: The settings a rung is run from, recorded in its spec with the paper's parameters.
_SETTINGS = ("target", "cap_loads", "segment_loads", "first_segment_loads", "samples_per_load")
_SETTINGS += ("perturbation", "down_perturbation", "seed")


def params_at(cfg: dict[str, Any], beta: float):
    """The chain of eq. (4) with the ladder's settings at ``beta``."""
    return point_params("chain", {**cfg, "N": int(cfg["N"]), "beta": float(beta)})


#: The files of a rung's folder, each recorded with its SHA-256 in rung.json.
RUNG_FILES = ("state.npz", "samples.npz")
#: A running rung's progress after its last finished segment (gone once the rung is written).
PROGRESS_FILE = "progress.npz"


def ladder_entry(path: Path, rel: str = ""):
    """Whether an entry of a ladder's folder is the ladder's: the sweep's bookkeeping, and its
    ``rungs`` folder, holding only rungs (``<k>-beta<b>``) of ``rung.json``,
    :data:`RUNG_FILES` and :data:`PROGRESS_FILE`. True or False, or for a folder the test of its entries (the walk of
    :func:`stickslip.experiments.study_run.foreign_files`)."""

    def rung(p: Path, r: str) -> bool:
        return p.is_file() and p.name in ("rung.json", PROGRESS_FILE, *RUNG_FILES)

    def rungs(p: Path, r: str):
        return rung if p.is_dir() and re.fullmatch(r"\d{2,}-beta[^/]+", p.name) else False

    if path.name == "rungs" and path.is_dir():
        return rungs
    return path.is_file() and path.name in BOOKKEEPING


def _replay(rdir: Path, spec: dict[str, Any], params) -> tuple[dict[str, Any] | None, str | None]:
    """The row and final state of the rung stored in ``rdir`` if it was run from ``spec`` and is
    whole: its record as written (its SHA-256), every file present with the checksum recorded
    when it was written, the state the one its row names and one a run can go on from. Else
    None, and why a stored rung of this spec is not reused (None when there is none)."""
    # another rung's record (another start or settings) is not this rung's: (None, None)
    rec, why = read_done(rdir / "rung.json", spec, "row")
    if rec is None:
        return None, why
    row = rec["row"]
    if set(rec["files"]) != set(RUNG_FILES):
        return None, "rung.json records no checksums of its files"
    try:
        state = read_state_file(rdir / "state.npz")
        if state.sha256() != row.get("final_sha256"):
            return None, "state.npz is not the final state its row records"
        check_start_state(state, params, where="state.npz")
    except (ValueError, ParameterError) as exc:
        return None, str(exc)
    return {"row": row, "state": state}, None


def _keep_progress(path: Path, spec: dict[str, Any], progress: dict[str, Any]) -> None:
    """A rung's progress after a segment (:func:`stickslip.analysis.dynamics.adaptive.run_rung`) to ``path``,
    with its spec and checksum (:func:`stickslip.run.checkpoint.write_state_npz`): an interrupted
    rung loses at most the segment it was in."""
    arrays = {k: np.asarray(progress[k]) for k in ("t", "L", "n_moving")}
    arrays["devs"] = np.asarray(progress["devs"], dtype=float)
    path.parent.mkdir(parents=True, exist_ok=True)
    header = {"spec": spec} | {k: float(progress[k]) for k in ("seg", "t_start", "wall_seconds")}
    write_state_npz(path, progress["state"], header, arrays)


def _progress(path: Path, spec: dict[str, Any], params) -> dict[str, Any] | None:
    """The progress kept at ``path`` by :func:`_keep_progress` if it is whole, of this rung's spec
    and its state one a run can go on from; else None (the rung starts over)."""
    found = read_state_npz(path, spec, params)
    if found is None:
        return None
    state, header, arrays = found
    try:
        check_start_state(state, params, where=path.name)
        out = {k: arrays[k] for k in ("t", "L", "n_moving")} | {"devs": arrays["devs"].tolist(), "state": state}
        return out | {k: float(header[k]) for k in ("seg", "t_start", "wall_seconds")}
    except (ParameterError, KeyError, TypeError, ValueError):
        return None


def _rung(
    ladder_dir: Path, index: int, beta: float, state, start: str, cfg: dict[str, Any], role: str = "grid", **kw
) -> dict[str, Any]:
    """Rung ``index`` at ``beta`` from ``state``: reused from its directory when it was run from the
    same state with the same settings and its files are whole (:func:`_replay`), else run and
    written; a rung run again because its stored files were damaged says so in its row's ``note``."""
    rdir = ladder_dir / "rungs" / f"{index:02d}-beta{beta:.6g}"
    sha = state.sha256()
    settings = {k: cfg[k] for k in _SETTINGS} | {k: cfg.get(k, v) for k, v in _PAPER.items()}
    # a rung of another stop rule is not this rung: it is run again, not replayed
    settings["stop_batches"] = int(cfg.get("stop_batches", STOP_BATCHES))
    # The rung's spec: the state it starts from and its settings (the study cache's record format).
    spec = canonical({"start_sha256": sha, "settings": settings})
    params = params_at(cfg, beta)
    stored, why = _replay(rdir, spec, params)
    if stored is not None:
        return stored
    progress = rdir / PROGRESS_FILE
    resume = _progress(progress, spec, params)
    res = run_rung(params, state, cfg, resume=resume, save=lambda p: _keep_progress(progress, spec, p), **kw)
    row = {**res["row"], "branch": cfg["direction"], "replica": int(cfg.get("replica", 0)), "seed": int(cfg["seed"])}
    row.update(rung=index, role=role, start=start, start_sha256=sha, final_sha256=res["state"].sha256())
    row = to_jsonable(row)  # as a replay reads it back (NaN and inf become None)
    rdir.mkdir(parents=True, exist_ok=True)
    (rdir / "rung.json").unlink(missing_ok=True)  # no record while its files are rewritten
    write_state_file(rdir / "state.npz", res["state"])
    samples = BytesIO()  # written whole or not at all (a full disk leaves no half file)
    np.savez(samples, **res["samples"])
    io.write_bytes(rdir / "samples.npz", samples.getvalue())
    files = {name: file_sha256(rdir / name) for name in RUNG_FILES}
    io.write_json(rdir / "rung.json", sealed({"spec": spec, "row": row, "files": files}))
    progress.unlink(missing_ok=True)
    if why is not None:  # this run's row says why the stored rung was not reused
        row = {**row, "note": f"cached rung damaged ({why}): run again"}
    return {"row": row, "state": res["state"]}


def ladder_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """One ladder of the transition study (a task of ``run_sweep``): ``point`` holds ``N``,
    ``direction`` (``up``/``down``), the coarse grid ``betas``, ``bisections``, the rung settings
    (``target``, ``cap_loads``, segments, ``samples_per_load``) and the start's ``perturbation``
    and ``seed``. Returns the rungs as rows (``rows``) and the bracket found."""
    from stickslip.experiments.sweep import stop_requested

    cfg, d = dict(point), Path(point_dir)
    up = cfg["direction"] == "up"
    betas = sorted((float(b) for b in cfg["betas"]), reverse=not up)
    # The down ladder's perturbation stays well below V: a kick of v by V stops blocks at once.
    amp = float(cfg["perturbation"] if up else cfg["down_perturbation"])
    seed = int(cfg["seed"])
    kw = {"leave_stops": not up, "stop_requested": stop_requested(d)}
    state = ChainState.steady(params_at(cfg, betas[0]), amp, seed)
    start = f"steady sliding + uniform perturbation {amp:g} (seed {seed})"
    own = "stick-slip" if up else "sliding"
    rows: list[dict[str, Any]] = []
    inside = outside = None  # (beta, state) on the ladder's own branch / the first beta off it
    for b in betas:
        r = _rung(d, len(rows), b, state, start, cfg, **kw)
        rows.append(r["row"])
        if r["row"]["branch_state"] != own:
            outside = b
            break
        inside = (b, r["state"])
        state = r["state"] if up else r["state"].perturbed(amp, seed + len(rows))
        start = f"final state of beta = {b:g}" + (
            "" if up else f" + uniform perturbation {amp:g} (seed {seed + len(rows)})"
        )
    for _ in range(int(cfg["bisections"]) if inside is not None and outside is not None else 0):
        b_in, s_in = inside
        mid = round(0.5 * (b_in + outside), 6)
        s0 = s_in if up else s_in.perturbed(amp, seed + len(rows) + 1)
        start = f"final state of beta = {b_in:g}" + ("" if up else " + perturbation")
        r = _rung(d, len(rows), mid, s0, start, cfg, role="bisection", **kw)
        rows.append(r["row"])
        if r["row"]["branch_state"] == own:
            inside = (mid, r["state"])
        else:
            outside = mid
    return {
        "N": int(cfg["N"]),
        "direction": cfg["direction"],
        "inside": inside[0] if inside else None,
        "outside": outside,
        "rows": rows,
    }
