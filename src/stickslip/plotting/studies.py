"""Figures of the studies (``stickslip study``): the phase diagrams and tau against beta.

Each function takes the study's table (one row per point, :mod:`stickslip.experiments.study_run`)
and returns a matplotlib Figure.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from stickslip.models.presets import PRESETS, is_paper
from stickslip.plotting.style import new_figure

__all__ = [
    "phase_map_figure",
    "exponents_figure",
    "STATE_STYLE",
]

#: Marker colour of each final state.
STATE_STYLE = {"steady": "C0", "stick-slip": "C3", "undecided": "C1", "failed": "0.5"}


def phase_map_figure(table: pd.DataFrame, x: str, title: str) -> Figure:
    """Final state (left) and m (right) over (``x``, beta): filled markers from the paper's start,
    rings from perturbed steady sliding; crosses where the two disagree (hysteresis). The
    dashed line is the linear threshold beta_c = alpha (eq. 5, Fig. 4)."""
    fig, (a1, a2) = new_figure(1, 2, width=5.0, height=4.2)
    paper = table[table["start"] == "paper"].set_index([x, "beta"])
    steady = table[table["start"] == "steady"].set_index([x, "beta"])
    for (xv, b), r in paper.iterrows():
        a1.plot(xv, b, "o", ms=9, color=STATE_STYLE.get(r["final_state"], "k"))
        if (xv, b) in steady.index:
            s = steady.loc[(xv, b)]
            a1.plot(xv, b, "o", ms=14, mfc="none", mew=2, mec=STATE_STYLE.get(s["final_state"], "k"))
            if s["final_state"] != r["final_state"]:
                a1.plot(xv, b, "kx", ms=12)
    sc = a2.scatter(
        [i[0] for i in paper.index], [i[1] for i in paper.index], c=paper["order_parameter"], cmap="viridis", s=80
    )
    fig.colorbar(sc, ax=a2, label="m (paper's start)")
    for ax in (a1, a2):
        xs = np.array(sorted(table[x].unique()), dtype=float)
        if x == "alpha":
            ax.plot(xs, xs, "k--", lw=1)
        else:
            ax.axhline(1.0, color="k", ls="--", lw=1)
        ax.set_xlabel(x if x != "alpha" else r"$\alpha$")
        ax.set_ylabel(r"$\beta$")
        if x == "D":
            ax.set_xscale("log")
    handles = [Line2D([], [], ls="", marker="o", color=c, label=s) for s, c in STATE_STYLE.items()]
    handles.append(Line2D([], [], ls="", marker="x", color="k", label="starts disagree"))
    handles.append(Line2D([], [], ls="--", color="k", label=r"$\beta_c = \alpha$"))
    a1.legend(handles=handles, fontsize=7, loc="best")
    a1.set_title(f"{title}: final state (dot: paper start, ring: steady start)", fontsize=8)
    a2.set_title(f"{title}: order parameter", fontsize=8)
    return fig


def exponents_figure(table: pd.DataFrame) -> Figure:
    """tau against beta for eq. (4) (bootstrap errors) with Carlson-Langer's tau as a band, and
    the great-event excess (observed / power-law count at and above the smallest spanning event)."""
    fig, (a1, a2) = new_figure(1, 2, width=4.6, height=3.8)
    chain = table[table["model"].map(is_paper)].sort_values("beta")
    cl = table[~table["model"].map(is_paper)]
    a1.errorbar(chain["beta"], chain["tau"], yerr=chain["tau_err"], fmt="o-", ms=4, capsize=2, label="eq. (4)")
    for r in cl.itertuples():
        if np.isfinite(r.tau):
            label = PRESETS[r.model].point_label(0.0, r.N)
            a1.axhspan(r.tau - r.tau_err, r.tau + r.tau_err, color="C3", alpha=0.25, label=label)
    a1.plot([1.0], [1.5], "k*", ms=8, label="paper, beta = 1")
    a1.plot([0.2], [1.6], "k^", ms=6, label="paper, beta = 0.2")
    a1.set_xlabel(r"$\beta$")
    a1.set_ylabel(r"$\tau$")
    a1.legend(fontsize=7)
    a2.plot(chain["beta"], chain["excess"], "o-", ms=4, label="eq. (4)")
    for r in cl.itertuples():
        a2.axhline(r.excess, color="C3", ls="--", label=PRESETS[r.model].label or r.model)
    a2.axhline(1.0, color="0.5", lw=0.8)
    a2.set_yscale("log")
    a2.set_xlabel(r"$\beta$")
    a2.set_ylabel("great-event excess (observed / power law)")
    a2.legend(fontsize=7)
    return fig
