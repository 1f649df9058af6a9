"""Figures of ``stickslip study disorder`` (docs/studies/disorder.md): the order parameter of the
paper's chain with random thresholds against beta, the avalanche exponent under a force ramp
beside qEW's, and the mean velocity against a constant force.

Each function takes the study's rows of one part (or its fits) and returns a matplotlib Figure.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from stickslip.plotting.style import new_figure

__all__ = ["order_figure", "ramp_figure", "force_figure"]


def order_figure(rows: pd.DataFrame) -> Figure:
    """Part a: m = 1 - <L>/L_ss of eq. (4) against beta, one line per width w (filled markers
    where the run ends in stick-slip), and tau at beta = 0.4 against w."""
    fig, (a1, a2) = new_figure(1, 2, width=4.6, height=3.8)
    order = rows[rows["analysis"] == "order"]
    for k, (w, g) in enumerate(order.groupby("w")):
        g = g.sort_values("beta")
        color = f"C{k}"
        a1.plot(g["beta"], g["order_parameter"], "-", color=color, label=f"w = {w:g}")
        ss = g["final_state"] == "stick-slip"
        a1.plot(g["beta"][ss], g["order_parameter"][ss], "o", color=color, ms=5)
        a1.plot(g["beta"][~ss], g["order_parameter"][~ss], "o", mfc="none", color=color, ms=5)
    a1.axvline(1.0, color="0.5", ls="--", lw=0.8)
    a1.set_xlabel(r"$\beta$")
    a1.set_ylabel(r"$m = 1 - \langle L\rangle / L_{ss}$")
    a1.legend(fontsize=7)
    sizes = rows[rows["analysis"] == "sizes"].sort_values("w")
    if len(sizes):
        a2.errorbar(sizes["w"], sizes["tau"].astype(float), yerr=sizes["tau_err"].astype(float), fmt="o-", capsize=2)
    a2.set_xlabel("relative width w of Fs")
    a2.set_ylabel(r"$\tau$ at $\beta = 0.4$")
    return fig


def ramp_figure(fits: list[dict[str, Any]], qew: tuple[float, float]) -> Figure:
    """Part b: tau of the pooled avalanches against N at beta = 1 (left) and against beta at the
    chain of the beta scan (right), with qEW's tau as a band."""
    fig, (a1, a2) = new_figure(1, 2, width=4.6, height=3.8)
    f = pd.DataFrame(fits)
    at1 = f[f["beta"] == 1.0].sort_values("N")
    a1.errorbar(at1["N"], at1["tau"], yerr=at1["tau_err"], fmt="o-", capsize=2, label=r"ramp, $\beta = 1$")
    a1.set_xscale("log")
    a1.set_xlabel("N")
    counts = f.groupby("N")["beta"].nunique()
    scan = f[f["N"] == counts.idxmax()].sort_values("beta") if len(counts) else f.iloc[:0]
    a2.errorbar(
        scan["beta"],
        scan["tau"],
        yerr=scan["tau_err"],
        fmt="s-",
        capsize=2,
        label=f"N = {int(scan['N'].max()) if len(scan) else 0}",
    )
    a2.set_xscale("log")
    a2.set_xlabel(r"$\beta$")
    for ax in (a1, a2):
        ax.axhspan(qew[0] - max(qew[1], 0.005), qew[0] + max(qew[1], 0.005), color="C3", alpha=0.3, label="qEW 1.111")
        ax.set_ylabel(r"$\tau$")
        ax.legend(fontsize=7)
    return fig


def force_figure(rows: pd.DataFrame) -> Figure:
    """Part c: the mean velocity x/t (markers) and the final velocity (crosses) against the
    constant force F, one panel per friction; for the strengthening law the closed form
    (F - F0)/beta of its sliding branch (dashed)."""
    frictions = sorted(rows["friction"].unique())
    fig, axes = new_figure(1, max(len(frictions), 1), width=4.6, height=3.8)
    axes = np.atleast_1d(axes)
    for ax, friction in zip(axes, frictions, strict=False):
        g = rows[rows["friction"] == friction].groupby("F")[["v_mean", "v_end"]].mean().reset_index()
        ax.plot(g["F"], g["v_mean"], "o-", label="x / t")
        ax.plot(g["F"], g["v_end"], "x", label="final v")
        if friction == "strengthening":
            r0 = rows[rows["friction"] == friction].iloc[0]
            F = np.linspace(float(r0["F0"]), float(g["F"].max()), 50)
            ax.plot(F, (F - float(r0["F0"])) / float(r0["beta"]), "k--", lw=0.8, label=r"$(F - F_0)/\beta$")
        ax.set_xlabel("F")
        ax.set_ylabel("mean velocity")
        ax.set_title(friction, fontsize=8)
        ax.legend(fontsize=7)
    return fig
