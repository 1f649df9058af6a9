"""``stickslip study transition``: the stick-slip transition of eq. (4) at beta = 1 as N grows, by
continuation in beta (:mod:`stickslip.experiments.ladders`).

For each N ``up`` ladders and a ``down`` ladder run as independent Dask tasks
(:func:`stickslip.experiments.sweep.run_sweep`: a finished ladder is reused, a failed one recorded
and retried, an interrupted one continues its running rung from its last finished segment). From
the rungs, per N (:func:`per_n_summary`): the loop's upper edge ``beta_t``, its lower edge (linear
stability of steady sliding puts it at beta = 1) and the step of the order parameter m at beta_t
(from steady sliding's 0); and the power laws beta_t - 1 ~ N^b and (size of the step) ~ N^b
(:func:`stickslip.analysis.stats.order.power_law_fit`).

Layout: ``OUT/runs/transition-<key>/points/<ladder>/rungs/...`` and ``OUT/transition/`` (table,
figures, ``study.json``, ``index.html``).
"""

from __future__ import annotations

import json
import math
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from stickslip.experiments.studies import Design, Option, Study
from stickslip.jsonable import table_records
from stickslip.models.params import MAX_BLOCKS, check_number
from stickslip.models.presets import paper_parameters

if TYPE_CHECKING:  # loaded where used, so that listing the studies loads no heavy module
    import pandas as pd

__all__ = ["DESIGN", "ladder_points", "transition_loop", "per_n_summary", "ROW_COLUMNS", "PER_N_COLUMNS", "LADDER_NS"]

#: The leading columns of the study's rows (one per rung) and of its per-N table.
ROW_COLUMNS = (
    "N beta branch replica order_parameter order_parameter_err stuck_fraction stuck_fraction_err final_state "
    "branch_state t_end loads tau_int_loads t_cut_loads err_reliable role start final_reason wall_seconds"
).split()
PER_N_COLUMNS = (
    "N beta_t beta_t_err lower_edge lower_edge_err step step_err step_phi step_phi_err beta_t_spread replicas"
).split()

#: N of each mode; ``extra_Ns`` (for example 1599) adds chains.
LADDER_NS = {"tiny": (9,), "quick": (49, 99, 199), "full": (49, 99, 199, 399, 799)}
#: Up ladders per N, each from its own seeded start: where the up ladder leaves stick-slip is a
#: random event near beta_t (at N = 99 five seeds gave beta_t from 1.11 to 1.20), so beta_t and
#: the step are means over replicas with the spread between them as their error.
REPLICAS = {"tiny": 2, "quick": 4, "full": 4}


def _cap_loads(N: int) -> float:
    """The cap of one rung in loading times: long enough for 16 batches of 10 tau_int where a
    loading time costs seconds (the largest events of a short chain come once per loading time,
    so its m needs several), shorter where a loading time costs minutes (there tau_int is a few
    thousandths of a loading time)."""
    return next((cap for n, cap in ((99, 16.0), (199, 8.0), (399, 3.0), (799, 1.5)) if N <= n), 0.8)


def _grids(N: int, mode: str) -> tuple[list[float], list[float]]:
    """Coarse grids in beta of the up and down ladders: steps in 1 + k / N, where beta_t(N) lies
    for small N (about 1 + 15 / N), and a few points below 1."""
    above = [round(1.0 + k / N, 6) for k in (5, 10, 20, 40, 80)]
    if mode == "tiny":
        return [0.8, 2.0, 4.0], [2.0, 1.2, 0.8]
    below_up = [0.8, 0.9, 1.0] if N <= 199 else [0.95, 1.0]
    down = sorted(above[:4] + [round(1.0 + 2.0 / N, 6), 1.0, 0.97, 0.9], reverse=True)
    return below_up + above, down


def ladder_points(mode: str, extra_Ns: tuple[int, ...] = ()) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """The shared settings and the ladders (one per N and direction) of a mode; large N first (the
    up ladder of the largest chain is the longest task: it sets the wall time on a few workers)."""
    from stickslip.analysis.dynamics.adaptive import STOP_BATCHES

    common = {
        **paper_parameters("N", "beta"),
        "model": "sakaguchi",
        "target": 0.006,
        "segment_loads": 0.25,
        "first_segment_loads": 0.02,
        "samples_per_load": 2000 if mode != "tiny" else 400,
        "perturbation": 1e-3,
        "down_perturbation": 1e-5,
        "seed": 0,
        "bisections": 3 if mode != "tiny" else 1,
        "replicas": REPLICAS[mode],
        "stop_batches": STOP_BATCHES,
    }
    points = []
    for N in sorted(set(LADDER_NS[mode]) | {int(n) for n in extra_Ns}, reverse=True):
        up, down = _grids(N, mode)
        cap = _cap_loads(N) if mode != "tiny" else 1.0
        for r in range(REPLICAS[mode]):
            points.append({"N": N, "direction": "up", "betas": up, "cap_loads": cap, "seed": r, "replica": r})
        points.append({"N": N, "direction": "down", "betas": down, "cap_loads": cap, "seed": 0, "replica": 0})
    return common, points


def build(mode: str, extra_Ns: Sequence[int] = ()) -> Study:
    """The study of ``mode``: :func:`ladder_points`, with chains of ``extra_Ns`` blocks added."""
    for n in extra_Ns:
        check_number("extra-n", n, low=3, high=MAX_BLOCKS, integer=True)
    common, points = ladder_points(mode, tuple(extra_Ns))
    Ns = sorted({p["N"] for p in points})
    note = (
        f"{mode}: N in {Ns}, {common['replicas']} up ladders and one down ladder per N, rungs to an "
        f"error of m of {common['target']:g}, {common['bisections']} bisections of each bracket"
    )
    return Study("transition", mode, common, tuple(points), note=note)


def check(cfg: dict[str, Any]) -> None:
    """Refuse a ladder whose chain at one of its betas is not a valid chain (ParameterError)."""
    from stickslip.experiments.ladders import params_at

    for beta in cfg["betas"]:
        params_at(cfg, float(beta))


def _bracket(ladder: pd.DataFrame) -> tuple[float, float]:
    """A ladder's last stick-slip beta and the first sliding beta above it (NaN where none)."""
    lo = float(ladder.loc[ladder["branch_state"] == "stick-slip", "beta"].max())
    return lo, float(ladder.loc[(ladder["branch_state"] == "sliding") & (ladder["beta"] > lo), "beta"].min())


def _replica_edge(up: pd.DataFrame) -> dict[str, Any] | None:
    """One up ladder's upper edge: the last stick-slip beta with half the bracket to the first
    sliding beta above it as its error, and m (``step``) and phi (``step_phi``) there (None when
    the ladder never stick-slipped)."""
    bt, above = _bracket(up)
    if math.isnan(bt):
        return None
    at = up[(up["branch_state"] == "stick-slip") & (up["beta"] == bt)].iloc[-1]
    return {
        "beta_t": bt,
        "beta_t_err": 0.5 * (above - bt),
        "step": float(at["order_parameter"]),
        "step_err": float(at["order_parameter_err"]),
        "step_phi": float(at["stuck_fraction"]),
        "step_phi_err": float(at["stuck_fraction_err"]),
        "reliable": bool(at["err_reliable"]),
        "tau": float(at["tau_int_loads"]) if at["tau_int_loads"] is not None else math.nan,
    }


def _mean_err(values: list[float], errs: list[float]) -> tuple[float, float]:
    """Mean of the replicas' values; its error the larger of the spread between them (standard
    error of the mean) and their own errors combined (which is all there is for one replica)."""
    v, e = np.asarray(values, dtype=float), np.asarray(errs, dtype=float)
    own = float(np.sqrt(np.nanmean(e * e) / v.size)) if np.isfinite(e).any() else math.nan
    spread = float(np.std(v, ddof=1) / math.sqrt(v.size)) if v.size > 1 else 0.0
    return float(v.mean()), float(np.nanmax([own, spread]))


def per_n_summary(rows: pd.DataFrame) -> pd.DataFrame:
    """What the rungs of the transition study say per N: the loop's edges and the step at its top.

    Parameters
    ----------
    rows : pandas.DataFrame
        The rungs (the study's table, or :func:`transition_loop`).

    Returns
    -------
    pandas.DataFrame
        One row per N, the columns :data:`PER_N_COLUMNS`: ``beta_t`` (last beta where the up
        ladders stick-slip, the mean over their replicas) and ``beta_t_err`` (the larger of the
        replicas' spread and their half brackets), ``lower_edge`` (middle of the bracket where the
        down ladder leaves steady sliding) and ``lower_edge_err`` (half the bracket), ``step`` of
        m and ``step_phi`` of the stuck fraction at beta_t with their errors, ``replicas``,
        ``undecided`` and ``rungs``.
    """
    import pandas as pd

    out = []
    if "replica" not in rows:
        rows = rows.assign(replica=0)
    for N, g in rows.groupby("N"):
        up, down = g[g["branch"] == "up"], g[g["branch"] == "down"]
        rec: dict[str, Any] = {"N": int(N), **{k: math.nan for k in PER_N_COLUMNS[1:]}}
        edges = [e for _, u in up.groupby("replica") if (e := _replica_edge(u)) is not None]
        if edges:
            for k in ("beta_t", "step", "step_phi"):
                rec[k], rec[f"{k}_err"] = _mean_err([e[k] for e in edges], [e[f"{k}_err"] for e in edges])
            rec["beta_t_replicas"] = [e["beta_t"] for e in edges]
            rec["beta_t_spread"] = float(np.std(rec["beta_t_replicas"], ddof=1)) if len(edges) > 1 else math.nan
            rec["m_at_beta_t_reliable"] = all(e["reliable"] for e in edges)
            rec["tau_int_loads_at_beta_t"] = float(np.nanmean([e["tau"] for e in edges]))
            rec["replicas"] = len(edges)
        lo, hi = _bracket(down)  # NaN unless the down ladder left steady sliding below a sliding rung
        rec["lower_edge"], rec["lower_edge_err"] = 0.5 * (lo + hi), 0.5 * (hi - lo)
        rec["undecided"] = int((g["final_state"] == "undecided").sum())
        rec["rungs"] = len(g)
        out.append(rec)
    return pd.DataFrame(out)


def _fits(per_n: pd.DataFrame) -> dict[str, Any]:
    from stickslip.analysis.stats.order import power_law_fit

    bt, step = per_n.dropna(subset=["beta_t"]), per_n.dropna(subset=["step"])
    return {
        "beta_t_minus_1": power_law_fit(bt["N"], bt["beta_t"] - 1.0, bt["beta_t_err"].fillna(bt["beta_t"] - 1.0)),
        "step": power_law_fit(step["N"], step["step"].abs(), step["step_err"]),
    }


def rungs(sweep: pd.DataFrame) -> pd.DataFrame:
    """The study's table, one row per rung, from the sweep's (one row per ladder)."""
    ok = sweep[sweep["status"] == "ok"]  # the rows of each ladder as JSON text (the sweep's table)
    return _rows_table([r for text in ok.get("rows", []) for r in json.loads(text)])


def findings(spec: Study, table: pd.DataFrame) -> dict[str, Any]:
    """beta_t, the lower edge and the step at beta_t per N (:func:`per_n_summary`), their power
    laws in N and the statements of the page, from the rungs of the finished ladders (never none:
    :func:`stickslip.experiments.study_run.run_study` asks only then)."""
    per_n = per_n_summary(table)
    fits = _fits(per_n)
    undecided = int((table["final_state"] == "undecided").sum())
    say = [
        f"N = {r.N}: beta_t = {r.beta_t:.4g} +- {r.beta_t_err:.2g}, lower edge {r.lower_edge:.4g} "
        f"+- {r.lower_edge_err:.2g}, step of m at beta_t {r.step:.3g} +- {r.step_err:.2g}, "
        f"stuck fraction there {r.step_phi:.3g}"
        for r in per_n.itertuples()
    ]
    for name, label in (("beta_t_minus_1", "beta_t - 1"), ("step", "|step of m|")):
        f = fits[name]
        if math.isfinite(f["b"]):
            say.append(f"{label} ~ N^b with b = {f['b']:.2f} +- {f['b_err']:.2f} ({f['n']} values of N)")
    say.append(f"{undecided} of {len(table)} rungs undecided at their cap (reasons in the table)")
    return {
        "statements": say,
        "fits": fits,
        "per_N": table_records(per_n),
        "rungs": len(table),
        "undecided": undecided,
        "rungs_damaged": int(table["note"].notna().sum()) if "note" in table else 0,
    }


def figures(spec: Study, table: pd.DataFrame, page_dir: Path) -> list[tuple[str, Any, str]]:
    """The loops of m and the stuck fraction against beta, and the scaling of beta_t - 1 and the
    step with N (:mod:`stickslip.plotting.ladders`)."""
    from stickslip.plotting.ladders import loops_figure, scaling_figure

    per_n = per_n_summary(table)
    return [
        ("loops", loops_figure(table), "m and the stuck fraction against beta: up ladders and the down ladder, per N."),
        ("scaling", scaling_figure(per_n, _fits(per_n)), "beta_t - 1 and the step of m at beta_t against N."),
    ]


def _rows_table(rows: list[dict[str, Any]]) -> pd.DataFrame:
    """The rungs as the study's table: :data:`ROW_COLUMNS` first, by N, branch, replica and beta."""
    import pandas as pd

    table = pd.DataFrame(rows)
    if len(table):
        table = table[[c for c in ROW_COLUMNS if c in table] + [c for c in table if c not in ROW_COLUMNS]]
        table = table.sort_values(["N", "branch", "replica", "beta"], kind="stable").reset_index(drop=True)
    return table


def transition_loop(
    N: int,
    *,
    out_dir: str | Path | None = None,
    replicas: int = 1,
    bisections: int = 3,
    cap_loads: float | None = None,
    up: Sequence[float] | None = None,
    down: Sequence[float] | None = None,
) -> pd.DataFrame:
    """The hysteresis loop of the chain of eq. (4) across beta_c = 1 at one N, by continuation in
    beta: the up and down ladders of ``stickslip study transition`` (docs/studies/transition.md),
    run one after the other in this process.

    The rungs (:mod:`stickslip.experiments.ladders`) are those of the study with the same
    settings, bit for bit: at N = 49 (about 15 s) replica 0 of ``--quick``.

    Parameters
    ----------
    N : int
        Blocks of the chain (the paper's other parameters: K = 10, D = 5, V = 0.001, Fs = 3).
    out_dir : str or Path, optional
        Where the ladders keep their rungs; a call with the same settings reuses them. A new
        temporary folder when not given.
    replicas : int
        Up ladders, each from its own seeded start (the study runs 4: where an up ladder leaves
        stick-slip is a random event near beta_t).
    bisections : int
        Bisections of the bracket where each ladder leaves its branch.
    cap_loads : float, optional
        Longest rung, in loading times L_ss / V (default the study's: 16 for N <= 99, fewer for
        longer chains).
    up, down : sequence of float, optional
        The ladders' coarse grids in beta (default the study's: 0.8, 0.9, 1 and 1 + k / N,
        k = 5 ... 80, up; 1 + k / N down to 0.9, down).

    Returns
    -------
    pandas.DataFrame
        One row per rung, with the columns of the study's table (:data:`ROW_COLUMNS`): ``beta``,
        ``branch`` (``up``/``down``), ``replica``, the order parameter m = 1 - <L>/L_ss
        (``order_parameter``) and the stuck fraction (``stuck_fraction``) with their errors,
        ``final_state``, ``branch_state`` (``stick-slip``/``sliding``), ``loads``, ...
        :func:`per_n_summary` reads beta_t, the lower edge and the step from it;
        :func:`stickslip.plotting.ladders.loops_figure` draws it.

    Examples
    --------
    >>> from stickslip.experiments.studies.transition import per_n_summary, transition_loop
    >>> rows = transition_loop(9, bisections=0, cap_loads=1.0, up=[0.8, 4.0], down=[4.0, 0.8])
    >>> [(r.branch, r.beta, r.branch_state) for r in rows.itertuples()]
    [('down', 0.8, 'stick-slip'), ('down', 4.0, 'sliding'), ('up', 0.8, 'stick-slip'), ('up', 4.0, 'sliding')]
    """
    N = int(check_number("N", N, low=1, integer=True))
    replicas = int(check_number("replicas", replicas, low=1, integer=True))
    bisections = int(check_number("bisections", bisections, low=0, integer=True))
    common, _ = ladder_points("quick")
    grid_up, grid_down = _grids(N, "quick")
    cap = _cap_loads(N) if cap_loads is None else float(check_number("cap_loads", cap_loads, low=0.0, low_open=True))
    ladders = [{"direction": "up", "betas": list(up or grid_up), "seed": r, "replica": r} for r in range(replicas)]
    ladders.append({"direction": "down", "betas": list(down or grid_down), "seed": 0, "replica": 0})
    points = [{**common, "N": N, "cap_loads": cap, "bisections": bisections, **lad} for lad in ladders]
    for point in points:  # every rung's parameters refused before any ladder runs
        check(point)
    folder = Path(out_dir) if out_dir is not None else Path(tempfile.mkdtemp(prefix="stickslip-transition-"))
    rows: list[dict[str, Any]] = []
    for point in points:
        rows += _ladder_task(point, folder / f"N{N}-{point['direction']}-{point['replica']}")["rows"]
    return _rows_table(rows)


#: The wall time of each mode (``stickslip study --help``, the README).
COST = {"quick": "5 to 11 minutes on two cores", "full": "about 45 minutes on two free cores"}


def describe() -> str:
    """The text of ``stickslip study transition --help``."""
    quick, full = build("quick"), build("full")
    return (
        "Where does the chain of eq. (4) leave stick-slip as beta crosses 1, and how does that change "
        "with N? By continuation in beta: for each N, up ladders start in stick-slip below beta = 1 "
        "and hand each rung's final state to the next larger beta until the chain slides; a down "
        "ladder starts from steady sliding and goes down until a block sticks; each bisects the "
        "bracket it finds. Each rung stops when its answer is known (error of m, steady sliding "
        "reached, or its cap). "
        f"Grid: --quick {quick.note.split(': ', 1)[1]} ({len(quick.points)} ladders, {COST['quick']}"
        f"); --full {full.note.split(': ', 1)[1]} ({len(full.points)} ladders, {COST['full']}); "
        "--extra-n adds a chain (1599: hours)."
        " Outputs in "
        "DIR/transition/: table.parquet and table.csv (one row per rung: m, the stuck fraction, "
        "their errors, the final state), loops and scaling (PNG, PDF), study.json (with beta_t, "
        "the lower edge and the step per N and their power laws in N), index.html."
    )


def _ladder_task(*args: Any, **kwargs: Any) -> dict[str, Any]:
    """A point of the study: :func:`stickslip.experiments.ladders.ladder_task`, loaded when a point
    runs (listing the studies, as ``stickslip --help`` does, loads no engine)."""
    from stickslip.experiments.ladders import ladder_task

    return ladder_task(*args, **kwargs)


# A point's stored result is keyed by its task's name (experiments/sweep.py): the ladders' own.
_ladder_task.__module__, _ladder_task.__qualname__ = "stickslip.experiments.ladders", "ladder_task"


def _ladder_entry(*args: Any, **kwargs: Any) -> Any:
    """:func:`stickslip.experiments.ladders.ladder_entry`, loaded when asked."""
    from stickslip.experiments.ladders import ladder_entry

    return ladder_entry(*args, **kwargs)


DESIGN = Design(
    cost=COST,
    name="transition",
    summary="the edges of the stick-slip loop at beta = 1 against N, by continuation in beta",
    describe=describe,
    build=build,
    task=_ladder_task,
    check=check,
    findings=findings,
    figures=figures,
    columns=tuple(ROW_COLUMNS),
    rows=rungs,
    tables=lambda found: [("Per N", PER_N_COLUMNS + ["undecided", "rungs"], found.get("per_N", []))],
    point_entry=_ladder_entry,
    options=(Option("--extra-n", "extra_Ns", "N", "add a chain of N blocks (both ladders), e.g. 1599; repeatable"),),
)
