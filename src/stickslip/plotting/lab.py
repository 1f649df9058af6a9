"""Figures of the rock-friction laboratory (:mod:`stickslip.lab`): a velocity step, a
slide-hold-slide test, a fit (data, model, residuals) and a stick-slip inversion."""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from stickslip.plotting.style import SIM, THEORY, new_figure


def plot_step(ds: xr.Dataset, summary: dict | None = None) -> Figure:
    """Friction and slip rate against load-point displacement through velocity steps
    (:func:`stickslip.lab.protocols.velocity_step`), the closed-form steady states dashed.

    Parameters
    ----------
    ds : xarray.Dataset
        The run of the spring-slider.
    summary : dict, optional
        The protocol's summary (its ``steps`` give the steady states drawn).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (ax, axv) = new_figure(2, 1, width=6.0, height=2.6, sharex=True)
    x = ds.load_point.values - float(ds.load_point[0])
    mass = ds.attrs.get("M")
    ax.plot(x, ds.mu, **SIM, label="spring-slider" + (f", M = {mass:g}" if mass else ", quasi-static"))
    if summary:
        starts = [st["t"] for st in summary["steps"]] + [float(ds.t[-1])]
        for st, t1 in zip(summary["steps"], starts[1:], strict=True):
            x0, x1 = np.interp([st["t"], t1], ds.t, x)
            ax.plot([x0, x1], [st["mu_ss_closed_form"]] * 2, **THEORY)
        ax.plot([], [], **THEORY, label=r"$\mu_{ss} = \mu_0 + (a-b)\ln(V/V_0)$")
    ax.set_ylabel(r"friction $\mu$")
    ax.legend(fontsize=8)
    axv.semilogy(x, ds.v, **SIM, label="slip rate $v$")
    axv.semilogy(x, np.where(ds.V > 0, ds.V, np.nan), color="0.5", lw=0.8, ls=":", label="load point $V$")
    axv.set_xlabel("load-point displacement")
    axv.set_ylabel("velocity")
    axv.legend(fontsize=8)
    return fig


def plot_shs(ds: xr.Dataset, summary: dict) -> Figure:
    """A slide-hold-slide test (:func:`stickslip.lab.protocols.slide_hold_slide`): friction against
    time, and the healing Delta mu against log10 t_hold with the fitted healing rate.

    Parameters
    ----------
    ds : xarray.Dataset
        The run of the spring-slider.
    summary : dict
        The protocol's summary (``holds``, ``healing_rate``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (ax, axh) = new_figure(1, 2, width=4.6, height=3.4)
    ax.plot(ds.t, ds.mu, **SIM)
    ax.set_xlabel("time")
    ax.set_ylabel(r"friction $\mu$")
    th = np.array([r["t_hold"] for r in summary["holds"]])
    dmu = np.array([r["delta_mu"] for r in summary["holds"]])
    axh.semilogx(th, dmu, "o", color="C0", label=r"$\Delta\mu = \mu_{peak} - \mu_{ss}$")
    rate = summary.get("healing_rate")
    if rate is not None:
        c0 = np.mean(dmu - rate * np.log10(th))
        axh.semilogx(th, c0 + rate * np.log10(th), **THEORY, label=rf"$\beta$ = {rate:.4g} per decade")
    axh.set_xlabel(r"hold time $t_h$")
    axh.set_ylabel(r"healing $\Delta\mu$")
    axh.legend(fontsize=8)
    return fig


def plot_fit(result) -> Figure:
    """A fit (:class:`stickslip.lab.fitting.FitResult`): data and model of each record against time, and
    the residuals below; samples outside the fit's window in grey.

    Parameters
    ----------
    result : FitResult
        What :func:`stickslip.lab.fitting.fit` returned.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (ax, axr) = new_figure(2, 1, width=6.0, height=2.6, sharex=True, gridspec_kw={"height_ratios": [2, 1]})
    for i, (rec, pred) in enumerate(zip(result.records, result.predictions, strict=True)):
        m = rec.mask
        color = f"C{i % 10}"
        ax.plot(rec.t[m], rec.mu[m], ".", ms=2, color=color, alpha=0.5, label=f"data {rec.name}".strip())
        ax.plot(rec.t[~m], rec.mu[~m], ".", ms=2, color="0.7")
        ax.plot(rec.t, pred, color="k", lw=1.0)
        axr.plot(rec.t[m], (rec.mu - pred)[m], ".", ms=2, color=color)
    ax.plot([], [], color="k", lw=1.0, label="model")
    text = "\n".join(
        f"{n} = {v:.4g} ± {e:.2g}" for n, v, e in zip(result.names, result.values, result.errors, strict=True)
    )
    ax.text(0.99, 0.5, text, transform=ax.transAxes, ha="right", va="center", fontsize=7)
    ax.set_ylabel(r"friction $\mu$")
    ax.legend(fontsize=8, loc="upper right")
    axr.axhline(0.0, color="0.4", lw=0.8)
    axr.set_xlabel("time")
    axr.set_ylabel("residual")
    return fig


def plot_posterior(post, result=None) -> Figure:
    """A corner figure of a posterior (:func:`stickslip.lab.posterior.posterior`): the histogram of
    each parameter on the diagonal, the samples of each pair below it, the least-squares value and
    its two-standard-error interval in red where ``result`` (the FitResult) is given.

    Parameters
    ----------
    post : Posterior
    result : FitResult, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    p = len(post.names)
    fig, axes = new_figure(p, p, width=1.9, height=1.9)
    axes = np.asarray(axes).reshape(p, p)
    x = post.samples
    for i in range(p):
        for j in range(p):
            ax = axes[i, j]
            if j > i:
                ax.set_visible(False)
                continue
            ax.locator_params(nbins=3)
            ax.ticklabel_format(useOffset=False)
            if i == j:
                ax.hist(x[:, i], bins=40, color="C0", histtype="step")
                if result is not None:
                    v, e = result.values[i], result.errors[i]
                    ax.axvline(v, **THEORY)
                    ax.axvspan(v - 2 * e, v + 2 * e, color="C3", alpha=0.1)
                ax.set_yticks([])
            else:
                ax.plot(x[:, j], x[:, i], ",", color="C0", alpha=0.3)
                if result is not None:
                    ax.plot(result.values[j], result.values[i], "+", color="C3", ms=8)
            if i == p - 1:
                ax.set_xlabel(post.names[j])
            else:
                ax.set_xticklabels([])
            if j == 0 and i > 0:
                ax.set_ylabel(post.names[i])
            elif j > 0:
                ax.set_yticklabels([])
            ax.tick_params(labelsize=6)
            for label in ax.get_xticklabels():
                label.set_rotation(30)
    return fig


def plot_stick_slip(result) -> Figure:
    """A stick-slip inversion (:func:`stickslip.lab.inversion.invert_stick_slip`): the data's and the
    fitted model's friction over the window read (a record's samples as dots), and each observable
    observed (with two standard errors) against the model's, relative to the observed mean.

    Parameters
    ----------
    result : StickSlipResult

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (ax, axo) = new_figure(1, 2, width=7.5, height=2.8, gridspec_kw={"width_ratios": [2.2, 1]})
    s = result.series
    t0, t1 = s["window"]
    ax.plot(s["t"], s["mu"], color="k", lw=0.8, label="model")
    if "data_t" in s:
        m = (s["data_t"] >= t0) & (s["data_t"] <= t1)
        ax.plot(s["data_t"][m], s["data_mu"][m], ".", ms=3, color=SIM["color"], alpha=0.6, label="data", zorder=3)
    ax.set_xlabel("time")
    ax.set_ylabel(r"friction $k\,(p - x)$")
    ax.legend(fontsize=8, loc="lower left")
    text = "\n".join(
        f"{n} = {v:.4g} ± {e:.2g}" for n, v, e in zip(result.names, result.values, result.errors, strict=True)
    )
    ax.text(0.99, 0.02, text, transform=ax.transAxes, ha="right", va="bottom", fontsize=7)
    y = np.arange(len(result.observables))
    scale = np.where(result.observed != 0.0, np.abs(result.observed), 1.0)
    axo.errorbar(
        np.zeros(y.size),
        y,
        xerr=2.0 * result.stderr / scale,
        fmt="o",
        color=SIM["color"],
        ms=4,
        label="observed ± 2 s.e.",
    )
    axo.plot((result.predicted - result.observed) / scale, y, "x", color=THEORY["color"], ms=6, label="model")
    axo.set_yticks(y, [o.replace("_", " ") for o in result.observables], fontsize=7)
    axo.axvline(0.0, color="0.7", lw=0.8)
    axo.set_xlabel("relative to the observed mean")
    axo.legend(fontsize=7, loc="best")
    axo.set_title(rf"$\chi^2$ = {result.chi2:.3g} ({result.dof} dof)", fontsize=8)
    return fig
