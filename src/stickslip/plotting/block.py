"""Figures 1-3 of the paper: the single block and spring (section 2).

Each function takes results (a :class:`~stickslip.run.block.BlockRun`, a
:class:`~stickslip.analysis.dynamics.slip_limit.SlipLimit`, the table of
:func:`~stickslip.analysis.dynamics.slip_limit.period_sweep`) and returns a matplotlib Figure.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import xarray as xr
from matplotlib.figure import Figure

from stickslip.analysis.dynamics.slip_limit import SlipLimit
from stickslip.plotting.style import SIM, THEORY, new_figure
from stickslip.run.block import BlockRun


def _param_text(p) -> str:
    return rf"$K={p.K:g}$, $V={p.V:g}$, $\beta={p.beta:g}$, $F_s={p.Fs:g}$"


def fig1_position(run: BlockRun) -> Figure:
    """Fig. 1: time evolution of the block position x(t) in eq. (1) (stick-slip staircase)."""
    fig, ax = new_figure(width=6.0, height=3.6)
    s = run.series
    ax.plot(s["t"], s["x"], **SIM, label="$x(t)$, eq. (1)")
    ax.set_xlabel("$t$")
    ax.set_ylabel("$x$")
    ax.set_xlim(0.0, float(s["t"][-1]))
    ax.set_title(f"Fig. 1: single block, {_param_text(run.params)}", fontsize=9, wrap=True)
    return fig


def slip_window(run: BlockRun, index: int | None = None, margin: int = 0) -> xr.Dataset:
    """The series of one slip of ``run`` with time measured from its start t_c (Fig. 2).

    ``index`` picks the slip (default: the second, or the first if there is only one);
    ``margin`` extra stored samples are kept after t_e.
    """
    if len(run.slips) == 0:
        raise ValueError("the run has no complete slip")
    if index is None:
        index = 1 if len(run.slips) > 1 else 0
    slip = run.slips.iloc[index]
    t = run.series["t"].values
    lo = int(np.searchsorted(t, slip["t_c"] - 1e-9 * run.params.dt))
    hi = int(np.searchsorted(t, slip["t_e"] + 1e-9 * run.params.dt, side="right")) + margin
    window = run.series.isel(t=slice(lo, hi))
    return window.assign_coords(t=window["t"] - slip["t_c"]).assign_attrs(slip_index=int(index))


def fig2_slip(run: BlockRun, limit: SlipLimit, index: int | None = None) -> Figure:
    """Fig. 2: (a) v(t - t_c) during a slip of eq. (1) and of eq. (3); (b) the (v, theta) portrait.

    Eq. (1) (``run``, solid) against the slip in the limit V -> 0 (``limit``, dashed), as in the
    paper's Fig. 2 at V = 0.001, where the two curves overlap. ``run`` should keep every step
    (every = 1) around the slip.
    """
    w = slip_window(run, index)
    c = limit.curve
    fig, (ax_v, ax_p) = new_figure(1, 2, width=4.6, height=3.6)
    ax_v.plot(w["t"], w["v"], **SIM, label=f"eq. (1), $V={run.params.V:g}$")
    ax_v.plot(c["t"], c["v"], **THEORY, label="eq. (3)")
    ax_v.set_xlabel("$t - t_c$")
    ax_v.set_ylabel("$v$")
    ax_v.set_title("(a)", loc="left")
    ax_v.legend()
    ax_p.plot(w["v"], w["theta"], **SIM, label=f"eq. (1), $V={run.params.V:g}$")
    ax_p.plot(c["v"], c["theta"], **THEORY, label="eq. (3)")
    ax_p.set_xlabel("$v$")
    ax_p.set_ylabel(r"$\theta$")
    ax_p.set_title("(b)", loc="left")
    ax_p.legend()
    fig.suptitle(f"Fig. 2: one slip, {_param_text(run.params)}", fontsize=9, wrap=True)
    return fig


def fig3_period(sweep: pd.DataFrame, limit: SlipLimit) -> Figure:
    """Fig. 3: period of the stick-slip oscillation against V, simulated (marks) and the law (dashed).

    ``sweep`` is the table of :func:`~stickslip.analysis.dynamics.slip_limit.period_sweep`; the dashed curve is
    T(V) = a + b / (K V) from eq. (3) (``limit``). The lower panel shows the relative deviation
    of the simulated period from the law.
    """
    fig, (ax, ax_d) = new_figure(2, 1, width=5.2, height=2.4, sharex=True, gridspec_kw={"height_ratios": [2.2, 1.0]})
    V = sweep["V"].to_numpy()
    grid = np.logspace(np.log10(V.min()), np.log10(V.max()), 200)
    ax.plot(grid, limit.period(grid), **THEORY,
            label=f"$T = {limit.law_a:.4f} + {limit.law_b:.4f} / (KV)$")  # fmt: skip
    ax.plot(V, sweep["period"], "o", color=SIM["color"], ms=5, label="eq. (1), Heun")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_ylabel("period $T$")
    ax.legend()
    ax.set_title(rf"Fig. 3: $K={limit.params.K:g}$, $\beta={limit.params.beta:g}$, $F_s={limit.params.Fs:g}$",
                 fontsize=9, wrap=True)  # fmt: skip
    ax_d.axhline(0.0, color="0.5", lw=0.8)
    ax_d.plot(V, 100.0 * sweep["rel_dev"], "o-", color=SIM["color"], ms=4, lw=0.8)
    ax_d.set_xlabel("$V$")
    ax_d.set_ylabel(r"$T_\mathrm{sim} / T_\mathrm{law} - 1$ (%)")
    return fig


__all__ = ["fig1_position", "fig2_slip", "fig3_period", "slip_window"]
