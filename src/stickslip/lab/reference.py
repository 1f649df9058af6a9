"""A plain-Python spring-slider on :func:`scipy.integrate.odeint`: the yardstick of the compiled one.

The same equations as :mod:`stickslip.lab.quasi_static` in the log form without damping, written
once more by hand, statement by statement, as a lab's own script would (one state variable, any
of the four laws): dmu/dt = k (V - v), v = V0 exp((mu - mu0 - b ln(V0 theta / (s D_c))) / a).
Tests compare against it and the bench times against it.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import odeint


def odeint_spring_slider(a, b, Dc, mu0, V0, k, law, history, t, *, c=0.0, rtol=1e-10, atol=1e-12):
    """mu, theta and v at the times ``t`` (including every breakpoint of ``history``, starting at
    its first), starting in steady state at the first load-point velocity; one odeint call per
    interval of the history.

    Returns
    -------
    mu, theta, v : arrays
    """
    s = 2.0 if law == "prz" else 1.0

    def velocity(mu, theta):
        return V0 * math.exp((mu - mu0 - b * math.log(V0 * theta / (s * Dc))) / a)

    def rhs(y, t, vlp):
        mu, theta = y
        v = velocity(mu, theta)
        dmu = k * (vlp - v)
        x = v * theta / (s * Dc)
        if law == "aging":
            dth = 1.0 - x
        elif law == "slip":
            dth = -x * math.log(x)
        elif law == "prz":
            dth = 1.0 - x * x
        else:
            dth = 1.0 - x - (c / b) * theta * dmu
        return [dmu, dth]

    t = np.asarray(t, dtype=float)
    V1 = history.velocities[0]
    y = [mu0 + (a - b) * math.log(V1 / V0), s * Dc / V1]
    mu = np.empty(t.size)
    th = np.empty(t.size)
    for i, vlp in enumerate(history.velocities):
        t0, t1 = history.times[i], history.times[i + 1]
        sel = np.flatnonzero((t >= t0) & (t <= t1))
        ts = t[sel]
        sol = odeint(rhs, y, ts, args=(vlp,), rtol=rtol, atol=atol, mxstep=10_000_000)
        mu[sel], th[sel] = sol[:, 0], sol[:, 1]
        y = list(sol[-1])
    v = np.array([velocity(m_, th_) for m_, th_ in zip(mu, th, strict=True)])
    return mu, th, v
