"""Figures of the flow's chaos tests (docs/lyapunov.md, "The flow: located switches").

Each function takes a list of curves, one per point: a dict with ``label`` and the data of the
point's ``flow.json`` (:func:`stickslip.experiments.chaos_verdict.verdict_point`):

* :func:`flow_ladder_figure`: the largest exponent of the flow against dt (``ladder`` rows of
  ``dt``, ``lyapunov``, ``lyapunov_err``) with the fit lambda(dt) = lambda_0 + c dt^2
  (``lyapunov_dt0``, ``lyapunov_dt0_err``, ``dt2_slope``) drawn down to dt = 0;
* :func:`fsle_figure`: the finite-size Lyapunov exponent lambda(delta) = ln 2 / <tau(delta)>
  (Aurell et al. 1997; ``finite_size`` with rows of ``delta``, ``rate``, ``rate_err``);
* :func:`decorrelation_figure`: the number of slip events n(delta) that agree between two runs
  started delta apart (``decorrelation`` rows of ``delta``, ``events``, ``decorrelated``); runs
  that still agreed at the end are drawn as open markers at the number of events compared.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from stickslip.plotting.style import new_figure

__all__ = ["flow_ladder_figure", "fsle_figure", "decorrelation_figure"]


def _f(x) -> float:
    """A number of a JSON row (NaN where it was written as null)."""
    return math.nan if x is None else float(x)


def _grid(n: int, ncols: int = 4) -> tuple[int, int]:
    ncols = max(1, min(ncols, n))
    return int(math.ceil(n / ncols)), ncols


def flow_ladder_figure(curves: list[dict[str, Any]]) -> Figure:
    """lambda(dt) of the flow (Benettin et al. 1980 on located switches) at dt, dt/2, dt/4, one
    panel per point, with the weighted fit lambda_0 + c dt^2 (Heun's order) and lambda_0 at
    dt = 0 with its error bar."""
    n = max(1, len(curves))
    nrows, ncols = _grid(n)
    fig, axes = new_figure(nrows, ncols, width=2.6, height=2.2)
    flat = list(np.atleast_1d(axes).ravel())
    for ax, c in zip(flat, curves, strict=False):
        rows = c.get("ladder", [])
        dt = np.array([_f(r["dt"]) for r in rows], dtype=float)
        lam = np.array([_f(r["lyapunov"]) for r in rows], dtype=float)
        err = np.array([_f(r["lyapunov_err"]) for r in rows], dtype=float)
        ax.errorbar(dt, lam, yerr=err, fmt="o", color="C0", ms=4, capsize=2, label="ladder")
        lam0, err0 = _f(c.get("lyapunov_dt0")), _f(c.get("lyapunov_dt0_err"))
        slope = _f(c.get("dt2_slope"))
        if dt.size and math.isfinite(lam0):
            h = np.linspace(0.0, float(dt.max()), 50)
            ax.plot(h, lam0 + slope * h**2, color="C3", lw=1.0, ls="--", label=r"$\lambda_0 + c\,dt^2$")
            ax.errorbar([0.0], [lam0], yerr=[err0], fmt="s", color="C3", ms=4, capsize=2, label=r"$dt \to 0$")
        ax.axhline(0.0, color="0.3", lw=0.6)
        ax.set_title(c.get("label", ""), fontsize=8)
        ax.set_xlabel("dt", fontsize=8)
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-3, 3))
        ax.tick_params(labelsize=7)
    for ax in flat[len(curves) :]:
        ax.set_visible(False)
    flat[0].set_ylabel(r"$\lambda$ of the flow", fontsize=8)
    if curves:
        flat[0].legend(fontsize=6)
    return fig


def fsle_figure(curves: list[dict[str, Any]]) -> Figure:
    """Finite-size exponent lambda(delta) = ln 2 / <tau(delta)> against delta (log axes, Aurell
    et al. 1997), one line per point; rows without a finished doubling are left out."""
    fig, ax = new_figure(width=5.6, height=3.8)
    for k, c in enumerate(curves):
        fsle = (c.get("finite_size") or {}).get("fsle", [])
        rows = [r for r in fsle if r["cycles"] and math.isfinite(_f(r["rate"])) and _f(r["rate"]) > 0]
        if not rows:
            continue
        d = np.array([_f(r["delta"]) for r in rows], dtype=float)
        rate = np.array([_f(r["rate"]) for r in rows], dtype=float)
        err = np.nan_to_num(np.array([_f(r["rate_err"]) for r in rows], dtype=float))
        ax.errorbar(d, rate, yerr=err, fmt="o-", ms=3, lw=1, capsize=1.5, color=f"C{k % 10}", label=c.get("label", ""))
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(r"separation $\delta$")
    ax.set_ylabel(r"FSLE $\lambda(\delta) = \ln 2 / \langle\tau(\delta)\rangle$")
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=6, ncols=2)
    return fig


def decorrelation_figure(curves: list[dict[str, Any]]) -> Figure:
    """n(delta), the slip events that agree (sizes within 1e-3) between runs started delta apart,
    against delta (log x), one line per point; open markers: still agreeing after the number of
    events compared (a lower bound)."""
    fig, ax = new_figure(width=5.6, height=3.8)
    for k, c in enumerate(curves):
        rows = c.get("decorrelation", [])
        d = np.array([r["delta"] for r in rows if r["delta"] > 0], dtype=float)
        if not d.size:
            continue
        n = np.array([r["events"] for r in rows if r["delta"] > 0], dtype=float)
        dec = np.array([bool(r["decorrelated"]) for r in rows if r["delta"] > 0])
        color = f"C{k % 10}"
        ax.plot(d, n, "-", lw=1, color=color, label=c.get("label", ""))
        ax.plot(d[dec], n[dec], "o", ms=4, color=color)
        ax.plot(d[~dec], n[~dec], "^", ms=6, mfc="none", color=color)
    ax.set_xscale("log")
    ax.set_xlabel(r"initial separation $\delta$")
    ax.set_ylabel(r"events in agreement $n(\delta)$")
    ax.set_ylim(bottom=0)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=6, ncols=2, title="open triangles: never decorrelated", title_fontsize=6)
    return fig
