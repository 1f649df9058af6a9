"""The figures of one chain run (eq. 4 or a relative), from Python or its run directory (``stickslip plot``).

One function per figure, each taking a :class:`~stickslip.run.outputs.ChainRun` (a run just made
or one read back with :func:`~stickslip.run.rundir.load_run`), drawing into ``ax`` when given and
returning the Figure: :func:`length` (L(t) against the steady length and the loading time),
:func:`snapshot` (the final state or a stored snapshot against steady sliding, Fig. 5a),
:func:`sizes` (the slip-size distribution of the stationary window with its truncated power-law
fit, Figs. 7, 8) and :func:`fronts` (the rupture fronts of the largest events with stored
displacement profiles, Fig. 6). :func:`run_figures` looks at what the run recorded and draws
every figure it supports; those it cannot (no events, no profiles) are listed with the reason.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from stickslip.analysis.stats.chain_runs import (
    front_statistics,
    run_size_statistics,
    stationary_events,
    stationary_from,
)
from stickslip.models.physics import chain_steady_length, has_steady_state, loading_time
from stickslip.models.presets import model_name, model_title
from stickslip.plotting.chain import fronts_figure, sizes_figure, snapshot_figure
from stickslip.plotting.style import FIGURE_FORMATS, PAPER, SIM, THEORY, new_figure, save_figure

__all__ = [
    "length",
    "snapshot",
    "sizes",
    "fronts",
    "RunFigure",
    "length_series",
    "run_figures",
    "draw_run_figures",
    "size_numbers",
    "MIN_EVENTS_FOR_SIZES",
]

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


def length_series(samples, params, *, ax=None) -> Figure:
    """L(t) = x_1 - x_N of a run against the exact steady length L_ss and the loading time L_ss / V
    (Fig. 5b's quantity over time); ``samples`` as :attr:`ChainRun.samples <stickslip.run.outputs.ChainRun>`."""
    fig, ax = new_figure(1, 1, width=6.0, height=3.2) if ax is None else (ax.figure, ax)
    ax.plot(samples["t"].values, samples["L"].values, color=SIM["color"], lw=0.7, label="$L(t) = x_1 - x_N$")
    if has_steady_state(params) and not params.drive_piece.leaf_spring:
        ax.axhline(chain_steady_length(params), **THEORY, label="steady sliding $L_{ss}$")
        t_load = loading_time(params)
        if math.isfinite(t_load) and t_load <= float(samples["t"].values[-1]) * 1.05:
            ax.axvline(t_load, **PAPER, label="loading time $L_{ss}/V$")
    ax.set_xlabel("$t$")
    ax.set_ylabel("$L$")
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title(f"$L(t)$\n{model_title(params)}", loc="left", fontsize=8)
    return fig


def length(run, *, ax=None) -> Figure:
    """L(t) = x_1 - x_N of ``run`` against the steady length L_ss and the loading time L_ss / V.

    Parameters
    ----------
    run : ChainRun
        A run of :func:`~stickslip.run.driver.run_chain` or one read by :func:`~stickslip.run.rundir.load_run`.
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new Figure if not given.

    Returns
    -------
    matplotlib.figure.Figure
        The Figure drawn in (that of ``ax`` when given).
    """
    return length_series(run.samples, run.params, ax=ax)


def snapshot(run, t: float | None = None, *, ax=None) -> Figure:
    """x_i - V t of ``run`` at its end (or at a stored snapshot time ``t``) against the exact
    discrete steady sliding profile and the paper's continuum form (Fig. 5a).

    Parameters
    ----------
    run : ChainRun
        A run whose model has steady sliding pulled from one end (eq. 4 and the train model).
    t : float, optional
        A time in ``run.snapshots["snapshot_time"]`` (``snapshot_times`` of the run); the end if
        not given.
    ax : matplotlib.axes.Axes, optional
        Draw the snapshot panel alone into this Axes; else a Figure with the residual beneath.

    Returns
    -------
    matplotlib.figure.Figure
    """
    p = run.params
    if not has_steady_state(p) or p.drive_piece.leaf_spring:
        raise ValueError(f"no steady sliding profile pulled from one end for this model ({model_name(p)})")
    if t is None:
        return snapshot_figure(run.state.blocks()["x"], p, float(run.summary["t_end"]), ax=ax)
    times = run.snapshots["snapshot_time"].values
    near = [float(s) for s in times if math.isclose(float(s), float(t), rel_tol=1e-9, abs_tol=0.5 * p.dt)]
    if not near:
        raise ValueError(f"no snapshot stored at t = {t:g} (stored: {', '.join(f'{s:g}' for s in times)})")
    return snapshot_figure(run.snapshots.sel(snapshot_time=near[0]), p, near[0], ax=ax)


def sizes(run, *, ax=None, bins: int = 30) -> Figure:
    """The slip-size distribution of ``run``'s stationary window with its truncated power-law
    fit (:func:`~stickslip.analysis.stats.chain_runs.run_size_statistics`), and S against time (Figs. 7, 8).

    Parameters
    ----------
    run : ChainRun
    ax : matplotlib.axes.Axes, optional
        Draw the distribution alone into this Axes; else a Figure with S against time beside it.
    bins : int
        Logarithmic bins of the density.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ParameterError
        With fewer than :data:`MIN_EVENTS_FOR_SIZES` slips with S > 0 in the stationary window, or
        where the sizes have no power-law fit (the message says why; one line).
    """
    from stickslip.models.params import ParameterError

    window = stationary_events(run)
    n_pos = int(np.count_nonzero(window["S"].to_numpy(dtype=float) > 0)) if len(window) else 0
    if n_pos < MIN_EVENTS_FOR_SIZES:
        raise ParameterError(
            f"{n_pos} slips with S > 0 at t >= {stationary_from(run):g} (the run's stationary window); "
            f"a size distribution needs at least {MIN_EVENTS_FOR_SIZES}: run longer"
        )
    try:
        stats = run_size_statistics(run, small_only=False)
    except ValueError as exc:
        raise ParameterError(f"no size distribution to draw: {exc}") from None
    return sizes_figure(window, stats["fit"], params=run.params, bins=bins, ax=ax)


def fronts(run, *, ax=None) -> Figure:
    """The rupture fronts of ``run``'s largest events with stored displacement profiles (Fig. 6):
    a run made with ``profile_window`` (20 in the paper).

    Parameters
    ----------
    run : ChainRun
    ax : matplotlib.axes.Axes or a pair of them, optional
        Draw the largest event's windows (and, given two Axes, its first moves) there.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if not run.profiles.sizes.get("profile_row", 0):
        raise ValueError("no displacement profiles stored (run with profile_window=20)")
    found = front_statistics(run, run.params.N, 0.0)
    if not found["fronts"]:
        raise ValueError("no event with stored profiles could be fitted")
    return fronts_figure(
        run.profiles,
        run.first_move,
        found["fronts"],
        run.params,
        labels=found["labels"],
        window=run.options.profile_window,
        ax=ax,
    )


class RunPlots:
    """The figures of one chain run (eq. 4), lent to it as ``run.plot`` (:mod:`stickslip.accessors`).

    Parameters
    ----------
    run : ChainRun
        The run drawn.

    Examples
    --------
    >>> import stickslip
    >>> run = stickslip.run_chain(stickslip.chain_params(N=10), 2e4)
    >>> type(run.plot.length()).__name__
    'Figure'
    """

    def __init__(self, run):
        self.run = run

    def length(self, *, ax=None) -> Figure:
        """L(t) against steady sliding (:func:`length`)."""
        return length(self.run, ax=ax)

    def snapshot(self, t: float | None = None, *, ax=None) -> Figure:
        """The final state, or the snapshot at ``t``, against steady sliding (Fig. 5a; :func:`snapshot`)."""
        return snapshot(self.run, t, ax=ax)

    def sizes(self, *, ax=None, bins: int = 30) -> Figure:
        """The slip-size distribution with its fit (Figs. 7, 8; :func:`sizes`)."""
        return sizes(self.run, ax=ax, bins=bins)

    def fronts(self, *, ax=None) -> Figure:
        """The rupture fronts of the largest events (Fig. 6; :func:`fronts`)."""
        return fronts(self.run, ax=ax)


def run_figures(run, *, max_snapshots: int = 4) -> list[RunFigure]:
    """The figures a chain run supports, in a fixed order: what ``stickslip plot`` draws.

    Parameters
    ----------
    run : ChainRun
        A run (``run_chain`` or ``load_run``).
    max_snapshots : int
        Most stored snapshots drawn (besides the final state).

    Returns
    -------
    list of RunFigure
        Each with its file stem, title and Figure, or None and why it was not drawn (``skipped``:
        no steady profile for this model, too few events, no stored profiles).
    """
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
                snapshot_figure(run.state.blocks()["x"], p, t_end),
            )
        )
        times = run.snapshots["snapshot_time"].values
        for t in [t for t in times if not math.isclose(float(t), t_end)][:max_snapshots]:
            out.append(
                RunFigure(
                    f"snapshot_t{float(t):.6g}",
                    f"snapshot at t = {float(t):g}",
                    snapshot_figure(run.snapshots.sel(snapshot_time=t), p, float(t)),
                )
            )
    else:
        out.append(RunFigure("snapshot_final", "final state", None, "no steady sliding profile for this model"))
    events = run.events
    # The stationary window shared with `reproduce` and `catalog` (analysis.stats.chain_runs.stationary_from).
    window = stationary_events(run)
    n_pos = int(np.count_nonzero(window["S"].to_numpy(dtype=float) > 0)) if len(window) else 0
    stats = None
    why = (
        f"{n_pos} events with S > 0 at t >= {stationary_from(run):g}, the stationary window "
        f"(a distribution needs {MIN_EVENTS_FOR_SIZES})"
    )
    if n_pos >= MIN_EVENTS_FOR_SIZES:
        try:
            stats = run_size_statistics(run, small_only=False)
        except ValueError as exc:  # no power law on the sizes: the figure says why
            why = f"no power-law fit: {exc}"
    if stats is not None:
        out.append(
            RunFigure(
                "sizes",
                f"slip-size distribution (events at t >= {stats['t_from']:g})",
                sizes_figure(window, stats["fit"], params=p),
                numbers=size_numbers(run, stats),
            )
        )
    else:
        out.append(
            RunFigure(
                "sizes",
                "slip-size distribution",
                None,
                why,
            )
        )
    if run.profiles.sizes.get("profile_row", 0) and len(events):
        fronts = front_statistics(run, p.N, 0.0)
        if fronts["fronts"]:
            fig = fronts_figure(
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
    """Save every figure of :func:`run_figures` as OUT_DIR/<stem>.<fmt>.

    Parameters
    ----------
    run : ChainRun
        A run.
    out_dir : str or Path
        The folder (``RUN_DIR/figures`` for ``stickslip plot``).
    formats : tuple of str
        File formats.

    Returns
    -------
    list of dict
        One record per figure: ``figure`` (stem), ``title``, and ``files`` written or ``skipped``
        with why; ``numbers`` where the figure has some (the size fit).
    """
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
