"""Figures of the linear stability (section 2, Fig. 4) and of the hysteresis loop (section 2).

Each function takes results (the Datasets of :mod:`stickslip.analysis.dynamics.stability` and
:mod:`stickslip.analysis.dynamics.hysteresis`) and returns a matplotlib Figure.
"""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.colors import TwoSlopeNorm
from matplotlib.figure import Figure

from stickslip.plotting.style import PAPER, SIM, THEORY, new_figure

#: Hopf point stated in section 2 (K = 10, beta = 0.08).
PAPER_HOPF = {"beta": 0.08, "V": 0.106}
#: Inverse transition stated in section 2 (K = 10, beta = 1, Fs = 3).
PAPER_V_UP = 0.345
PAPER_SWEEP = {"K": 10.0, "beta": 1.0, "Fs": 3.0, "alpha": 1.0, "M": 1.0, "sigma": 1.0}


def plot_stability_map(curve: xr.Dataset, growth: xr.DataArray | None = None, *, mark: dict | None = None) -> Figure:
    """Stability map of steady sliding of the block (section 2, eq. 2): V_c(beta) at fixed K.

    ``curve`` is :func:`stickslip.analysis.dynamics.stability.hopf_curve`; ``growth`` (optional) the largest
    Re(lambda) over (beta, V), shown as shading; ``mark`` an optional {"beta", "V"} point.
    """
    fig, ax = new_figure(width=5.6, height=4.0)
    if growth is not None:
        g = growth.transpose("V", "beta").values
        lim = float(np.nanmax(np.abs(g))) or 1.0
        mesh = ax.pcolormesh(
            growth["beta"].values,
            growth["V"].values,
            g,
            cmap="RdBu_r",
            norm=TwoSlopeNorm(vcenter=0.0, vmin=-lim, vmax=lim),
            shading="auto",
            rasterized=True,
        )
        fig.colorbar(mesh, ax=ax, label=r"largest Re$\,\lambda$")
    ax.plot(curve["beta"], curve["V_c"], **SIM, label=r"Hopf curve $V_c(\beta)$ (root finding)")
    ax.plot(curve["beta"], curve["V_c_closed_form"], **THEORY, label="Routh-Hurwitz closed form")
    ax.plot(
        [PAPER_HOPF["beta"]],
        [PAPER_HOPF["V"]],
        "o",
        mfc="none",
        mec="k",
        ms=7,
        label=r"paper: $V_c=0.106$ at $\beta=0.08$",
    )
    if mark is not None:
        ax.plot([mark["beta"]], [mark["V"]], "x", color="k", ms=7, label="requested point")
    K = curve.attrs.get("K")
    ax.set_xlabel(r"$\beta$")
    ax.set_ylabel(r"$V$")
    ax.set_title(f"one block, $K = {K:g}$: steady sliding unstable below the curve" if K else "", fontsize=9)
    if growth is not None:
        ax.set_xlim(float(growth["beta"].min()), float(growth["beta"].max()))
        ax.set_ylim(float(growth["V"].min()), float(growth["V"].max()))
    ax.legend(loc="upper right", fontsize=8)
    return fig


def plot_fig4(ds: xr.Dataset, *, k_zoom: float = 0.3) -> Figure:
    """Fig. 4: real parts of the two largest eigenvalues of the Fourier modes of eq. (5).

    ``ds`` is :func:`stickslip.analysis.dynamics.stability.fig4_data`. Left: 0 <= k <= pi; right: the long
    waves k <= ``k_zoom``, where the instability for beta < alpha lives. Solid: largest,
    dashed: second largest; one colour per beta.
    """
    fig, axes = new_figure(1, 2, width=4.4, height=3.6)
    for j, b in enumerate(ds["beta"].values):
        sel = ds.sel(beta=b)
        color = f"C{j}"
        for ax in axes:
            ax.plot(sel["k"], sel["real"].isel(branch=0), color=color, lw=1.3, label=rf"$\beta={b:g}$")
            ax.plot(sel["k"], sel["real"].isel(branch=1), color=color, lw=1.0, ls="--")
    for ax in axes:
        ax.axhline(0.0, color="k", lw=0.6)
        ax.set_xlabel(r"wavenumber $k$")
    axes[0].set_ylabel(r"Re$\,\lambda$ (two largest)")
    axes[1].set_ylabel(rf"Re$\,\lambda$ (two largest), $k \leq {k_zoom:g}$")
    axes[0].set_xlim(0.0, np.pi)
    axes[1].set_xlim(0.0, k_zoom)
    small = ds["real"].where(ds["k"] <= k_zoom).isel(branch=slice(0, 2))
    lo, hi = float(small.min()), float(small.max())
    pad = 0.08 * (hi - lo)
    axes[1].set_ylim(lo - pad, hi + pad)
    attrs = ds.attrs
    axes[0].set_title("(a) every wavenumber", loc="left", fontsize=9)
    axes[1].set_title("(b) long waves (solid: largest, dashed: second)", loc="left", fontsize=9)
    axes[0].legend(fontsize=8)
    fig.suptitle(
        "Fig. 4: growth rates of the Fourier modes of steady sliding, eq. (5), "
        f"$K = {attrs.get('K', float('nan')):g}$, $D = {attrs.get('D', float('nan')):g}$, "
        f"$V = {attrs.get('V', float('nan')):g}$",
        fontsize=9,
        wrap=True,
    )
    return fig


def plot_hysteresis(sweep: xr.Dataset) -> Figure:
    """Bifurcation diagram of the single block (section 2): max and min of v against V.

    ``sweep`` is :func:`stickslip.analysis.dynamics.hysteresis.hysteresis_sweep`'s ``data``: both sweeps, with
    the transitions V_up and V_down marked and the paper's V = 0.345 for comparison.
    """
    fig, ax = new_figure(width=6.0, height=4.0)
    styles = {"up": {"color": "C0", "marker": "^"}, "down": {"color": "C1", "marker": "v"}}
    for direction in ("up", "down"):
        d = sweep.sel(direction=direction)
        st = styles[direction]
        # markers only: a line across the jump at V_up would suggest states that do not exist
        ax.plot(d["V"], d["v_max"], ls="none", ms=4, **st, label=f"sweep {direction}: max $v$")
        ax.plot(d["V"], d["v_min"], ls="none", ms=4, mfc="none", **st, label=f"sweep {direction}: min $v$")
    V = sweep["V"].values
    ax.plot(V, V, **THEORY, label="steady sliding $v = V$")
    v_up = sweep.attrs.get("V_up")
    v_down = sweep.attrs.get("V_down")
    if v_up is not None and np.isfinite(v_up):
        ax.axvline(v_up, color="C0", lw=0.8, alpha=0.6)
        ax.annotate(
            rf"$V_\mathrm{{up}}={v_up:.4g}$",
            (v_up, 0.55),
            xycoords=("data", "axes fraction"),
            xytext=(-3, 0),
            textcoords="offset points",
            ha="right",
            va="center",
            fontsize=8,
            color="C0",
            rotation=90,
        )
    if v_down is not None and np.isfinite(v_down):
        ax.axvline(v_down, color="C1", lw=0.8, alpha=0.6)
        ax.annotate(
            rf"$V_{{down}}={v_down:.4g}$",
            (v_down, 0.55),
            xycoords=("data", "axes fraction"),
            xytext=(-3, 0),
            textcoords="offset points",
            ha="right",
            va="center",
            fontsize=8,
            color="C1",
            rotation=90,
        )
    elif v_up is not None and np.isfinite(v_up):
        ax.text(
            0.98,
            0.55,
            "going down: no return\nto stick-slip in this range",
            transform=ax.transAxes,
            ha="right",
            va="center",
            fontsize=8,
            color="C1",
        )
    a = sweep.attrs
    if all(a.get(name) == value for name, value in PAPER_SWEEP.items()):
        ax.axvline(PAPER_V_UP, **PAPER, label="paper: $V = 0.345$")
    ax.set_xlabel(r"pulling velocity $V$")
    ax.set_ylabel(r"block velocity $v$ (max, min)")
    ax.set_title(
        f"single block, $K = {a.get('K', float('nan')):g}$, $\\beta = {a.get('beta', float('nan')):g}$, "
        f"$F_s = {a.get('Fs', float('nan')):g}$; $\\Delta V = {a.get('dV', float('nan')):g}$, "
        f"{a.get('time_per_step', float('nan')):g} time units per V",
        fontsize=9,
    )
    ax.legend(fontsize=7, loc="best")
    return fig


def plot_mode_growth(ds: xr.Dataset, modes=None) -> Figure:
    """Growth rate of steady sliding against k for a chain without state variable (like Fig. 4).

    ``ds`` is :func:`stickslip.analysis.dynamics.stability.mode_dispersion`: Re of both roots of
    lambda^2 + phi'(V) lambda + w_k^2 = 0 (plate drive of Carlson-Langer, or the train model);
    ``modes`` (optional) :func:`~stickslip.analysis.dynamics.stability.mode_growth_rates`, the finite
    chain's modes, drawn as points (k folded into [0, pi]).
    """
    fig, ax = new_figure(width=5.6, height=4.0)
    k = ds["k"].values
    ax.plot(k, ds["real"].isel(branch=0), color="C0", lw=1.4, label=r"Re$\,\lambda$ (largest)")
    ax.plot(k, ds["real"].isel(branch=1), color="C0", lw=1.0, ls="--", label=r"Re$\,\lambda$ (other root)")
    if modes is not None:
        km = np.asarray(modes["k"], dtype=float)
        km = np.where(km > np.pi, 2.0 * np.pi - km, km)
        ax.plot(
            km, modes["growth_rate"], "o", ms=3, mfc="none", color="C1", label=f"modes of the chain ($N = {len(km)}$)"
        )
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlim(0.0, np.pi)
    ax.set_xlabel(r"wavenumber $k$")
    ax.set_ylabel(r"Re$\,\lambda$")
    a = ds.attrs
    names = [n for n in ("K", "Kp", "V", "alpha", "sigma", "beta") if n in a and not isinstance(a[n], str)]
    ax.set_title(
        f"{a.get('model', '')}: {a.get('drive', '')} drive, {a.get('friction', '')} friction\n"
        + ", ".join(f"{n} = {a[n]:g}" for n in names),
        fontsize=8,
    )
    ax.legend(fontsize=8, loc="best")
    return fig
