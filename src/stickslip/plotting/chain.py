"""The chain's figures (section 3; the paper's Figs. 5-8 for its own runs): any model of the family.

Each function takes results of a chain run (a snapshot of x_i, a table of <L> against beta, the
``profiles``/``first_move``/``events`` tables) and analysis results from
:mod:`stickslip.analysis.stats.statistics`, and returns a matplotlib Figure; given ``ax``, it draws its
main panel into that Axes and returns the Axes' Figure. Titles name the model and the parameters
it reads (:func:`stickslip.models.presets.model_title`); "Fig. N" appears only on the paper's
runs (:func:`stickslip.models.presets.is_paper_run`) or where the caller names the figure
(``paper_figure``). Blocks are numbered 1..N. The paper's names (``fig5a_snapshot``, ...) stay
as aliases.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr
from matplotlib import cm
from matplotlib.figure import Figure

from stickslip.analysis.stats.statistics import EdgeSpeed, FrontSpeed, PowerLawFit, central_interval, size_distribution
from stickslip.models.params import ChainParams
from stickslip.models.physics import chain_steady_length, chain_steady_profile_paper, chain_steady_state
from stickslip.models.presets import is_paper_model, is_paper_run, model_title
from stickslip.plotting.style import PAPER, SIM, THEORY, new_figure, ordinal

__all__ = [
    "snapshot_figure",
    "length_against_beta",
    "fronts_figure",
    "sizes_figure",
    "fig5a_snapshot",
    "fig5b_length",
    "fig6_fronts",
    "fig7_8_sizes",
    "PAPER_FRONT_SPEED",
]

# The paper's rupture-front speed in large events at beta = 1 (section 3, Fig. 6).
PAPER_FRONT_SPEED = 1.43


def _title(
    what: str, params: ChainParams | None, paper_figure: str | None, number: str, *, wrap: bool = False, **kw: Any
) -> str:
    """``what`` and the model (when ``params`` are known; on a line of its own with ``wrap``, for
    one panel among others), headed by the paper's figure number where the run is the paper's
    (``number``) or the caller names one (``paper_figure``)."""
    if paper_figure is None and params is not None and is_paper_run(params):
        paper_figure = number
    head = f"{paper_figure}: " if paper_figure else ""
    return head + what + (("\n" if wrap else ", ") + model_title(params, **kw) if params is not None else "")


def _snapshot_array(x: Any, N: int) -> np.ndarray:
    # a snapshot picked from a (time, block) array may keep a time axis of length 1
    values = np.squeeze(np.asarray(x.values if isinstance(x, xr.DataArray) else x, dtype=np.float64))
    if values.ndim != 1 or values.size != N:
        raise ValueError(f"the snapshot must hold x_i for i = 1..N = {N} (got shape {values.shape})")
    return values


def snapshot_figure(x: Any, params: ChainParams, t: float, *, ax=None, paper_figure: str | None = None) -> Figure:
    """A snapshot of x_i at time t against the steady sliding profile (the paper's Fig. 5a).

    Top: x_i - V t of the run (solid), of the exact discrete steady sliding solution
    (:func:`~stickslip.models.physics.chain_steady_state`, dashed) and of the paper's continuum form
    x_i = V t - c/K {N^2 - (i - N)^2}/2 (dotted), in the frame of the pulling point x_0 = V t.
    Bottom: the run's departure from the exact steady profile, and the continuum form's, which lies
    c i / (2K) above it (about 20 at the free end of the paper's chain).

    Parameters
    ----------
    x : array_like or xarray.DataArray
        x_1..x_N (``run.state.blocks()["x"]``, or one time of ``run.snapshots``).
    params : ChainParams
        The chain (end drive).
    t : float
        The snapshot's time.
    ax : matplotlib.axes.Axes, optional
        Draw only the top panel, into this Axes.
    paper_figure : str, optional
        The paper's figure this is (by default named only for the paper's own runs).

    Returns
    -------
    matplotlib.figure.Figure
    """
    xs = _snapshot_array(x, params.N)
    i = np.arange(1, params.N + 1)
    shift = params.V * t
    exact = chain_steady_state(params, t)["x"]
    paper = chain_steady_profile_paper(params, t)
    if ax is None:
        fig, (ax, ax_r) = new_figure(
            2, 1, width=6.0, height=2.4, sharex=True, gridspec_kw={"height_ratios": [2.2, 1.0]}
        )
    else:
        fig, ax_r = ax.figure, None
    ax.plot(i, xs - shift, **SIM, label=f"$x_i$ at t = {t:.4g}")
    ax.plot(i, exact - shift, **THEORY, label="steady sliding, exact discrete")
    ax.plot(i, paper - shift, **PAPER, label="steady sliding, paper's continuum form")
    ax.set_ylabel(r"$x_i - Vt$")
    ax.legend(loc="upper right", fontsize=8)
    title = _title(
        f"snapshot at $t = {t:.4g}$ and steady sliding", params, paper_figure, "Fig. 5(a)", wrap=ax_r is None
    )
    if ax_r is None:
        ax.set_xlabel("block $i$")
        ax.set_title(title, loc="left", fontsize=8)
        return fig
    ax_r.axhline(0.0, color="0.6", lw=0.6)
    ax_r.plot(i, xs - exact, **SIM, label="run - exact")
    ax_r.plot(i, paper - exact, **PAPER, label="continuum - exact")
    ax_r.set_xlabel("block $i$")
    ax_r.set_ylabel(r"$x_i - x_i^{ss}$")
    ax_r.set_xlim(1, params.N)
    ax_r.legend(loc="lower left", fontsize=8)
    fig.suptitle(title, fontsize=9, wrap=True)
    return fig


def length_against_beta(
    table: pd.DataFrame, params: ChainParams, *, beta_c: float = 1.0, ax=None, paper_figure: str | None = None
) -> Figure:
    """Average total length <L> = <x_1 - x_N> against beta, with steady sliding (the paper's Fig. 5b).

    The dashed line is the exact discrete steady length L_ss = (c/K) N (N - 1) / 2 with
    c = 1 - (1 - beta) V (:func:`~stickslip.models.physics.chain_steady_length`); the paper's
    printed L = c N^2 / 2 lacks the factor 1/K (docs/model.md) and is not drawn. The dotted line
    marks beta_c, where the long-wave instability sets in (Fig. 4).

    Parameters
    ----------
    table : pandas.DataFrame
        Columns ``beta`` and ``L_mean``, optionally ``L_err`` (error bars) and ``final_state``
        (runs above beta_c not settled into steady sliding are drawn open), e.g. a sweep's summary.
    params : ChainParams
        The chain's other parameters.
    beta_c : float
        The linear threshold marked.
    ax : matplotlib.axes.Axes, optional
        Draw into this Axes.
    paper_figure : str, optional
        The paper's figure this is.

    Returns
    -------
    matplotlib.figure.Figure
    """
    data = table.sort_values("beta")
    beta = data["beta"].to_numpy(dtype=np.float64)
    L = data["L_mean"].to_numpy(dtype=np.float64)
    err = data["L_err"].to_numpy(dtype=np.float64) if "L_err" in data else None
    fig, ax = new_figure(width=5.6, height=3.8) if ax is None else (ax.figure, ax)
    lo, hi = (float(beta.min()), float(beta.max())) if beta.size else (0.0, 2.0)
    pad = 0.05 * max(hi - lo, 0.1)
    grid = np.linspace(max(lo - pad, 0.0), hi + pad, 200)
    steady = np.array([chain_steady_length(params.replace(beta=float(b))) for b in grid])
    ax.plot(
        grid,
        steady,
        **THEORY,
        label="steady sliding, $L_{ss} = (c/K)\\,N(N-1)/2$,\n$c = 1 - (1-\\beta)V$ (paper prints $cN^2/2$, "
        "without 1/K)",
    )
    ax.errorbar(
        beta, L, yerr=err, fmt="o-", color=SIM["color"], lw=SIM["lw"], ms=4, capsize=2, label=r"$\langle L\rangle$, run"
    )
    if "final_state" in data:
        unsettled = (beta > beta_c) & (data["final_state"].to_numpy() != "steady sliding")
        if unsettled.any():
            # open symbols over the filled ones: not settled by the end of the run
            ax.scatter(
                beta[unsettled],
                L[unsettled],
                s=30,
                facecolors="white",
                edgecolors=SIM["color"],
                zorder=3,
                label="not settled into steady sliding\nby the end of the run",
            )
    ax.axvline(beta_c, color="0.5", lw=0.8, ls=":")
    ax.annotate(
        rf"$\beta_c = {beta_c:g}$ (Fig. 4)",
        (beta_c, 0.97),
        xycoords=("data", "axes fraction"),
        xytext=(-3, 0),
        textcoords="offset points",
        ha="right",
        va="top",
        fontsize=8,
        color="0.35",
    )
    ax.set_xlabel(r"$\beta$")
    ax.set_ylabel(r"$L = \langle x_1 - x_N \rangle$")
    ax.legend(loc="lower right", fontsize=7)
    what = r"average length against $\beta$"
    ax.set_title(_title(what, params, paper_figure, "Fig. 5(b)", skip=("dt", "beta")), loc="left", fontsize=8)
    return fig


def _event_profiles(profiles: xr.Dataset, event: int) -> xr.Dataset:
    rows = np.flatnonzero(profiles["profile_event"].values == event)
    if rows.size == 0:
        raise ValueError(f"no displacement profiles stored for event {event}")
    sub = profiles.isel(profile_row=rows)
    return sub.isel(profile_row=np.argsort(sub["profile_t"].values, kind="stable"))


def _nice(x: float) -> float:
    """A round number (1, 2 or 5 times a power of ten) not above x."""
    if not x > 0:
        return 1.0
    e = math.floor(math.log10(x))
    m = x / 10**e
    return (5.0 if m >= 5 else 2.0 if m >= 2 else 1.0) * 10**e


def _advance(edge: EdgeSpeed) -> int:
    """Number of windows up to the one whose edge first reaches the farthest block."""
    return int(np.argmax(edge.edges)) + 1


#: Most windows a waterfall draws: more would shrink the scale bar to a dot (a long event of the
#: paper's chain has a hundred windows); the others are left out evenly.
MAX_WINDOWS = 12


def _waterfall(ax, sub: xr.Dataset, window: float | None, edge: EdgeSpeed | None = None) -> None:
    """Delta x_i over successive windows, each curve lifted by its place, with a scale bar (Fig. 6).

    Curves are lifted by a little more than the largest Delta x_i, so they do not overlap; the
    bar at the right gives the Delta x_i scale. At most :data:`MAX_WINDOWS` windows are drawn,
    evenly spaced from the first. ``edge``: the leading edge of each window (marks).
    """
    dx = sub["profile_dx"].transpose("profile_row", "block").values
    blocks = sub["block"].values if "block" in sub.coords else np.arange(1, dx.shape[1] + 1)
    t = sub["profile_t"].values
    every = max(1, int(math.ceil(dx.shape[0] / MAX_WINDOWS)))
    shown = np.arange(0, dx.shape[0], every)
    n = shown.size
    peak = float(np.nanmax(np.abs(dx[shown]))) if np.isfinite(dx[shown]).any() else 1.0
    step = 1.1 * peak if peak > 0 else 1.0
    colors = cm.viridis(np.linspace(0.0, 0.9, max(n, 1)))
    for k, row in enumerate(shown):
        ax.plot(blocks, dx[row] + k * step, color=colors[k], lw=0.9)
    if edge is not None and len(edge.edges) == dx.shape[0]:
        marked = shown[shown < _advance(edge)]
        ax.scatter(
            np.asarray(edge.edges)[marked],
            np.arange(marked.size) * step,
            marker="|",
            s=60,
            color="C3",
            zorder=3,
            label=rf"leading edge ($\Delta x_i \geq {edge.edge_fraction:g}\,\max_i \Delta x_i$)",
        )
        ax.legend(loc="upper left", fontsize=7)
    ticks = np.arange(n) * step
    stride = max(1, int(math.ceil(n / 8)))
    ax.set_yticks(ticks[::stride])
    ax.set_yticklabels([f"{t[row] - t[0]:.0f}" for row in shown[::stride]])
    bar = _nice(0.8 * peak)
    x_bar = blocks.max() + 0.03 * (blocks.max() - blocks.min())
    ax.vlines([x_bar], 0.0, bar, color="k", lw=2.0, clip_on=False)
    ax.annotate(
        rf"$\Delta x_i = {bar:g}$",
        (x_bar, bar / 2),
        xytext=(4, 0),
        textcoords="offset points",
        rotation=90,
        va="center",
        ha="left",
        fontsize=8,
        annotation_clip=False,
    )
    ax.set_ylabel(r"window start $t - t_s$", fontsize=9)
    ax.set_xlabel("block $i$")
    ax.set_xlim(blocks.min(), blocks.max())
    w = f"{window:g}" if window else "W"
    every_text = f", every {ordinal(every)} window" if every > 1 else ""
    ax.text(
        0.99,
        0.01,
        rf"curves: $\Delta x_i$ over $\Delta t = {w}${every_text}",
        transform=ax.transAxes,
        ha="right",
        va="bottom",
        fontsize=7,
        color="0.3",
    )


def _arrivals(
    ax, first_move: pd.DataFrame, front: FrontSpeed, K: float, edge: EdgeSpeed | None = None, paper: bool = True
) -> None:
    """First-move time against block, the fitted front, the paper's c (``paper``) and the sound speed."""
    rows = first_move[(first_move["event"] == front.event) & np.isfinite(first_move["t_first"])]
    i = rows["block"].to_numpy()
    t = rows["t_first"].to_numpy() - front.t_start
    used = (i >= front.i_min) & (i <= front.i_max)
    ax.plot(i[~used], t[~used], ".", color="0.6", ms=2.5, label="first motion")
    ax.plot(i[used], t[used], ".", color=SIM["color"], ms=2.5, label="first motion (fitted)")
    line_i = np.array([front.i_min, front.i_max], dtype=np.float64)
    t_anchor = float(front.arrival_time(front.i_min)) - front.t_start
    ax.plot(
        line_i,
        front.arrival_time(line_i) - front.t_start,
        **THEORY,
        label=f"fit: $c = {front.speed:.3g} \\pm {front.speed_err:.2g}$",
    )
    if paper:
        ax.plot(
            line_i,
            t_anchor + (line_i - front.i_min) / PAPER_FRONT_SPEED,
            **PAPER,
            label=f"paper: $c = {PAPER_FRONT_SPEED}$",
        )
    sound = math.sqrt(K)
    ax.plot(
        line_i,
        t_anchor + (line_i - front.i_min) / sound,
        color="0.2",
        lw=0.9,
        ls="-.",
        label=f"sound speed $\\sqrt{{K}} = {sound:.3g}$",
    )
    if edge is not None:
        # window ends at which the edge had advanced to a block (upper bounds of its arrival)
        k = _advance(edge)
        ax.scatter(
            edge.edges[:k],
            np.asarray(edge.times[:k]) - front.t_start,
            marker="|",
            s=40,
            color="C3",
            label=f"leading edge of the windows: $c = {edge.speed:.3g}$",
        )
    ax.set_xlabel("block $i$")
    ax.set_ylabel("first-move time $t - t_s$")
    ax.legend(loc="upper left", fontsize=7)


def _speed_histogram(ax, speeds: np.ndarray, title: str, level: float = 0.9) -> None:
    """Per-event front speeds with the paper's c, its percentile and the central ``level`` (Fig. 6)."""
    x = np.asarray(speeds, dtype=np.float64)
    x = x[np.isfinite(x)]
    ax.set_title(title, loc="left", fontsize=9, wrap=True)
    ax.set_xlabel("front speed $c$ (blocks per time unit)")
    ax.set_ylabel("events")
    if x.size == 0:
        ax.text(0.5, 0.5, "no event", transform=ax.transAxes, ha="center")
        return
    ci = central_interval(x, PAPER_FRONT_SPEED, level=level)
    lo = min(float(x.min()), PAPER_FRONT_SPEED)
    hi = max(float(x.max()), PAPER_FRONT_SPEED)
    ax.hist(
        x,
        bins=np.linspace(lo - 0.02, hi + 0.02, 31),
        color=SIM["color"],
        alpha=0.8,
        label=f"{x.size} events reaching block $N$",
    )
    ax.axvspan(ci.lo, ci.hi, color="0.85", zorder=0, label=f"central {100 * level:.0f}%: ${ci.lo:.3g}$-${ci.hi:.3g}$")
    ax.axvline(ci.median, color=SIM["color"], lw=1.0, ls="--", label=f"median ${ci.median:.3g}$")
    ax.axvline(
        PAPER_FRONT_SPEED,
        **{**PAPER, "lw": 1.6},
        label=f"paper: $c = {PAPER_FRONT_SPEED}$, percentile {ci.percentile:.0f}",
    )
    ax.legend(loc="upper left", fontsize=7)


def fronts_figure(
    profiles: xr.Dataset,
    first_move: pd.DataFrame,
    fronts: Sequence[FrontSpeed],
    params: ChainParams,
    *,
    labels: Sequence[str] | None = None,
    window: float | None = 20.0,
    edges: Sequence[EdgeSpeed | None] | None = None,
    speeds: pd.DataFrame | None = None,
    ax=None,
    paper_figure: str | None = None,
) -> Figure:
    """Rupture fronts, one row per event (the paper's Fig. 6: (a) a large, (b) an intermediate event).

    Left: the displacement Delta x_i = x_i(t + Delta t) - x_i(t) over successive windows of
    Delta t = ``window`` (20 in the paper) from the event's start, stacked upwards in time like
    the paper's plot, with a scale bar for Delta x_i. Right: the time each block first moved
    against i, the front speed fitted over the far part of the chain
    (:func:`~stickslip.analysis.stats.statistics.front_speed`), the sound speed sqrt(K) (3.16 for
    K = 10) and, for the paper's chain, its c = 1.43 as slopes from the same point.

    Parameters
    ----------
    profiles : xarray.Dataset
        The stored windows, ``ChainRun.profiles``: ``profile_dx`` over (``profile_row``,
        ``block``) with ``profile_event`` and ``profile_t`` per row.
    first_move : pandas.DataFrame
        ``ChainRun.first_move``: columns ``event``, ``block``, ``t_first``.
    fronts : sequence of FrontSpeed
        The fitted fronts, one per event drawn (:func:`~stickslip.analysis.stats.statistics.front_speed`).
    params : ChainParams
        The run's model (titles, sqrt(K), the paper's c only for eq. 4).
    labels : sequence of str, optional
        One label per front (default ``event <number>``).
    window : float or None
        Delta t of the windows, for the axis label.
    edges : sequence of EdgeSpeed or None, optional
        The leading edge of each front's windows, marked in both panels.
    speeds : pandas.DataFrame, optional
        Columns ``c_first_move`` and ``c_leading_edge``, one row per event that reached block N:
        adds a last row, the per-event distribution of c by both definitions with the paper's
        value and its percentile.
    ax : matplotlib.axes.Axes or a pair of them, optional
        Draw the first front's windows (and, given two Axes, its first moves) there.
    paper_figure : str, optional
        The paper's figure this drawing is (``"Fig. 6"``); by default named only for the
        paper's own runs.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fronts = list(fronts)
    if not fronts:
        raise ValueError("give at least one fitted front")
    if labels is None:
        labels = [f"event {f.event}" for f in fronts]
    edges = list(edges) if edges is not None else [None] * len(fronts)
    paper = is_paper_model(params)
    if ax is not None:
        pair = list(np.ravel(ax))
        sub = _event_profiles(profiles, fronts[0].event)
        _waterfall(pair[0], sub, window, edges[0])
        t0 = float(sub["profile_t"].values[0])
        pair[0].set_title(f"{labels[0]}, $t_s \\approx {t0:.6g}$", loc="left", fontsize=8)
        if len(pair) > 1:
            _arrivals(pair[1], first_move, fronts[0], params.K, edges[0], paper)
            pair[1].set_title(f"front: blocks {fronts[0].i_min}-{fronts[0].i_max}", loc="left", fontsize=8)
        return pair[0].figure
    n_rows = len(fronts) + (1 if speeds is not None else 0)
    fig, axes = new_figure(n_rows, 2, width=5.2, height=3.6)
    axes = np.asarray(axes).reshape(n_rows, 2)
    letters = "abcdefgh"
    for row, (front, label, edge) in enumerate(zip(fronts, labels, edges, strict=False)):
        ax_w, ax_t = axes[row]
        sub = _event_profiles(profiles, front.event)
        _waterfall(ax_w, sub, window, edge)
        letter = letters[row] if row < 8 else str(row)
        t0 = float(sub["profile_t"].values[0])
        ax_w.set_title(f"({letter}) {label}, $t_s \\approx {t0:.6g}$", loc="left", fontsize=9, wrap=True)
        _arrivals(ax_t, first_move, front, params.K, edge, paper)
        ax_t.set_title(f"front: blocks {front.i_min}-{front.i_max}", loc="left", fontsize=9, wrap=True)
    if speeds is not None:
        letter = letters[len(fronts)]
        _speed_histogram(
            axes[-1, 0], speeds["c_first_move"].to_numpy(dtype=float), f"({letter}) per event: first motion, far half"
        )
        _speed_histogram(
            axes[-1, 1],
            speeds["c_leading_edge"].to_numpy(dtype=float),
            f"({letter}) per event: leading edge of the windows",
        )
    fig.suptitle(_title("rupture fronts", params, paper_figure, "Fig. 6"), fontsize=9, wrap=True)
    return fig


def sizes_figure(
    events: pd.DataFrame,
    fit: PowerLawFit,
    beta: float | None = None,
    *,
    params: ChainParams | None = None,
    bins: int | Any = 30,
    paper_tau: float | None = None,
    ax=None,
    paper_figure: str | None = None,
) -> Figure:
    """Slip sizes: (a) their distribution with the fitted power law, (b) S against event time (the
    paper's Figs. 7 at beta = 1 and 8 at beta = 0.2).

    (a): the density of S on logarithmic bins
    (:func:`~stickslip.analysis.stats.statistics.size_distribution`) with the fitted power law
    p ~ S^-tau over [s_min, s_max], scaled by the share of events in that range. (b): S of every
    event against its start time.

    Parameters
    ----------
    events : pandas.DataFrame
        The events (``S``, ``t_start``), usually the stationary window's.
    fit : PowerLawFit
        The fit drawn (:func:`~stickslip.analysis.stats.statistics.fit_power_law`).
    beta : float, optional
        For the title, without ``params``.
    params : ChainParams, optional
        The model the title names.
    bins : int or array_like
        Bins of the density.
    paper_tau : float, optional
        The paper's exponent (1.5 at beta = 1, about 1.6 at beta = 0.2) as a dotted guide below
        the fit.
    ax : matplotlib.axes.Axes, optional
        Draw only (a), into this Axes.
    paper_figure : str, optional
        The paper's figure this is.

    Returns
    -------
    matplotlib.figure.Figure
    """
    S = events["S"].to_numpy(dtype=np.float64)
    dist = size_distribution(S, bins)
    if ax is None:
        fig, (ax_a, ax_b) = new_figure(1, 2, width=4.8, height=3.8)
    else:
        fig, ax_a, ax_b = ax.figure, ax, None
    filled = dist["count"].values > 0
    ax_a.loglog(
        dist["S"].values[filled],
        dist["density"].values[filled],
        "o",
        color=SIM["color"],
        ms=4,
        label=f"simulation ({dist.attrs['n_binned']} events)",
    )
    share = fit.n / dist.attrs["n_binned"] if dist.attrs["n_binned"] else 1.0
    s_line = np.geomspace(fit.s_min, fit.s_max, 100)
    err = f" ± {fit.tau_err:.2f}" if math.isfinite(fit.tau_err) else ""
    ax_a.loglog(
        s_line,
        share * fit.pdf(s_line),
        **THEORY,
        label=f"fit: $\\tau = {fit.tau:.2f}${err}\n($S \\in [{fit.s_min:.3g}, {fit.s_max:.3g}]$, {fit.n} events)",
    )
    if paper_tau is not None:
        # a guide of the paper's slope a factor PAPER_GUIDE_BELOW under the fit, not hidden by it
        s_mid = math.sqrt(fit.s_min * fit.s_max)
        anchor = share * float(fit.pdf(s_mid)) / PAPER_GUIDE_BELOW
        ax_a.loglog(
            s_line,
            anchor * (s_line / s_mid) ** (-paper_tau),
            **{**PAPER, "lw": 1.4},
            label=f"paper: slope $-{paper_tau:g}$ (set {PAPER_GUIDE_BELOW:g}x lower)",
        )
    ax_a.set_xlabel("$S$")
    ax_a.set_ylabel("$p(S)$")
    ax_a.legend(loc="lower left", fontsize=8)
    number = {1.0: "Fig. 7", 0.2: "Fig. 8"}.get(round(float(params.beta if params else beta or 0.0), 6), "")
    what = r"slip sizes $S = \sum_i \Delta x_i$"
    if params is None and beta is not None:
        what += f" at $\\beta = {beta:g}$"
    title = _title(what, params, paper_figure, number, wrap=ax_b is None)
    if ax_b is None:
        ax_a.set_title(title, loc="left", fontsize=8)
        return fig
    ax_a.set_title("(a)", loc="left")
    t = events["t_start"].to_numpy(dtype=np.float64)
    positive = S > 0
    ax_b.semilogy(t[positive], S[positive], ".", color=SIM["color"], ms=2.0)
    ax_b.set_xlabel("event start time $t$")
    ax_b.set_ylabel("$S$")
    ax_b.set_title("(b)", loc="left")
    fig.suptitle(title, fontsize=9, wrap=True)
    return fig


#: The paper's slope is drawn this factor below the fit (the two nearly coincide on its runs).
PAPER_GUIDE_BELOW = 3.0

# The paper's names of the figures, kept for scripts that use them.
fig5a_snapshot = snapshot_figure
fig5b_length = length_against_beta
fig6_fronts = fronts_figure
fig7_8_sizes = sizes_figure
