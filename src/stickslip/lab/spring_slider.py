"""The quasi-static spring-slider of the rock-friction laboratory.

A massless block on a rate-and-state interface (:mod:`stickslip.lab.laws`) pulled through a spring
of stiffness k by a load point at p(t) (:class:`~stickslip.lab.history.LoadHistory`):

    tau = k (p(t) - x) = mu(v, theta) + eta v,    v = dx/dt,

so dtau/dt = k (V(t) - v) and each theta_k follows its law; v follows from tau and theta
(:func:`stickslip.lab.laws.slip_rate`). This is how the laboratory reads a velocity step or a
slide-hold-slide test (Dieterich 1979; Ruina 1983; Marone 1998, Annu. Rev. Earth Planet. Sci.
26, 643). The measured friction is the spring's, tau; with eta = 0 it is mu(v, theta).
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from stickslip.lab.history import LoadHistory
from stickslip.lab.integrate import checked, integrate
from stickslip.lab.laws import RateState, friction_of, steady_theta
from stickslip.models.params import ParameterError, check_number

__all__ = ["dataset", "initial_state", "quasi_static", "slip_of", "solve"]


def initial_state(
    model: RateState, history: LoadHistory, *, v_init: float | None = None, theta_init=None
) -> np.ndarray:
    """y0 = (tau, theta_1 .. theta_m) at the history's start: steady sliding at ``v_init`` (default
    the load point's first velocity) unless ``theta_init`` is given, and tau = mu(v_init, theta) + eta v_init.

    Parameters
    ----------
    model : RateState
    history : LoadHistory
    v_init : float, optional
    theta_init : float or array, optional

    Returns
    -------
    numpy.ndarray
        (tau, theta_1 .. theta_m).

    Raises
    ------
    ParameterError
        The history starts with a hold and neither v_init nor a positive first velocity is given
        (the law is singular at v = 0), or theta_init is not one positive number per state variable.
    """
    if v_init is None:
        v_init = float(history.velocities[0])
        if v_init <= 0.0:
            raise ParameterError(
                "the history starts at V = 0, where the law is singular: give v_init > 0 (the slip rate at t = 0)"
            )
    v_init = check_number("v_init", v_init, low=0.0, low_open=True)
    if theta_init is None:
        th = steady_theta(model, v_init)
    else:
        th = np.atleast_1d(np.asarray(theta_init, dtype=float))
        if th.size != model.n_states or not np.all(np.isfinite(th)) or np.any(th <= 0.0):
            raise ParameterError(
                f"theta_init must be {model.n_states} finite number(s) > 0, one per state variable (got {theta_init!r})"
            )
    mu = friction_of(model, v_init, th)
    return np.concatenate([[mu + model.eta * v_init], th])


def output_times(history: LoadHistory, t=None, n: int = 2001) -> np.ndarray:
    """The sorted, distinct output times: ``t`` as given (within the history), else ``n`` even
    points and every breakpoint.

    Parameters
    ----------
    history : LoadHistory
    t : array, optional
    n : int

    Returns
    -------
    numpy.ndarray
    """
    if t is None:
        n = int(check_number("n", n, low=2, integer=True))
        t = np.union1d(np.linspace(history.times[0], history.t_end, n), history.times)
        return t
    t = np.asarray(t, dtype=float).ravel()
    if t.size == 0 or not np.all(np.isfinite(t)):
        raise ParameterError("t must be finite output times")
    if np.any(np.diff(t) <= 0.0):
        raise ParameterError("t must increase")
    if t[0] < history.times[0] or t[-1] > history.t_end:
        raise ParameterError(
            f"t must lie within the history, [{history.times[0]:g}, {history.t_end:g}] (got {t[0]:g} .. {t[-1]:g})"
        )
    return t


def solve(
    model: RateState,
    history: LoadHistory,
    t,
    *,
    v_init: float | None = None,
    theta_init=None,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    method: str = "auto",
) -> dict:
    """The arrays of :func:`quasi_static` without the Dataset around them (what a fit evaluates
    many times).

    Parameters
    ----------
    model, history, v_init, theta_init, rtol, atol, method
        As for :func:`quasi_static`.
    t : array
        Output times, increasing, within the history.

    Returns
    -------
    dict
        ``t``, ``mu``, ``v``, ``theta`` (t, m), ``y0`` and the integrator's ``info``.
    """
    k = model.require_k()
    rtol, atol = checked(method, rtol, atol)
    y0 = initial_state(model, history, v_init=v_init, theta_init=theta_init)
    Y, v, info = integrate(model, history, y0, t, rtol=rtol, atol=atol, method=method)
    tau = Y[:, 0]
    if k == np.inf:
        # A rigid machine: the friction of the imposed slip rate and the state reached.
        tau = np.array([friction_of(model, vi, yi[1:]) for vi, yi in zip(v, Y, strict=True)])
    return {"t": t, "mu": tau, "v": v, "theta": Y[:, 1:], "y0": y0, "info": info}


def slip_of(history: LoadHistory, t_out, tau, tau0: float, k: float):
    """x(t) - x(0) = p(t) - p(0) - (tau - tau_0) / k from the spring's tau = k (p - x) (the load
    point's own displacement for a rigid machine, k = inf).

    Parameters
    ----------
    history : LoadHistory
    t_out : array
        Times.
    tau : array
        The spring's friction at ``t_out``.
    tau0 : float
        The spring's friction at the history's start.
    k : float
        Stiffness.

    Returns
    -------
    numpy.ndarray
    """
    dp = history.position(t_out) - float(history.position(history.times[0]))
    return dp if k == np.inf else dp - (tau - tau0) / k


def quasi_static(
    model: RateState,
    history: LoadHistory,
    *,
    t=None,
    n: int = 2001,
    v_init: float | None = None,
    theta_init=None,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    method: str = "auto",
) -> xr.Dataset:
    """Integrate the quasi-static spring-slider (module docstring) over a load history.

    Parameters
    ----------
    model : RateState
        The friction law and the stiffness k (required) and damping eta.
    history : LoadHistory
        The load point; the integrator restarts at each breakpoint.
    t : array, optional
        Output times (increasing, within the history); default ``n`` even points and every breakpoint.
    v_init, theta_init : optional
        The start: steady sliding at v_init (default the first load-point velocity), or the
        state variables theta_init.
    rtol, atol : float
        Tolerances (down to rtol = 1e-13 or so).
    method : str
        ``auto`` (default: the compiled ``dop853``, or ``LSODA`` for a very stiff spring),
        ``dop853``, or ``LSODA``, ``Radau``, ``BDF`` through solve_ivp (:mod:`stickslip.lab.integrate`).

    Returns
    -------
    xarray.Dataset
        Over ``t``: ``mu`` (the spring's friction k (p - x)), ``v`` (slip rate), ``theta`` (with a
        ``state`` dimension when m > 1), ``load_point`` p(t), ``V`` (load-point velocity),
        ``slip`` x(t) - x(0); attributes hold the parameters, the method and its work.

    Examples
    --------
    >>> from stickslip.lab import LoadHistory, RateState
    >>> m = RateState(a=0.005, b=0.01, Dc=10.0, mu0=0.6, V0=1.0, k=1e-3)
    >>> ds = quasi_static(m, LoadHistory.steps([1.0, 10.0], [20.0, 200.0]))
    >>> round(float(ds.mu[-1]), 4)  # mu0 + (a - b) ln 10
    0.5885
    """
    k = model.require_k()
    t_out = output_times(history, t, n)
    r = solve(model, history, t_out, v_init=v_init, theta_init=theta_init, rtol=rtol, atol=atol, method=method)
    tau, v, y0, info, Y = r["mu"], r["v"], r["y0"], r["info"], r["theta"]
    slip = slip_of(history, t_out, tau, y0[0], k)
    return dataset(model, history, t_out, tau, v, Y, slip, info, rtol=rtol, atol=atol)


def dataset(model: RateState, history: LoadHistory, t_out, tau, v, Y, slip, info, *, rtol, atol, M: float = 0.0):
    """The Dataset of a spring-slider's run (:func:`quasi_static`, and the inertial one of
    :mod:`stickslip.lab.inertial_ode`): ``mu``, ``v``, ``theta`` (with a ``state`` dimension
    when m > 1), ``load_point``, ``V`` and ``slip`` over ``t``, the parameters as attributes
    (and the mass M where M > 0).

    Parameters
    ----------
    model : RateState
    history : LoadHistory
    t_out : array
        Output times.
    tau, v : array
        The spring's friction and the slip rate at ``t_out``.
    Y : array (len(t_out), m)
        The state variables.
    slip : array
        x - x(0) (:func:`slip_of`).
    info : dict
        The integrator's ``method``, ``steps`` and ``evaluations``.
    rtol, atol : float
        The tolerances used.
    M : float
        The mass (0: quasi-static).

    Returns
    -------
    xarray.Dataset
    """
    m = model.n_states
    theta = (("t", "state"), Y) if m > 1 else ("t", Y[:, 0])
    coords = {"t": ("t", t_out, {"long_name": "time"})}
    if m > 1:
        coords["state"] = np.arange(1, m + 1)
    ds = xr.Dataset(
        {
            "mu": ("t", tau, {"long_name": "friction k (p - x)", "units": "1"}),
            "v": ("t", v, {"long_name": "slip rate"}),
            "theta": (*theta[:-1], theta[-1], {"long_name": "state variable"}),
            "load_point": ("t", history.position(t_out), {"long_name": "load-point displacement p"}),
            "V": ("t", history.velocity(t_out), {"long_name": "load-point velocity"}),
            "slip": ("t", slip, {"long_name": "slip x - x(0)"}),
        },
        coords=coords,
    )
    ds.attrs.update(
        {
            "model": (
                "inertial spring-slider, M dv/dt = k (p - x) - mu(v, theta) - eta v"
                if M > 0.0
                else "quasi-static spring-slider, k (p - x) = mu(v, theta) + eta v"
            ),
            "law": ",".join(model.law),
            "form": model.form,
            "a": model.a,
            "b": list(model.b) if m > 1 else model.b[0],
            "Dc": list(model.Dc) if m > 1 else model.Dc[0],
            "mu0": model.mu0,
            "V0": model.V0,
            "k": model.k,
            "eta": model.eta,
            **({"M": float(M)} if M > 0.0 else {}),
            "integrator": info["method"],
            "rtol": float(rtol),
            "atol": float(atol),
            "steps": info["steps"],
            "evaluations": info["evaluations"],
        }
    )
    return ds
