"""The inertial spring-slider of the laboratory, sampled: the chain's single block with a mass.

M dv/dt = k (p(t) - x) - mu(v, theta),  dtheta/dt = 1 - v theta / D_c (aging; or the slip, PRZ or
Nagata law),

with mu the regularised (asinh) rate-and-state law and no static threshold (docs/lab.md, "The
inertial route"): the chain of eq. (4) at N = 1, drive ``history``, friction ``rate-state`` (or
``rate-state-slip``, ``rate-state-prz``, ``rate-state-nagata``), threshold ``none``, sigma_n = 1 so
that its K is the lab's k and its M is the mass per unit normal stress. The run is the chain's
own (:class:`stickslip.run.driver.Stepper`, the exact integrator at a fixed step dt); this module
only starts it and reads x and v at the sample times, where the spring's friction is
k (p(t) - x). Below the critical stiffness k_c = (b - a) / D_c (1 + M V^2 / (a D_c)) (Rice and
Ruina 1983) steady sliding is unstable and the block settles into stick-slip cycles, whose
observables :mod:`stickslip.lab.cycles` measures. Models the chain's block has not (several
state variables, radiation damping) are sampled from the same equations integrated adaptively,
:func:`stickslip.lab.inertial_ode.inertial_slider`.
"""

from __future__ import annotations

import numpy as np

from stickslip.lab.history import LoadHistory
from stickslip.lab.laws import RateState, friction_of, steady_theta
from stickslip.models.params import ParameterError, check_number

__all__ = ["FRICTION", "check_route", "critical_stiffness_inertial", "on_chain", "sample"]

#: The chain's friction piece of each evolution law the inertial route has.
FRICTION = {"aging": "rate-state", "slip": "rate-state-slip", "prz": "rate-state-prz", "nagata": "rate-state-nagata"}


def critical_stiffness_inertial(model: RateState, M: float, V: float) -> float:
    """k_c = (b - a) / D_c (1 + M V^2 / (a D_c)) of the inertial spring-slider with one state
    variable (aging, slip or PRZ law, which linearise alike; Rice and Ruina 1983, eq. (23) with
    the mass per unit normal stress M); with Nagata's law
    k_c = (b - a) (a D_c + M V^2) / (D_c (a D_c (1 + c) + c M V^2)) (docs/models/rate-state.md,
    "The Nagata law"), the same at c = 0.

    Parameters
    ----------
    model : RateState
    M : float
    V : float

    Returns
    -------
    float
    """
    a, b, dc = model.a, model.b[0], model.Dc[0]
    if model.law[0] == "nagata" and model.c[0] != 0.0:
        c, mv2 = model.c[0], M * V * V
        return (b - a) * (a * dc + mv2) / (dc * (a * dc * (1.0 + c) + c * mv2))
    return (b - a) / dc * (1.0 + M * V * V / (a * dc))


def on_chain(model: RateState) -> bool:
    """Whether the chain's single block has the model: one state variable with a law of
    :data:`FRICTION` and no radiation damping (the others take the adaptive route,
    :func:`stickslip.lab.inertial_ode.inertial_slider`).

    Parameters
    ----------
    model : RateState

    Returns
    -------
    bool
    """
    return model.n_states == 1 and model.law[0] in FRICTION and model.eta == 0.0


def check_route(model: RateState) -> float:
    """The model's k, where the inertial route has the model: a finite k.

    Raises
    ------
    ParameterError
        No k, or k = inf, in one line.
    """
    k = model.require_k()
    if k == np.inf:
        raise ParameterError("the inertial route needs a finite k (k = inf imposes the slip rate)")
    return k


def chain_params_of(model: RateState, M: float, dt: float, history: LoadHistory):
    """The chain's parameters (N = 1) of the inertial spring-slider (module docstring).

    Raises
    ------
    ParameterError
        More than one state variable, a law other than aging, slip, prz or nagata, damping eta, no
        finite k.
    """
    from stickslip.models.presets import chain_params

    k = check_route(model)
    if not on_chain(model):
        raise ParameterError(
            "the chain's single block has one state variable with the aging, slip, prz or nagata law and no "
            f"damping (got law {','.join(model.law)}, eta {model.eta:g}); inertial_slider has the rest"
        )
    # Nagata's c (the chain's rs_c) where the law has it; the other laws do not read it.
    c = {"rs_c": float(model.c[0])} if model.law[0] == "nagata" else {}
    return chain_params(
        "sakaguchi", N=1, drive="history", history=history, friction=FRICTION[model.law[0]], threshold="none",
        rs_a=model.a, rs_b=model.b[0], Dc=model.Dc[0], v0=model.V0, mu0=model.mu0, sigma_n=1.0, K=k,
        M=float(M), dt=float(dt), V=max(float(np.max(history.velocities)), 1e-300), **c,
    )  # fmt: skip


def sample(
    model: RateState,
    M: float,
    history: LoadHistory,
    t,
    *,
    dt: float,
    v_init: float | None = None,
    kick: float = 0.5,
) -> dict:
    """Run the inertial spring-slider over ``history`` and read it at the times ``t``: on the chain's
    single block where it has the model (:func:`on_chain`), else adaptively
    (:func:`stickslip.lab.inertial_ode.inertial_slider`, the same start, ``dt`` unread).

    The block starts at the history's first time t_0 in steady sliding at the load point's first
    velocity V_1 (theta = s D_c / V_1, s = 2 for the PRZ law and 1 otherwise; the spring at
    mu_ss(V_1)), but with the slip rate
    ``v_init``, default (1 + ``kick``) V_1: the kick starts the cycles where steady sliding is
    unstable.

    Parameters
    ----------
    model : RateState
        a, b, D_c, mu0, V0, k and eta (read in the asinh form): on the chain with one state
        variable (aging, slip, PRZ or Nagata law) and eta = 0, adaptively otherwise.
    M : float
        Mass per unit normal stress (> 0).
    history : LoadHistory
        The load point.
    t : array
        Sample times, increasing, within the history, at least ``dt`` apart.
    dt : float
        The integrator's fixed step.
    v_init : float, optional
        The slip rate at t_0.
    kick : float
        Relative kick of the default v_init.

    Returns
    -------
    dict
        ``t``, ``mu`` (the spring's friction k (p - x)), ``v`` (slip rate), ``steps``.

    Raises
    ------
    ParameterError
        Bad M or dt, samples closer than dt or outside the history, a model the route lacks.
    stickslip.run.errors.NonFiniteState
        The run blew up (dt too large for the slip rates reached).
    """
    from stickslip.run.driver import ChainState, Stepper

    M = check_number("M", M, low=0.0, low_open=True)
    dt = check_number("dt", dt, low=0.0, low_open=True)
    t = np.asarray(t, dtype=float).ravel()
    t0 = float(history.times[0])
    if t.size == 0 or t[0] < t0 or t[-1] > history.t_end or np.any(np.diff(t) <= 0.0):
        raise ParameterError(f"sample times must increase within the history [{t0:g}, {history.t_end:g}]")
    steps = np.rint((t - t0) / dt).astype(np.int64)
    if np.any(np.diff(steps) <= 0):
        raise ParameterError(f"dt = {dt:g} must be smaller than the spacing of the samples ({np.min(np.diff(t)):g})")
    V1 = float(history.velocities[0])
    if V1 <= 0.0:
        raise ParameterError("the inertial route starts in steady sliding: the history must start at V > 0")
    lab = model.with_values(form="asinh")
    v0 = (1.0 + kick) * V1 if v_init is None else check_number("v_init", v_init, low=0.0, low_open=True)
    if not on_chain(model):
        from stickslip.lab.inertial_ode import inertial_slider

        ds = inertial_slider(lab, history, M, t=t, kick=kick if v_init is None else v0 / V1 - 1.0)
        return {"t": t, "mu": ds.mu.values, "v": ds.v.values, "steps": int(ds.attrs["steps"])}
    # the chain's time starts at 0: the history shifted to start there
    shifted = LoadHistory.table(history.times - t0, history.positions)
    p = chain_params_of(model, M, dt, shifted)
    theta = float(steady_theta(lab, V1)[0])
    p0 = float(history.positions[0])
    x0 = p0 - friction_of(lab, V1, np.array([theta])) / p.K
    state = ChainState.from_blocks([x0], [v0], [theta], [False])
    stepper = Stepper(p)
    x = np.empty(t.size)
    v = np.empty(t.size)
    for i, n in enumerate(steps):
        if n > 0:
            stepper.advance(state, int(n))
        x[i] = state.x[0]
        v[i] = state.v[0]
    mu = p.K * (history.position(t) - x)
    return {"t": t, "mu": mu, "v": v, "steps": int(steps[-1])}
