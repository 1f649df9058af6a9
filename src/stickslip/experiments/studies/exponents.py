"""``stickslip study exponents``: the slip-size exponent tau of eq. (4) (Figs. 7, 8) against beta,
and of Carlson-Langer for comparison (docs/studies/exponents.md).

Each point is one chain run and the truncated power law of its slip sizes below the smallest
spanning event (:func:`stickslip.experiments.studies.chain_point.sizes_task`).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from stickslip.experiments.studies import Design, Study, finite, short
from stickslip.experiments.studies.chain_point import check_point, sizes_task, t_end_of
from stickslip.models.presets import PRESETS, is_paper

if TYPE_CHECKING:  # loaded where used, so that listing the studies loads no heavy module
    import pandas as pd

__all__ = ["DESIGN"]


def build(mode: str) -> Study:
    """eq. (4) at one N for several beta over the second half of 5 loading times, and
    Carlson-Langer at its standard parameters after the first fifth of its run."""
    if mode == "tiny":
        N, betas, loads, cl = 19, (0.2, 1.0), 5.0, {"N": 16, "t_end": 2000.0}
    elif mode == "quick":
        N, betas, loads, cl = 199, (0.2, 0.4, 0.6, 0.8, 1.0), 5.0, {"N": 100, "t_end": 1e5}
    else:
        N, betas, loads, cl = 399, (0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0), 5.0, {"N": 100, "t_end": 1e6}
    t_end = t_end_of(N, loads)
    points = [{"model": "sakaguchi", "N": N, "beta": b, "t_end": t_end} for b in betas]
    family = {"start": "rest", "perturbation": 0.01, "seed": 0, "spanning": "n_blocks", "transient": 0.2}
    points.append({"model": "carlson-langer", **cl, **family})
    common = {
        "start": "paper",
        "average_fraction": 0.5,
        "n_samples": 2000,
        "analysis": "sizes",
        "spanning": "max_block",
        "bootstrap": 200,
    }
    note = (
        f"{mode}: eq. (4) at N = {N} to t = {t_end:g} ({loads:g} loading times), events of the "
        f"second half; Carlson-Langer (standard parameters, N = {cl['N']}, periodic) to "
        f"t = {cl['t_end']:g}, events after the first fifth"
    )
    return Study("exponents", mode, common, tuple(points), note=note)


def findings(spec: Study, table: pd.DataFrame) -> dict[str, Any]:
    """tau with its error, the fitted range and the excess of great events of every point, and
    the least-squares change of tau with beta for eq. (4)."""
    out: dict[str, Any] = {"statements": []}
    say = out["statements"].append
    for r in table.sort_values(["model", "beta"]).itertuples():
        label = PRESETS[r.model].point_label(r.beta, r.N, with_N=False)
        say(
            f"{label}: tau = {short(r.tau)} +- {short(getattr(r, 'tau_err', math.nan), 2)} on S in "
            f"[{short(getattr(r, 's_min', math.nan))}, {short(getattr(r, 's_max', math.nan))}] "
            f"({short(getattr(r, 'n_fit', math.nan))} of {r.n_events} events), great-event excess "
            f"{short(getattr(r, 'excess', math.nan))} ({getattr(r, 'observed', 'n/a')} observed / "
            f"{short(getattr(r, 'expected', math.nan))} expected)."
        )
    ok = table[table["model"].map(is_paper) & np.isfinite(table["tau"].astype(float))].sort_values("beta")
    if len(ok) > 1:
        slope = np.polyfit(ok["beta"].astype(float), ok["tau"].astype(float), 1)[0]
        say(
            f"eq. (4): tau changes by {slope:+.2f} per unit beta between beta = {ok['beta'].min():g} and "
            f"{ok['beta'].max():g} (least squares)."
        )
    return out


def figures(spec: Study, table: pd.DataFrame, page_dir: Path) -> list[tuple[str, Any, str]]:
    """tau and the great-event excess against beta (:func:`stickslip.plotting.studies.exponents_figure`),
    and the slip-size densities of Carlson-Langer beside eq. (4) at the smallest beta (Fig. 8's
    0.2), each with its power law (:func:`stickslip.plotting.family.family_sizes`)."""
    from stickslip.plotting.family import family_sizes
    from stickslip.plotting.studies import exponents_figure

    caption = (
        "Slip-size exponent tau (truncated power law below the smallest spanning event, "
        "bootstrap errors) and great-event excess against beta; Carlson-Langer as a band."
    )
    out = [("tau_beta", exponents_figure(table), caption)]
    panels = _family_panels(table, spec.runs_dir(Path(page_dir).parent) / "points")
    if len(panels) == 2:
        caption = (
            "Slip-size density p(S) on logarithmic bins, log-log, of the events after each run's transient. "
            "Dashed: the truncated power-law fit on its range; dotted: the same power law continued; "
            "vertical line: the smallest system-spanning event, with the count of events above it "
            "against the power law's prediction."
        )
        out.append(("family_sizes", family_sizes(panels), caption))
    return out


def _family_panels(table: pd.DataFrame, points: Path) -> list[tuple[str, pd.DataFrame, dict[str, Any]]]:
    """(title, events, statistics) of the relative's run and of eq. (4) at its smallest beta, each
    fitted as its point was (:func:`stickslip.analysis.stats.chain_runs.size_statistics`); none without a fit."""
    from stickslip import io
    from stickslip.analysis.stats.chain_runs import size_statistics

    fitted = table[np.isfinite(table["tau"].astype(float))] if "tau" in table else table.iloc[:0]
    chain = fitted[fitted["model"].map(is_paper)].sort_values("beta")
    rows = [r for _, r in fitted[~fitted["model"].map(is_paper)].iterrows()][:1] + [r for _, r in chain.iterrows()][:1]
    panels = []
    for r in rows:
        events = io.read_table(points / r["point_dir"] / "events.parquet")
        events = events[events["t_start"] >= float(r["t_from"])]
        seed = int(r["seed"]) if finite(r.get("seed")) else 0  # as sizes_task: the point's, else 0
        bootstrap = int(r["bootstrap"]) if finite(r.get("bootstrap")) else 200
        stats = size_statistics(
            events, int(r["N"]), small_only=True, seed=seed, spanning=r["spanning"], bootstrap=bootstrap
        )
        label = ("eq. (4), " if is_paper(r["model"]) else "") + PRESETS[r["model"]].point_label(r["beta"], int(r["N"]))
        panels.append((f"{label}\nevents from t = {float(r['t_from']):.3g} to {float(r['t_end']):.3g}", events, stats))
    return panels


#: The wall time of each mode (``stickslip study --help``, the README).
COST = {"quick": "4 to 5 minutes on two cores", "full": "about 25 minutes on two cores"}


def describe() -> str:
    """The text of ``stickslip study exponents --help``."""
    quick, full = build("quick"), build("full")
    return (
        "Does the slip-size exponent tau of eq. (4) (Figs. 7, 8) change with beta? A truncated power "
        "law below the smallest spanning event, s_min by least KS distance, bootstrap errors, and the "
        "excess of great events; Carlson-Langer as the known power law. "
        f"Grid: --quick {quick.note.split(': ', 1)[1]} ({len(quick.points)} runs, {COST['quick']}"
        f"); --full {full.note.split(': ', 1)[1]} ({len(full.points)} runs, {COST['full']}). "
        "Outputs in DIR/exponents/: table.parquet and table.csv (one row per run: tau, its error, the "
        "fitted range, the excess), tau_beta and family_sizes (Carlson-Langer beside beta = 0.2; PNG, PDF), "
        "study.json, index.html."
    )


DESIGN = Design(
    cost=COST,
    name="exponents",
    summary="slip-size exponent tau against beta, and Carlson-Langer",
    describe=describe,
    build=build,
    task=sizes_task,
    check=check_point,
    findings=findings,
    figures=figures,
    columns=tuple(
        "model N beta tau tau_err s_min s_max n_fit n_events excess observed expected n_spanning S_max t_end".split()
    ),
)
