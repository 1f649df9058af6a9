"""Integrators of the quasi-static spring-slider over a load history, restarting at its breakpoints.

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
"""

from __future__ import annotations

import numpy as np
from numba import njit
from scipy.integrate import solve_ivp
from scipy.integrate._ivp import dop853_coefficients as _dop

from stickslip.lab.laws import rhs

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
METHODS = ("dop853", "LSODA", "Radau", "BDF")

#: Status codes of the compiled route.
STATUS_TEXT = {
    0: "done",
    -1: "too many steps",
    -2: "the step size fell to round-off: the slip rate runs away (a dynamic instability the quasi-static "
    "model cannot follow; a stiffer spring or a smaller step of the load point stays quasi-static)",
}


class IntegrationError(RuntimeError):
    """The quasi-static integration could not go on (one line saying why and where)."""


@njit(cache=True)
def _initial_step(t, y, f, t_bound, vl, rtol, atol, work, fw, args):
    """scipy's select_initial_step (Hairer et al., sec. II.4) for an error of order 7."""
    a, mu0, V0, k, eta, form, b, sdc, cb, codes = args
    n = y.size
    length = t_bound - t
    d0 = 0.0
    d1 = 0.0
    for i in range(n):
        sc = atol + abs(y[i]) * rtol
        d0 += (y[i] / sc) ** 2
        d1 += (f[i] / sc) ** 2
    d0 = np.sqrt(d0 / n)
    d1 = np.sqrt(d1 / n)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, length)
    for i in range(n):
        work[i] = y[i] + h0 * f[i]
    rhs(t + h0, work, fw, vl, a, mu0, V0, k, eta, form, b, sdc, cb, codes)
    d2 = 0.0
    for i in range(n):
        sc = atol + abs(y[i]) * rtol
        d2 += ((fw[i] - f[i]) / sc) ** 2
    d2 = np.sqrt(d2 / n) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    return min(100.0 * h0, h1, length)


@njit(cache=True)
def _dense(K, y, y_new, f_new, t_old, h, t_out, j0, j1, Y, Vs, vl, A, C, D, work, args):
    """Outputs t_out[j0:j1] inside the step (t_old, t_old + h) from DOP853's interpolant (scipy's
    ``_dense_output_impl`` and ``Dop853DenseOutput``): three more stages, then
    y(t_old + x h) = y_old + sum of the seven coefficient rows in Horner form in x and 1 - x."""
    a, mu0, V0, k, eta, form, b, sdc, cb, codes = args
    n = y.size
    ns = 12
    for st in range(ns + 1, ns + 4):
        for i in range(n):
            acc = 0.0
            for q in range(st):
                acc += A[st, q] * K[q, i]
            work[i] = y[i] + h * acc
        rhs(t_old + C[st] * h, work, K[st], vl, a, mu0, V0, k, eta, form, b, sdc, cb, codes)
    F = np.empty((7, n))
    for i in range(n):
        dy = y_new[i] - y[i]
        F[0, i] = dy
        F[1, i] = h * K[0, i] - dy
        F[2, i] = 2.0 * dy - h * (f_new[i] + K[0, i])
        for r in range(4):
            acc = 0.0
            for q in range(ns + 4):
                acc += D[r, q] * K[q, i]
            F[3 + r, i] = h * acc
    fw = np.empty(n)
    for j in range(j0, j1):
        x = (t_out[j] - t_old) / h
        for i in range(n):
            acc = 0.0
            for r in range(7):
                acc += F[6 - r, i]
                if r % 2 == 0:
                    acc *= x
                else:
                    acc *= 1.0 - x
            Y[j, i] = acc + y[i]
        Vs[j] = rhs(t_out[j], Y[j], fw, vl, a, mu0, V0, k, eta, form, b, sdc, cb, codes)


@njit(cache=True)
def dop853_history(y0, seg_t, seg_v, t_out, rtol, atol, max_steps, A, B, C, E3, E5, A_full, C_full, D, args):
    """Integrate y' = rhs(t, y; V(t)) from seg_t[0] to seg_t[-1] with V = seg_v[i] on
    [seg_t[i], seg_t[i+1]), writing y and v at each of the sorted times ``t_out``.

    The step is scipy's DOP853 (module docstring): error norm
    |h| ||e5||^2 / sqrt((||e5||^2 + 0.01 ||e3||^2) n), step factor 0.9 err^(-1/8) within [0.2, 10],
    no growth right after a rejection; outputs inside a step by :func:`_dense`.
    Returns (Y, v, status, steps, evaluations).
    """
    a, mu0, V0, k, eta, form, b, sdc, cb, codes = args
    n = y0.size
    ns = B.size
    nout = t_out.size
    Y = np.full((nout, n), np.nan)
    Vs = np.full(nout, np.nan)
    K = np.empty((ns + 4, n))
    y = y0.copy()
    y_new = np.empty(n)
    f = np.empty(n)
    work = np.empty(n)
    fw = np.empty(n)
    t = seg_t[0]
    j = 0
    steps = 0
    nfev = 0
    for s in range(seg_t.size - 1):
        tb = seg_t[s + 1]
        vl = seg_v[s]
        v = rhs(t, y, f, vl, a, mu0, V0, k, eta, form, b, sdc, cb, codes)
        nfev += 1
        while j < nout and t_out[j] <= t:
            Y[j] = y
            Vs[j] = v
            j += 1
        h_abs = _initial_step(t, y, f, tb, vl, rtol, atol, work, fw, args)
        nfev += 1
        while t < tb:
            if steps >= max_steps:
                return Y, Vs, -1, steps, nfev
            rejected = False
            while True:
                min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
                if h_abs < min_step:
                    return Y, Vs, -2, steps, nfev
                clipped = t + h_abs >= tb
                t_new = tb if clipped else t + h_abs
                h = t_new - t
                for i in range(n):
                    K[0, i] = f[i]
                for st in range(1, ns):
                    for i in range(n):
                        acc = 0.0
                        for q in range(st):
                            acc += A[st, q] * K[q, i]
                        work[i] = y[i] + h * acc
                    rhs(t + C[st] * h, work, K[st], vl, a, mu0, V0, k, eta, form, b, sdc, cb, codes)
                for i in range(n):
                    acc = 0.0
                    for q in range(ns):
                        acc += B[q] * K[q, i]
                    y_new[i] = y[i] + h * acc
                v_new = rhs(t_new, y_new, K[ns], vl, a, mu0, V0, k, eta, form, b, sdc, cb, codes)
                nfev += ns
                e5 = 0.0
                e3 = 0.0
                finite = True
                for i in range(n):
                    sc = atol + max(abs(y[i]), abs(y_new[i])) * rtol
                    s5 = 0.0
                    s3 = 0.0
                    for q in range(ns + 1):
                        s5 += E5[q] * K[q, i]
                        s3 += E3[q] * K[q, i]
                    e5 += (s5 / sc) ** 2
                    e3 += (s3 / sc) ** 2
                    if not np.isfinite(y_new[i]):
                        finite = False
                if not finite or not np.isfinite(e5) or not np.isfinite(e3):
                    h_abs *= 0.2
                    rejected = True
                    continue
                if e5 == 0.0 and e3 == 0.0:
                    err = 0.0
                else:
                    err = h * e5 / np.sqrt((e5 + 0.01 * e3) * n)
                if err < 1.0:
                    factor = 10.0 if err == 0.0 else min(10.0, 0.9 * err ** (-1.0 / 8.0))
                    if rejected:
                        factor = min(1.0, factor)
                    # A step cut short at a breakpoint says nothing against the step proposed before it.
                    h_abs = max(h_abs, h * factor) if clipped else h * factor
                    break
                h_abs *= max(0.2, 0.9 * err ** (-1.0 / 8.0))
                rejected = True
            steps += 1
            j1 = j
            while j1 < nout and t_out[j1] < t_new:
                j1 += 1
            if j1 > j:
                _dense(K, y, y_new, K[ns], t, h, t_out, j, j1, Y, Vs, vl, A_full, C_full, D, work, args)
                nfev += 3 + j1 - j
                j = j1
            t = t_new
            for i in range(n):
                y[i] = y_new[i]
                f[i] = K[ns, i]
            while j < nout and t_out[j] <= t:
                Y[j] = y
                Vs[j] = v_new
                j += 1
    return Y, Vs, 0, steps, nfev


def integrate(model, history, y0, t_out, *, rtol=1e-10, atol=1e-12, method="dop853", max_steps=10_000_000):
    """y = (tau, theta_1 .. theta_m) and v at the times ``t_out`` over the whole ``history``.

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

    Returns
    -------
    Y : array (len(t_out), m + 1), v : array, info : dict
        ``info`` has the status, steps and right-hand-side evaluations.

    Raises
    ------
    IntegrationError
        The integrator failed (too many steps, step size at round-off, a non-finite state).
    """
    args = model.arrays()
    history = history.merged()
    seg_t = np.ascontiguousarray(history.times, dtype=float)
    seg_v = np.ascontiguousarray(history.velocities, dtype=float)
    t_out = np.ascontiguousarray(t_out, dtype=float)
    y0 = np.ascontiguousarray(y0, dtype=float)
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
        sol = solve_ivp(fun, (t0, t1), y, method=method, t_eval=t_eval, rtol=rtol, atol=atol)
        if sol.status != 0 or not np.all(np.isfinite(sol.y)):
            raise IntegrationError(f"the integration stopped in [{t0:g}, {t1:g}]: {sol.message}")
        Y[inside] = sol.y[:, :-1].T if t_eval[-1] not in t_out[inside] else sol.y.T
        y = sol.y[:, -1].copy()
        steps += sol.t.size
        nfev += sol.nfev
    v = np.array([rhs(0.0, row, out, 0.0, *args) for row in Y])
    return Y, v, {"method": method, "steps": int(steps), "evaluations": int(nfev)}
