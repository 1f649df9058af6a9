"""The largest Lyapunov exponent against beta (:func:`stickslip.analysis.dynamics.lyapunov.lyapunov_vs_beta`)."""

from __future__ import annotations

import pandas as pd
from matplotlib.figure import Figure

from stickslip.plotting.style import SIM, new_figure


def plot_lyapunov_beta(table: pd.DataFrame, params=None, *, beta_c: float | None = 1.0) -> Figure:
    """lambda(beta) with its error bars (Benettin et al. 1980 two-trajectory estimate of eq. (4)).

    ``table`` has columns beta, lyapunov, lyapunov_err; ``params`` only labels the figure;
    ``beta_c`` draws the long-wave critical value (beta = alpha = 1, Fig. 4) as a dotted line.
    """
    fig, ax = new_figure()
    ax.errorbar(table["beta"], table["lyapunov"], yerr=table["lyapunov_err"], marker="o", ms=4, capsize=3, **SIM)
    ax.axhline(0.0, color="0.3", lw=0.8)
    if beta_c is not None:
        ax.axvline(beta_c, color="0.5", lw=0.8, ls=":", label=rf"$\beta_c = {beta_c:g}$ (linear threshold)")
        ax.legend()
    ax.set_xlabel(r"$\beta$")
    ax.set_ylabel(r"largest Lyapunov exponent $\lambda$")
    if params is not None:
        ax.set_title(f"chain, N = {params.N}, K = {params.K:g}, D = {params.D:g}, V = {params.V:g}", fontsize=9)
    return fig
