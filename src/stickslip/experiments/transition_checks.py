"""Checks that the transition study by continuation measures what the runs from the paper's start
measure (:mod:`stickslip.experiments.studies.transition`).

* :func:`paper_start_check`: m = 1 - <L>/L_ss from the paper's start (x_i = 0, section 3) over the
  second half of a run of 4 loading times (:func:`stickslip.analysis.stats.order.order_summary`)
  against the up ladder's m at the same (N, beta): the difference in units of the combined error.
* :func:`longer_check`: a rung run again from the same start state for ``factor`` times its
  adaptive length, without the stop rule; its m against the adaptive one.
"""

from __future__ import annotations

import math
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

from stickslip import io
from stickslip.analysis.dynamics.adaptive import run_rung
from stickslip.analysis.stats.order import order_summary
from stickslip.experiments.ladders import params_at
from stickslip.experiments.studies.chain_point import point_run_options, t_end_of
from stickslip.experiments.sweep import point_name
from stickslip.experiments.sweep_points import point_params
from stickslip.models.physics import UNTIL_STEADY
from stickslip.run.driver import run_chain
from stickslip.run.rundir import read_state_file
from stickslip.run.state import ChainState

__all__ = ["paper_start_check", "longer_check", "rung_start_state"]


def paper_start_check(
    rows: list[dict[str, Any]], betas_below: float = 0.95, loads: float = 4.0
) -> list[dict[str, Any]]:
    """For every up-ladder row (replica 0) below ``betas_below``: its m against m from the paper's
    start (the batch-means estimate over the second half of a run of ``loads`` loading times of the
    chain of eq. (4), a point of the phase diagram's kind with 20000 samples:
    :func:`stickslip.experiments.studies.chain_point.point_run_options`), and the difference over
    the combined error (``z``)."""
    out = []
    for r in rows:
        if r["branch"] != "up" or r.get("replica", 0) != 0 or r["beta"] >= betas_below:
            continue
        N, beta = int(r["N"]), float(r["beta"])
        cfg = {"N": N, "beta": beta, "t_end": t_end_of(N, loads), "start": "paper", "n_samples": 20000}
        cfg |= {"analysis": "order", "until_steady": UNTIL_STEADY}
        p = point_params("chain", cfg)
        t_end, options = point_run_options(cfg, p)
        run = run_chain(p, t_end, **options)
        s = order_summary(run, p, options["average_from"])
        comb = math.hypot(r["order_parameter_err"], s["order_parameter_err"])
        out.append(
            {
                "N": N,
                "beta": beta,
                "paper_m": s["order_parameter"],
                "paper_m_err": s["order_parameter_err"],
                "paper_stuck_any": s["stuck_fraction"],
                "paper_t_end": t_end,
                "paper_wall_seconds": float(run.summary["wall_seconds"]),
                "ladder_m": r["order_parameter"],
                "ladder_m_err": r["order_parameter_err"],
                "ladder_loads": r["loads"],
                "ladder_wall_seconds": r["wall_seconds"],
                "z": (r["order_parameter"] - s["order_parameter"]) / comb if comb > 0 else math.nan,
            }
        )
    return out


def rung_start_state(ladder_dir: str | Path, index: int, cfg: dict[str, Any]):
    """The state rung ``index`` of an up ladder started from: the loaded start for rung 0, else the
    final state of rung ``index - 1`` (grid rungs of the up ladder hand over so); checked against
    the SHA-256 the rung recorded."""
    rungs = sorted((Path(ladder_dir) / "rungs").iterdir())
    rec = io.read_json(rungs[index] / "rung.json")
    if index == 0:
        state = ChainState.steady(params_at(cfg, rec["row"]["beta"]), float(cfg["perturbation"]), int(cfg["seed"]))
    else:
        state = read_state_file(rungs[index - 1] / "state.npz")
    if state.sha256() != rec["row"]["start_sha256"]:
        raise ValueError(f"rung {index} in {ladder_dir} did not start from the state before it")
    return state, rec["row"]


def longer_check(ladder_dir: str | Path, index: int, cfg: dict[str, Any], factor: float = 4.0) -> dict[str, Any]:
    """Rung ``index`` run again from its start for ``factor`` times its adaptive length (no stop
    rule, the same transient cut): its m and error against the adaptive ones."""
    state, row = rung_start_state(ladder_dir, index, cfg)
    long_cfg = {**cfg, "target": 0.0, "cap_loads": factor * float(row["loads"])}
    res = run_rung(params_at(cfg, row["beta"]), state, long_cfg)["row"]
    comb = math.hypot(row["order_parameter_err"], res["order_parameter_err"])
    return {
        "N": row["N"],
        "beta": row["beta"],
        "adaptive_m": row["order_parameter"],
        "adaptive_m_err": row["order_parameter_err"],
        "adaptive_loads": row["loads"],
        "long_m": res["order_parameter"],
        "long_m_err": res["order_parameter_err"],
        "long_loads": res["loads"],
        "adaptive_phi": row["stuck_fraction"],
        "long_phi": res["stuck_fraction"],
        "z": (res["order_parameter"] - row["order_parameter"]) / comb if comb > 0 else math.nan,
        "long_wall_seconds": res["wall_seconds"],
    }


def write_checks(
    study_json: str | Path,
    runs_dir: str | Path,
    path: str | Path,
    *,
    paper_Ns: tuple[int, ...] = (49, 99, 199),
    longer: tuple[tuple[int, float], ...] = (),
    factor: float = 4.0,
    n_workers: int = 2,
) -> dict[str, Any]:
    """Both checks for a finished study (its ``study.json`` and its runs folder
    ``runs/transition-<key>``), in parallel on a local process pool, written to ``path`` as JSON:
    the paper-start comparison for the up ladders of ``paper_Ns`` below beta = 0.95 and the longer
    runs of the up-ladder grid rungs (N, beta) in ``longer``."""
    data = io.read_json(study_json)
    spec = io.read_json(Path(runs_dir) / "study-spec.json")
    # replica 0 of each up ladder: the one whose rungs the longer runs restart
    up = [r for r in data["rows"] if r["branch"] == "up" and r.get("replica", 0) == 0]
    with ProcessPoolExecutor(n_workers) as pool:
        paper = [pool.submit(paper_start_check, [r]) for r in up if r["N"] in paper_Ns and r["beta"] < 0.95]
        jobs = []
        for N, beta in longer:
            (lad,) = [p for p in spec["points"] if p["N"] == N and p["direction"] == "up" and p.get("replica", 0) == 0]
            (row,) = [r for r in up if r["N"] == N and r["beta"] == beta]
            ldir = Path(runs_dir) / "points" / point_name(lad)
            jobs.append(pool.submit(longer_check, ldir, int(row["rung"]), {**spec["common"], **lad}, factor))
        out = {
            "paper_start": [c for f in paper for c in f.result()],
            "longer": [f.result() for f in jobs],
            "factor": factor,
        }
    io.write_json(path, out)
    return out
