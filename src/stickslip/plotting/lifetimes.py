"""Figures of the lifetimes study (docs/studies/lifetimes.md): how long the irregular motion of
the chain of eq. (4) lasts against N.

* :func:`survival_figure`: Kaplan-Meier survival curves S(t) = P(T > t)
  (:func:`stickslip.analysis.stats.survival.kaplan_meier`), one panel per beta, one curve per N;
* :func:`lifetime_figure`: <T> against N with its error (lower bounds where no lifetime ended)
  and the fits of ln <T> on N and on ln N (:func:`stickslip.analysis.stats.survival.size_fits`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from stickslip.plotting.style import new_figure

__all__ = ["survival_figure", "lifetime_figure"]


def survival_figure(curves: list[dict[str, Any]]) -> Figure:
    """Kaplan-Meier survival of the irregular motion: ``curves`` of ``beta``, ``N`` and ``km`` (the
    DataFrame of :func:`~stickslip.analysis.stats.survival.kaplan_meier`), a step curve per N in a panel
    per beta; a curve that stays above 0 ends at its last censored lifetime."""
    betas = sorted({c["beta"] for c in curves})
    fig, axes = new_figure(1, max(1, len(betas)), width=3.0, height=2.6)
    flat = list(np.atleast_1d(axes).ravel())
    Ns = sorted({c["N"] for c in curves})
    colours = {N: f"C{k % 10}" for k, N in enumerate(Ns)}
    for ax, beta in zip(flat, betas, strict=False):
        for c in sorted((c for c in curves if c["beta"] == beta), key=lambda c: c["N"]):
            km = c["km"]
            t = km["t"].to_numpy(float)
            positive = t[t > 0]
            # S = 1 from a little before the first lifetime (a log axis has no t = 0)
            t = np.concatenate([[positive.min() / 2 if positive.size else 1.0], np.maximum(t, 1e-300)])
            s = np.concatenate([[1.0], km["survival"].to_numpy(float)])
            ax.step(t, s, where="post", color=colours[c["N"]], lw=1.0, label=f"N = {c['N']}")
        ax.set_xscale("log")
        ax.set_ylim(-0.02, 1.02)
        ax.set_title(f"beta = {beta:g}", fontsize=8)
        ax.set_xlabel("t since the start")
    if flat:
        flat[0].set_ylabel("S(t) = P(T > t)")
        flat[0].legend(fontsize=6)
    return fig


def lifetime_figure(points: list[dict[str, Any]], fits: list[dict[str, Any]]) -> Figure:
    """<T> against N per beta: ``points`` with ``beta``, ``N``, ``mean_T``, ``mean_T_err`` (None
    where none ended) and ``mean_T_low95``; ``fits`` with ``beta`` and, where fitted,
    ``exponential`` and ``power`` line fits of ln <T> (intercept, slope)."""
    fig, ax = new_figure(1, 1, width=4.6, height=3.4)
    betas = sorted({p["beta"] for p in points})
    for k, beta in enumerate(betas):
        colour = f"C{k}"
        mine = [p for p in points if p["beta"] == beta]
        seen = [p for p in mine if p["mean_T"] is not None]
        bound = [p for p in mine if p["mean_T"] is None and p["mean_T_low95"] > 0]
        if seen:
            ax.errorbar(
                [p["N"] for p in seen],
                [p["mean_T"] for p in seen],
                yerr=[p["mean_T_err"] for p in seen],
                fmt="o",
                color=colour,
                ms=4,
                capsize=2,
                label=f"beta = {beta:g}",
            )
        if bound:
            ax.plot([p["N"] for p in bound], [p["mean_T_low95"] for p in bound], "^", color=colour, ms=5, mfc="none")
        fit = next((f for f in fits if f["beta"] == beta and "exponential" in f), None)
        if fit is not None:
            n = np.linspace(min(fit["Ns"]), max(fit["Ns"]), 50)  # over the N fitted only
            e, pw = fit["exponential"], fit["power"]
            ax.plot(n, np.exp(e["intercept"] + e["slope"] * n), color=colour, lw=1.0)
            ax.plot(n, np.exp(pw["intercept"] + pw["slope"] * np.log(n)), color=colour, lw=1.0, ls="--")
    ax.set_yscale("log")
    ax.set_xlabel("N")
    ax.set_ylabel("<T> (model time units)")
    if betas:
        ax.legend(fontsize=7)
    if not any(math.isfinite(p["mean_T_low95"] or math.nan) for p in points):
        ax.set_yscale("linear")
    return fig
