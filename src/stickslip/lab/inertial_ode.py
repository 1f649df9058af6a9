"""The inertial spring-slider with any number of state variables, integrated adaptively.

A block of mass M (per unit normal stress) on a rate-and-state interface (:mod:`stickslip.lab.laws`),
pulled through a spring of stiffness k by a load point at p(t) (:class:`~stickslip.lab.history.LoadHistory`):

    M dv/dt = k (p(t) - x) - mu(v, theta) - eta v,    dtheta_k/dt by law k,

integrated over y = (tau, v, theta_1 .. theta_m) with tau = k (p - x) the spring's friction, so
that dtau/dt = k (V(t) - v) (:func:`stickslip.lab.compiled.rhs` with M > 0). It is the
quasi-static spring-slider of :mod:`stickslip.lab.spring_slider` with the mass put back: the same
compiled right-hand side, laws and integrators (DOP853, or LSODA for stiff springs and through
holds too long for DOP853: :mod:`stickslip.lab.integrate`), so each state variable may follow its own law (aging,
slip, PRZ, Nagata) in the log or the asinh form, with radiation damping eta. As M -> 0 it tends to
the quasi-static solution linearly in M.

The chain's single block (:mod:`stickslip.lab.inertial`, the chain of eq. (4) at N = 1 with
threshold ``none``) is the same physics for one state variable without damping, stepped by the
chain's own fixed-step integrator; the two agree to that integrator's O(dt^2)
(tests/test_lab_inertial_ode.py). This route adds the models the chain's block has not (several
state variables, damping) and an error control in place of a fixed step.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from stickslip.lab.history import LoadHistory
from stickslip.lab.integrate import checked, integrate
from stickslip.lab.laws import RateState
from stickslip.lab.spring_slider import dataset, initial_state, output_times, slip_of
from stickslip.models.params import ParameterError, check_number

__all__ = ["inertial_slider", "initial_state_inertial"]


def initial_state_inertial(
    model: RateState, history: LoadHistory, *, v_init: float | None = None, theta_init=None, kick: float = 0.0
) -> np.ndarray:
    """y0 = (tau, v, theta_1 .. theta_m) at the history's start: steady sliding at ``v_init``
    (default the load point's first velocity; theta_k = s_k D_c,k / v_init unless ``theta_init``
    is given, tau = mu(v_init, theta) + eta v_init), with the slip rate (1 + ``kick``) v_init.

    Parameters
    ----------
    model : RateState
    history : LoadHistory
    v_init : float, optional
    theta_init : float or array, optional
    kick : float
        Relative kick of the slip rate (> -1): a kick starts the cycles where steady sliding is
        unstable (k < k_c).

    Returns
    -------
    numpy.ndarray

    Raises
    ------
    ParameterError
        No positive v_init (a history that starts with a hold), a bad theta_init or kick.
    """
    kick = check_number("kick", kick, low=-1.0, low_open=True)
    y = initial_state(model, history, v_init=v_init, theta_init=theta_init)
    v = float(history.velocities[0]) if v_init is None else float(v_init)
    return np.concatenate([[y[0], (1.0 + kick) * v], y[1:]])


def inertial_slider(
    model: RateState,
    history: LoadHistory,
    M: float,
    *,
    t=None,
    n: int = 2001,
    v_init: float | None = None,
    theta_init=None,
    kick: float = 0.0,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    method: str = "auto",
) -> xr.Dataset:
    """Integrate the inertial spring-slider (module docstring) over a load history.

    Parameters
    ----------
    model : RateState
        The friction law (any number of state variables, each its law; log or asinh form), a
        finite stiffness k (required) and the damping eta.
    history : LoadHistory
        The load point; the integrator restarts at each breakpoint.
    M : float
        Mass per unit normal stress (> 0): the block's relaxation time is M v / a.
    t : array, optional
        Output times (increasing, within the history); default ``n`` even points and every breakpoint.
    v_init, theta_init, kick : optional
        The start (:func:`initial_state_inertial`): steady sliding at v_init (default the first
        load-point velocity), the slip rate kicked by the factor 1 + kick.
    rtol, atol : float
        Tolerances of the error control.
    method : str
        ``auto`` (``dop853``; ``LSODA`` for a very stiff spring, or through a hold that ``dop853``
        does not cross in :data:`~stickslip.lab.integrate.HOLD_BUDGET` steps), ``dop853``,
        ``LSODA``, ``Radau`` or ``BDF`` (:mod:`stickslip.lab.integrate`).

    Returns
    -------
    xarray.Dataset
        As :func:`stickslip.lab.spring_slider.quasi_static`'s (``mu`` is the spring's friction
        k (p - x), which differs from mu(v, theta) + eta v by M dv/dt), with the attribute ``M``.

    Raises
    ------
    ParameterError
        M not > 0, no finite k, bad tolerances or method, a bad start.
    stickslip.lab.integrate.IntegrationError
        The integrator could not go on (in the log form, a slip rate driven to 0 or below).

    Examples
    --------
    >>> from stickslip.lab import LoadHistory, RateState
    >>> m = RateState(a=0.005, b=(0.006, 0.004), Dc=(5.0, 50.0), law=("aging", "slip"), mu0=0.6, V0=1.0, k=1e-3)
    >>> ds = inertial_slider(m, LoadHistory.steps([1.0, 3.0], [20.0, 600.0]), M=1e-4)
    >>> round(float(ds.mu[-1]), 6)  # mu0 + (a - b1 - b2) ln 3
    0.594507
    """
    M = check_number("M", M, low=0.0, low_open=True)
    k = model.require_k()
    if k == np.inf:
        raise ParameterError("the inertial spring-slider needs a finite k (k = inf imposes the slip rate)")
    rtol, atol = checked(method, rtol, atol)
    t_out = output_times(history, t, n)
    y0 = initial_state_inertial(model, history, v_init=v_init, theta_init=theta_init, kick=kick)
    Y, v, info = integrate(model, history, y0, t_out, rtol=rtol, atol=atol, method=method, M=M)
    tau = Y[:, 0]
    slip = slip_of(history, t_out, tau, y0[0], k)
    return dataset(model, history, t_out, tau, v, Y[:, 2:], slip, info, rtol=rtol, atol=atol, M=M)
