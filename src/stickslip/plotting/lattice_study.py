"""Figures of ``stickslip study lattice`` (docs/studies/lattice.md): eq. (4) on the square, the
transition against beta from both ladders, and the slip-size and magnitude distributions beside
the chain's and Carlson-Langer's.

Each function takes the study's rungs or sizes and returns a matplotlib Figure.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.figure import Figure

from stickslip.plotting.style import new_figure

__all__ = ["ladders_figure", "sizes_figure", "magnitudes_figure", "log_binned_density"]


def ladders_figure(rungs: list[dict[str, Any]], edges: list[dict[str, Any]]) -> Figure:
    """m = 1 - <d>/d_ss and the stuck fraction against beta, one colour per L; up ladders filled
    and solid, down ladders open and dashed, a ring where the rung ended steady; the finite
    lattice's linear threshold dotted."""
    fig, (a1, a2) = new_figure(1, 2, width=4.6, height=3.8)
    Ls = sorted({r["L"] for r in rungs})
    for k, L in enumerate(Ls):
        color = f"C{k}"
        for d, ls, fill in (("up", "-", color), ("down", "--", "none")):
            g = sorted((r for r in rungs if r["L"] == L and r["direction"] == d), key=lambda r: r["beta"])
            if not g:
                continue
            b = np.array([r["beta"] for r in g])
            m = np.array([r["order_parameter"] for r in g], dtype=float)
            e = np.array([r["order_parameter_err"] for r in g], dtype=float)
            st = np.array([r["stuck_fraction"] for r in g], dtype=float)
            a1.errorbar(b, m, yerr=e, fmt="o" + ls, color=color, mfc=fill, ms=5, capsize=2, label=f"L = {L}, {d}")
            a2.plot(b, st, "o" + ls, color=color, mfc=fill, ms=5)
            steady = np.array([r["final_state"] == "steady" for r in g])
            a1.plot(b[steady], m[steady], "o", mfc="none", mec="k", ms=9)
        for e in edges:
            if e["L"] == L and np.isfinite(e["linear_threshold"]):
                for ax in (a1, a2):
                    ax.axvline(e["linear_threshold"], color=color, ls=":", lw=0.8)
    a1.set_xlabel(r"$\beta$")
    a1.set_ylabel(r"$m = 1 - \langle d\rangle / d_{ss}$")
    a1.legend(fontsize=7)
    a2.set_xlabel(r"$\beta$")
    a2.set_ylabel("fraction of time with a block stuck")
    return fig


def log_binned_density(S: np.ndarray, bins_per_decade: int = 5) -> tuple[np.ndarray, np.ndarray]:
    """The density p(S) of positive sizes on logarithmic bins (counts over n times the bin's
    width), at the bins' geometric centres; empty bins left out."""
    S = np.asarray(S, dtype=float)
    S = S[S > 0]
    if S.size == 0:
        return np.array([]), np.array([])
    lo, hi = np.floor(np.log10(S.min())), np.ceil(np.log10(S.max())) + 1e-9
    edges = 10.0 ** np.arange(lo, hi + 1.0 / bins_per_decade, 1.0 / bins_per_decade)
    counts, edges = np.histogram(S, edges)
    centres = np.sqrt(edges[1:] * edges[:-1])
    keep = counts > 0
    return centres[keep], counts[keep] / (S.size * np.diff(edges)[keep])


def sizes_figure(square: list[dict[str, Any]], chain: list[dict[str, Any]]) -> Figure:
    """The size densities of eq. (4) on the square (left) and of the chain (right), one colour per
    L (the same L the same colour in both panels)."""
    fig, axes = new_figure(1, 2, width=4.6, height=3.8, sharey=True)
    Ls = sorted({s["L"] for s in square + chain})
    for ax, runs, title in ((axes[0], square, "square L x L"), (axes[1], chain, "chain N = L")):
        for s in runs:
            x, p = log_binned_density(s["S"])
            ax.loglog(x, p, "o-", ms=3, color=f"C{Ls.index(s['L'])}", label=f"L = {s['L']} ({s['S'].size} events)")
        ax.set_xlabel("S (moment)")
        ax.set_title(title)
        ax.legend(fontsize=7)
    axes[0].set_ylabel("p(S)")
    return fig


def magnitudes_figure(sizes: dict[str, list[dict[str, Any]]]) -> Figure:
    """N(>= M) per unit time against M = (2/3) log10 S: one panel each for the square, the chain
    and Carlson-Langer, one curve per L."""
    from stickslip.analysis.stats.magnitudes import magnitude

    titles = {"sizes": "eq. (4), square", "chain": "eq. (4), chain", "cl": "Carlson-Langer, square"}
    panels = [p for p in ("sizes", "chain", "cl") if sizes.get(p)]
    fig, axes = new_figure(1, max(1, len(panels)), width=3.2, height=3.4)
    axes = np.atleast_1d(axes)
    Ls = sorted({s["L"] for p in panels for s in sizes[p]})  # one colour per L in every panel
    for ax, part in zip(axes, panels, strict=False):
        for s in sizes[part]:
            M = np.sort(magnitude(s["S"][s["S"] > 0]))[::-1]
            if M.size:
                rate = np.arange(1, M.size + 1) / s["t"]
                ax.step(M, rate, where="post", color=f"C{Ls.index(s['L'])}", label=f"L = {s['L']}")
                ax.set_yscale("log")
        ax.set_xlabel("M = (2/3) log10 S")
        ax.set_title(titles[part])
        ax.legend(fontsize=7)
    axes[0].set_ylabel("events with magnitude >= M per unit time")
    return fig
