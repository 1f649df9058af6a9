"""Figures of a lattice run (docs/lattice.md, "Figures"): the state over (row, col) as images,
the slip map of an event and its rupture front as a sequence of frames.

Each function takes a :class:`~stickslip.run.lattice.LatticeRun` (from
:func:`~stickslip.run.lattice.run_lattice`, or a run directory read back with
:func:`~stickslip.run.lattice_dir.load_lattice_run`) and returns a matplotlib Figure; none calls
``show()``. Images are drawn with row 1 at the top and column 1 at the left, as the square's
sides are named (docs/lattice.md, "Edges"). The slip map and the rupture frames need the event's
fields, recorded by ``run_lattice(..., slip_maps=K)`` (``stickslip chain --lattice ...
--slip-maps K``). The run lends them as ``run.plot`` (:class:`LatticePlots`) and
``run.plot_snapshot()``, ``run.plot_event()``, ``run.plot_rupture()``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from stickslip.models.params import ParameterError
from stickslip.plotting.style import FIGURE_FORMATS, new_figure, save_figure

__all__ = ["LatticePlots", "snapshot_images", "slip_map", "rupture_frames", "draw_lattice_figures"]

_LABELS = {"x": "$x$", "v": "$v$", "theta": "$\\theta$", "stopped": "stopped"}
_CMAPS = {"x": "viridis", "v": "magma", "theta": "cividis", "stopped": "Greys"}


def _title(run) -> str:
    return f"{run.params.model} on the {run.params.lattice.describe()}"


def _extent(shape: tuple[int, int]) -> tuple[float, float, float, float]:
    rows, cols = shape
    return 0.5, cols + 0.5, rows + 0.5, 0.5


def _state_at(run, t: float | None) -> tuple[dict[str, np.ndarray], float]:
    """The fields over (row, col) at the end (t None) or of the snapshot nearest t."""
    if t is None:
        f = run.final()
        return {k: f[k].values for k in f.data_vars}, float(run.summary.get("t_end", np.nan))
    if run.snapshots is None:
        raise ParameterError("t: the run kept no snapshots (run_lattice(..., snapshot_every=T))")
    i = int(np.argmin(np.abs(run.snapshots["time"].values - float(t))))
    snap = run.snapshots.isel(time=i)
    return {k: snap[k].values for k in snap.data_vars}, float(snap["time"].values)


def snapshot_images(run, t: float | None = None, *, fields=("x", "v", "stopped")) -> Figure:
    """The state over (row, col) as images, one panel per field, at the end of the run or at
    the snapshot nearest ``t``.

    Parameters
    ----------
    run : LatticeRun
        A lattice run.
    t : float, optional
        The time of a snapshot (the nearest kept one); the final state by default.
    fields : sequence of str
        Of ``x``, ``v``, ``theta``, ``stopped``.

    Returns
    -------
    matplotlib.figure.Figure
        One Axes per field with its image of shape (rows, cols), and their colour bars.
    """
    state, time = _state_at(run, t)
    fields = tuple(fields)
    unknown = [f for f in fields if f not in _LABELS]
    if unknown or not fields:
        raise ParameterError(f"fields must be some of {', '.join(_LABELS)} (got {', '.join(map(str, fields))})")
    rows, cols = run.params.lattice.shape
    aspect = rows / cols
    fig, axes = new_figure(1, len(fields), width=3.6, height=max(1.6, 3.2 * min(aspect, 1.5) + 0.6))
    for ax, name in zip(np.atleast_1d(axes), fields, strict=True):
        data = np.asarray(state[name], dtype=float)
        im = ax.imshow(data, cmap=_CMAPS[name], extent=_extent((rows, cols)), interpolation="nearest")
        fig.colorbar(im, ax=ax, shrink=0.8)
        ax.grid(False)
        ax.set_title(_LABELS[name], fontsize=9)
        ax.set_xlabel("column")
        ax.set_ylabel("row")
    fig.suptitle(f"{_title(run)}, t = {time:g}", fontsize=9)
    return fig


def _event_index(run, event: int | None) -> int:
    """The position of ``event`` (default the largest by moment) among the recorded fields."""
    f = run.event_fields
    if f is None or f.sizes.get("event", 0) == 0:
        raise ParameterError(
            "the run recorded no event's fields: run_lattice(..., slip_maps=K) or stickslip chain --slip-maps K"
        )
    ids = f["event"].values
    if event is None:
        return int(np.argmax(f["moment"].values))
    hits = np.flatnonzero(ids == int(event))
    if not hits.size:
        raise ParameterError(f"event {event} has no recorded fields (recorded: {', '.join(map(str, ids))})")
    return int(hits[0])


def slip_map(run, event: int | None = None) -> Figure:
    """The slip of every block in an event, x(end) - x(first move), as an image, with the
    contours of the rupture front (the time of each block's first move after the event's start)
    and the epicentre marked.

    Parameters
    ----------
    run : LatticeRun
        A run with recorded event fields (``slip_maps``).
    event : int, optional
        The event's number (default the largest recorded by moment).

    Returns
    -------
    matplotlib.figure.Figure
        One Axes, its image the slip field of shape (rows, cols) (summing to the event's moment).
    """
    j = _event_index(run, event)
    f = run.event_fields.isel(event=j)
    slip = f["slip"].values
    first = f["first_step"].values
    dt = float(run.event_fields.attrs.get("dt", run.params.dt))
    rows, cols = slip.shape
    fig, ax = new_figure(1, 1, width=5.0, height=max(2.0, 4.2 * min(rows / cols, 1.5)))
    im = ax.imshow(slip, cmap="viridis", extent=_extent((rows, cols)), interpolation="nearest")
    fig.colorbar(im, ax=ax, shrink=0.8, label="slip")
    ax.grid(False)
    moved = first >= 0
    if moved.sum() > 3 and len(np.unique(first[moved])) > 2:
        t_front = np.where(moved, (first - int(f["step_start"])) * dt, np.nan)
        r, c = np.meshgrid(np.arange(1, rows + 1), np.arange(1, cols + 1), indexing="ij")
        cs = ax.contour(c, r, t_front, levels=6, colors="w", linewidths=0.7)
        ax.clabel(cs, fontsize=6, fmt="%.3g")
    e = int(f["event"])
    row = run.events[run.events["event"] == e]
    if len(row):
        ax.plot(int(row["epicentre_col"].iloc[0]), int(row["epicentre_row"].iloc[0]), "r*", ms=9)
    ax.set_xlabel("column")
    ax.set_ylabel("row")
    ax.set_title(
        f"event {e}: moment {float(f['moment']):.4g}, area {int(moved.sum())}; contours: time since its start",
        loc="left",
        fontsize=8,
    )
    fig.suptitle(_title(run), fontsize=9)
    return fig


def rupture_frames(run, event: int | None = None, *, frames: int = 6) -> Figure:
    """The rupture front of an event as ``frames`` images at equal times from its start to its
    last first move: in each, the blocks that have started by then, coloured by the time of
    their first move (the rest blank).

    Parameters
    ----------
    run : LatticeRun
        A run with recorded event fields.
    event : int, optional
        The event (default the largest recorded).
    frames : int
        How many frames, 1 to 24.

    Returns
    -------
    matplotlib.figure.Figure
        ``frames`` Axes, each with an image of shape (rows, cols).
    """
    frames = int(frames)
    if not 1 <= frames <= 24:
        raise ParameterError(f"frames must be in [1, 24] (got {frames})")
    j = _event_index(run, event)
    f = run.event_fields.isel(event=j)
    first = f["first_step"].values
    dt = float(run.event_fields.attrs.get("dt", run.params.dt))
    t = np.where(first >= 0, (first - int(f["step_start"])) * dt, np.nan)
    t_last = float(np.nanmax(t)) if np.any(first >= 0) else 0.0
    times = np.linspace(t_last / frames, t_last, frames) if t_last > 0 else np.zeros(frames)
    rows, cols = first.shape
    ncols = min(frames, 6)
    nrows = -(-frames // ncols)
    fig, axes = new_figure(nrows, ncols, width=2.4, height=max(1.2, 2.2 * min(rows / cols, 1.5)))
    axes = np.atleast_1d(axes)
    for k, ax in enumerate(axes.ravel()):
        if k >= frames:
            ax.set_axis_off()
            continue
        shown = np.where(t <= times[k] + 0.5 * dt, t, np.nan)
        im = ax.imshow(shown, cmap="plasma", vmin=0.0, vmax=max(t_last, dt), extent=_extent((rows, cols)))
        ax.set_title(f"t - t0 = {times[k]:.3g}", fontsize=8)
        ax.set_xticks([])
        ax.set_yticks([])
        ax.grid(False)
    fig.colorbar(im, ax=axes.ravel().tolist(), shrink=0.8, label="time of first move")
    fig.suptitle(f"{_title(run)}: rupture front of event {int(f['event'])}", fontsize=9)
    return fig


@dataclass
class LatticePlots:
    """The figures of one lattice run, lent to it as ``run.plot`` (:mod:`stickslip.accessors`)."""

    run: Any

    def snapshot(self, t: float | None = None, *, fields=("x", "v", "stopped")) -> Figure:
        """:func:`snapshot_images`."""
        return snapshot_images(self.run, t, fields=fields)

    def event(self, event: int | None = None) -> Figure:
        """:func:`slip_map`."""
        return slip_map(self.run, event)

    def rupture(self, event: int | None = None, *, frames: int = 6) -> Figure:
        """:func:`rupture_frames`."""
        return rupture_frames(self.run, event, frames=frames)


def draw_lattice_figures(run, out_dir: str | Path, *, formats=FIGURE_FORMATS, events: int = 3) -> list[dict]:
    """Every figure a lattice run supports, saved as OUT_DIR/<stem>.<fmt> (``stickslip plot``
    on a lattice run directory): ``snapshot_final``, ``snapshot_t<T>`` of the last snapshot, and
    ``slip_map_e<ID>`` and ``rupture_e<ID>`` of the ``events`` largest recorded events.

    Returns
    -------
    list of dict
        One record per figure: ``figure`` (stem) and ``files`` written, or ``skipped`` with why.
    """
    out_dir = Path(out_dir)
    items: list[tuple[str, Any]] = [("snapshot_final", lambda: snapshot_images(run))]
    if run.snapshots is not None:
        t_last = float(run.snapshots["time"].values[-1])
        items.append((f"snapshot_t{t_last:g}", lambda: snapshot_images(run, t_last)))
    records = []
    f = run.event_fields
    if f is None or f.sizes.get("event", 0) == 0:
        records.append({"figure": "slip_map", "skipped": "no event fields recorded (stickslip chain --slip-maps K)"})
    else:
        order = np.argsort(-f["moment"].values, kind="stable")[:events]
        for e in f["event"].values[order]:
            items.append((f"slip_map_e{int(e)}", lambda e=e: slip_map(run, int(e))))
            items.append((f"rupture_e{int(e)}", lambda e=e: rupture_frames(run, int(e))))
    for stem, draw in items:
        files = save_figure(draw(), out_dir / stem, formats=formats)
        records.append({"figure": stem, "files": [str(p) for p in files]})
    return records
