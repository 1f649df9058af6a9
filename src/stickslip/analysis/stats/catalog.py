"""Slip catalogues of chain runs as seismologists read them (``stickslip catalog``).

:func:`slip_catalog` turns the events of a chain run (eq. 4, or any model of its family) into a
catalogue: per slip its start time, duration, size S, magnitude M = (2/3) log10 S
(:mod:`stickslip.analysis.stats.magnitudes`), epicentre (the block that moved first), extent (the
blocks that moved), reach (the farthest block) and whether it spans the system
(:func:`stickslip.analysis.stats.chain_runs.spanning_column`), over the stationary window of
:func:`stickslip.analysis.stats.chain_runs.stationary_from` that ``plot`` and ``reproduce`` use too.

:func:`catalog_analysis` adds what is read from such a catalogue: the frequency-magnitude
statistics (b-value, completeness, doubly truncated Gutenberg-Richter, the size exponent tau of
Figs. 7, 8 and the relation b = (3/2)(tau - 1)), which distribution the sizes follow
(:mod:`stickslip.analysis.stats.model_comparison`), the recurrence of all and of system-spanning slips
(:mod:`stickslip.analysis.stats.recurrence`) and the moment rate of the largest events whose
displacement profiles the run kept. Every part that cannot be computed says why instead.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from stickslip.analysis.stats import magnitudes as mg
from stickslip.analysis.stats.chain_runs import run_size_statistics, spanning_column, stationary_events, stationary_from
from stickslip.analysis.stats.model_comparison import compare_distributions, power_law_gof
from stickslip.analysis.stats.recurrence import recurrence
from stickslip.models.params import ParameterError, check_number

__all__ = [
    "CATALOG_COLUMNS",
    "CATALOG_DOCS",
    "MIN_EVENTS",
    "Catalog",
    "slip_catalog",
    "moment_rate",
    "catalog_analysis",
    "load_catalog_run",
]

#: Fewest slips with S > 0 in the stationary window for a catalogue's fits.
MIN_EVENTS = 50
#: The most resamples of the bootstrap errors: with 1e5 the error of an error is 0.2%.
MAX_BOOTSTRAP = 100_000
#: The most synthetic catalogues of the goodness of fit: with 1e4, p is known to +-0.005.
MAX_GOF_SIMS = 10_000
#: The most magnitude bins of width dm over the catalogue's magnitudes: the completeness scan
#: fits a b-value at each bin (work growing as the square of their number).
MAX_MAGNITUDE_BINS = 10_000


def check_counts(bootstrap: int, gof_sims: int, names: tuple[str, str] = ("bootstrap", "gof_sims")) -> None:
    """Refuse counts of work that do not end in reasonable time (:data:`MAX_BOOTSTRAP`,
    :data:`MAX_GOF_SIMS`; ParameterError in one line naming them as ``names`` says)."""
    from stickslip.run.budget import check_count

    check_count(names[0], bootstrap, MAX_BOOTSTRAP, "the errors' own errors are then 0.2%; more changes nothing")
    check_count(names[1], gof_sims, MAX_GOF_SIMS, "p is then known to +-0.005; more changes nothing")


def check_magnitude_bins(M: np.ndarray, dm: float) -> None:
    """Refuse a bin ``dm`` that cuts the catalogue's magnitudes into more than
    :data:`MAX_MAGNITUDE_BINS` bins, saying how many and what they would cost."""
    if dm <= 0 or M.size == 0:
        return
    span = float(np.nanmax(M) - np.nanmin(M))
    bins = span / dm + 1
    if bins > MAX_MAGNITUDE_BINS:
        raise ParameterError(
            f"dm = {dm:g} cuts the magnitudes (from {float(np.nanmin(M)):.3g} to {float(np.nanmax(M)):.3g}) into "
            f"{bins:.3g} bins, about {8 * bins / 2**30:.3g} GiB per scan of them and {bins:.3g} scans; "
            f"at most {MAX_MAGNITUDE_BINS} bins: dm >= {span / (MAX_MAGNITUDE_BINS - 1):.2g} here"
        )


CATALOG_COLUMNS = ["event", "t_start", "duration", "S", "magnitude", "epicentre", "extent", "reach", "spans"]
CATALOG_DOCS = {
    "event": "event number of the run (events.parquet column event)",
    "t_start": "start time of the slip, model units",
    "duration": "duration of the slip, model units",
    "S": "slip size S = sum_i (x_i(end) - x_i(start)), model units (Figs. 7, 8)",
    "magnitude": "magnitude M = (2/3) log10 S, the moment-magnitude analogue (docs/statistics.md)",
    "epicentre": "block that moved first (1..N)",
    "extent": "number of blocks that moved",
    "reach": "farthest block that moved (1..N)",
    "spans": "the slip spans the system (end-driven chain: reaches block N; plate-driven: all N blocks moved)",
}


def load_catalog_run(run_dir: str | Path):
    """The chain run of a run directory, for ``stickslip catalog``.

    Parameters
    ----------
    run_dir : str or Path
        A directory written by ``stickslip chain --out`` or ``run.save``.

    Returns
    -------
    ChainRun
        The run (:func:`~stickslip.run.rundir.load_run`).

    Raises
    ------
    ParameterError
        In one line, where the folder holds no whole run.
    """
    from stickslip.run.rundir import RunDirDamaged, load_run, refuse_lattice_run

    run_dir = Path(run_dir)
    if not run_dir.is_dir():
        raise ParameterError(f"{run_dir} is not a directory (a catalogue is read from a chain run directory)")
    try:
        refuse_lattice_run(run_dir, "the catalogue")
    except RunDirDamaged as exc:
        raise ParameterError(str(exc)) from None
    if not (run_dir / "run.json").is_file() or not (run_dir / "events.parquet").is_file():
        raise ParameterError(
            f"{run_dir} is not a chain run directory (no run.json or events.parquet; "
            "write one with stickslip chain --out)"
        )
    try:
        return load_run(run_dir)
    except RunDirDamaged as exc:
        raise ParameterError(str(exc)) from None


def slip_catalog(run) -> pd.DataFrame:
    """The catalogue of a run's slips in its stationary window.

    Parameters
    ----------
    run : ChainRun
        A chain run (eq. 4 or a relative).

    Returns
    -------
    pandas.DataFrame
        One row per slip, the columns :data:`CATALOG_COLUMNS` (described in :data:`CATALOG_DOCS`):
        ``event``, ``t_start``, ``duration``, ``S``, ``magnitude`` = (2/3) log10 S, ``epicentre``,
        ``extent``, ``reach``, ``spans``.
    """
    events = stationary_events(run)
    column = spanning_column(run.params)
    S = events["S"].to_numpy(dtype=np.float64)
    return pd.DataFrame(
        {
            "event": events["event"].to_numpy(dtype=np.int64),
            "t_start": events["t_start"].to_numpy(dtype=np.float64),
            "duration": events["duration"].to_numpy(dtype=np.float64),
            "S": S,
            "magnitude": mg.magnitude(S),
            "epicentre": events["start_block"].to_numpy(dtype=np.int64),
            "extent": events["n_blocks"].to_numpy(dtype=np.int64),
            "reach": events["max_block"].to_numpy(dtype=np.int64),
            "spans": (events[column].to_numpy() >= run.params.N),
        },
        columns=CATALOG_COLUMNS,
    )


def moment_rate(run, catalog: pd.DataFrame, *, largest: int = 5) -> tuple[pd.DataFrame, list[dict[str, Any]], str]:
    """Moment rate of the largest slips with stored displacement profiles (``profile_window``).

    For each window [t, t + W] of an event's profiles the moment rate is sum_i Delta x_i / W, the
    slip rate summed over the blocks (S is the moment up to a constant, so this is the
    moment-rate function up to the same constant); its time integral is the slip the windows
    cover, at most S.

    Parameters
    ----------
    run : ChainRun
        A run with ``profiles``.
    catalog : pandas.DataFrame
        Its catalogue (:func:`slip_catalog`), from which the largest slips are picked.
    largest : int
        How many slips.

    Returns
    -------
    tuple of (pandas.DataFrame, list of dict, str)
        The table (``event``, ``t``: window centre from the slip's start, ``rate``), one summary
        per event (S, covered fraction, peak rate and its time, duration) and, when there is
        nothing to show, why (else an empty string).
    """
    profiles = run.profiles
    if not profiles.sizes.get("profile_row", 0):
        return (
            pd.DataFrame(columns=["event", "t", "rate"]),
            [],
            "no displacement profiles stored (run with --profile-window W)",
        )
    stored = set(np.unique(profiles["profile_event"].values).tolist())
    picks = catalog[catalog["event"].isin(stored)].nlargest(largest, "S")
    if picks.empty:
        return pd.DataFrame(columns=["event", "t", "rate"]), [], "no slip of the stationary window has stored profiles"
    event_of_row = profiles["profile_event"].values
    rows, summaries = [], []
    for r in picks.itertuples():
        sel = np.flatnonzero(event_of_row == r.event)
        t0 = profiles["profile_t"].values[sel]
        t1 = profiles["profile_t_next"].values[sel]
        slip = profiles["profile_dx"].values[sel].sum(axis=1)
        rate = slip / (t1 - t0)
        centre = 0.5 * (t0 + t1) - r.t_start
        rows.append(pd.DataFrame({"event": int(r.event), "t": centre, "rate": rate}))
        k = int(np.argmax(rate))
        summaries.append(
            {
                "event": int(r.event),
                "S": float(r.S),
                "magnitude": float(r.magnitude),
                "duration": float(r.duration),
                "windows": int(sel.size),
                "covered_fraction": float(slip.sum() / r.S) if r.S > 0 else math.nan,
                "peak_rate": float(rate[k]),
                "t_peak": float(centre[k]),
            }
        )
    return pd.concat(rows, ignore_index=True), summaries, ""


def _frequency_magnitude(M: np.ndarray, S: np.ndarray, size_fit, *, dm: float, bootstrap: int, seed: int) -> dict:
    """b-value, completeness, doubly truncated Gutenberg-Richter and their relation to tau."""
    out: dict[str, Any] = {"dm": dm, "definition": "M = (2/3) log10 S", "relation": "b = (3/2)(tau - 1)"}
    try:
        c = mg.completeness(M, dm=dm)
        out["completeness"] = {"mc": c.mc, "method": c.method, "R": c.R}
        out["b_value"] = mg.b_value(M, c.mc, dm=dm, bootstrap=bootstrap, seed=seed).to_dict()
    except ValueError as exc:
        out["completeness"] = None
        out["b_value"] = None
        out["reason"] = f"no b-value: {exc}"
    if size_fit is not None:
        m_lo, m_hi = (float(v) for v in mg.magnitude([size_fit.s_min, size_fit.s_max]))
        try:
            out["truncated_gr"] = mg.truncated_gr_fit(M, m_lo, m_hi).to_dict()
        except ValueError as exc:
            out["truncated_gr"] = None
            out["truncated_gr_reason"] = f"no fit: {exc}"
        out["b_from_tau"] = mg.b_from_tau(size_fit.tau)
        out["b_from_tau_err"] = 1.5 * size_fit.tau_err
    return out


@dataclass
class Catalog:
    """A run's catalogue and what is read from it (:func:`catalog_analysis`).

    Attributes
    ----------
    table : pandas.DataFrame
        One row per slip of the stationary window (:func:`slip_catalog`).
    summary : dict
        Every number read from it, JSON-able.
    size_fits : dict
        The Figs. 7/8 statistics (:func:`~stickslip.analysis.stats.chain_runs.run_size_statistics`) by
        reading ("whole range", "below spanning").
    candidates : dict
        The fitted candidate densities of the sizes.
    moment_rate : pandas.DataFrame or None
        The moment-rate table (:func:`moment_rate`).
    intervals : dict
        Inter-event times, all and of the spanning slips.
    """

    table: pd.DataFrame
    summary: dict[str, Any]
    size_fits: dict[str, Any] = field(default_factory=dict)
    candidates: dict[str, Any] = field(default_factory=dict)
    moment_rate: pd.DataFrame | None = None
    intervals: dict[str, np.ndarray] = field(default_factory=dict)


def check_catalog_options(dm: Any, bootstrap: Any, gof_sims: Any, seed: Any, spell=None) -> None:
    """The one check of a catalogue's options, for :func:`catalog_analysis` and ``stickslip
    catalog`` alike: ``dm`` (the magnitude bin of the b-value) in [0, 1], the counts of
    resamples and synthetic catalogues and the seed whole numbers >= 0. ``spell`` names an
    argument as the user gave it (``gof-sims`` on the command line)."""
    name = spell if spell is not None else (lambda n: n)
    check_number(name("dm"), dm, low=0.0, high=1.0)
    check_number(name("bootstrap"), bootstrap, low=0, integer=True)
    check_number(name("gof_sims"), gof_sims, low=0, integer=True)
    check_number(name("seed"), seed, low=0, integer=True)


def catalog_analysis(
    run,
    *,
    dm: float = mg.DM,
    bootstrap: int = 200,
    gof_sims: int = 100,
    seed: int = 0,
    min_events: int = MIN_EVENTS,
) -> Catalog:
    """Catalogue of a chain run and everything read from it (``stickslip catalog``; module docstring).

    Parameters
    ----------
    run : ChainRun or str or Path
        A run, or a run directory.
    dm : float
        Magnitude bin of the b-value.
    bootstrap : int
        Resamples of the tau and b errors.
    gof_sims : int
        Synthetic catalogues of the KS goodness of fit (0: none).
    seed : int
        Seed of all of them.
    min_events : int
        Fewest slips with S > 0 in the stationary window.

    Returns
    -------
    Catalog
        The table, the summary, the size fits, the candidate distributions, the moment rate and
        the inter-event times.

    Raises
    ------
    ParameterError
        For a run with fewer than ``min_events`` slips, or counts or a bin whose work cannot
        finish (:data:`MAX_BOOTSTRAP`, :data:`MAX_GOF_SIMS`, :data:`MAX_MAGNITUDE_BINS`; one line).
    """
    check_catalog_options(dm, bootstrap, gof_sims, seed)
    check_counts(bootstrap, gof_sims)
    if isinstance(run, (str, Path)):
        run = load_catalog_run(run)
    from stickslip.run.state import loading_warnings

    table = slip_catalog(run)
    t_from = stationary_from(run)
    positive = table[np.isfinite(table["S"]) & (table["S"] > 0)]
    if len(positive) < min_events:
        raise ParameterError(
            f"{len(positive)} slips with S > 0 at t >= {t_from:g} (the run's stationary window, "
            f"{len(run.events)} in all); a catalogue's fits need at least {min_events}: run longer"
        )
    check_magnitude_bins(positive["magnitude"].to_numpy(dtype=np.float64), dm)
    p = run.params
    start = (run.start or {}).get("kind", "paper") if isinstance(run.start, dict) else "paper"
    from stickslip.models.presets import is_paper_run

    summary: dict[str, Any] = {
        "model": p.model,
        "pieces": p.pieces,
        "N": p.N,
        # the paper's chain at the paper's parameters: its beta picks the paper's numbers to cite
        "paper_beta": float(p.beta) if is_paper_run(p) else None,
        "t_end": float(run.summary.get("t_end", run.options.t_end)),
        "window": {
            "t_from": t_from,
            "rule": "slips starting at t >= the run's averaging window of <L> (default t_end / 2)",
            "warnings": loading_warnings(p, float(run.options.t_end), run.options.average_from, start)
            if not p.drive_piece.leaf_spring
            else [],
        },
        "n_events_run": int(len(run.events)),
        "n_events": int(len(table)),
        "n_positive": int(len(positive)),
        "spanning": spanning_column(p),
        "n_spanning": int(table["spans"].sum()),
        "magnitude": {
            "definition": "M = (2/3) log10 S",
            "min": float(positive["magnitude"].min()),
            "max": float(positive["magnitude"].max()),
        },
    }
    cat = Catalog(table=table, summary=summary)
    S = positive["S"].to_numpy(dtype=np.float64)
    M = positive["magnitude"].to_numpy(dtype=np.float64)

    # Sizes: the exponent tau of Figs. 7, 8, read as `plot` and `reproduce` read it
    sizes: dict[str, Any] = {}
    for key, small in (("whole_range", False), ("below_spanning", True)):
        if small and not summary["n_spanning"]:
            sizes[key] = {"reason": "no system-spanning slip: no cut-off below them"}
            continue
        try:
            st = run_size_statistics(run, small_only=small, seed=seed, bootstrap=bootstrap)
        except ValueError as exc:
            sizes[key] = {"reason": f"no fit: {exc}"}
            continue
        cat.size_fits[key] = st
        sizes[key] = {**st["fit"].to_dict(), "s_span": st["s_span"], "excess": st["excess"]}
    summary["sizes"] = sizes
    whole = cat.size_fits.get("whole_range")
    summary["frequency_magnitude"] = _frequency_magnitude(
        M, S, whole["fit"] if whole else None, dm=dm, bootstrap=bootstrap, seed=seed
    )

    # Which distribution: every candidate on the range of the whole-range fit
    if whole is not None:
        fit = whole["fit"]
        comparison = compare_distributions(S, fit.s_min, fit.s_max)
        cat.candidates = comparison.pop("objects")
        summary["distributions"] = comparison
        if gof_sims > 0:
            try:
                summary["goodness_of_fit"] = power_law_gof(S, fit.s_max, sims=gof_sims, seed=seed)
            except ValueError as exc:
                summary["goodness_of_fit"] = {"reason": f"no fit: {exc}"}
        else:
            summary["goodness_of_fit"] = {"reason": "not computed (gof_sims = 0)"}
    else:
        summary["distributions"] = {"reason": "no power-law fit of the sizes"}
        summary["goodness_of_fit"] = {"reason": "no power-law fit of the sizes"}

    # Recurrence of all and of system-spanning slips
    rec = {}
    for key, rows in (("all", table), ("spanning", table[table["spans"]])):
        t = rows["t_start"].to_numpy(dtype=np.float64)
        cat.intervals[key] = np.diff(np.sort(t))
        rec[key] = recurrence(t)
    summary["recurrence"] = rec

    rate, per_event, why = moment_rate(run, table)
    cat.moment_rate = rate
    summary["moment_rate"] = {"events": per_event, **({"reason": why} if why else {})}
    return cat
