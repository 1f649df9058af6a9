"""The lab's compiled functions, in one module: the friction law, the quasi-static right-hand side
and the DOP853 integrator that steps it.

They sit together because numba's on-disk cache stamps a compiled function with its own source
file only: an integrator that calls a right-hand side in another module would be loaded stale
after that module changed. The state laws are the exception: each is its friction module's
``lab_rate`` (:mod:`stickslip.models.friction`, :class:`~stickslip.models.piece.LabLaw`), which
:func:`law_rates` gathers from the registry of laws when the right-hand side is compiled. The
registry and those modules are part of the digest that names the cache's directory
(:mod:`stickslip.kernels._cache`), so an edit to a law, or a new one, compiles afresh. The
equations are those of :mod:`stickslip.lab.laws` (the friction, the laws) and
:mod:`stickslip.lab.spring_slider` (the spring-slider); the integrator is described in
:mod:`stickslip.lab.integrate`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numba.extending import overload

import stickslip.kernels  # noqa: F401  (the digest's cache directory, set before numba decorates below)


@njit(cache=True, inline="always")
def psi_of(th, first, mu0, V0, b, sdc):
    """psi = mu0 + sum_k b_k ln(V0 theta_k / (s_k D_c,k)) with theta_k = th[first + k] (``sdc``
    holds s_k D_c,k): the state read in place, from the right-hand side's y or a theta array."""
    psi = mu0
    for i in range(b.size):
        psi += b[i] * math.log(V0 * th[first + i] / sdc[i])
    return psi


@njit(cache=True)
def friction(v, th, a, mu0, V0, form, b, sdc):
    """mu(v, theta) in the log form (form 0) or the asinh form (form 1) (:mod:`stickslip.lab.laws`)."""
    psi = psi_of(th, 0, mu0, V0, b, sdc)
    if form == 0:
        return psi + a * math.log(v / V0)
    return a * math.asinh(v / (2.0 * V0) * math.exp(psi / a))


@njit(cache=True, inline="always")
def slip_rate(tau, psi, a, V0, eta, form):
    """The slip rate v at which mu(v, theta) + eta v = tau, for the state's psi.

    Without damping it is explicit: v = V0 exp((tau - psi) / a) (log form) or
    v = 2 V0 exp(-psi / a) sinh(tau / a) (asinh form). With eta > 0, Newton's method on
    u = ln v: g(u) = mu(e^u) + eta e^u - tau is increasing and convex in u for both forms, and the
    undamped root lies to its right, so the iterates fall monotonically onto the root.
    """
    if form == 0:
        u = (tau - psi) / a + math.log(V0)
    else:
        if tau <= 0.0:
            return 2.0 * V0 * math.exp(-psi / a) * math.sinh(tau / a)
        u = (tau - psi) / a + math.log(V0) + math.log1p(-math.exp(-2.0 * tau / a))
    if eta == 0.0:
        return math.exp(u)
    for _ in range(100):
        v = math.exp(u)
        if form == 0:
            g = psi + a * (u - math.log(V0)) + eta * v - tau
            dg = a + eta * v
        else:
            z = v / (2.0 * V0) * math.exp(psi / a)
            g = a * math.asinh(z) + eta * v - tau
            dg = a * z / math.sqrt(1.0 + z * z) + eta * v
        du = g / dg
        u -= du
        if abs(du) <= 1e-15 * max(1.0, abs(u)):
            break
    return math.exp(u)


def lab_laws() -> tuple:
    """The friction pieces that declare their lab form (:attr:`~stickslip.models.piece.Piece.lab`),
    in the registry's order: a law's code in :func:`rhs` is its place here."""
    from stickslip.models.pieces import PIECES

    return tuple(p for p in PIECES["friction"] if p.lab is not None)


def law_rates(codes, v, y, first, sdc, cb, dtau, out):
    """out[first + k] = dtheta_k/dt of each state variable theta_k = y[first + k]: the
    ``lab_rate(x_k, theta_k, c_k / b_k, dtau/dt)`` of the law of code ``codes[k]``
    (:func:`lab_laws`), x_k = v theta_k / (s_k D_c,k) with ``sdc`` holding s_k D_c,k
    (:mod:`stickslip.lab.laws`)."""
    import importlib

    laws = lab_laws()
    for i in range(codes.size):
        rate = importlib.import_module(laws[codes[i]].module).lab_rate
        out[first + i] = rate(v * y[first + i] / sdc[i], y[first + i], cb[i], dtau)


def _pick_from(rates, j):
    """A compiled ``pick(code, x, th, cb, dtau)``: ``rates[code]`` called, for the codes j, j + 1,
    ... (the last also takes any code beyond): the laws' branches, unrolled at compile time."""
    rate = rates[j]
    if j + 1 == len(rates):

        def impl(code, x, th, cb, dtau):
            return rate(x, th, cb, dtau)

    else:
        rest = _pick_from(rates, j + 1)

        def impl(code, x, th, cb, dtau):
            if code == j:
                return rate(x, th, cb, dtau)
            return rest(code, x, th, cb, dtau)

    return njit(inline="always")(impl)


@overload(law_rates)
def _law_rates(codes, v, y, first, sdc, cb, dtau, out):
    import importlib

    pick = _pick_from(tuple(importlib.import_module(p.module).lab_rate for p in lab_laws()), 0)

    def impl(codes, v, y, first, sdc, cb, dtau, out):
        for i in range(codes.size):
            th = y[first + i]
            out[first + i] = pick(codes[i], v * th / sdc[i], th, cb[i], dtau)

    return impl


_LN2 = math.log(2.0)


@njit(cache=True, inline="always")
def mu_at(v, psi, a, V0, form):
    """mu(v, theta) of the state's psi at any slip rate v: psi + a ln(v / V0) (log form, v > 0) or
    a asinh(v / (2 V0) exp(psi / a)) (asinh form, odd in v), the latter through ln z for
    z = abs(v) / (2 V0) exp(psi / a) > e^20, where asinh z = ln 2z to round-off and exp could overflow."""
    if form == 0:
        return psi + a * math.log(v / V0)
    s = 0.5 * abs(v) / V0
    if s == 0.0:
        return 0.0
    lz = math.log(s) + psi / a
    mu = a * (lz + _LN2) if lz > 20.0 else a * math.asinh(math.exp(lz))
    return mu if v > 0.0 else -mu


# Inlined where the integrator calls it: a call passes six arrays, and the calls cost as much as
# the equations (the velocity step's integration 250 -> 140 us with 3 outputs).
@njit(cache=True, inline="always")
def rhs(t, y, out, vlp, a, mu0, V0, k, eta, form, b, sdc, cb, codes, M):
    """The spring-slider as d/dt of its state y, with V(t) = ``vlp`` the load point's velocity on
    this interval of the history. Quasi-static (M = 0; :mod:`stickslip.lab.spring_slider`),
    k (p(t) - x) = tau = mu(v, theta) + eta v and y = (tau, theta_1 .. theta_m):

        dtau/dt = k (V(t) - v),   dtheta_k/dt by law k (:mod:`stickslip.lab.laws`),

    with v from :func:`slip_rate`; with k = inf (a rigid machine) v = V(t) and tau is left alone.
    Inertial (mass M > 0 per unit normal stress; :mod:`stickslip.lab.inertial_ode`),
    y = (tau, v, theta_1 .. theta_m):

        dtau/dt = k (V(t) - v),   M dv/dt = tau - mu(v, theta) - eta v   (:func:`mu_at`),

    and the same laws, Nagata's reading dtau/dt. Writes ``out`` and returns v.
    """
    if M > 0.0:
        v = y[1]
        dtau = k * (vlp - v)
        out[0] = dtau
        out[1] = (y[0] - mu_at(v, psi_of(y, 2, mu0, V0, b, sdc), a, V0, form) - eta * v) / M
        law_rates(codes, v, y, 2, sdc, cb, dtau, out)
        return v
    if k == np.inf:
        v = vlp
        dtau = 0.0
    else:
        psi = psi_of(y, 1, mu0, V0, b, sdc)
        v = slip_rate(y[0], psi, a, V0, eta, form)
        dtau = k * (vlp - v)
    out[0] = dtau
    law_rates(codes, v, y, 1, sdc, cb, dtau, out)
    return v


@njit(cache=True)
def _initial_step(t, y, f, t_bound, vl, rtol, atol, work, fw, args):
    """scipy's select_initial_step (Hairer et al., sec. II.4) for an error of order 7."""
    a, mu0, V0, k, eta, form, b, sdc, cb, codes, M = args
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
    rhs(t + h0, work, fw, vl, a, mu0, V0, k, eta, form, b, sdc, cb, codes, M)
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
    a, mu0, V0, k, eta, form, b, sdc, cb, codes, M = args
    n = y.size
    ns = 12
    for st in range(ns + 1, ns + 4):
        for i in range(n):
            acc = 0.0
            for q in range(st):
                acc += A[st, q] * K[q, i]
            work[i] = y[i] + h * acc
        rhs(t_old + C[st] * h, work, K[st], vl, a, mu0, V0, k, eta, form, b, sdc, cb, codes, M)
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
        Vs[j] = rhs(t_out[j], Y[j], fw, vl, a, mu0, V0, k, eta, form, b, sdc, cb, codes, M)


@njit(cache=True)
def dop853_history(y0, seg_t, seg_v, t_out, rtol, atol, max_steps, A, B, C, E3, E5, A_full, C_full, D, args):
    """Integrate y' = rhs(t, y; V(t)) from seg_t[0] to seg_t[-1] with V = seg_v[i] on
    [seg_t[i], seg_t[i+1]), writing y and v at each of the sorted times ``t_out``.

    The step is scipy's DOP853 (:mod:`stickslip.lab.integrate`): error norm
    ``|h| ||e5||^2 / sqrt((||e5||^2 + 0.01 ||e3||^2) n)``, step factor 0.9 err^(-1/8) within [0.2, 10],
    no growth right after a rejection; outputs inside a step by :func:`_dense`.
    Returns (Y, v, status, steps, evaluations).
    """
    a, mu0, V0, k, eta, form, b, sdc, cb, codes, M = args
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
        v = rhs(t, y, f, vl, a, mu0, V0, k, eta, form, b, sdc, cb, codes, M)
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
                    rhs(t + C[st] * h, work, K[st], vl, a, mu0, V0, k, eta, form, b, sdc, cb, codes, M)
                for i in range(n):
                    acc = 0.0
                    for q in range(ns):
                        acc += B[q] * K[q, i]
                    y_new[i] = y[i] + h * acc
                v_new = rhs(t_new, y_new, K[ns], vl, a, mu0, V0, k, eta, form, b, sdc, cb, codes, M)
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
