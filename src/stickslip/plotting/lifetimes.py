"""Figures of the lifetimes study (docs/studies/lifetimes.md): how long the irregular motion of
the chain of eq. (4) and its relatives lasts against N, and the flow's exponent against N.

* :func:`survival_figure`: Kaplan-Meier survival curves S(t) = P(T > t)
  (:func:`stickslip.analysis.stats.survival.kaplan_meier`), one panel per model and beta, one curve per N;
* :func:`lifetime_figure`: <T> against N with its error (lower bounds where no lifetime ended)
  and the fits of ln <T> on N and on ln N (:func:`stickslip.analysis.stats.survival.size_fits`), one
  series per model and beta;
* :func:`exponent_figure`: the flow's largest exponent against N
  (:func:`stickslip.analysis.dynamics.lyapunov_flow.flow_lyapunov`), one panel per model.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from stickslip.plotting.style import new_figure

__all__ = ["survival_figure", "lifetime_figure", "exponent_figure"]


def survival_figure(curves: list[dict[str, Any]]) -> Figure:
    """Kaplan-Meier survival of the irregular motion: ``curves`` of ``panel`` (a model and beta, or
    ``beta`` alone: its title), ``N`` and ``km`` (the DataFrame of
    :func:`~stickslip.analysis.stats.survival.kaplan_meier`), a step curve per N in a panel per title; a
    curve that stays above 0 ends at its last censored lifetime."""
    curves = [{**c, "panel": c.get("panel", f"beta = {c.get('beta', 0.0):g}")} for c in curves]
    panels = list(dict.fromkeys(c["panel"] for c in curves))
    ncols = min(4, max(1, len(panels)))
    nrows = -(-len(panels) // ncols) if panels else 1
    fig, axes = new_figure(nrows, ncols, width=3.0, height=2.6)
    flat = list(np.atleast_1d(axes).ravel())
    Ns = sorted({c["N"] for c in curves})
    colours = {N: f"C{k % 10}" for k, N in enumerate(Ns)}
    for ax, panel in zip(flat, panels, strict=False):
        for c in sorted((c for c in curves if c["panel"] == panel), key=lambda c: c["N"]):
            km = c["km"]
            t = km["t"].to_numpy(float)
            positive = t[t > 0]
            # S = 1 from a little before the first lifetime (a log axis has no t = 0)
            t = np.concatenate([[positive.min() / 2 if positive.size else 1.0], np.maximum(t, 1e-300)])
            s = np.concatenate([[1.0], km["survival"].to_numpy(float)])
            ax.step(t, s, where="post", color=colours[c["N"]], lw=1.0, label=f"N = {c['N']}")
        ax.set_xscale("log")
        ax.set_ylim(-0.02, 1.02)
        ax.set_title(panel, fontsize=8)
        ax.set_xlabel("t since the start")
        ax.legend(fontsize=5)
    for ax in flat[len(panels) :]:
        ax.set_visible(False)
    if flat:
        flat[0].set_ylabel("S(t) = P(T > t)")
    return fig


def lifetime_figure(points: list[dict[str, Any]], fits: list[dict[str, Any]]) -> Figure:
    """<T> against N per series: ``points`` with ``series`` (a model and beta; ``beta = ...`` when
    absent), ``N``, ``mean_T``, ``mean_T_err`` (None where none ended, or a single lifetime) and
    ``mean_T_low95``; ``fits`` with the same ``series`` and, where fitted, ``exponential`` and
    ``power`` line fits of ln <T> (intercept, slope)."""

    def name(p: dict[str, Any]) -> str:
        return p.get("series") or f"beta = {p['beta']:g}"

    fig, ax = new_figure(1, 1, width=4.6, height=3.4)
    betas = list(dict.fromkeys(name(p) for p in points))
    for k, beta in enumerate(betas):
        colour = f"C{k % 10}"
        mine = [p for p in points if name(p) == beta]
        seen = [p for p in mine if p["mean_T"] is not None]
        bound = [p for p in mine if p["mean_T"] is None and p["mean_T_low95"] > 0]
        if seen:
            ax.errorbar(
                [p["N"] for p in seen],
                [p["mean_T"] for p in seen],
                # no error where a single lifetime ended (NaN: matplotlib refuses None)
                yerr=[float("nan") if p["mean_T_err"] is None else p["mean_T_err"] for p in seen],
                fmt="o",
                color=colour,
                ms=4,
                capsize=2,
                label=beta,
            )
        if bound:
            ax.plot(
                [p["N"] for p in bound],
                [p["mean_T_low95"] for p in bound],
                "^",
                color=colour,
                ms=5,
                mfc="none",
                label=None if seen else f"{beta} (lower bounds)",
            )
        fit = next((f for f in fits if name(f) == beta and "exponential" in f), None)
        if fit is not None:
            n = np.linspace(min(fit["Ns"]), max(fit["Ns"]), 50)  # over the N fitted only
            e, pw = fit["exponential"], fit["power"]
            ax.plot(n, np.exp(e["intercept"] + e["slope"] * n), color=colour, lw=1.0)
            ax.plot(n, np.exp(pw["intercept"] + pw["slope"] * np.log(n)), color=colour, lw=1.0, ls="--")
    ax.set_yscale("log")
    ax.set_xlabel("N")
    ax.set_ylabel("<T> (model time units)")
    if betas:
        ax.legend(fontsize=6)
    if not any(math.isfinite(p["mean_T_low95"] or math.nan) for p in points):
        ax.set_yscale("linear")
    return fig


def exponent_figure(rows: list[dict[str, Any]]) -> Figure:
    """The flow's largest exponent against N: ``rows`` with ``panel`` (the model), ``beta`` (None
    for a friction that reads none), ``N``, ``lyapunov``, ``lyapunov_err`` and ``orbit_period``
    (not None: the engine's slips were periodic over the same stretch, drawn open); one panel per
    model, one colour per beta, zero dotted."""
    panels = list(dict.fromkeys(r["panel"] for r in rows))
    fig, axes = new_figure(1, max(1, len(panels)), width=3.0, height=2.8)
    flat = list(np.atleast_1d(axes).ravel())
    betas = sorted({r["beta"] for r in rows if r["beta"] is not None})
    colours = {b: f"C{k % 10}" for k, b in enumerate(betas)}
    for ax, panel in zip(flat, panels, strict=False):
        mine = [r for r in rows if r["panel"] == panel]
        for beta in sorted({r["beta"] for r in mine}, key=lambda b: -1.0 if b is None else b):
            line = sorted((r for r in mine if r["beta"] == beta), key=lambda r: r["N"])
            colour = colours.get(beta, "k")
            for r in line:
                ax.errorbar(
                    r["N"],
                    r["lyapunov"],
                    yerr=r["lyapunov_err"],
                    fmt="o",
                    color=colour,
                    mfc="none" if r.get("orbit_period") else colour,
                    ms=4,
                    capsize=2,
                )
            ax.plot(
                [r["N"] for r in line],
                [r["lyapunov"] for r in line],
                color=colour,
                lw=0.8,
                label=f"beta = {beta:g}" if beta is not None else panel,
            )
        ax.axhline(0.0, color="0.5", lw=0.6, ls=":")
        ax.set_title(panel, fontsize=8)
        ax.set_xlabel("N")
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 2))
        ax.legend(fontsize=6)
    if flat:
        flat[0].set_ylabel("flow's exponent (per time unit)")
    return fig
