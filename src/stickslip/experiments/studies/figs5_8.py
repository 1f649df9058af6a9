"""The paper's section 3 as a study of ``stickslip reproduce``: chain runs of eq. (4) from the paper's
initial state for the final states, Fig. 5(b) (<L> against beta) and Figs. 5(a), 6, 7, 8 (the runs
at beta = 1 and 0.2). ``full`` runs the paper's chains (N = 399 to t = 2e7) at the values of beta
of Fig. 5(b) with more near beta = 1, ``quick`` shorter chains in minutes (a chain loads in about
L_ss / V time units and L_ss grows like N^2), ``tiny`` chains of N = 19 for the tests (:func:`build`).

Chain runs at beta > 1 (beyond 1.2 in ``full``) stop once the chain slides steadily
(``until_steady``): from then on every block moves every step and nothing changes but the position
of the pulling point. Each run averages <L> and counts events over its second half only.
"""

from __future__ import annotations

import functools
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from stickslip.experiments.studies import Design, Study
from stickslip.jsonable import table_records
from stickslip.models.physics import UNTIL_STEADY
from stickslip.models.presets import paper_parameters
from stickslip.outcome import Outcome, Results, point_settings
from stickslip.report.commands import reproduce_command

if TYPE_CHECKING:  # loaded where used, so that listing the studies loads no heavy module
    import pandas as pd

__all__ = ["DESIGN", "chain_point_task"]

# Just above beta = 1 (1.025 to 1.1) the chain stick-slips for a very long time: at N = 99 it
# still does at t = 1e7, so such a point at N = 399 costs a whole run of the sliding regime
# (an hour on one core) and ends without settling. The full set therefore jumps to 1.2.
_FULL_BETAS = (0.2, 0.4, 0.6, 0.7, 0.8, 0.85, 0.9, 0.95, 0.975, 0.99, 1.0, 1.2, 1.5)
_QUICK_BETAS = (0.2, 0.4, 0.6, 0.8, 0.9, 0.95, 1.0, 1.1, 1.2, 1.5)


def build(mode: str) -> Study:
    """The chain runs of ``mode`` (``quick``, ``full`` or ``tiny``) and the settings they share."""
    if mode == "full":
        sweep_N = figure_N = 399
        t_sweep = t_fig = 2e7
        betas, steady_above = _FULL_BETAS, 1.3
        note = (
            "full: beta = 1.2 runs its whole length (the paper's run of the sliding regime); "
            "beta = 1.5 stops at steady sliding"
        )
    elif mode == "quick":
        sweep_N, figure_N = 99, 199
        t_sweep, t_fig = 2e6, 4e6
        betas, steady_above = _QUICK_BETAS, 1.0
        note = (
            "quick: Fig. 5(b) on N = 99 chains to t = 2e6, Figs. 5(a), 6, 7, 8 on N = 199 chains "
            "to t = 4e6 (the paper: N = 399 to t = 2e7)"
        )
    else:  # tiny
        sweep_N = figure_N = 19
        t_sweep = t_fig = 4e4
        betas, steady_above = (0.2, 1.0, 1.5), 1.0
        note = "tiny: tiny chains for tests; the numbers mean nothing"
    common = {
        **paper_parameters("N", "beta"),
        # A chain loads in about L_ss / V: average and count events over the second half only.
        "t_end_by_N": {str(sweep_N): t_sweep, str(figure_N): t_fig},
        "average_fraction": 0.5,
        "sample_interval": 100.0 if mode != "tiny" else 10.0,
        "until_steady": UNTIL_STEADY,
        "until_steady_above": steady_above,
        "profile_betas": [1.0],
        "profile_N": figure_N,
        "profile_window": 20.0,
        "profile_min_fraction": 0.25,
        "sweep_N": sweep_N,
        "figure_N": figure_N,
    }
    # The runs of Figs. 5(a), 6, 7 (beta = 1) and 8 (beta = 0.2) first, then the Fig. 5(b) sweep from
    # the largest beta down, sharing a run where N agrees: the longest runs start first.
    points = [{"N": figure_N, "beta": b} for b in (1.0, 0.2)]
    points += [p for b in sorted(betas, reverse=True) if (p := {"N": sweep_N, "beta": b}) not in points]
    return Study("figs5-8", mode, common, tuple(points), note=note)


def chain_point_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """One chain run of eq. (4) for Figs. 5-8, as a task of :func:`stickslip.experiments.sweep.run_sweep`.

    ``point`` holds N and beta merged with the study's shared settings (:func:`build`). Runs at
    beta above ``until_steady_above`` stop once the chain slides steadily; the runs at N =
    ``profile_N`` and beta in ``profile_betas`` also store the displacement over windows of
    ``profile_window`` for Fig. 6. The run checkpoints and resumes in ``point_dir``
    (:func:`stickslip.experiments.sweep.run_chain_point`). Returns the run's summary with <L> and
    its batch-means error (Fig. 5b) and the final state ("steady sliding" or "stick-slip", section 3).
    """
    from stickslip.analysis.stats.chain_runs import run_summary
    from stickslip.experiments.sweep import run_chain_point

    params, t_end, options = point_settings(point)
    run = run_chain_point(params, t_end, point_dir, **options)
    return {**run_summary(run, params, options["average_from"], UNTIL_STEADY), "t_end_requested": t_end}


def check(cfg: dict[str, Any]) -> None:
    """Refuse a chain run whose parameters or run length the model refuses."""
    point_settings(cfg)


def load(spec: Study, table: pd.DataFrame, points_dir: Path) -> Results | None:
    """The chain runs (each read from its folder when first asked for) and their analysis
    (:func:`stickslip.analysis.stats.chain_runs.chain_analysis`); None unless every run finished."""
    import pandas as pd

    from stickslip.analysis.stats.chain_runs import chain_analysis
    from stickslip.experiments.sweep import point_name
    from stickslip.run.driver import load_run

    if len(table) < len(spec.points):
        return None
    # as the table reads back from JSON; the final state of each run is its task's
    summary = {"points": table_records(table)}
    table = pd.DataFrame(summary["points"])

    @functools.cache
    def get(N: int, beta: float):
        """The full run at (N, beta), read from its folder when first asked for."""
        return load_run(points_dir / point_name({"N": int(N), "beta": float(beta)}))

    wall = float(np.nansum(table["wall_seconds"].to_numpy(dtype=float)))
    data = {"table": table, "run": get}
    outcome = Outcome(dict(spec.common), points_dir, data, summary, bool(table["reused"].all()), wall)
    return Results({"chain-runs": outcome}, chain_analysis(outcome), spec.mode)


def findings(spec: Study, results: Results | None) -> dict[str, Any]:
    """The rows of section 3 and Figs. 5-8 (:func:`stickslip.report.rows.chain_rows`), and one
    statement per row."""
    from stickslip.report.rows import chain_rows, findings_of

    return findings_of(chain_rows(results.outcomes["chain-runs"], results.analysis, results.mode) if results else None)


def figures(spec: Study, results: Results | None, page_dir: Path) -> list[tuple]:
    """Figs. 5-8, with their data beside them (:func:`stickslip.plotting.figures.chain_figures`)."""
    from stickslip.plotting.figures import chain_figures
    from stickslip.report import commands

    if not results:
        return []
    return chain_figures(results.outcomes["chain-runs"], results.analysis, page_dir, results.mode, commands)


def describe() -> str:
    """The text of ``stickslip study figs5-8 --help`` (section 3 of the paper)."""
    quick, full = build("quick"), build("full")
    return (
        "Section 3 of the paper, one of the two studies of `stickslip reproduce`: chain runs of eq. (4) "
        "from the paper's initial state, each a point on Dask: the final state and <L> against beta "
        "(Fig. 5b), and at beta = 1 and 0.2 the snapshot, the rupture fronts and the slip sizes (Figs. "
        f"5a, 6, 7, 8). Grid: --quick {quick.note.split(': ', 1)[1]} ({len(quick.points)} runs, one to "
        f"two minutes on two cores); --full: the paper's chains, N = 399 to t = 2e7, at {len(full.points)} "
        "values of beta (hours on two cores; run again to resume). "
        "Outputs in DIR/figs5-8/: fig5a, fig5b, fig6, fig7, fig8 (PNG, PDF, "
        "their data), table.parquet and table.csv (one row per run: final state, <L>, events), "
        "study.json (the paper's stated numbers of section 3 against ours), index.html."
    )


def _stated_numbers(*args: Any, **kwargs: Any) -> Any:
    """The paper's stated numbers: :func:`stickslip.report.rows.stated_numbers`, loaded when a
    page is written (listing the studies loads no report)."""
    from stickslip.report.rows import stated_numbers

    return stated_numbers(*args, **kwargs)


DESIGN = Design(
    name="figs5-8",
    summary="section 3 of the paper: chain runs for Figs. 5-8",
    describe=describe,
    build=build,
    task=chain_point_task,
    check=check,
    findings=findings,
    figures=figures,
    columns=("N", "beta", "final_state", "L_mean", "L_err", "L_steady", "n_events", "t_end"),
    tables=_stated_numbers,
    load=load,
    command=reproduce_command,
)
