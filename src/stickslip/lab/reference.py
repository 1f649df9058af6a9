"""A plain-Python spring-slider on :func:`scipy.integrate.odeint`: the yardstick of the compiled one.

The same equations as :mod:`stickslip.lab.spring_slider` in the log form, written once more by hand,
statement by statement, as a lab's own script would: tau = k (p - x) = mu + eta v,
dtau/dt = k (V - v), mu = mu0 + a ln(v / V0) + sum_k b_k ln(V0 theta_k / (s_k D_c,k)), each
theta_k by its law; v in closed form without damping, by Brent's method on
mu(v) + eta v = tau with it. Tests compare against it and the bench times against it.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import odeint
from scipy.optimize import brentq


def odeint_spring_slider(a, b, Dc, mu0, V0, k, law, history, t, *, c=0.0, eta=0.0, rtol=1e-10, atol=1e-12):
    """mu (the spring's friction tau), theta and v at the times ``t`` (which must include every
    breakpoint of ``history``, starting at its first), starting in steady state at the first
    load-point velocity; one odeint call per interval of the history.

    Parameters
    ----------
    a, mu0, V0, k, eta : float
    b, Dc, c : float or sequence of float
        One per state variable.
    law : str or sequence of str
        ``aging``, ``slip``, ``prz`` or ``nagata`` for each state variable.
    history : LoadHistory
    t : array

    Returns
    -------
    mu, theta, v : arrays
        ``theta`` has one column per state variable when there are several.
    """
    bs = list(b) if isinstance(b, list | tuple) else [b]
    m = len(bs)
    dcs = list(Dc) if isinstance(Dc, list | tuple) else [Dc] * m
    laws = list(law) if isinstance(law, list | tuple) else [law] * m
    cs = list(c) if isinstance(c, list | tuple) else [c] * m
    s = [2.0 if name == "prz" else 1.0 for name in laws]

    def friction(v, theta):
        mu = mu0 + a * math.log(v / V0)
        for j in range(m):
            mu += bs[j] * math.log(V0 * theta[j] / (s[j] * dcs[j]))
        return mu

    def velocity(tau, theta):
        psi = friction(V0, theta)
        v = V0 * math.exp((tau - psi) / a)
        if eta == 0.0:
            return v
        # the undamped v is an upper bound: mu(v) + eta v - tau > 0 there
        return brentq(lambda w: friction(w, theta) + eta * w - tau, v * 1e-30, v, xtol=1e-300, rtol=1e-15)

    def rhs(y, t, vlp):
        tau, theta = y[0], y[1:]
        v = velocity(tau, theta)
        dtau = k * (vlp - v)
        out = [dtau]
        for j in range(m):
            x = v * theta[j] / (s[j] * dcs[j])
            if laws[j] == "aging":
                out.append(1.0 - x)
            elif laws[j] == "slip":
                out.append(-x * math.log(x))
            elif laws[j] == "prz":
                out.append(1.0 - x * x)
            else:
                out.append(1.0 - x - (cs[j] / bs[j]) * theta[j] * dtau)
        return out

    t = np.asarray(t, dtype=float)
    V1 = history.velocities[0]
    theta0 = [s[j] * dcs[j] / V1 for j in range(m)]
    y = [friction(V1, theta0) + eta * V1, *theta0]
    Y = np.empty((t.size, m + 1))
    for i, vlp in enumerate(history.velocities):
        t0, t1 = history.times[i], history.times[i + 1]
        sel = np.flatnonzero((t >= t0) & (t <= t1))
        sol = odeint(rhs, y, t[sel], args=(vlp,), rtol=rtol, atol=atol, mxstep=10_000_000)
        Y[sel] = sol
        y = list(sol[-1])
    v = np.array([velocity(row[0], row[1:]) for row in Y])
    theta = Y[:, 1] if m == 1 else Y[:, 1:]
    return Y[:, 0], theta, v


def odeint_one_state(a, b, Dc, mu0, V0, k, history, t, *, rtol=1e-10, atol=1e-12):
    """The aging law with one state variable and no damping, as lean as a lab's script writes it
    (what :mod:`stickslip.lab.bench` times: no loops over state variables, no root finding).

    Returns
    -------
    mu, theta : arrays
        At the times ``t`` (which must include every breakpoint of ``history``).
    """

    def rhs(y, t, vlp):
        mu, theta = y
        v = V0 * math.exp((mu - mu0 - b * math.log(V0 * theta / Dc)) / a)
        return [k * (vlp - v), 1.0 - v * theta / Dc]

    t = np.asarray(t, dtype=float)
    V1 = history.velocities[0]
    y = [mu0 + (a - b) * math.log(V1 / V0), Dc / V1]
    Y = np.empty((t.size, 2))
    for i, vlp in enumerate(history.velocities):
        sel = np.flatnonzero((t >= history.times[i]) & (t <= history.times[i + 1]))
        sol = odeint(rhs, y, t[sel], args=(vlp,), rtol=rtol, atol=atol, mxstep=10_000_000)
        Y[sel] = sol
        y = list(sol[-1])
    return Y[:, 0], Y[:, 1]
