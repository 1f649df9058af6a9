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

from stickslip.analysis.stats.statistics import (
    choose_s_min,
    fit_power_law,
    front_speed,
    leading_edge_speed,
    pick_front_events,
    time_average,
)
from stickslip.models.params import ChainParams
from stickslip.models.physics import chain_steady_length
from stickslip.run.state import steady_deviation

# choose_s_min lives in stickslip.analysis.stats.statistics; the name is kept importable from here.
__all__ = [
    "stationary_from",
    "stationary_events",
    "spanning_column",
    "run_size_statistics",
    "final_state",
    "choose_s_min",
    "size_statistics",
    "sizes_summary",
    "run_summary",
    "front_speeds",
    "front_statistics",
    "chain_analysis",
    "fig6_start_note",
    "sweep_table",
]


def stationary_from(run) -> float:
    """Start of the stationary window of a chain run (eq. 4 and its relatives): the one rule for
    every slip statistic (``stickslip plot``, ``reproduce`` and ``catalog``; docs/statistics.md).

    The window is the run's own averaging window of <L> (Fig. 5b): events that start at
    t >= ``average_from`` of the run, which is the second half of the run unless the run was
    given another (``stickslip chain --average-from``). A chain loaded from x_i = 0 needs about
    L_ss / V to load (:func:`stickslip.run.state.loading_warnings` says so when the window starts
    earlier); its events before then are the loading, not the stationary state.

    Parameters
    ----------
    run : ChainRun
        A chain run (from ``run_chain`` or ``load_run``).

    Returns
    -------
    float
        The window's start time (model units).
    """
    summary = getattr(run, "summary", {}) or {}
    if summary.get("L_mean_from") is not None:
        return float(summary["L_mean_from"])
    options = run.options
    return float(options.average_from) if options.average_from is not None else float(options.t_end) / 2.0


def stationary_events(run) -> pd.DataFrame:
    """The events of ``run`` in its stationary window (:func:`stationary_from`), in order.

    Parameters
    ----------
    run : ChainRun
        A chain run.

    Returns
    -------
    pandas.DataFrame
        The rows of ``run.events`` with ``t_start`` in the window.
    """
    return run.events[run.events["t_start"] >= stationary_from(run)]


def spanning_column(params: ChainParams) -> str:
    """Which column of the event table says that a slip spans the system, as the drive piece has it.

    A chain pulled at one end (eq. 4) is spanned by an event that reaches its far end: column
    ``max_block`` = N. A plate-driven chain (Burridge-Knopoff, Carlson-Langer) has no far end
    (periodic or not, every block is loaded alike): an event spans it when all N blocks moved,
    column ``n_blocks`` = N.

    Parameters
    ----------
    params : ChainParams
        The model (its drive piece).

    Returns
    -------
    str
        ``"max_block"`` or ``"n_blocks"``.
    """
    return "n_blocks" if params.drive_piece.leaf_spring else "max_block"


def run_size_statistics(run, *, small_only: bool, seed: int = 0, bootstrap: int = 200) -> dict[str, Any]:
    """:func:`size_statistics` of a run's stationary events (Figs. 7, 8), as ``plot``, ``reproduce``
    and ``catalog`` all compute it: the window of :func:`stationary_from`, spanning events by
    :func:`spanning_column`.

    Parameters
    ----------
    run : ChainRun
        A chain run.
    small_only : bool
        Fit below the smallest spanning event (Fig. 8) rather than over the whole range (Fig. 7).
    seed : int
        Seed of the bootstrap.
    bootstrap : int
        Bootstrap resamples of the error of tau.

    Returns
    -------
    dict
        :func:`size_statistics`'s (``fit``, a
        :class:`~stickslip.analysis.stats.statistics.PowerLawFit`, the spanning events and the excess of
        large events) with ``t_from`` (start of the window) and ``spanning``.

    Raises
    ------
    ValueError
        When the window holds no event with S > 0.

    Examples
    --------
    >>> import stickslip
    >>> from stickslip.analysis.stats.chain_runs import run_size_statistics
    >>> run = stickslip.run_chain(stickslip.chain_params(N=12), 6e4)
    >>> fit = run_size_statistics(run, small_only=False, bootstrap=0)["fit"]
    >>> 1.0 < fit.tau < 3.0 and fit.n <= fit.n_total
    True
    """
    events = stationary_events(run)
    S = events["S"].to_numpy(dtype=float)
    if not np.any(np.isfinite(S) & (S > 0)):
        raise ValueError(f"no slip with S > 0 at t >= {stationary_from(run):g} (the stationary window)")
    spanning = spanning_column(run.params)
    out = size_statistics(
        events, run.params.N, small_only=small_only, seed=seed, spanning=spanning, bootstrap=bootstrap
    )
    return {**out, "t_from": stationary_from(run), "spanning": spanning}


def run_summary(run, params: ChainParams, average_from: float, tolerance: float) -> dict[str, Any]:
    """The summary of one chain run of Figs. 5-8 (``stickslip reproduce``): the run's own with the
    events after ``average_from``, the batch-means error of <L> (Fig. 5b; zero for a run stopped
    at steady sliding) and the final state (section 3, :func:`final_state`).

    Parameters
    ----------
    run : ChainRun
        The run.
    params : ChainParams
        Its model.
    average_from : float
        Start of the averaging window of <L>.
    tolerance : float
        Largest deviation from steady sliding taken as steady.

    Returns
    -------
    dict
        The run's summary with ``n_events_late``, ``t_last_event``, ``L_err``, ``final_state`` and
        ``steady_deviation_final``.
    """
    s = dict(run.summary)
    s["n_events_late"] = int((run.events["t_start"] >= average_from).sum())
    s["t_last_event"] = float(run.events["t_end"].max()) if len(run.events) else None
    if s.get("stopped_early", False):
        s["L_err"] = 0.0
    else:
        try:
            s["L_err"] = time_average(run.samples["L"], average_from).stderr
        except ValueError:
            s["L_err"] = math.nan
    s["final_state"], s["steady_deviation_final"] = final_state(s, run.state, params, tolerance)
    return s


def final_state(summary: dict[str, Any], state, params: ChainParams, tolerance: float) -> tuple[str, float]:
    """The final state of a chain run (sec. 3): 'steady sliding', 'stick-slip' or 'sliding, not yet steady'.

    Steady sliding: the run stopped there (``until_steady``), or its final state is within
    ``tolerance`` of it (:func:`stickslip.run.state.steady_deviation`; ``stickslip reproduce``
    uses :data:`stickslip.models.physics.UNTIL_STEADY`), which for beta > 1 it never leaves.
    Otherwise stick-slip if events happened in the averaged second half or some block is stopped
    at the end.

    Parameters
    ----------
    summary : dict
        The run's summary (``stopped_early``, ``n_events_late``, ``n_moving``).
    state : ChainState
        Its final state.
    params : ChainParams
        Its model.
    tolerance : float
        Largest deviation from steady sliding taken as steady.

    Returns
    -------
    tuple of (str, float)
        The state and the final deviation from steady sliding.
    """
    deviation = steady_deviation(state, params)
    if summary.get("stopped_early") or deviation <= tolerance:
        return "steady sliding", deviation
    if summary.get("n_events_late", 0) > 0 or summary["n_moving"] < params.N:
        return "stick-slip", deviation
    return "sliding, not yet steady", deviation


def size_statistics(
    events: pd.DataFrame, N: int, *, small_only: bool, seed: int = 0, spanning: str = "max_block", bootstrap: int = 200
) -> dict[str, Any]:
    """Slip-size statistics of one chain run for Fig. 7 (beta = 1) or Fig. 8 (beta = 0.2).

    The events that span the system set the largest sizes. With ``small_only`` (Fig. 8, "about
    1.6 for small S") the power law is fitted below the smallest spanning event, s_span; otherwise
    (Fig. 7) up to the largest S, with the cut-off in the likelihood. s_min is the default of
    :func:`~stickslip.analysis.stats.statistics.fit_power_law`
    (:func:`~stickslip.analysis.stats.statistics.choose_s_min`, least KS distance).

    Parameters
    ----------
    events : pandas.DataFrame
        The event table (``S`` and the ``spanning`` column), usually the stationary window's.
    N : int
        Blocks of the chain.
    small_only : bool
        Fit below s_span (Fig. 8) or over the whole range (Fig. 7).
    seed : int
        Seed of the bootstrap.
    spanning : str
        Which events span the system: ``"max_block"`` (they reach block N: the end-driven chain
        of eq. 4) or ``"n_blocks"`` (all N blocks moved: the periodic Carlson-Langer chain, which
        has no far end).
    bootstrap : int
        Bootstrap resamples of the error of tau.

    Returns
    -------
    dict
        ``fit`` (:class:`~stickslip.analysis.stats.statistics.PowerLawFit`), ``n_events``,
        ``n_spanning``, ``s_span``, ``S_max``, ``largest_reaches_N``, and ``excess``: the number of
        events with S >= s_span (``observed``) over the number the fitted power law, continued
        without cut-off beyond s_span, predicts for them (``expected``); the paper's "excess of
        large events" at beta = 0.2 is > 1.
    """
    if spanning not in ("max_block", "n_blocks"):
        raise ValueError(f"spanning must be 'max_block' or 'n_blocks' (got {spanning!r})")
    S = events["S"].to_numpy(dtype=float)
    S = S[np.isfinite(S) & (S > 0)]
    span_rows = events[events[spanning] >= N]
    s_span = float(span_rows["S"].min()) if len(span_rows) else math.nan
    s_max = s_span if (small_only and math.isfinite(s_span)) else float(S.max())
    fit = fit_power_law(S, s_max=s_max, bootstrap=bootstrap, seed=seed)
    s_min = fit.s_min
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


def _sizes_or_none(run, *, small_only: bool) -> dict[str, Any] | None:
    """:func:`run_size_statistics`, or None where the sizes have no power-law fit."""
    try:
        return run_size_statistics(run, small_only=small_only)
    except ValueError:
        return None


def front_speeds(run, N: int, t_from: float) -> pd.DataFrame:
    """Per-event rupture-front speeds of every event after ``t_from`` that reached block N (Fig. 6).

    Two definitions side by side: ``c_first_move``, the least-squares slope of block against
    first-move time over the far half (:func:`~stickslip.analysis.stats.statistics.front_speed`), and
    ``c_leading_edge``, the slope of the leading edge of the Delta x_i windows against window
    end (:func:`~stickslip.analysis.stats.statistics.leading_edge_speed`).

    Parameters
    ----------
    run : ChainRun
        A chain run (its ``first_move`` and ``profiles``).
    N : int
        The block an event must reach.
    t_from : float
        Earliest start time of the events.

    Returns
    -------
    pandas.DataFrame
        One row per event: ``event``, ``t_start``, ``S``, ``c_first_move`` and ``c_leading_edge``
        (blocks per time unit; NaN where the event has no stored profiles or fewer than two
        windows in the far half).
    """
    events = run.events[(run.events["t_start"] >= t_from) & (run.events["max_block"] >= N)]
    groups = {int(e): g for e, g in run.first_move.groupby("event")}
    profiles = run.profiles if run.profiles.sizes.get("profile_row") else None
    stored = set(np.unique(profiles["profile_event"].values).tolist()) if profiles is not None else set()
    rows = []
    for r in events.itertuples():
        e = int(r.event)
        c_fm = c_edge = math.nan
        fm = groups.get(e)
        if fm is not None:
            try:
                c_fm = front_speed(fm, e).speed
            except ValueError:
                pass
        if e in stored:
            try:
                c_edge = leading_edge_speed(profiles, e).speed
            except ValueError:
                pass
        rows.append(
            {"event": e, "t_start": float(r.t_start), "S": float(r.S), "c_first_move": c_fm, "c_leading_edge": c_edge}
        )
    return pd.DataFrame(rows, columns=["event", "t_start", "S", "c_first_move", "c_leading_edge"])


def front_statistics(run, N: int, t_from: float) -> dict[str, Any]:
    """Rupture fronts for Fig. 6: the picked large and intermediate events and all spanning ones.

    The picks (:func:`stickslip.analysis.stats.statistics.pick_front_events`) are made among the events
    after ``t_from`` whose displacement profiles were stored.

    Parameters
    ----------
    run : ChainRun
        A chain run with ``profiles``.
    N : int
        The block a spanning event reaches.
    t_from : float
        Earliest start time of the events.

    Returns
    -------
    dict
        ``fronts`` (the picks' :class:`~stickslip.analysis.stats.statistics.FrontSpeed`), their
        ``labels`` and ``edges`` (leading-edge fits, None where there is none), ``picks``,
        ``per_event`` (:func:`front_speeds`), ``speeds`` (its first-move column without NaN),
        ``median_speed`` and ``quartiles`` of them, and ``t_first_span`` (start of the run's
        first event that reached block N; NaN if none).
    """
    events = run.events[run.events["t_start"] >= t_from]
    prof = run.profiles
    with_profiles = set(np.unique(prof["profile_event"].values).tolist()) if prof.sizes.get("profile_row") else set()
    candidates = events[events["event"].isin(with_profiles)]
    picks = pick_front_events(candidates, N) if len(candidates) else candidates.assign(kind=pd.Series(dtype=str))
    groups = {int(e): g for e, g in run.first_move.groupby("event")}
    fronts, labels, edges = [], [], []
    for row in picks.itertuples():
        fm = groups.get(int(row.event))
        if fm is None:
            continue
        try:
            fronts.append(front_speed(fm, int(row.event)))
        except ValueError:
            continue
        try:
            edges.append(leading_edge_speed(run.profiles, int(row.event)))
        except ValueError:
            edges.append(None)
        labels.append(f"{row.kind} event ($S = {row.S:.4g}$, {row.n_blocks} blocks)")
    per_event = front_speeds(run, N, t_from)
    speeds = per_event["c_first_move"].to_numpy(dtype=float)
    speeds = speeds[np.isfinite(speeds)]
    spanning = run.events[run.events["max_block"] >= N]
    return {
        "fronts": fronts,
        "labels": labels,
        "edges": edges,
        "picks": picks,
        "per_event": per_event,
        "speeds": speeds,
        "median_speed": float(np.median(speeds)) if speeds.size else math.nan,
        "quartiles": [float(q) for q in np.quantile(speeds, [0.25, 0.75])] if speeds.size else [math.nan] * 2,
        "t_first_span": float(spanning["t_start"].min()) if len(spanning) else math.nan,
    }


def fig6_start_note(a: dict[str, Any]) -> str:
    """Why the paper's event times of Fig. 6 (t ~ 19100, 40400) cannot come from its stated start.

    From x_i(0) = 0 the pulled end must first stretch the chain by about its steady length
    L_ss = (c/K) N (N - 1) / 2 before an event can reach block N, which at pulling speed V takes
    t ~ L_ss / V (8.0e6 for N = 399).

    Parameters
    ----------
    a : dict
        :func:`chain_analysis` of the experiment.

    Returns
    -------
    str
        The note, with the numbers of the paper's N = 399 and of this run.
    """
    p = a["run1"].params
    p399 = p.replace(N=399)
    t_span = a["fronts"].get("t_first_span", float("nan"))
    here = (
        f"in this run (N = {p.N}) the first event that reached block N started at t = {t_span:.3g} "
        f"(L_ss / V = {chain_steady_length(p) / p.V:.3g})"
        if np.isfinite(t_span)
        else f"in this run (N = {p.N}) no event reached block N"
    )
    return (
        "The paper's event times (t ~ 19100 and 40400) cannot come from its stated start x_i(0) = 0: the "
        f"chain must first stretch by about L_ss = (c/K) N (N - 1) / 2 = {chain_steady_length(p399):.4g} "
        f"(N = 399), which at V = {p.V:g} takes t ~ {chain_steady_length(p399) / p.V:.2g}; {here}."
    )


def chain_analysis(outcome) -> dict[str, Any]:
    """Everything Figs. 5-8 and their rows need from the chain runs of ``stickslip reproduce``.

    Parameters
    ----------
    outcome : Outcome
        The :class:`~stickslip.outcome.Outcome` of the chain runs: its settings name the
        sweep's N, the figures' N and their run length.

    Returns
    -------
    dict
        The sweep's ``table``, the runs at beta = 1 and 0.2 (``run1``, ``run02``), their
        stationary events and size statistics (``sizes1``, ``sizes02``; None with fewer than 10
        events), the rupture fronts (``fronts``), ``t_from``, ``sweep_N``, ``figure_N``, ``t_fig``.
    """
    opts = outcome.settings
    table = outcome.data["table"]
    sweep_N, fig_N = int(opts["sweep_N"]), int(opts["figure_N"])
    t_fig = float(opts["t_end_by_N"][str(fig_N)])
    run1 = outcome.data["run"](fig_N, 1.0)
    run02 = outcome.data["run"](fig_N, 0.2)
    # The stationary window of every slip statistic (stationary_from): the run's <L> window.
    t_from = stationary_from(run1)
    out: dict[str, Any] = {"table": table, "sweep_N": sweep_N, "figure_N": fig_N, "t_fig": t_fig, "t_from": t_from}
    out["run1"], out["run02"] = run1, run02
    ev1, ev02 = stationary_events(run1), stationary_events(run02)
    out["events1"], out["events02"] = ev1, ev02
    out["sizes1"] = _sizes_or_none(run1, small_only=False) if len(ev1) >= 10 else None
    out["sizes02"] = _sizes_or_none(run02, small_only=True) if len(ev02) >= 10 else None
    out["fronts"] = front_statistics(run1, fig_N, t_from)
    return out


def sweep_table(a: dict[str, Any]) -> pd.DataFrame:
    """The runs at the sweep's N (Fig. 5b), by beta, with the columns the figure and its row show.

    Parameters
    ----------
    a : dict
        :func:`chain_analysis` of the experiment.

    Returns
    -------
    pandas.DataFrame
        One row per beta: ``beta``, ``N``, ``L_mean``, ``L_err``, ``L_steady``, ``final_state``,
        ``n_events``, ``n_events_late``, ``t_steady``, ``stopped_early``, ``t_end``,
        ``wall_seconds``.
    """
    t = a["table"]
    t = t[t["N"] == a["sweep_N"]].sort_values("beta")
    cols = [
        "beta",
        "N",
        "L_mean",
        "L_err",
        "L_steady",
        "final_state",
        "n_events",
        "n_events_late",
        "t_steady",
        "stopped_early",
        "t_end",
        "wall_seconds",
    ]
    return t[[c for c in cols if c in t.columns]].reset_index(drop=True)


def sizes_summary(
    run, t_from: float, *, spanning: str = "max_block", seed: int = 0, bootstrap: int = 200
) -> dict[str, Any]:
    """The slip-size exponent tau of one chain run (Figs. 7, 8) over its events from ``t_from``.

    Parameters
    ----------
    run : ChainRun
        The run.
    t_from : float
        Events that start before it (the transient) are left out.
    spanning, seed, bootstrap
        As :func:`size_statistics` takes them: what counts as a spanning event, the seed and the
        number of the bootstrap resamples.

    Returns
    -------
    dict
        ``t_from``, ``n_events``, ``spanning`` and, with 20 events or more, tau of the truncated
        power law below the smallest spanning event (s_min by least KS distance) with its
        bootstrap and Fisher errors, the fitted range, the KS distance and the excess of great
        events (observed and expected); else tau = NaN and an ``error_note``.
    """
    events = run.events[run.events["t_start"] >= t_from]
    out: dict[str, Any] = {"t_from": t_from, "n_events": int(len(events)), "spanning": spanning}
    if len(events) < 20:
        out.update(tau=math.nan, tau_err=math.nan, error_note=f"only {len(events)} events after t = {t_from:g}")
        return out
    try:
        st = size_statistics(events, run.params.N, small_only=True, seed=seed, spanning=spanning, bootstrap=bootstrap)
    except ValueError as exc:  # no power law on the range: the row says why
        out.update(tau=math.nan, tau_err=math.nan, error_note=str(exc))
        return out
    fit = st["fit"]
    out.update(
        tau=fit.tau,
        tau_err=fit.tau_err,
        tau_err_fisher=fit.tau_err_fisher,
        s_min=fit.s_min,
        s_max=fit.s_max,
        n_fit=fit.n,
        ks_distance=fit.ks_distance,
        n_spanning=st["n_spanning"],
        s_span=st["s_span"],
        S_max=st["S_max"],
        excess=st["excess"],
        observed=st["observed"],
        expected=st["expected"],
    )
    return out
