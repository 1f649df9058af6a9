"""The paper's section 2 and Fig. 4 as a study of ``stickslip reproduce``: the single block of eq. (1)
(Figs. 1-3, the Hopf point of eq. 2, the inverse transition), the slip of eq. (3) and the Fourier
modes of the chain, eq. (5).

Each point is one experiment, named by ``experiment``, with its model parameters (``params``),
run length (``t_end``, the block run only) and ``options``; its folder is ``<experiment>-<key>``
(:func:`point_name`), so a changed experiment gets a folder of its own. Its runner computes it on
a worker and its loader reads it back for the rows (:func:`stickslip.report.rows.section2_rows`)
and the figures (:func:`stickslip.plotting.figures.section2_figures`). Every mode takes seconds;
``tiny`` shortens the block run and coarsens the period sweep, the stability map and the hysteresis.
"""

from __future__ import annotations

import dataclasses
from collections import namedtuple
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from stickslip import io
from stickslip.experiments.cache import spec_key
from stickslip.experiments.studies import Design, Study
from stickslip.models.params import BlockParams, ChainParams
from stickslip.models.presets import block_params, paper_parameters
from stickslip.outcome import Outcome, Results
from stickslip.report.commands import reproduce_command

if TYPE_CHECKING:  # loaded where used, so that listing the studies loads no heavy module
    import pandas as pd

__all__ = ["DESIGN", "task"]

#: The paper's chain (section 3) apart from beta and N, and its single block (section 2, Fig. 1).
_CHAIN = paper_parameters("N", "beta")
_BLOCK = {k: v for k, v in dataclasses.asdict(block_params()).items() if k != "threshold"}


def build(mode: str) -> Study:
    """The experiments of section 2 and Fig. 4 in ``mode`` (``quick``, ``full`` or ``tiny``)."""
    tiny = mode == "tiny"
    hysteresis = {"V_min": 0.25, "V_max": 0.45, "dV": 0.05 if tiny else 0.005}
    hysteresis.update(time_per_step=50.0 if tiny else 400.0, transient=0.5)
    points = [
        # Fig. 1: the first slip at t = Fs / (K V) = 300, then one every T = 344.3: six slips.
        {"experiment": "block", "params": _BLOCK, "t_end": 600.0 if tiny else 2000.0},
        {"experiment": "slip-limit", "params": _BLOCK, "options": {"rtol": 1e-10, "atol": 1e-12}},
        {
            "experiment": "period-sweep",
            "params": _BLOCK,
            "options": {"V_min": 1e-3, "V_max": 1e-1, "n": 4 if tiny else 13, "periods": 4},
        },
        {
            "experiment": "stability-block",
            "params": {**_BLOCK, "beta": 0.08},
            "options": {"beta_stable": 1.0, "map_betas": 31 if tiny else 121, "map_Vs": 40 if tiny else 200},
        },
        {"experiment": "hysteresis", "params": {k: v for k, v in _BLOCK.items() if k != "V"}, "options": hysteresis},
        {
            "experiment": "chain-modes",
            "params": {**_CHAIN, "N": 399, "beta": 1.0},
            "options": {"betas": [0.5, 1.0, 1.5], "n_k": 629},
        },
    ]
    return Study("figs1-4", mode, {}, tuple(points), note=f"{mode}: the single block of section 2 and Fig. 4")


# ---------------------------------------------------------------------------------------------
# The runners: compute into the point's folder (a summary back), load from it


#: An experiment's ``compute(cfg, run_dir)`` (its summary) and ``load(cfg, run_dir, summary)``.
_Runner = namedtuple("_Runner", ["compute", "load"])


def _reads(key: str, file: str) -> Callable[[dict[str, Any], Path, dict[str, Any]], dict[str, Any]]:
    """The loader of an experiment whose result is one file of its folder: ``{key: its data}``."""
    read = io.read_table if file.endswith(".parquet") else io.read_dataset
    return lambda cfg, run_dir, summary: {key: read(run_dir / file)}


def _compute_block_run(cfg: dict[str, Any], run_dir: Path) -> dict[str, Any]:
    """Eq. (1) at the paper's parameters with every step stored (Figs. 1, 2)."""
    from stickslip.run.block import simulate_block

    run = simulate_block(BlockParams(**cfg["params"]), cfg["t_end"], every=1)
    io.write_dataset(run_dir / "series.nc", run.series)
    io.write_table_files(run_dir / "slips", run.slips)
    f = run.final
    return {**run.summary(), "final": {"x": f.x, "v": f.v, "theta": f.theta, "stopped": f.stopped}}


def _load_block_run(cfg: dict[str, Any], run_dir: Path, summary: dict[str, Any]) -> dict[str, Any]:
    from stickslip.run.block import BlockRun, BlockState

    numbers = {k: int(summary[k]) for k in ("steps", "every", "n_stops", "n_starts")}
    numbers |= {k: float(summary[k]) for k in ("v_min", "v_max")}
    series, slips = io.read_dataset(run_dir / "series.nc"), io.read_table(run_dir / "slips.parquet")
    return {"run": BlockRun(BlockParams(**cfg["params"]), series, slips, BlockState(**summary["final"]), **numbers)}


def _compute_slip_limit(cfg: dict[str, Any], run_dir: Path) -> dict[str, Any]:
    """Eq. (3) accurately (DOP853, event v = 0) and with the Heun step of the paper."""
    from stickslip.analysis.dynamics.slip_limit import heun_slip_limit, solve_slip_limit

    p = BlockParams(**cfg["params"])
    law = solve_slip_limit(p, rtol=cfg["options"]["rtol"], atol=cfg["options"]["atol"])
    heun = heun_slip_limit(p)
    io.write_dataset(run_dir / "curve.nc", law.curve)
    return {**law.summary(), "heun_duration": heun.duration, "heun_force_at_stop": heun.force_at_stop, "heun_dt": p.dt}


def _load_slip_limit(cfg: dict[str, Any], run_dir: Path, summary: dict[str, Any]) -> dict[str, Any]:
    from stickslip.analysis.dynamics.slip_limit import SlipLimit

    numbers = {k: float(summary[k]) for k in ("duration", "force_at_stop", "slip", "theta_at_stop")}
    curve = io.read_dataset(run_dir / "curve.nc")
    return {"law": SlipLimit(BlockParams(**cfg["params"]), **numbers, method=str(summary["method"]), curve=curve)}


def _compute_period_sweep(cfg: dict[str, Any], run_dir: Path) -> dict[str, Any]:
    """Simulated stick-slip period at log-spaced V (Fig. 3)."""
    from stickslip.analysis.dynamics.slip_limit import paper_V_values, period_sweep

    o = cfg["options"]
    V = paper_V_values(o["n"], o["V_min"], o["V_max"])
    table = period_sweep(BlockParams(**cfg["params"]), V, periods=o["periods"])
    io.write_table_files(run_dir / "periods", table)
    return {
        "max_abs_rel_dev": float(np.nanmax(np.abs(table["rel_dev"]))),
        "n_V": int(len(table)),
        "V": table["V"].tolist(),
        "rel_dev": table["rel_dev"].tolist(),
    }


def _compute_block_stability(cfg: dict[str, Any], run_dir: Path) -> dict[str, Any]:
    """Eq. (2): Hopf point at the point's beta, stability for all V at ``beta_stable``, the map."""
    from stickslip.analysis.dynamics import stability as st

    p = BlockParams(**cfg["params"])
    hopf = st.hopf_point(p)
    q = p.replace(beta=float(cfg["options"]["beta_stable"]))
    hopf_q = st.hopf_point(q)
    V_scan = np.linspace(0.0, 1.0 / q.alpha, 2001)[1:-1]
    growth_q = st.block_growth_map(q, np.array([q.beta]), V_scan)
    betas = np.linspace(0.0, 1.5 * st.hopf_beta_limit(p), int(cfg["options"]["map_betas"]))
    Vs = np.linspace(0.0, 1.0 / p.alpha, int(cfg["options"]["map_Vs"]) + 1)[1:]
    ds = st.hopf_curve(p, betas).assign(growth_rate=st.block_growth_map(p, betas, Vs))
    io.write_dataset(run_dir / "stability_map.nc", ds)
    return {
        "beta": p.beta,
        "hopf_V": hopf.V,
        "hopf_V_closed_form": st.hopf_point_closed_form(p),
        "hopf_omega": hopf.omega,
        "regime": hopf.regime,
        "beta_stable": q.beta,
        "regime_stable": hopf_q.regime,
        "hopf_V_stable": hopf_q.V,
        "max_growth_stable": float(growth_q.max()),
        "V_scan": [float(V_scan[0]), float(V_scan[-1]), int(V_scan.size)],
    }


def _compute_hysteresis(cfg: dict[str, Any], run_dir: Path) -> dict[str, Any]:
    """V raised slowly and lowered again for the single block (the inverse transition, sec. 2)."""
    from stickslip.analysis.dynamics import hysteresis as hy

    result = hy.hysteresis_sweep(BlockParams(**cfg["params"]), hy.SweepSettings(**cfg["options"]))
    io.write_dataset(run_dir / "hysteresis.nc", result.data)
    return result.summary()


def _compute_chain_modes(cfg: dict[str, Any], run_dir: Path) -> dict[str, Any]:
    """Fourier modes of the linearised chain at the betas of Fig. 4, and the critical beta."""
    from stickslip.analysis.dynamics import stability as st

    p = ChainParams(**cfg["params"])
    betas = [float(b) for b in cfg["options"]["betas"]]
    ds = st.fig4_data(p, betas=betas, k=np.linspace(0.0, np.pi, int(cfg["options"]["n_k"])))
    io.write_dataset(run_dir / "fig4.nc", ds)
    keys = ("max_growth_rate", "k_at_max", "unstable", "marginal")
    per_beta = [{"beta": b, **{k: getattr(st.chain_stability(p.replace(beta=b)), k) for k in keys}} for b in betas]
    return {
        "critical_beta": st.chain_critical_beta(p),
        "critical_beta_numeric": st.chain_critical_beta_numeric(p),
        "per_beta": per_beta,
    }


_RUNNERS: dict[str, _Runner] = {
    "block": _Runner(_compute_block_run, _load_block_run),
    "slip-limit": _Runner(_compute_slip_limit, _load_slip_limit),
    "period-sweep": _Runner(_compute_period_sweep, _reads("table", "periods.parquet")),
    "stability-block": _Runner(_compute_block_stability, _reads("map", "stability_map.nc")),
    "hysteresis": _Runner(_compute_hysteresis, _reads("data", "hysteresis.nc")),
    "chain-modes": _Runner(_compute_chain_modes, _reads("modes", "fig4.nc")),
}


def task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """One experiment of section 2 or Fig. 4 on a worker (a task of
    :func:`stickslip.experiments.sweep.run_sweep`): its runner computes it into ``point_dir`` and
    returns its summary."""
    return _RUNNERS[point["experiment"]].compute(point, point_dir)


def check(cfg: dict[str, Any]) -> None:
    """Refuse an experiment this study has no runner for, or parameters its model refuses."""
    if cfg.get("experiment") not in _RUNNERS:
        raise ValueError(f"experiment must be one of {', '.join(_RUNNERS)} (got {cfg.get('experiment')!r})")
    (ChainParams if cfg["experiment"] == "chain-modes" else BlockParams)(**cfg["params"])


def point_name(point: dict[str, Any]) -> str:
    """An experiment's folder: ``<experiment>-<key>``, the key hashing its settings
    (:func:`stickslip.experiments.cache.spec_key`)."""
    return f"{point['experiment']}-{spec_key(point)}"


def load(spec: Study, table: pd.DataFrame, points_dir: Path) -> Results | None:
    """Every experiment's result read back from its folder (None unless each experiment of
    section 2 and Fig. 4 finished)."""
    from stickslip.experiments.sweep import DONE_FILE

    rows = {r.point_dir: r for r in table.itertuples()}
    if {p["experiment"] for p in spec.points if point_name(p) in rows} != set(_RUNNERS):
        return None
    outcomes = {}
    for point in spec.points:
        name, cfg = point["experiment"], {**spec.common, **point}
        run_dir, row = points_dir / point_name(point), rows[point_name(point)]
        summary = io.read_json(run_dir / DONE_FILE)["summary"]
        data = _RUNNERS[name].load(cfg, run_dir, summary)
        outcomes[name] = Outcome(cfg, run_dir, data, summary, bool(row.reused), float(row.wall_seconds))
    return Results(outcomes, None, spec.mode)


def findings(spec: Study, results: Results | None) -> dict[str, Any]:
    """The rows of the paper's stated numbers of section 2, eq. (3), Figs. 3 and 4
    (:func:`stickslip.report.rows.section2_rows`), and one statement per row."""
    from stickslip.report.rows import findings_of, section2_rows

    return findings_of(section2_rows(results.outcomes) if results else None)


def figures(spec: Study, results: Results | None, page_dir: Path) -> list[tuple]:
    """Figs. 1-4, the stability map and the hysteresis sweep, with their data beside them."""
    from stickslip.plotting.figures import section2_figures
    from stickslip.report import commands

    return section2_figures(results.outcomes, page_dir, commands) if results else []


def describe() -> str:
    """The text of ``stickslip study figs1-4 --help`` (section 2 and Fig. 4 of the paper)."""
    return (
        "Section 2 and Fig. 4 of the paper, one of the two studies of `stickslip reproduce`: the single "
        "block of eq. (1) at the paper's parameters to t = 2000 (Figs. 1, 2), the slip of eq. (3) solved "
        "accurately and with the Heun step, the period against 13 values of V (Fig. 3), the Hopf point "
        "and a 121 x 200 stability map of eq. (2), V raised and lowered from 0.25 to 0.45 (the inverse "
        "transition), the Fourier modes of the chain at beta = 0.5, 1, 1.5 (eq. 5, Fig. 4). Each is one "
        "point: seconds in every mode (--quick and --full are the same). Outputs in DIR/figs1-4/: fig1 to "
        "fig4, stability_map and hysteresis (PNG, PDF, their data), table.parquet and table.csv (one row "
        "per experiment), study.json (the paper's stated numbers of section 2 against ours), index.html."
    )


def _stated_numbers(*args: Any, **kwargs: Any) -> Any:
    """The paper's stated numbers: :func:`stickslip.report.rows.stated_numbers`, loaded when a
    page is written (listing the studies loads no report)."""
    from stickslip.report.rows import stated_numbers

    return stated_numbers(*args, **kwargs)


DESIGN = Design(
    name="figs1-4",
    summary="section 2 and Fig. 4 of the paper",
    describe=describe,
    build=build,
    task=task,
    check=check,
    findings=findings,
    figures=figures,
    columns=("experiment", "t_end", "params", "options"),
    tables=_stated_numbers,
    load=load,
    point_name=point_name,
    command=reproduce_command,
)
