"""The paper's figures (Figs. 1-8 and the two of section 2) drawn from a reproduction's results.

:func:`section2_figures` and :func:`chain_figures` draw the figures of the paper's two studies
(:data:`stickslip.experiments.studies.PAPER`): each writes the data drawn in a figure (NetCDF or
CSV) into the study's page folder and gives the figure as its study's ``figures`` hook does,
``(stem, Figure, caption, entry)`` with the report's label, data files and command in ``entry``,
or ``(stems, None, reason)`` for figures these results cannot give. The drawing itself is in
:mod:`stickslip.plotting.block`, :mod:`stickslip.plotting.stability` and
:mod:`stickslip.plotting.chain`.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from stickslip import io
from stickslip.analysis.stats.chain_runs import fig6_start_note, sweep_table
from stickslip.outcome import Outcome, chain_params

#: A drawn figure: its stem, the figure, its caption and the further fields of its report entry.
Drawn = tuple[str, Any, str, dict[str, Any]]


def _figure(stem: str, label: str, caption: str, fig, data: list[Path], command: str = "") -> Drawn:
    return stem, fig, caption, {"figure": label, "data": [p.name for p in data], "command": command}


def _fig1_2(o: dict[str, Outcome], d: Path, cmd) -> list[Drawn]:
    """Figs. 1 and 2 from the block run and eq. (3)."""
    from stickslip.plotting.block import fig1_position, fig2_slip, slip_window

    run = o["block"].data["run"]
    law = o["slip-limit"].data["law"]
    s = run.series
    f1 = io.write_dataset(d / "fig1.nc", s[["x"]])
    figs = [
        _figure(
            "fig1",
            "Fig. 1",
            "Time evolution of x of the single block, eq. (1), at M = alpha = beta = "
            "sigma = 1, K = 10, V = 0.001, Fs = 3 (Heun, dt = 0.005, from x = v = 0, theta = 0.1): "
            "stick-slip with period 344.",
            fig1_position(run),
            [f1],
            cmd.block_command(o["block"]),
        )
    ]
    w = slip_window(run)
    f2 = io.write_dataset(
        d / "fig2.nc",
        xr.Dataset(
            {
                "eq1_v": ("t_eq1", w["v"].values),
                "eq1_theta": ("t_eq1", w["theta"].values),
                "eq3_v": ("t_eq3", law.curve["v"].values),
                "eq3_theta": ("t_eq3", law.curve["theta"].values),
            },
            coords={"t_eq1": w["t"].values, "t_eq3": law.curve["t"].values},
            attrs={"description": "Fig. 2: v and theta against t - t_c, eq. (1) (Heun) and eq. (3) (DOP853)"},
        ),
    )
    figs.append(
        _figure(
            "fig2",
            "Fig. 2",
            "(a) v(t - t_c) during the second slip of the run of Fig. 1 (solid) "
            "and of eq. (3) (dashed); (b) the phase portrait (v, theta). The paper: the curves "
            "overlap.",
            fig2_slip(run, law),
            [f2],
            cmd.block_command(o["block"]),
        )
    )
    return figs


def _fig3(o: dict[str, Outcome], d: Path) -> list[Drawn]:
    """Fig. 3: period against V with the law T = a + b / (K V) of eq. (3)."""
    from stickslip.plotting.block import fig3_period

    table = o["period-sweep"].data["table"]
    law = o["slip-limit"].data["law"]
    f = io.write_table_files(d / "fig3", table)
    return [
        _figure(
            "fig3",
            "Fig. 3",
            f"Period of stick-slip against V: simulated (marks) and "
            f"T = {law.law_a:.4f} + {law.law_b:.4f} / (K V) from eq. (3) (dashed; the paper: "
            "T = 1.035 + 3.432 / (K V)).",
            fig3_period(table, law),
            f,
            "stickslip block --fig3 --out DIR",
        )
    ]


def _stability_map(o: dict[str, Outcome], d: Path) -> list[Drawn]:
    """Section 2: the Hopf curve V_c(beta) of the single block at K = 10 (eq. 2)."""
    from stickslip.plotting.stability import plot_stability_map

    ds = o["stability-block"].data["map"]
    f = io.write_dataset(d / "stability_map.nc", ds)
    fig = plot_stability_map(ds[["V_c", "V_c_closed_form"]].assign_attrs(ds.attrs), ds["growth_rate"])
    return [
        _figure(
            "stability_map",
            "Section 2, eq. (2)",
            "Linear stability of steady sliding of the single "
            "block at K = 10: largest Re(lambda) of eq. (2) over (beta, V) and the Hopf curve V_c(beta). "
            "The paper: V_c = 0.106 at beta = 0.08; stable for all V at beta = 1.",
            fig,
            [f],
            "stickslip stability block --K 10 --beta 0.08 --out DIR",
        )
    ]


def _hysteresis(o: dict[str, Outcome], d: Path, cmd) -> list[Drawn]:
    """Section 2: V raised slowly and lowered again; the inverse transition at V_up."""
    from stickslip.plotting.stability import plot_hysteresis

    data = o["hysteresis"].data["data"]
    f = io.write_dataset(d / "hysteresis.nc", data)
    return [
        _figure(
            "hysteresis",
            "Section 2, inverse transition",
            "Single block, beta = 1, Fs = 3, K = 10: "
            "largest and least v at each V as V is raised slowly and lowered again. Stick-slip "
            "(min v = 0) ends at V_up (the paper: 0.345).",
            plot_hysteresis(data),
            [f],
            cmd.hysteresis_command(o["hysteresis"], draw=True),
        )
    ]


def _fig4(o: dict[str, Outcome], d: Path) -> list[Drawn]:
    """Fig. 4: real parts of the two largest eigenvalues of the Fourier modes of eq. (5)."""
    from stickslip.plotting.stability import plot_fig4

    ds = o["chain-modes"].data["modes"]
    f = io.write_dataset(d / "fig4.nc", ds)
    return [
        _figure(
            "fig4",
            "Fig. 4",
            "Real parts of the two largest eigenvalues of the Fourier modes of the "
            "linearised chain, eq. (5), against k at beta = 0.5, 1, 1.5 (K = 10, D = 5). Right: long "
            "waves, unstable for beta < 1.",
            plot_fig4(ds),
            [f],
            "stickslip stability chain --K 10 --D 5 --beta 1 --out DIR",
        )
    ]


def _fig5(o: dict[str, Outcome], a: dict[str, Any], d: Path, mode: str, cmd) -> list[Drawn]:
    """Fig. 5: (a) snapshot at the end of the beta = 1 run; (b) <L> against beta."""
    from stickslip.models.physics import chain_steady_profile_paper, chain_steady_state
    from stickslip.plotting.chain import fig5a_snapshot, fig5b_length

    run = a["run1"]
    snap = run.snapshots.isel(snapshot_time=-1)
    t = float(snap["snapshot_time"])
    p = run.params
    fa = io.write_table_files(
        d / "fig5a",
        pd.DataFrame(
            {
                "block": np.arange(1, p.N + 1),
                "x": snap.values,
                "x_steady_exact": chain_steady_state(p, t)["x"],
                "x_steady_paper": chain_steady_profile_paper(p, t),
            }
        ),
    )
    figs = [
        _figure(
            "fig5a",
            "Fig. 5(a)",
            f"Snapshot of x_i at t = {t:.3g} at beta = 1 (N = {p.N}), in the frame "
            "of the pulling point, against the exact discrete steady sliding profile (dashed) and the "
            "paper's continuum form (dotted).",
            fig5a_snapshot(snap, p, t, paper_figure="Fig. 5(a)"),
            fa,
            cmd.chain_command(o["chain-runs"], p.N, 1.0, plot="snapshot_final"),
        )
    ]
    sweep = sweep_table(a)
    fb = io.write_table_files(d / "fig5b", sweep)
    q = chain_params(o["chain-runs"].settings, N=a["sweep_N"])
    steady_note = ", ".join(f"{b:g}" for b in sweep.loc[sweep["final_state"] == "steady sliding", "beta"])
    figs.append(
        _figure(
            "fig5b",
            "Fig. 5(b)",
            f"Time-averaged length <L> = <x_1 - x_N> against beta (N = "
            f"{a['sweep_N']}, second half of each run; error bars: batch means) and the steady "
            "sliding length L_ss = (c/K) N (N - 1) / 2 with the steady friction c = 1 - (1 - beta) V "
            "(dashed); dotted: beta_c = 1. Runs that reached steady sliding (beta = "
            f"{steady_note or 'none'}) were stopped there and count L_ss from then on; open symbols: "
            "runs above beta_c that had not settled into steady sliding by their end.",
            fig5b_length(sweep, q, paper_figure="Fig. 5(b)"),
            fb,
            cmd.sweep_command(o["chain-runs"], mode),
        )
    )
    return figs


def _fig6(o: dict[str, Outcome], a: dict[str, Any], d: Path, cmd) -> list[Drawn]:
    """Fig. 6: rupture fronts of a large and an intermediate event at beta = 1, and c per event."""
    from stickslip.analysis.stats.statistics import central_interval
    from stickslip.plotting.chain import PAPER_FRONT_SPEED, fig6_fronts

    fr = a["fronts"]
    run = a["run1"]
    if not fr["fronts"]:
        raise ValueError("no event with stored profiles to draw")
    ids = [f.event for f in fr["fronts"]]
    rows = np.flatnonzero(np.isin(run.profiles["profile_event"].values, ids))
    prof = run.profiles.isel(profile_row=rows)
    f1 = io.write_dataset(d / "fig6.nc", prof)
    fm = run.first_move[run.first_move["event"].isin(ids)]
    f2 = io.write_table_files(d / "fig6_first_move", fm)
    f3 = io.write_table_files(
        d / "fig6_fronts",
        pd.DataFrame([f.to_dict() for f in fr["fronts"]]).assign(
            label=fr["labels"], c_leading_edge=[e.speed if e is not None else np.nan for e in fr["edges"]]
        ),
    )
    per_event = fr["per_event"]
    f4 = io.write_table_files(d / "fig6_speeds", per_event)
    parts = []
    for col, name in (("c_first_move", "first motion"), ("c_leading_edge", "leading edge")):
        x = per_event[col].to_numpy(dtype=float)
        x = x[np.isfinite(x)]
        if x.size:
            ci = central_interval(x, PAPER_FRONT_SPEED)
            parts.append(
                f"{name}: median {ci.median:.3g}, central 90% {ci.lo:.3g}-{ci.hi:.3g}, the paper's 1.43 at "
                f"percentile {ci.percentile:.0f}"
            )
    caption = (
        f"(a, b) Displacement over windows of 20 time units in a large and an intermediate slip event at "
        f"beta = 1 (N = {run.params.N}; curves lifted, scale bar at the right; red marks: leading edge of each "
        f"window), and the time each block first moved with the fitted front speed. (c) Front speed of each "
        f"of the {len(per_event)} events that reached block N in the second half, by first motion over the "
        f"far half and by the leading edge of the windows: "
        + "; ".join(parts)
        + f" (sound speed 3.16). {fig6_start_note(a)}"
    )
    fig = fig6_fronts(
        prof,
        fm,
        fr["fronts"],
        run.params,
        labels=fr["labels"],
        window=20.0,
        edges=fr["edges"],
        speeds=per_event,
        paper_figure="Fig. 6",
    )
    return [
        _figure(
            "fig6",
            "Fig. 6",
            caption,
            fig,
            [f1, *f2, *f3, *f4],
            cmd.chain_command(o["chain-runs"], run.params.N, 1.0, plot="fronts"),
        )
    ]


def _fig7_8(o: dict[str, Outcome], a: dict[str, Any], d: Path, which: str, cmd) -> list[Drawn]:
    """Figs. 7 (beta = 1) and 8 (beta = 0.2): slip-size distribution and S against time."""
    from stickslip.analysis.stats.statistics import size_distribution
    from stickslip.plotting.chain import fig7_8_sizes

    beta, stem, label, paper_tau = (1.0, "fig7", "Fig. 7", 1.5) if which == "7" else (0.2, "fig8", "Fig. 8", 1.6)
    events = a["events1"] if which == "7" else a["events02"]
    stats = a["sizes1"] if which == "7" else a["sizes02"]
    if stats is None:
        raise ValueError("too few events in the second half of the run")
    fit = stats["fit"]
    f1 = io.write_table_files(d / f"{stem}_events", events[["event", "t_start", "S", "max_block", "n_blocks"]])
    hist = size_distribution(events["S"].to_numpy(dtype=float), 30)
    f2 = io.write_dataset(d / f"{stem}_histogram.nc", hist)
    N = a["figure_N"]
    fit_range = f"fitted on [{fit.s_min:.3g}, {fit.s_max:.3g}]" + (
        " (below the smallest event that reached block N)" if which == "8" else " with the cut-off in the likelihood"
    )
    caption = (
        f"(a) Density of slip sizes S = sum_i dx_i at beta = {beta:g} (N = {N}, events of the second half "
        f"of the run), truncated power law {fit_range}: tau = {fit.tau:.2f} ± {fit.tau_err:.2f} (the paper: "
        f"{'nearly 1.5' if which == '7' else 'about 1.6 for small S, with an excess of large events'}). "
        f"(b) S against the event's start time."
    )
    return [
        _figure(
            stem,
            label,
            caption,
            fig7_8_sizes(events, fit, beta, paper_tau=paper_tau, paper_figure=label),
            [*f1, f2],
            cmd.chain_command(o["chain-runs"], N, beta, plot="sizes"),
        )
    ]


def _draw(steps: list[tuple[str, Callable[[], list[Drawn]]]]) -> list[tuple]:
    """Each step's figures, or for a step these results cannot give (e.g. no event reached block N
    in a tiny run) its stems with the reason."""
    out: list[tuple] = []
    for name, draw in steps:
        try:
            out += draw()
        except (ValueError, KeyError, IndexError) as exc:
            out.append((name, None, f"{type(exc).__name__}: {exc}"))
    return out


def section2_figures(outcomes: dict[str, Outcome], page_dir: Path, commands) -> list[tuple]:
    """Figs. 1-4 and the two figures of section 2 (the stability map, the hysteresis sweep) from the
    outcomes of the experiments of :mod:`stickslip.experiments.studies.figs1_4`, their data
    written into ``page_dir``. ``commands`` makes the command line of each figure's entry
    (``block_command``, ``hysteresis_command``: :mod:`stickslip.report.commands`, handed down by
    the study, as the drawing does not know the command line)."""
    d, cmd = Path(page_dir), commands
    return _draw(
        [
            ("fig1, fig2", lambda: _fig1_2(outcomes, d, cmd)),
            ("fig3", lambda: _fig3(outcomes, d)),
            ("stability_map", lambda: _stability_map(outcomes, d)),
            ("hysteresis", lambda: _hysteresis(outcomes, d, cmd)),
            ("fig4", lambda: _fig4(outcomes, d)),
        ]
    )


def chain_figures(outcome: Outcome, analysis: dict[str, Any], page_dir: Path, mode: str, commands) -> list[tuple]:
    """Figs. 5-8 from the chain runs of :mod:`stickslip.experiments.studies.figs5_8` and their
    ``analysis`` (:func:`stickslip.analysis.stats.chain_runs.chain_analysis`), their data written into
    ``page_dir``. ``commands`` makes the command line of each figure's entry (``chain_command``,
    ``sweep_command``: :mod:`stickslip.report.commands`, handed down by the study)."""
    d, o, cmd = Path(page_dir), {"chain-runs": outcome}, commands
    return _draw(
        [
            ("fig5a, fig5b", lambda: _fig5(o, analysis, d, mode, cmd)),
            ("fig6", lambda: _fig6(o, analysis, d, cmd)),
            ("fig7", lambda: _fig7_8(o, analysis, d, "7", cmd)),
            ("fig8", lambda: _fig7_8(o, analysis, d, "8", cmd)),
        ]
    )
