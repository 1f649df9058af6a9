"""Every figure one chain run (eq. 4) supports, drawn from its run directory (``stickslip plot``).

:func:`run_figures` looks at what the run recorded and draws: L(t) against the steady length and
the loading time (Fig. 5b's quantity over time); the final state, and each stored snapshot,
against the steady sliding profile (Fig. 5a); the slip-size distribution with its truncated
power-law fit (Figs. 7, 8); the rupture fronts of the largest events with stored displacement
profiles (Fig. 6). Figures a run cannot support (no events, no profiles) are listed with the reason.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from stickslip.analysis.chain_runs import front_statistics, run_size_statistics, stationary_events, stationary_from
from stickslip.models.physics import chain_steady_length, has_steady_state, loading_time
from stickslip.plotting.chain import fig5a_snapshot, fig6_fronts, fig7_8_sizes
from stickslip.plotting.style import FIGURE_FORMATS, PAPER, SIM, THEORY, new_figure, save_figure

__all__ = ["RunFigure", "length_series", "run_figures", "draw_run_figures", "size_numbers", "MIN_EVENTS_FOR_SIZES"]

#: Fewest events with S > 0 for a size distribution and its fit.
MIN_EVENTS_FOR_SIZES = 50


@dataclass(frozen=True)
class RunFigure:
    """One figure of a run: file stem, title, and the Figure (None, with ``skipped``, if not drawn)."""

    stem: str
    title: str
    figure: Figure | None
    skipped: str = ""
    numbers: dict | None = None


def length_series(samples, params) -> Figure:
    """L(t) = x_1 - x_N of a run against the exact steady length L_ss and the loading time L_ss / V."""
    fig, ax = new_figure(1, 1, width=6.0, height=3.2)
    ax.plot(samples["t"].values, samples["L"].values, color=SIM["color"], lw=0.7, label="$L(t) = x_1 - x_N$")
    if has_steady_state(params) and not params.drive_piece.leaf_spring:
        ax.axhline(chain_steady_length(params), **THEORY, label="steady sliding $L_{ss}$")
        t_load = loading_time(params)
        if math.isfinite(t_load) and t_load <= float(samples["t"].values[-1]) * 1.05:
            ax.axvline(t_load, **PAPER, label="loading time $L_{ss}/V$")
    ax.set_xlabel("$t$")
    ax.set_ylabel("$L$")
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title(f"$L(t)$, $\\beta$ = {params.beta:g}, N = {params.N}", loc="left", fontsize=9)
    return fig


def run_figures(run, *, max_snapshots: int = 4) -> list[RunFigure]:
    """The figures ``run`` (a :class:`~stickslip.run.outputs.ChainRun`) supports, in a fixed order."""
    p = run.params
    out = []
    if run.samples.sizes.get("t", 0) > 1:
        out.append(RunFigure("length", "L(t)", length_series(run.samples, p)))
    else:
        out.append(RunFigure("length", "L(t)", None, "fewer than two samples of L"))
    steady = has_steady_state(p) and not p.drive_piece.leaf_spring
    t_end = float(run.summary["t_end"])
    if steady:
        out.append(
            RunFigure(
                "snapshot_final",
                f"final state at t = {t_end:g} against steady sliding",
                fig5a_snapshot(run.state.blocks()["x"], p, t_end),
            )
        )
        times = run.snapshots["time"].values if "time" in run.snapshots.dims else []
        for t in [t for t in times if not math.isclose(float(t), t_end)][:max_snapshots]:
            out.append(
                RunFigure(
                    f"snapshot_t{float(t):.6g}",
                    f"snapshot at t = {float(t):g}",
                    fig5a_snapshot(run.snapshots.sel(time=t), p, float(t)),
                )
            )
    else:
        out.append(RunFigure("snapshot_final", "final state", None, "no steady sliding profile for this model"))
    events = run.events
    # The stationary window shared with `reproduce` and `catalog` (analysis.chain_runs.stationary_from).
    window = stationary_events(run)
    n_pos = int(np.count_nonzero(window["S"].to_numpy(dtype=float) > 0)) if len(window) else 0
    if n_pos >= MIN_EVENTS_FOR_SIZES:
        stats = run_size_statistics(run, small_only=False)
        out.append(
            RunFigure(
                "sizes",
                f"slip-size distribution (events at t >= {stats['t_from']:g})",
                fig7_8_sizes(window, stats["fit"], p.beta),
                numbers=size_numbers(run, stats),
            )
        )
    else:
        out.append(
            RunFigure(
                "sizes",
                "slip-size distribution",
                None,
                f"{n_pos} events with S > 0 at t >= {stationary_from(run):g}, the stationary window "
                f"(a distribution needs {MIN_EVENTS_FOR_SIZES})",
            )
        )
    if run.profiles.sizes.get("row", 0) and len(events):
        fronts = front_statistics(run, p.N, 0.0)
        if fronts["fronts"]:
            fig = fig6_fronts(
                run.profiles,
                run.first_move,
                fronts["fronts"],
                p,
                labels=fronts["labels"],
                window=run.options.profile_window,
            )
            out.append(RunFigure("fronts", "rupture fronts of the largest events", fig))
        else:
            out.append(RunFigure("fronts", "rupture fronts", None, "no event with stored profiles could be fitted"))
    else:
        out.append(
            RunFigure(
                "fronts", "rupture fronts", None, "no displacement profiles stored (run with --profile-window 20)"
            )
        )
    return out


def size_numbers(run, stats: dict) -> dict:
    """The exponent of the sizes figure and, where the run has system-spanning events, the one
    below the smallest of them (Fig. 8's reading), as ``plot --json`` reports them."""
    fit = stats["fit"]
    numbers = {
        "t_from": stats["t_from"],
        "tau": fit.tau,
        "tau_err": fit.tau_err,
        "s_min": fit.s_min,
        "s_max": fit.s_max,
        "n": fit.n,
        "n_spanning": stats["n_spanning"],
    }
    if stats["n_spanning"]:
        try:
            small = run_size_statistics(run, small_only=True)["fit"]
        except ValueError:
            small = None
        numbers["tau_below_span"] = small.tau if small is not None else None
    return numbers


def draw_run_figures(run, out_dir: str | Path, *, formats: tuple[str, ...] = FIGURE_FORMATS) -> list[dict]:
    """Save every figure of :func:`run_figures` as OUT_DIR/<stem>.<fmt>; one record per figure."""
    records = []
    for item in run_figures(run):
        record = {"figure": item.stem, "title": item.title}
        if item.numbers is not None:
            record["numbers"] = item.numbers
        if item.figure is None:
            record["skipped"] = item.skipped
        else:
            files = save_figure(item.figure, Path(out_dir) / item.stem, formats=formats)
            record["files"] = [str(f) for f in files]
        records.append(record)
    return records
