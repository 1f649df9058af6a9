"""Figures of the transition study by continuation (``stickslip study transition``): the
hysteresis loops of the order parameters against beta, and beta_t(N) - 1 and the step of m at
beta_t against N on log axes with their fitted power laws.

Each function takes the study's rows or per-N table (:mod:`stickslip.experiments.studies.transition`)
and returns a matplotlib Figure.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from stickslip.plotting.style import new_figure

__all__ = ["loops_figure", "scaling_figure"]


def loops_figure(rows: pd.DataFrame) -> Figure:
    """The hysteresis loops of the transition of eq. (4) at beta_c = 1: m = 1 - <L>/L_ss (left)
    and the stuck fraction phi (right) against beta, the up ladder (filled, solid; one line per
    replica) and the down ladder (open, dashed) of every N.

    Parameters
    ----------
    rows : pandas.DataFrame
        The rungs, one per row: ``N``, ``beta``, ``branch``, optionally ``replica``,
        ``order_parameter``, ``stuck_fraction`` and their ``_err`` columns (the table of
        ``stickslip study transition``, or
        :func:`~stickslip.experiments.studies.transition.transition_loop`).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (ax_m, ax_p) = new_figure(1, 2, width=5.6, height=4.0)
    for k, (N, g) in enumerate(rows.groupby("N")):
        colour = f"C{k % 10}"
        for branch, style, face in (("up", "-", colour), ("down", "--", "none")):
            mine = g[g["branch"] == branch]
            reps = mine.groupby("replica") if "replica" in mine else [(0, mine)]
            for j, (_, b) in enumerate(reps):  # each replica's ladder its own line
                b = b.sort_values("beta")
                if not len(b):
                    continue
                label = f"N = {N} {branch}" if j == 0 else None
                for ax, col in ((ax_m, "order_parameter"), (ax_p, "stuck_fraction")):
                    ax.errorbar(
                        b["beta"],
                        b[col],
                        yerr=b[f"{col}_err"],
                        fmt="o" + style,
                        ms=4,
                        color=colour,
                        mfc=face,
                        label=label if ax is ax_m else None,
                        lw=1,
                        alpha=1.0 if j == 0 else 0.55,
                    )
    for ax in (ax_m, ax_p):
        ax.axvline(1.0, color="0.6", lw=0.8, ls=":")
        ax.set_xlabel(r"$\beta$")
    ax_m.axhline(0.0, color="0.6", lw=0.8)
    ax_m.set_ylabel(r"$m = 1 - \langle L\rangle / L_{ss}$")
    ax_p.set_ylabel(r"stuck fraction $\phi = 1 - \langle n_{moving}\rangle / N$")
    ax_m.legend(fontsize=7, ncol=2)
    ax_m.set_title("up: from stick-slip; down: from steady sliding", fontsize=9)
    return fig


def scaling_figure(per_n: pd.DataFrame, fits: dict) -> Figure:
    """beta_t(N) - 1 (left) and the size of the step of m at beta_t (right) against N on log axes, with the
    fitted power laws A N^b."""
    fig, (ax_b, ax_s) = new_figure(1, 2, width=4.6, height=3.8)
    N = per_n["N"].to_numpy(dtype=float)
    for ax, y, err, key, label in (
        (ax_b, per_n["beta_t"] - 1.0, per_n["beta_t_err"], "beta_t_minus_1", r"$\beta_t(N) - 1$"),
        (ax_s, per_n["step"].abs(), per_n["step_err"], "step", r"$|$step of $m$ at $\beta_t|$"),
    ):
        y = np.asarray(y, dtype=float)
        ax.errorbar(N, y, yerr=np.asarray(err, dtype=float), fmt="o", color="C3")
        f = fits.get(key, {})
        if f and np.isfinite(f.get("b", np.nan)):
            xs = np.geomspace(N.min() * 0.8, N.max() * 1.25, 50)
            ax.plot(
                xs,
                f["A"] * xs ** f["b"],
                "-",
                color="0.4",
                lw=1,
                label=rf"$\propto N^{{{f['b']:.2f} \pm {f['b_err']:.2f}}}$",
            )
            ax.legend(fontsize=8)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("N")
        ax.set_ylabel(label)
    return fig
