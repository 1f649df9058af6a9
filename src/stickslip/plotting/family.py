"""Slip-size statistics across the model family: Carlson-Langer beside the paper's Fig. 8 chain.

The function takes event tables and the results of
:func:`stickslip.analysis.stats.chain_runs.size_statistics` and returns a matplotlib Figure.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from stickslip.analysis.stats.statistics import size_distribution
from stickslip.plotting.style import SIM, THEORY, new_figure

__all__ = ["family_sizes"]


def family_sizes(panels: Sequence[tuple[str, pd.DataFrame, dict[str, Any]]], *, bins: int = 40) -> Figure:
    """Slip-size densities p(S) side by side, log-log, with their truncated power-law fits.

    ``panels``: (title, events, stats) per panel, ``stats`` from ``size_statistics`` with
    ``small_only=True``. Each panel shows the density of S on logarithmic bins, the fitted power
    law on [s_min, s_max] (dashed), its continuation beyond s_max (dotted: what the power law
    predicts for the great events), and s_span, the smallest system-spanning event (vertical
    line), with the excess of events above it over the power law's count.
    """
    fig, axes = new_figure(1, len(panels), width=4.6, height=3.8)
    axes = np.atleast_1d(axes)
    for ax, (title, events, stats) in zip(axes, panels, strict=False):
        S = events["S"].to_numpy(dtype=np.float64)
        dist = size_distribution(S, bins)
        filled = dist["count"].values > 0
        ax.loglog(
            dist["S"].values[filled],
            dist["density"].values[filled],
            "o",
            color=SIM["color"],
            ms=3.5,
            label=f"{dist.attrs['n_binned']} events",
        )
        fit = stats["fit"]
        share = fit.n / dist.attrs["n_binned"]
        s_fit = np.geomspace(fit.s_min, fit.s_max, 100)
        err = f" ± {fit.tau_err:.2f}" if math.isfinite(fit.tau_err) else ""
        ax.loglog(
            s_fit,
            share * fit.pdf(s_fit),
            **THEORY,
            label=rf"$\tau = {fit.tau:.2f}${err} on $[{fit.s_min:.3g}, {fit.s_max:.3g}]$",
        )
        s_hi = float(np.nanmax(S))
        if s_hi > fit.s_max:
            s_ext = np.geomspace(fit.s_max, s_hi, 50)
            anchor = share * float(fit.pdf(fit.s_max))
            ax.loglog(
                s_ext,
                anchor * (s_ext / fit.s_max) ** (-fit.tau),
                color=THEORY["color"],
                lw=1.0,
                ls=":",
                label="power law continued",
            )
        if math.isfinite(stats["s_span"]):
            ex = stats["excess"]
            ax.axvline(
                stats["s_span"],
                color="0.5",
                lw=0.8,
                label=rf"$S \geq {stats['s_span']:.3g}$: {stats['observed']} events, "
                f"{ex:.3g}x the power law"
                if math.isfinite(ex)
                else "smallest spanning event",
            )
        ax.set_xlabel("$S$")
        ax.set_ylabel("$p(S)$")
        ax.set_title(title, fontsize=9, loc="left")
        ax.legend(loc="lower left", fontsize=7)
    return fig
