"""Analysis of the chain runs of eq. (4) behind Figs. 5-8 and the final state of section 3.

The final state of a run (steady sliding or stick-slip, section 3), the slip-size statistics
of Figs. 7 and 8 (a truncated power law with s_min by least KS distance, and the excess of
large events), the rupture fronts and their speeds (Fig. 6), the table of <L> against beta
(Fig. 5b), and :func:`chain_analysis`, which gathers all of them from one experiment's runs.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pandas as pd

from stickslip.analysis.statistics import fit_power_law, front_speed, pick_front_events
from stickslip.models.params import ChainParams
from stickslip.run.state import steady_deviation


def final_state(summary: dict[str, Any], state, params: ChainParams, tolerance: float) -> tuple[str, float]:
    """The final state of a chain run (sec. 3): 'steady sliding', 'stick-slip' or 'sliding, not yet steady'.

    Steady sliding: the run stopped there (``until_steady``), or its final state is within
    ``tolerance`` of it (:func:`stickslip.run.state.steady_deviation`; ``stickslip reproduce``
    uses :data:`stickslip.experiments.specs.UNTIL_STEADY`), which for beta > 1 it never leaves. Otherwise stick-slip if events happened in the averaged
    second half or some block is stopped at the end. Returns the state and the final deviation.
    """
    deviation = steady_deviation(state, params)
    if summary.get("stopped_early") or deviation <= tolerance:
        return "steady sliding", deviation
    if summary.get("n_events_late", 0) > 0 or summary["n_moving"] < params.N:
        return "stick-slip", deviation
    return "sliding, not yet steady", deviation


def choose_s_min(S: np.ndarray, s_max: float, *, max_quantile: float = 0.9, n_candidates: int = 40) -> float:
    """Lower end of the power-law fit of Figs. 7, 8: the s_min with the least KS distance.

    The candidates are ``n_candidates`` log-spaced values from the smallest S to its
    ``max_quantile`` quantile (and below ``s_max``); each gets the truncated maximum-likelihood
    fit of :func:`stickslip.analysis.statistics.fit_power_law` on [s_min, s_max], and the one whose
    fitted CDF is closest to the data (Kolmogorov-Smirnov) wins (the recipe of Clauset, Shalizi
    and Newman, SIAM Review 51, 661 (2009), with the upper cut-off kept).
    """
    S = np.asarray(S, dtype=float)
    S = S[np.isfinite(S) & (S > 0)]
    hi = min(float(np.quantile(S, max_quantile)), s_max / 10.0)
    lo = float(S.min())
    if not hi > lo:
        return lo
    best, best_ks = lo, math.inf
    for s_min in np.geomspace(lo, hi, n_candidates):
        if np.count_nonzero((S >= s_min) & (S <= s_max)) < 50:
            break
        fit = fit_power_law(S, s_min=float(s_min), s_max=s_max, bootstrap=0)
        if math.isfinite(fit.ks_distance) and fit.ks_distance < best_ks:
            best, best_ks = float(s_min), fit.ks_distance
    return best


def size_statistics(events: pd.DataFrame, N: int, *, small_only: bool, seed: int = 0,
                    spanning: str = "max_block", bootstrap: int = 200) -> dict[str, Any]:
    """Slip-size statistics of one chain run for Fig. 7 (beta = 1) or Fig. 8 (beta = 0.2).

    The events that reach block N ("system-spanning") set the largest sizes. With
    ``small_only`` (Fig. 8, "about 1.6 for small S") the power law is fitted below the smallest
    system-spanning event, s_span; otherwise (Fig. 7) up to the largest S, with the cut-off in
    the likelihood. s_min is chosen by :func:`choose_s_min`. ``excess`` is the number of events
    with S >= s_span over the number the fitted power law, continued without cut-off beyond
    s_span, predicts for them (the paper's "excess of large events" at beta = 0.2 is > 1).

    ``spanning`` says which events span the system: "max_block" (they reach block N: the
    end-driven chain of eq. 4) or "n_blocks" (all N blocks moved: the periodic Carlson-Langer
    chain, which has no far end). ``observed`` and ``expected`` are the two counts of the excess.
    """
    if spanning not in ("max_block", "n_blocks"):
        raise ValueError(f"spanning must be 'max_block' or 'n_blocks' (got {spanning!r})")
    S = events["S"].to_numpy(dtype=float)
    S = S[np.isfinite(S) & (S > 0)]
    span_rows = events[events[spanning] >= N]
    s_span = float(span_rows["S"].min()) if len(span_rows) else math.nan
    s_max = s_span if (small_only and math.isfinite(s_span)) else float(S.max())
    s_min = choose_s_min(S, s_max)
    fit = fit_power_law(S, s_min=s_min, s_max=s_max, bootstrap=bootstrap, seed=seed)
    excess = expected = math.nan
    observed = 0
    if math.isfinite(s_span) and fit.tau > 1.0:
        n_above_min = np.count_nonzero(S >= s_min)
        expected = n_above_min * (s_span / s_min) ** (1.0 - fit.tau)
        observed = np.count_nonzero(S >= s_span)
        excess = observed / expected if expected > 0 else math.nan
    largest = events.loc[events["S"].idxmax()] if len(events) else None
    return {
        "fit": fit,
        "n_events": int(len(events)),
        "n_spanning": int(len(span_rows)),
        "s_span": s_span,
        "S_max": float(S.max()) if S.size else math.nan,
        "largest_reaches_N": bool(largest is not None and int(largest[spanning]) >= N),
        "excess": excess,
        "observed": int(observed),
        "expected": float(expected),
    }


def front_statistics(run, N: int, t_from: float) -> dict[str, Any]:
    """Rupture fronts for Fig. 6: the picked large and intermediate events and all spanning ones.

    The picks (:func:`stickslip.analysis.statistics.pick_front_events`) are made among the events after
    ``t_from`` whose displacement profiles were stored. ``speeds`` are the front speeds
    (:func:`stickslip.analysis.statistics.front_speed`, far half of the chain) of every event after
    ``t_from`` that reached block N; their median is the number compared with the paper's c.
    """
    events = run.events[run.events["t_start"] >= t_from]
    with_profiles = set(np.unique(run.profiles["event"].values).tolist()) if run.profiles.sizes.get("row") else set()
    candidates = events[events["event"].isin(with_profiles)]
    picks = pick_front_events(candidates, N) if len(candidates) else candidates.assign(kind=pd.Series(dtype=str))
    groups = {int(e): g for e, g in run.first_move.groupby("event")}
    fronts, labels = [], []
    for row in picks.itertuples():
        fm = groups.get(int(row.event))
        if fm is None:
            continue
        try:
            fronts.append(front_speed(fm, int(row.event)))
        except ValueError:
            continue
        labels.append(f"{row.kind} event (S = {row.S:.4g}, {row.n_blocks} blocks)")
    speeds = []
    for e in events.loc[events["max_block"] >= N, "event"]:
        fm = groups.get(int(e))
        if fm is None:
            continue
        try:
            speeds.append(front_speed(fm, int(e)).speed)
        except ValueError:
            continue
    speeds = np.asarray(speeds, dtype=float)
    return {
        "fronts": fronts,
        "labels": labels,
        "picks": picks,
        "speeds": speeds,
        "median_speed": float(np.median(speeds)) if speeds.size else math.nan,
        "quartiles": [float(q) for q in np.quantile(speeds, [0.25, 0.75])] if speeds.size else [math.nan] * 2,
    }


def chain_analysis(outcome) -> dict[str, Any]:
    """Everything Figs. 5-8 and their rows need from the chain runs of one experiment.

    ``outcome`` is the :class:`~stickslip.experiments.specs.Outcome` of a ``chain_runs``
    experiment: its options name the sweep's N, the figures' N and their run length.
    """
    opts = outcome.experiment.options
    table = outcome.data["table"]
    sweep_N, fig_N = int(opts["sweep_N"]), int(opts["figure_N"])
    t_fig = float(opts["t_end_by_N"][str(fig_N)])
    t_from = float(opts["average_fraction"]) * t_fig
    out: dict[str, Any] = {"table": table, "sweep_N": sweep_N, "figure_N": fig_N, "t_fig": t_fig,
                           "t_from": t_from}
    run1 = outcome.data["run"](fig_N, 1.0)
    run02 = outcome.data["run"](fig_N, 0.2)
    out["run1"], out["run02"] = run1, run02
    ev1 = run1.events[run1.events["t_start"] >= t_from]
    ev02 = run02.events[run02.events["t_start"] >= t_from]
    out["events1"], out["events02"] = ev1, ev02
    out["sizes1"] = size_statistics(ev1, fig_N, small_only=False) if len(ev1) >= 10 else None
    out["sizes02"] = size_statistics(ev02, fig_N, small_only=True) if len(ev02) >= 10 else None
    out["fronts"] = front_statistics(run1, fig_N, t_from)
    return out


def sweep_table(a: dict[str, Any]) -> pd.DataFrame:
    """The runs at the sweep's N (Fig. 5b), by beta, with the columns the figure and its row show."""
    t = a["table"]
    t = t[t["N"] == a["sweep_N"]].sort_values("beta")
    cols = ["beta", "N", "L_mean", "L_err", "L_steady", "final_state", "n_events", "n_events_late",
            "t_steady", "stopped_early", "t_end", "wall_seconds"]
    return t[[c for c in cols if c in t.columns]].reset_index(drop=True)
