"""Figures of a slip catalogue (``stickslip catalog``): frequency-magnitude, CCDF, recurrence, moment rate.

Each function takes the :class:`~stickslip.analysis.stats.catalog.Catalog` of a run and returns a
matplotlib Figure, or None when the catalogue has nothing to draw (the caller says why).
"""

from __future__ import annotations

import math
import re

import numpy as np
from matplotlib.figure import Figure

from stickslip.analysis.stats import magnitudes as mg
from stickslip.analysis.stats.recurrence import renewal_pdf
from stickslip.plotting.style import PAPER, SIM, THEORY, new_figure

__all__ = [
    "magnitude_label",
    "frequency_magnitude_figure",
    "ccdf_figure",
    "recurrence_figure",
    "moment_rate_figure",
    "catalog_figures",
]

_CANDIDATE_STYLE = {
    "power_law": {"color": "C3", "ls": "--"},
    "power_law_exp_cutoff": {"color": "C1", "ls": "-."},
    "lognormal": {"color": "C2", "ls": ":"},
    "exponential": {"color": "C4", "ls": (0, (5, 2, 1, 2))},
    "stretched_exponential": {"color": "C5", "ls": (0, (1, 1))},
}
_RENEWAL_STYLE = {"exponential": "C4", "gamma": "C1", "weibull": "C3", "bpt": "C2"}


def _title(catalog) -> str:
    s = catalog.summary
    return f"{s['model']}, N = {s['N']}, slips at t >= {s['window']['t_from']:g}"


def magnitude_label(definition: str | None) -> str:
    """The axis label of a magnitude from the catalogue's definition of it
    (``summary["frequency_magnitude"]["definition"]``): "M = (2/3) log10 S" on a chain,
    "M = (2/3) log10 moment" on a lattice, the size each catalogue's magnitude is read from.

    Parameters
    ----------
    definition : str or None
        The catalogue's definition of M.

    Returns
    -------
    str
        The label in matplotlib's mathtext: a one-letter size in italics, a word upright; another
        definition as written.

    Examples
    --------
    >>> print(magnitude_label("M = (2/3) log10 S"))
    magnitude $M = \\frac{2}{3}\\log_{10} S$
    >>> print(magnitude_label("M = (2/3) log10 moment"))
    magnitude $M = \\frac{2}{3}\\log_{10} \\mathrm{moment}$
    """
    match = re.fullmatch(r"M = \(2/3\) log10 (\w+)", definition or "")
    if match is None:  # another definition: as written
        return f"magnitude {definition}" if definition else "magnitude $M$"
    size = match.group(1)
    symbol = size if len(size) == 1 else f"\\mathrm{{{size}}}"  # a symbol in italics, a word upright
    return f"magnitude $M = \\frac{{2}}{{3}}\\log_{{10}} {symbol}$"


def frequency_magnitude_figure(catalog) -> Figure | None:
    """Frequency-magnitude distribution: N(>= M) and the count per bin of M = (2/3) log10 S (of the
    moment on a lattice: the x label is the catalogue's own definition, :func:`magnitude_label`),
    with the Aki-Utsu Gutenberg-Richter line from the completeness magnitude and the doubly
    truncated fit."""
    fm = catalog.summary["frequency_magnitude"]
    M = catalog.table["magnitude"].to_numpy(dtype=float)
    M = M[np.isfinite(M)]
    if M.size < 2:
        return None
    dm = fm["dm"] or 0.1
    m_b = mg.bin_magnitudes(M, dm)
    centres, counts = np.unique(np.round(m_b / dm).astype(np.int64), return_counts=True)
    centres = centres * dm
    cumulative = np.array([np.count_nonzero(m_b >= c - dm / 2) for c in centres])
    fig, ax = new_figure(1, 1, width=6.0, height=4.2)
    ax.semilogy(centres, cumulative, "o", color=SIM["color"], ms=3.5, label="$N(\\geq M)$")
    ax.semilogy(centres, counts, "s", mfc="none", color="0.45", ms=3.5, label=f"per bin of {dm:g}")
    bv = fm.get("b_value")
    if bv:
        m_line = np.linspace(bv["mc"], float(M.max()), 100)
        ax.semilogy(
            m_line,
            bv["n"] * 10.0 ** (-bv["b"] * (m_line - bv["mc"])),
            **THEORY,
            label=f"Aki-Utsu: $b = {bv['b']:.3f} \\pm {bv['b_err_shi_bolt']:.3f}$ ($M \\geq M_c = {bv['mc']:.2g}$)",
        )
        ax.axvline(bv["mc"], color="0.6", lw=0.8)
    gr = fm.get("truncated_gr")
    if gr:
        beta = gr["b"] * math.log(10.0)
        width = gr["m_max"] - gr["m_min"]
        m_line = np.linspace(gr["m_min"], gr["m_max"], 200)
        n_above = (
            gr["n"] * (np.exp(-beta * (m_line - gr["m_min"])) - math.exp(-beta * width)) / -math.expm1(-beta * width)
        )
        n_above = n_above + np.count_nonzero(M > gr["m_max"])
        ax.semilogy(
            m_line[:-1],
            n_above[:-1],
            **PAPER,
            label=f"doubly truncated GR: $b = {gr['b']:.3f}$ ($\\tau = {gr['tau']:.3f}$)",
        )
    ax.set_xlabel(magnitude_label(fm.get("definition")))
    ax.set_ylabel("number of slips")
    ax.legend(loc="lower left", fontsize=8)
    ax.set_title(f"frequency-magnitude: {_title(catalog)}", loc="left", fontsize=9, wrap=True)
    return fig


def ccdf_figure(catalog) -> Figure | None:
    """P(S' >= S) of the sizes in the fit range against every fitted candidate distribution."""
    if not catalog.candidates:
        return None
    any_fit = next(iter(catalog.candidates.values()))
    lo, hi = any_fit.s_min, any_fit.s_max
    S = np.sort(catalog.table["S"].to_numpy(dtype=float))
    S = S[(S >= lo) & (S <= hi)]
    n = S.size
    fig, ax = new_figure(1, 1, width=6.0, height=4.2)
    ax.loglog(S, 1.0 - np.arange(n) / n, color=SIM["color"], lw=1.4, label=f"slips ({n} in $[s_{{min}}, s_{{max}}]$)")
    top = hi if math.isfinite(hi) else float(S.max())
    grid = np.geomspace(lo, top, 600)
    for name, fit in catalog.candidates.items():
        density = fit.pdf(grid)
        # CCDF by the trapezoid rule from the top of the range (the density is normalised on it)
        pieces = 0.5 * (density[1:] + density[:-1]) * np.diff(grid)
        ccdf = np.concatenate([np.cumsum(pieces[::-1])[::-1], [0.0]])
        ccdf = ccdf / ccdf[0] if ccdf[0] > 0 else ccdf
        shown = ", ".join(f"{k} = {v:.3g}" for k, v in fit.params.items())
        ax.loglog(grid[:-1], ccdf[:-1], lw=1.1, **_CANDIDATE_STYLE.get(name, {}), label=f"{name} ({shown})")
    ax.set_ylim(0.3 / n, 2.0)
    ax.set_xlabel("$S$")
    ax.set_ylabel("$P(S' \\geq S)$")
    ax.legend(loc="lower left", fontsize=7)
    ax.set_title(f"which distribution: {_title(catalog)}", loc="left", fontsize=9, wrap=True)
    return fig


def recurrence_figure(catalog) -> Figure | None:
    """Densities of the inter-event times of all slips and of system-spanning ones, with the renewal fits."""
    rec = catalog.summary["recurrence"]
    keys = [k for k in ("all", "spanning") if rec.get(k, {}).get("fits")]
    if not keys:
        return None
    fig, axes = new_figure(1, len(keys), width=4.8, height=3.8)
    axes = np.atleast_1d(axes)
    for ax, key in zip(axes, keys, strict=True):
        dt = catalog.intervals[key]
        dt = dt[dt > 0]
        bins = min(60, max(8, int(math.sqrt(dt.size))))
        ax.hist(dt, bins=bins, density=True, color=SIM["color"], alpha=0.35, label=f"{dt.size} intervals")
        x = np.linspace(0.0, float(dt.max()), 400)[1:]
        for f in rec[key]["fits"]:
            if "params" not in f:
                continue
            y = renewal_pdf(f, x)
            ax.plot(
                x,
                y,
                color=_RENEWAL_STYLE[f["model"]],
                lw=1.1,
                label=f"{f['model']} ($\\Delta$AIC {f['delta_aic']:.3g})",
            )
        ax.ticklabel_format(axis="x", style="sci", scilimits=(-3, 4))
        ax.set_xlabel("inter-event time $\\Delta t$")
        ax.set_ylabel("density")
        ax.set_title(f"{key} slips, CV = {rec[key]['cv']:.3g}", loc="left", fontsize=9, wrap=True)
        ax.legend(fontsize=7)
    fig.suptitle(f"recurrence: {_title(catalog)}", fontsize=9, wrap=True)
    return fig


def moment_rate_figure(catalog) -> Figure | None:
    """Moment rate sum_i Delta x_i / W against time from the slip's start, for the largest slips with profiles."""
    table = catalog.moment_rate
    if table is None or table.empty:
        return None
    fig, ax = new_figure(1, 1, width=6.0, height=3.8)
    per = {e["event"]: e for e in catalog.summary["moment_rate"]["events"]}
    for i, (event, rows) in enumerate(table.groupby("event", sort=False)):
        e = per.get(int(event), {})
        ax.plot(
            rows["t"],
            rows["rate"],
            "-o",
            ms=2.5,
            lw=1.0,
            color=f"C{i % 10}",
            label=f"slip {int(event)}: $S = {e.get('S', math.nan):.3g}$, $M = {e.get('magnitude', math.nan):.2f}$",
        )
    ax.set_xlabel("time since the slip's start")
    ax.set_ylabel("moment rate $\\sum_i \\Delta x_i / W$")
    ax.legend(fontsize=7)
    ax.set_title(f"moment rate of the largest slips: {_title(catalog)}", loc="left", fontsize=9, wrap=True)
    return fig


def catalog_figures(catalog) -> list[tuple[str, str, Figure | None, str]]:
    """Every figure of a catalogue: (stem, title, Figure or None, why not drawn)."""
    mr = catalog.summary["moment_rate"]
    return [
        (
            "frequency_magnitude",
            "frequency-magnitude distribution",
            frequency_magnitude_figure(catalog),
            "no magnitudes",
        ),
        ("ccdf", "sizes against the candidate distributions", ccdf_figure(catalog), "no power-law fit of the sizes"),
        ("recurrence", "inter-event times with renewal fits", recurrence_figure(catalog), "too few inter-event times"),
        ("moment_rate", "moment rate of the largest slips", moment_rate_figure(catalog), mr.get("reason", "")),
    ]
