"""The laboratory's protocols as one call each: velocity steps and slide-hold-slide tests.

- :func:`velocity_step`: the spring-slider through steps of the load-point velocity; for each step
  the friction before it, the peak (or trough) after it and the new steady state, with
  a - b = (mu_ss,after - mu_ss,before) / ln(V_after / V_before) read off the run.
- :func:`slide_hold_slide`: slides at V separated by holds at V = 0 of growing length t_h; for each
  hold the peak friction on reloading, the healing Delta mu = mu_peak - mu_ss (Beeler, Tullis and
  Weeks 1994; Marone 1998) and the relaxation during the hold, and the healing rate
  beta = d(Delta mu) / d log10 t_h fitted over the holds. For the aging law in a stiff machine
  theta grows as theta_0 + t_h in the hold, so Delta mu -> b ln(10) per decade at long holds.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import xarray as xr

from stickslip.lab.history import LoadHistory
from stickslip.lab.laws import RateState, steady_friction
from stickslip.lab.spring_slider import quasi_static
from stickslip.models.params import ParameterError, check_number

__all__ = ["slide_hold_slide", "velocity_step"]


def _grid(history: LoadHistory, n: int) -> np.ndarray:
    """Output times: ``n`` even points per interval and a geometric cluster after each breakpoint,
    where the friction peaks."""
    parts = []
    for t0, t1 in zip(history.times[:-1], history.times[1:], strict=True):
        span = t1 - t0
        parts.append(np.linspace(t0, t1, n))
        parts.append(t0 + np.geomspace(span * 1e-6, span, n))
    return np.unique(np.concatenate(parts))


def _run(model: RateState, history: LoadHistory, t, rtol: float, method: str, M: float) -> xr.Dataset:
    """The quasi-static spring-slider (M = 0) or the inertial one of mass M over ``history``."""
    if M == 0.0:
        return quasi_static(model, history, t=t, rtol=rtol, method=method)
    from stickslip.lab.inertial_ode import inertial_slider

    return inertial_slider(model, history, M, t=t, rtol=rtol, method=method)


def _peak(ds: xr.Dataset, t0: float, t1: float, sign: float) -> tuple[float, float]:
    """The extreme of mu (sign 1: maximum, -1: minimum) over [t0, t1], refined by a parabola through
    the largest sample and its neighbours. Returns (time, mu)."""
    sel = (ds.t.values >= t0) & (ds.t.values <= t1)
    t, mu = ds.t.values[sel], sign * ds.mu.values[sel]
    i = int(np.argmax(mu))
    if 0 < i < t.size - 1:
        c = np.polyfit(t[i - 1 : i + 2] - t[i], mu[i - 1 : i + 2], 2)
        if c[0] < 0.0:
            dt = -c[1] / (2.0 * c[0])
            if t[i - 1] - t[i] < dt < t[i + 1] - t[i]:
                return float(t[i] + dt), float(sign * np.polyval(c, dt))
    return float(t[i]), float(sign * mu[i])


def velocity_step(
    model: RateState,
    velocities: Sequence[float] = (1.0, 10.0),
    *,
    displacement: float | None = None,
    n: int = 400,
    rtol: float = 1e-10,
    method: str = "auto",
    M: float = 0.0,
) -> tuple[xr.Dataset, dict]:
    """Steps of the load-point velocity through ``velocities`` (the first is the steady start), each
    held for a load-point ``displacement`` (default 20 times the largest D_c).

    Parameters
    ----------
    model : RateState
        The friction law and the stiffness k.
    velocities : sequence of float
        Load-point velocities in turn, each > 0.
    displacement : float, optional
        Load-point displacement at each velocity.
    n : int
        Output points per interval (and as many clustered after each step).
    rtol : float
    method : str
        The integrator (:func:`stickslip.lab.spring_slider.quasi_static`).
    M : float
        Mass per unit normal stress: 0 (default) for the quasi-static spring-slider, > 0 for the
        inertial one (:func:`stickslip.lab.inertial_ode.inertial_slider`).

    Returns
    -------
    ds : xarray.Dataset
        The run (:func:`stickslip.lab.spring_slider.quasi_static`).
    summary : dict
        ``steps``: per step V_before, V_after, mu before, mu_peak (the extreme after the step),
        its time, mu at the end, the closed-form steady friction of the spring mu_ss + eta V and
        (a - b) read off the run (the damping's eta (V_after - V_before) taken out); and k_c.
    """
    from stickslip.lab.stability import critical_stiffness

    v = [check_number("V", x, low=0.0, low_open=True) for x in velocities]
    if len(v) < 2:
        raise ParameterError("velocities needs at least two values (before and after a step)")
    disp = (
        20.0 * max(model.Dc)
        if displacement is None
        else check_number("displacement", displacement, low=0.0, low_open=True)
    )
    history = LoadHistory.steps(v, [disp / x for x in v])
    M = check_number("M", M, low=0.0)
    ds = _run(model, history, _grid(history, n), rtol, method, M)
    steps = []
    for i in range(1, len(v)):
        t0, t1 = history.times[i], history.times[i + 1]
        before = float(ds.mu.sel(t=t0))
        sign = 1.0 if v[i] > v[i - 1] else -1.0
        tp, mp = _peak(ds, t0, t1, sign)
        end = float(ds.mu.sel(t=t1))
        steps.append(
            {
                "t": float(t0),
                "V_before": v[i - 1],
                "V_after": v[i],
                "mu_before": before,
                "mu_peak": mp,
                "t_peak": tp,
                "mu_end": end,
                # the spring carries mu + eta V in steady sliding
                "mu_ss_closed_form": steady_friction(model, v[i]) + model.eta * v[i],
                "a_minus_b_from_run": (end - before - model.eta * (v[i] - v[i - 1])) / math.log(v[i] / v[i - 1]),
            }
        )
    summary = {
        "model": model.summary(),
        "velocities": v,
        "displacement_per_step": disp,
        "k_c": critical_stiffness(model, v[-1]),
        "M": M,
        "steps": steps,
        "integrator": ds.attrs["integrator"],
        "steps_taken": ds.attrs["steps"],
    }
    return ds, summary


def slide_hold_slide(
    model: RateState,
    V: float,
    holds: Sequence[float] = (1.0, 3.0, 10.0, 30.0, 100.0, 300.0, 1000.0),
    *,
    slide: float | None = None,
    n: int = 200,
    rtol: float = 1e-10,
    method: str = "auto",
    M: float = 0.0,
) -> tuple[xr.Dataset, dict]:
    """A slide-hold-slide test (module docstring): slides at V of load-point displacement ``slide``
    (default 20 times the largest D_c) around holds of the given lengths.

    Parameters
    ----------
    model : RateState
        The friction law and a finite stiffness k.
    V : float
        Load-point velocity of the slides.
    holds : sequence of float
        Hold times, each > 0.
    slide : float, optional
        Load-point displacement of each slide.
    n : int
        Output points per interval (and as many clustered after each breakpoint).
    rtol : float
    method : str
        The integrator (:func:`stickslip.lab.spring_slider.quasi_static`).
    M : float
        Mass per unit normal stress: 0 (default) for the quasi-static spring-slider, > 0 for the
        inertial one (:func:`stickslip.lab.inertial_ode.inertial_slider`).

    Returns
    -------
    ds : xarray.Dataset
        The run.
    summary : dict
        ``holds``: per hold t_hold, mu_ss before it, mu at the end of the hold, the peak on
        reloading and Delta mu = mu_peak - mu_ss; ``healing_rate`` (d Delta mu / d log10 t_hold, by
        least squares over the holds, with its standard error) and ``aging_long_hold_rate`` = b ln 10
        (sum over the aging-law state variables).
    """
    V = check_number("V", V, low=0.0, low_open=True)
    holds = [check_number("hold", h, low=0.0, low_open=True) for h in holds]
    if len(holds) < 1:
        raise ParameterError("holds needs at least one hold time")
    if model.k == math.inf:
        raise ParameterError("slide_hold_slide needs a finite k (in a rigid machine the log form is -inf at V = 0)")
    slide = 20.0 * max(model.Dc) if slide is None else check_number("slide", slide, low=0.0, low_open=True)
    history = LoadHistory.slide_hold_slide(V, slide / V, holds)
    M = check_number("M", M, low=0.0)
    ds = _run(model, history, _grid(history, n), rtol, method, M)
    rows = []
    for i, th in enumerate(holds):
        t_hold0 = history.times[1 + 2 * i]
        t_hold1 = history.times[2 + 2 * i]
        t_end = history.times[3 + 2 * i]
        mu_ss = float(ds.mu.sel(t=t_hold0))
        tp, mp = _peak(ds, t_hold1, t_end, 1.0)
        rows.append(
            {
                "t_hold": th,
                "mu_ss": mu_ss,
                "mu_hold_end": float(ds.mu.sel(t=t_hold1)),
                "relaxation": mu_ss - float(ds.mu.sel(t=t_hold1)),
                "mu_peak": mp,
                "t_peak_after_reload": tp - t_hold1,
                "delta_mu": mp - mu_ss,
            }
        )
    lt = np.log10([r["t_hold"] for r in rows])
    dmu = np.array([r["delta_mu"] for r in rows])
    rate = err = None
    if lt.size >= 2:
        if lt.size >= 3:
            c, cov = np.polyfit(lt, dmu, 1, cov=True)
            rate, err = float(c[0]), float(np.sqrt(cov[0, 0]))
        else:
            rate = float((dmu[1] - dmu[0]) / (lt[1] - lt[0]))
    summary = {
        "model": model.summary(),
        "V": V,
        "M": M,
        "slide_displacement": slide,
        "holds": rows,
        "healing_rate": rate,
        "healing_rate_stderr": err,
        "aging_long_hold_rate": math.log(10.0)
        * sum(b for b, law in zip(model.b, model.law, strict=True) if law == "aging"),
        "integrator": ds.attrs["integrator"],
    }
    return ds, summary
