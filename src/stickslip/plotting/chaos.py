"""Figures of the chaos study (docs/studies/chaos.md, docs/lyapunov.md).

:func:`flow_ladder_figure` and :func:`decorrelation_figure` take a list of curves, one per point:
a dict with ``label``, ``N`` and ``beta`` (None for the relatives) and the data of the point's
``flow.json`` (:func:`stickslip.experiments.studies.chaos.chaos_point`):

* :func:`flow_ladder_figure`: the largest exponent of the flow against dt (``ladder`` rows of
  ``dt``, ``lyapunov``, ``lyapunov_err``) with the fit lambda(dt) = lambda_0 + c dt^2
  (``lyapunov_dt0``, ``lyapunov_dt0_err``, ``dt2_slope``) drawn down to dt = 0;
* :func:`decorrelation_figure`: n(delta), the slips that agree between a reference and a twin
  started delta apart (``decorrelation``: for each kind of perturbation, rows of ``delta``,
  ``seed``, ``events``, ``decorrelated``), one panel per kind and N, one line per beta and
  window; windows that still agreed at the end are open markers at the slips compared;
* :func:`threshold_figure`: delta* against N (:func:`stickslip.analysis.dynamics.threshold.delta_star`,
  :func:`~stickslip.analysis.dynamics.threshold.threshold_fit`), one panel per kind, one colour per beta.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from stickslip.plotting.style import new_figure

__all__ = ["flow_ladder_figure", "decorrelation_figure", "threshold_figure"]


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


_MARKERS = ("o", "s", "D", "v", "^")


def decorrelation_figure(curves: list[dict[str, Any]]) -> Figure:
    """n(delta) against delta (log x): rows of panels are the kinds of perturbation, columns the
    chain's N (then the relatives); in each panel one colour per beta and one marker per window
    (seed), filled where the twin disagreed, open at the slips compared where it never did."""
    kinds = [k for k in ("state", "Fs", "V") if any(k in (c.get("decorrelation") or {}) for c in curves)]
    columns: list[Any] = sorted({int(c["N"]) for c in curves if c.get("beta") is not None})
    if any(c.get("beta") is None for c in curves):
        columns.append("relatives")
    nrows, ncols = max(1, len(kinds)), max(1, len(columns))
    fig, axes = new_figure(nrows, ncols, width=2.6, height=2.2)
    axes = np.asarray(axes, dtype=object).reshape(nrows, ncols)
    betas = sorted({float(c["beta"]) for c in curves if c.get("beta") is not None})
    for i, kind in enumerate(kinds):
        for j, col in enumerate(columns):
            ax = axes[i][j]
            mine = [c for c in curves if (c.get("beta") is None) == (col == "relatives")]
            if col != "relatives":
                mine = [c for c in mine if int(c["N"]) == col]
            drawn = False
            for c in mine:
                rows = [r for r in (c.get("decorrelation") or {}).get(kind, {}).get("decorrelation", [])]
                if not rows:
                    continue
                drawn = True
                b = c.get("beta")
                color = f"C{betas.index(float(b)) % 10}" if b is not None else f"C{(len(betas) + mine.index(c)) % 10}"
                name = f"beta = {float(b):g}" if b is not None else c.get("label", "")
                for s in sorted({int(r["seed"]) for r in rows}):
                    rs = sorted((r for r in rows if int(r["seed"]) == s and r["delta"] > 0), key=lambda r: r["delta"])
                    d = np.array([r["delta"] for r in rs], dtype=float)
                    n = np.array([r["events"] for r in rs], dtype=float)
                    dec = np.array([bool(r["decorrelated"]) for r in rs])
                    m = _MARKERS[s % len(_MARKERS)]
                    ax.plot(d, n, "-", lw=0.6, color=color, alpha=0.6, label=name if s == 0 else None)
                    ax.plot(d[dec], n[dec], m, ms=3, color=color, ls="none")
                    ax.plot(d[~dec], n[~dec], m, ms=4, mfc="none", color=color, ls="none")
            if not drawn:
                ax.set_visible(False)
                continue
            ax.set_xscale("log")
            ax.set_ylim(bottom=-0.03 * max(ax.get_ylim()[1], 1.0))
            title = f"N = {col}" if col != "relatives" else "relatives"
            ax.set_title(f"{kind}, {title}", fontsize=8)
            ax.tick_params(labelsize=7)
            if i == nrows - 1:
                ax.set_xlabel(r"$\delta$", fontsize=8)
            if j == 0:
                ax.set_ylabel(r"slips in agreement $n(\delta)$", fontsize=8)
            if ax.get_legend_handles_labels()[0]:
                ax.legend(fontsize=6)
    return fig


def threshold_figure(points: list[dict[str, Any]], fits: list[dict[str, Any]]) -> Figure:
    """delta* against N (log axes), one panel per kind of perturbation: each window's delta*
    (small markers), the geometric mean over the windows with its standard error (factor
    10^(+-err)), and the least-squares line of log10 delta* on log10 N for each beta (dashed).

    ``points``: dicts with ``N``, ``beta``, ``kind``, ``per_seed`` (None where censored),
    ``geometric_mean``, ``log10_err``; ``fits``: dicts with ``beta``, ``kind``, ``slope``,
    ``intercept``, ``Ns``."""
    kinds = [k for k in ("state", "Fs", "V") if any(p["kind"] == k for p in points)]
    fig, axes = new_figure(1, max(1, len(kinds)), width=3.0, height=2.8)
    axes = np.asarray(axes, dtype=object).reshape(1, -1)
    betas = sorted({float(p["beta"]) for p in points})
    for ax, kind in zip(axes[0], kinds, strict=False):
        for p in (p for p in points if p["kind"] == kind):
            k = betas.index(float(p["beta"]))
            color = f"C{k % 10}"
            shift = 1.0 + 0.04 * (k - (len(betas) - 1) / 2)  # beside each other at one N
            vals = [v for v in p["per_seed"] if v is not None]
            ax.plot([p["N"] * shift] * len(vals), vals, ".", ms=3, color=color, alpha=0.6)
            gm, err = p.get("geometric_mean"), _f(p.get("log10_err"))
            if gm is not None:
                e = err if math.isfinite(err) else 0.0
                yerr = [[gm - gm * 10**-e], [gm * 10**e - gm]]
                ax.errorbar([p["N"] * shift], [gm], yerr=yerr, fmt="o", ms=4, color=color, capsize=2)
        for f in (f for f in fits if f["kind"] == kind):
            if not math.isfinite(_f(f.get("slope"))) or not f.get("Ns"):
                continue
            color = f"C{betas.index(float(f['beta'])) % 10}"
            N = np.geomspace(min(f["Ns"]), max(f["Ns"]), 20)
            label = f"beta = {float(f['beta']):g}: {f['slope']:+.2f} +- {_f(f.get('slope_err')):.2f}"
            ax.plot(N, 10.0 ** (f["intercept"] + f["slope"] * np.log10(N)), "--", lw=1, color=color, label=label)
        ax.set_xscale("log")
        ax.set_yscale("log")
        Ns = sorted({int(p["N"]) for p in points if p["kind"] == kind})
        ax.set_xticks(Ns, [str(n) for n in Ns])
        ax.set_xticks([], minor=True)
        ax.set_xlim(min(Ns) / 1.4, max(Ns) * 1.4)
        ax.set_title(f"perturbation: {kind}", fontsize=8)
        ax.set_xlabel("N", fontsize=8)
        ax.tick_params(labelsize=7)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=6, title="slope of log delta* on log N", title_fontsize=6)
    axes[0][0].set_ylabel(r"threshold $\delta^*$", fontsize=8)
    return fig
