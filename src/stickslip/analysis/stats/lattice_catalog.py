"""Slip catalogues of lattice runs (docs/lattice.md, "The catalogue"; ``stickslip catalog`` on a
lattice run directory).

An event on a lattice has a moment, the total slip of its blocks (every block has the same
area and rigidity, so the seismic moment up to a constant, as the chain's S). Its magnitude is
the chain's, M = (2/3) log10 moment (:func:`stickslip.analysis.stats.magnitudes.magnitude`, the
moment magnitude of Hanks and Kanamori without its constant). :func:`lattice_catalog` makes the
table (time, duration, moment, magnitude, area, epicentre, extent, whether every block slipped);
:func:`lattice_catalog_analysis` reads from it what :mod:`stickslip.analysis.stats.catalog` reads
from a chain's: the b-value of Aki and Utsu above the completeness magnitude, the doubly
truncated Gutenberg-Richter fit, the exponent tau of the moments and b = (3/2)(tau - 1), and
the recurrence of the events. Each part that cannot be computed says why instead.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from stickslip.analysis.stats import magnitudes as mg
from stickslip.analysis.stats.catalog import check_catalog_options, check_counts, check_magnitude_bins
from stickslip.analysis.stats.recurrence import recurrence
from stickslip.analysis.stats.statistics import fit_power_law
from stickslip.models.params import ParameterError, check_number

__all__ = [
    "LATTICE_CATALOG_COLUMNS",
    "LATTICE_CATALOG_DOCS",
    "LatticeCatalog",
    "lattice_catalog",
    "lattice_catalog_analysis",
]

#: Fewest events with a positive moment in the window for a catalogue's fits.
MIN_EVENTS = 50

LATTICE_CATALOG_COLUMNS = [
    "event",
    "t_start",
    "duration",
    "moment",
    "magnitude",
    "area",
    "epicentre_row",
    "epicentre_col",
    "rows",
    "cols",
    "spans",
]

LATTICE_CATALOG_DOCS = {
    "event": "the event's number in the run",
    "t_start": "time of its first step",
    "duration": "t_end - t_start",
    "moment": "total slip of its blocks, sum of x(end) - x(first move)",
    "magnitude": "M = (2/3) log10 moment",
    "area": "number of blocks that slipped",
    "epicentre_row": "row of the first block to move",
    "epicentre_col": "column of the first block to move",
    "rows": "rows of its bounding box",
    "cols": "columns of its bounding box",
    "spans": "every block of the lattice slipped",
}


def lattice_catalog(events: pd.DataFrame, n_blocks: int, *, t_from: float = 0.0) -> pd.DataFrame:
    """The catalogue of a lattice run's events that start at or after ``t_from``.

    Parameters
    ----------
    events : pandas.DataFrame
        The run's events (:attr:`stickslip.run.lattice.LatticeRun.events`: ``event``,
        ``t_start``, ``t_end``, ``moment``, ``area``, ``epicentre_row``, ``epicentre_col``,
        ``row_min`` .. ``col_max``).
    n_blocks : int
        The lattice's number of blocks (an event that slips them all spans it).
    t_from : float
        The window's start.

    Returns
    -------
    pandas.DataFrame
        One row per event, the columns :data:`LATTICE_CATALOG_COLUMNS`
        (:data:`LATTICE_CATALOG_DOCS`); ``magnitude`` = (2/3) log10 moment (NaN where the
        moment is not positive).

    Examples
    --------
    >>> import pandas as pd
    >>> ev = pd.DataFrame({"event": [0], "t_start": [1.0], "t_end": [2.0], "moment": [1000.0],
    ...     "area": [4], "epicentre_row": [1], "epicentre_col": [2], "row_min": [1], "row_max": [2],
    ...     "col_min": [1], "col_max": [2]})
    >>> float(lattice_catalog(ev, 4)["magnitude"].iloc[0])
    2.0
    """
    ev = events[events["t_start"] >= t_from]
    moment = ev["moment"].to_numpy(dtype=np.float64)
    return pd.DataFrame(
        {
            "event": ev["event"].to_numpy(dtype=np.int64),
            "t_start": ev["t_start"].to_numpy(dtype=np.float64),
            "duration": (ev["t_end"] - ev["t_start"]).to_numpy(dtype=np.float64),
            "moment": moment,
            "magnitude": mg.magnitude(moment),
            "area": ev["area"].to_numpy(dtype=np.int64),
            "epicentre_row": ev["epicentre_row"].to_numpy(dtype=np.int64),
            "epicentre_col": ev["epicentre_col"].to_numpy(dtype=np.int64),
            "rows": (ev["row_max"] - ev["row_min"] + 1).to_numpy(dtype=np.int64),
            "cols": (ev["col_max"] - ev["col_min"] + 1).to_numpy(dtype=np.int64),
            "spans": ev["area"].to_numpy() >= n_blocks,
        },
        columns=LATTICE_CATALOG_COLUMNS,
    )


@dataclass
class LatticeCatalog:
    """A lattice run's catalogue (:func:`lattice_catalog`), the numbers read from it
    (``summary``, JSON-able), the power-law fit of the moments (``size_fit``, or None) and the
    inter-event times (``intervals``).

    Attributes
    ----------
    table : pandas.DataFrame
        One row per event (:func:`lattice_catalog`): times, moment, magnitude M = (2/3) log10
        moment, area, epicentre and extent.
    summary : dict
        The numbers read from it (b-value, tau, recurrence), JSON-able.
    size_fit : object or None
        The power-law fit of the moments, None with too few events.
    intervals : numpy.ndarray
        The inter-event times.
    """

    table: pd.DataFrame
    summary: dict[str, Any]
    size_fit: Any = None
    intervals: np.ndarray = field(default_factory=lambda: np.zeros(0))


def lattice_catalog_analysis(
    run,
    *,
    t_from: float | None = None,
    dm: float = mg.DM,
    bootstrap: int = 200,
    seed: int = 0,
    min_events: int = MIN_EVENTS,
) -> LatticeCatalog:
    """The catalogue of a lattice run and the frequency-magnitude statistics read from it
    (module docstring): b-value above the completeness magnitude (Aki 1965, Utsu 1966;
    completeness by Wiemer and Wyss 2000), the doubly truncated Gutenberg-Richter fit over the
    magnitudes of the moments' power-law range, the exponent tau of p(moment) ~ moment^-tau
    (:func:`~stickslip.analysis.stats.statistics.fit_power_law`, Figs. 7, 8's estimator) with
    b = (3/2)(tau - 1), and the recurrence of the events.

    Parameters
    ----------
    run : LatticeRun or str or Path
        A lattice run, or its run directory.
    t_from : float, optional
        Events starting at or after it (default the second half of the run, t_end / 2, as the
        chain's catalogue's default window).
    dm : float
        Magnitude bin of the b-value.
    bootstrap : int
        Resamples of the errors of b and tau.
    seed : int
        Seed of the resampling.
    min_events : int
        Fewest events with a positive moment in the window.

    Returns
    -------
    LatticeCatalog
        The table, the summary, the moments' fit and the inter-event times.

    Raises
    ------
    ParameterError
        For fewer than ``min_events`` events, or options out of range (one line).
    """
    check_catalog_options(dm, bootstrap, 0, seed)
    check_counts(bootstrap, 0)
    if isinstance(run, (str, Path)):
        from stickslip.run.lattice_dir import load_lattice_run

        run = load_lattice_run(run)
    p = run.params
    t_end = float(run.summary.get("t_end", float(run.events["t_end"].max()) if len(run.events) else 0.0))
    t_from = 0.5 * t_end if t_from is None else check_number("t_from", t_from, low=0.0)
    table = lattice_catalog(run.events, p.lattice.n_blocks, t_from=t_from)
    positive = table[np.isfinite(table["magnitude"])]
    if len(positive) < min_events:
        raise ParameterError(
            f"{len(positive)} events with a positive moment at t >= {t_from:g} ({len(run.events)} in the run); "
            f"a catalogue's fits need at least {min_events}: run longer"
        )
    S = positive["moment"].to_numpy(dtype=np.float64)
    M = positive["magnitude"].to_numpy(dtype=np.float64)
    check_magnitude_bins(M, dm)
    summary: dict[str, Any] = {
        "model": p.model,
        "pieces": p.pieces,
        "lattice": p.lattice.describe(),
        "N": p.lattice.n_blocks,
        "t_end": t_end,
        "window": {"t_from": t_from, "rule": "events starting at t >= t_from (default t_end / 2)"},
        "n_events_run": int(len(run.events)),
        "n_events": int(len(table)),
        "n_positive": int(len(positive)),
        "n_spanning": int(table["spans"].sum()),
        "magnitude": {"definition": "M = (2/3) log10 moment", "min": float(M.min()), "max": float(M.max())},
    }
    cat = LatticeCatalog(table=table, summary=summary)
    try:
        cat.size_fit = fit_power_law(S, bootstrap=bootstrap, seed=seed)
        summary["moments"] = cat.size_fit.to_dict()
    except ValueError as exc:
        summary["moments"] = {"reason": f"no fit: {exc}"}
    summary["frequency_magnitude"] = _frequency_magnitude(M, cat.size_fit, dm=dm, bootstrap=bootstrap, seed=seed)
    t = positive["t_start"].to_numpy(dtype=np.float64)
    cat.intervals = np.diff(np.sort(t))
    summary["recurrence"] = recurrence(t)
    return cat


def _frequency_magnitude(M: np.ndarray, size_fit, *, dm: float, bootstrap: int, seed: int) -> dict[str, Any]:
    """Completeness, b-value, truncated Gutenberg-Richter and b from tau (each with its reason
    where it cannot be had)."""
    out: dict[str, Any] = {"dm": dm, "definition": "M = (2/3) log10 moment", "relation": "b = (3/2)(tau - 1)"}
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
