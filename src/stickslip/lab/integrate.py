"""Integrators of the spring-slider (quasi-static, or inertial with a mass) over a load history,
restarting at its breakpoints.

Two routes over the same compiled right-hand side (:func:`stickslip.lab.laws.rhs`):

- ``dop853`` (default): scipy's DOP853 pair (Dormand and Prince's 8(5,3); Hairer, Norsett and
  Wanner, Solving ODEs I, sec. II.10), its tableau read from scipy
  (``scipy.integrate._ivp.dop853_coefficients``) and its step, error norm and step-size control
  those of scipy's ``RungeKutta._step_impl``, compiled whole with numba so that no Python runs
  between steps. Steps end on every breakpoint (a new step size is chosen there, as at a start)
  and on every output time, so the outputs are the integrator's own values, not interpolants.
- ``LSODA``, ``Radau``, ``BDF``: :func:`scipy.integrate.solve_ivp`, one call per interval of
  the history, for stiff settings (a spring far stiffer than k_c, or very fast slip) where an
  explicit method needs many small steps.
- ``auto`` (the default of the callers): ``dop853`` unless the stiffness ratio
  S = k V_max min(D_c) / a exceeds 3000, then ``LSODA`` (the threshold's measurements are in
  docs/performance.md). For the inertial spring-slider through a hold, ``dop853`` for at most
  :data:`HOLD_BUDGET` steps, then ``LSODA`` from the start: a short hold is over in a few
  thousand explicit steps, a long one drives the slip rate, and with it the block's relaxation
  time M v / a, down by orders of magnitude.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.integrate._ivp import dop853_coefficients as _dop

from stickslip.lab.compiled import dop853_history, rhs
from stickslip.models.params import ParameterError, check_number

#: The DOP853 tableau (scipy's): stages, weights, nodes and the two error estimators.
_NS = _dop.N_STAGES
_A = np.ascontiguousarray(_dop.A[:_NS, :_NS])
_B = np.ascontiguousarray(_dop.B)
_C = np.ascontiguousarray(_dop.C[:_NS])
_E3 = np.ascontiguousarray(_dop.E3)
_E5 = np.ascontiguousarray(_dop.E5)
_A_FULL = np.ascontiguousarray(_dop.A)
_C_FULL = np.ascontiguousarray(_dop.C)
_D = np.ascontiguousarray(_dop.D)

#: Methods of :func:`integrate`.
METHODS = ("auto", "dop853", "LSODA", "Radau", "BDF")

#: Above this stiffness ratio ``auto`` takes LSODA (module docstring).
STIFF_RATIO = 3000.0


def stiffness_ratio(model, history, v_init: float | None = None) -> float:
    """S = k V_max min(D_c) / a: the rate k V / a at which the spring relaxes the friction against
    the rate V / D_c of the state, at the fastest load-point velocity (0 for a rigid machine,
    where no spring relaxes)."""
    if model.k is None or model.k == np.inf:
        return 0.0
    v_max = max(float(np.max(history.velocities)), v_init or 0.0)
    return model.k * v_max * min(model.Dc) / model.a


#: Steps ``auto`` gives ``dop853`` through a hold of the inertial spring-slider before it takes
#: LSODA (about 0.1 s of the compiled integrator; module docstring).
HOLD_BUDGET = 100_000


def choose(method: str, model, history, v_init: float | None = None, M: float = 0.0) -> str:
    """The integrator ``auto`` stands for: ``dop853`` up to :data:`STIFF_RATIO`, ``LSODA`` above.
    For the inertial spring-slider (M > 0) through a hold, where the slip rate falls and with it
    the block's relaxation time M v / a, ``dop853`` first for at most :data:`HOLD_BUDGET` steps
    and ``LSODA`` after it (:func:`integrate`); ``auto`` stands for that."""
    if method != "auto":
        return method
    if stiffness_ratio(model, history, v_init) > STIFF_RATIO:
        return "LSODA"
    hold = M > 0.0 and bool(np.any(np.asarray(history.velocities) == 0.0))
    return "auto" if hold else "dop853"


#: Status codes of the compiled route.
STATUS_TEXT = {
    0: "done",
    -1: "too many steps",
    -2: "the step size fell to round-off: the slip rate runs away (a dynamic instability the quasi-static "
    "model cannot follow; a stiffer spring or a smaller step of the load point stays quasi-static)",
}


def checked(method: str, rtol: float, atol: float) -> tuple[float, float]:
    """``rtol`` and ``atol`` checked (1e-14 <= rtol <= 1, atol > 0) for a ``method`` of :data:`METHODS`.

    Parameters
    ----------
    method : str
    rtol, atol : float

    Returns
    -------
    tuple of float
        (rtol, atol) as floats.

    Raises
    ------
    ParameterError
        An unknown method or a tolerance out of range, in one line.
    """
    if method not in METHODS:
        raise ParameterError(f"method must be one of {', '.join(METHODS)} (got {method!r})")
    return check_number("rtol", rtol, low=1e-14, high=1.0), check_number("atol", atol, low=0.0, low_open=True)


class IntegrationError(RuntimeError):
    """The quasi-static integration could not go on (one line saying why and where)."""


def integrate(model, history, y0, t_out, *, rtol=1e-10, atol=1e-12, method="dop853", max_steps=10_000_000, M=0.0):
    """y = (tau, theta_1 .. theta_m) and v at the times ``t_out`` over the whole ``history``
    (quasi-static); y = (tau, v, theta_1 .. theta_m) for the inertial spring-slider of mass
    ``M`` > 0 (:func:`stickslip.lab.compiled.rhs`).

    Parameters
    ----------
    model : RateState
    history : LoadHistory
    y0 : array
        The state at the history's first breakpoint.
    t_out : array
        Sorted output times within the history.
    rtol, atol : float
        Tolerances of the error control.
    method : str
        One of :data:`METHODS` (module docstring).
    M : float
        Mass per unit normal stress; 0 for the quasi-static spring-slider.

    Returns
    -------
    Y : array (len(t_out), m + 1, or m + 2 where M > 0), v : array, info : dict
        ``info`` has the status, steps and right-hand-side evaluations.

    Raises
    ------
    IntegrationError
        The integrator failed (too many steps, step size at round-off, a non-finite state).
    """
    args = model.arrays(M)
    method = choose(method, model, history, M=M)
    history = history.merged()
    seg_t = np.ascontiguousarray(history.times, dtype=float)
    seg_v = np.ascontiguousarray(history.velocities, dtype=float)
    t_out = np.ascontiguousarray(t_out, dtype=float)
    y0 = np.ascontiguousarray(y0, dtype=float)
    budgeted = method == "auto"  # an inertial run through a hold (choose)
    if budgeted:
        method, max_steps = "dop853", min(max_steps, HOLD_BUDGET)
    if method == "dop853":
        Y, v, status, steps, nfev = dop853_history(
            y0,
            seg_t,
            seg_v,
            t_out,
            float(rtol),
            float(atol),
            int(max_steps),
            _A,
            _B,
            _C,
            _E3,
            _E5,
            _A_FULL,
            _C_FULL,
            _D,
            args,
        )
        if status != 0 and budgeted:
            return _solve_ivp_history(args, seg_t, seg_v, y0, t_out, rtol, atol, "LSODA")
        if status != 0:
            t_last = t_out[np.flatnonzero(np.isfinite(v))[-1]] if np.isfinite(v).any() else seg_t[0]
            raise IntegrationError(f"the integration stopped after t = {t_last:g}: {STATUS_TEXT[status]}")
        return Y, v, {"method": method, "steps": int(steps), "evaluations": int(nfev)}
    return _solve_ivp_history(args, seg_t, seg_v, y0, t_out, rtol, atol, method)


def _solve_ivp_history(args, seg_t, seg_v, y0, t_out, rtol, atol, method):
    """The solve_ivp route: one call per interval, the state carried across the breakpoint."""
    n = y0.size
    Y = np.full((t_out.size, n), np.nan)
    out = np.empty(n)
    y = y0.copy()
    steps = nfev = 0
    for s in range(seg_t.size - 1):
        t0, t1, vl = seg_t[s], seg_t[s + 1], seg_v[s]

        def fun(t, yy, vl=vl):
            rhs(t, yy, out, vl, *args)
            return out.copy()

        inside = (t_out >= t0) & ((t_out < t1) | ((s == seg_t.size - 2) & (t_out <= t1)))
        t_eval = np.unique(np.concatenate([t_out[inside], [t1]]))
        # dense_output keeps the steps' own times (sol.sol.ts); the values at t_eval are the same.
        sol = solve_ivp(fun, (t0, t1), y, method=method, t_eval=t_eval, rtol=rtol, atol=atol, dense_output=True)
        if sol.status != 0 or not np.all(np.isfinite(sol.y)):
            raise IntegrationError(f"the integration stopped in [{t0:g}, {t1:g}]: {sol.message}")
        Y[inside] = sol.y[:, :-1].T if t_eval[-1] not in t_out[inside] else sol.y.T
        y = sol.y[:, -1].copy()
        steps += sol.sol.ts.size - 1
        nfev += sol.nfev
    v = np.array([rhs(0.0, row, out, 0.0, *args) for row in Y])
    return Y, v, {"method": method, "steps": int(steps), "evaluations": int(nfev)}
