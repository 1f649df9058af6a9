"""The expressions of one Heun step of the chain (eq. 4 and its relatives, docs/model.md):
spring force, acceleration under each friction, the state variable's rate, the start
threshold, the drive's position and the ghost cells.

One Heun step from t_n = n dt to t_{n+1} (docs/model.md):

1. start rule: a stopped block with f_i > threshold moves (with v = 0) for this step; ``mm``
   is this mid-step mask;
2. stage 1 at t_n: f_i = K ((x_{i-1} - x_i) - (x_i - x_{i+1})) [+ Kp (V t_n - x_i)],
   a_i = mm (f_i - friction), b_i = dtheta_i/dt; predictor xs = x + dt v, vs = v + dt a,
   ths = th + dt b;
3. stage 2 at t_{n+1} on the predictor, with the same mask; corrector
   x += dt/2 (v + vs), v += dt/2 (a + a2), th += dt/2 (b + b2);
4. stop rule: a moving block whose new v <= 0 gets v = 0 and stops.

Every integrator (:mod:`~stickslip.kernels.dense`, :mod:`~stickslip.kernels.exact`,
:mod:`~stickslip.kernels.plate`) evaluates each quantity through these functions, inlined, so
they agree bit for bit. Pieces and layout: :mod:`stickslip.kernels.layout`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from stickslip.kernels.layout import (
    DRIVE_END,
    DRIVE_PLATE,
    ENDS_FIXED,
    ENDS_PERIODIC,
    FRICTION_RATE_STATE,
    FRICTION_STATE,
    FRICTION_STRENGTHENING,
    FRICTION_WEAKENING,
    THRESHOLD_STATE,
)


@njit(cache=True, inline="always")
def _force(xl, xc, xr, K, Kp, p, drive):
    """Spring force on a block: K (x_{i+1} - 2 x_i + x_{i-1}) (eq. 4), plus Kp (V t - x_i)
    from the plate at p = V t with the plate drive (Burridge-Knopoff, Carlson-Langer)."""
    if drive == DRIVE_PLATE:
        return K * ((xl - xc) - (xc - xr)) + Kp * (p - xc)
    return K * ((xl - xc) - (xc - xr))


_LN2 = math.log(2.0)


@njit(cache=True, inline="always")
def _rate_state_mu(v, th, mp):
    """mu = a asinh(abs(v) / (2 v0) exp((mu0 + b ln(v0 theta / D_c)) / a)) of rate-and-state friction,
    regularised at v = 0 (Rice & Ben-Zion 1996; models/friction/rate_state.py).

    Read at abs(v): a moving block has v > 0, and where Heun's predictor dips below 0 within a step
    the friction keeps braking, so the stop rule catches a block that stops in the step (the odd
    extension would push it on into a spurious two-step cycle). Through log z: for z > e^20,
    asinh(z) = ln(2 z) to round-off, and exp cannot overflow.
    """
    s = 0.5 * abs(v) / mp[12]
    if s == 0.0:
        return 0.0
    lz = math.log(s) + (mp[13] + mp[10] * math.log(mp[12] * th / mp[11])) / mp[9]
    if lz > 20.0:
        return mp[9] * (lz + _LN2)
    return mp[9] * math.asinh(math.exp(lz))


@njit(cache=True, inline="always")
def _accel(f, th, v, m, mp, friction):
    """dv/dt of a block times the moving mask m (1.0 moving, 0.0 stopped).

    state (eq. 4): f - theta - beta v; weakening (Carlson-Langer): f - phi(v) with
    phi(v) = (1 - sigma) / (1 + 2 alpha max(v, 0) / (1 - sigma)); strengthening (train
    model): f - F0 - beta v; rate-state: f - sigma_n mu(v, theta) (:func:`_rate_state_mu`).
    ``mp`` = (K, Kp, beta, alpha, D, Fs, 1 - sigma, 2 alpha, F0, a, b, D_c, v0, mu0, sigma_n).
    """
    if friction == FRICTION_RATE_STATE:
        return m * (f - mp[14] * _rate_state_mu(v, th, mp))
    if friction == FRICTION_WEAKENING:
        w = mp[6]
        return m * (f - w / (1.0 + mp[7] * max(v, 0.0) / w))
    if friction == FRICTION_STRENGTHENING:
        return m * (f - mp[8] - mp[2] * v)
    return m * (f - th - mp[2] * v)


@njit(cache=True, inline="always")
def _dtheta(thl, th, thr, v, mp, friction):
    """dtheta/dt of eq. (4) with diffusion D, for moving and stopped blocks alike; the aging law
    1 - v theta / D_c of rate-state friction; 0 for frictions without a state variable."""
    if friction == FRICTION_RATE_STATE:
        return 1.0 - v * th / mp[11]
    if friction == FRICTION_STATE:
        return th * (1.0 - th) - mp[3] * th * v + mp[4] * ((thl - th) - (th - thr))
    return 0.0


@njit(cache=True, inline="always")
def _threshold(th, Fs, threshold):
    """Static threshold of the start rule: Fs, or theta_i for the state threshold."""
    if threshold == THRESHOLD_STATE:
        return th
    return Fs


@njit(cache=True, inline="always")
def _pull(V, n, dt):
    """Pulling point (or plate) V t_n with t_n = n dt from the integer step count (docs/model.md)."""
    return V * (np.float64(n) * dt)


@njit(cache=True, inline="always")
def _set_ghosts(x, th, N, p, drive, ends):
    """Ghost cells 0 and N + 1 from the drive and the ends (module docstring)."""
    if drive == DRIVE_END:
        x[0] = p
    elif ends == ENDS_PERIODIC:
        x[0] = x[N]
    elif ends == ENDS_FIXED:
        x[0] = 0.0
    else:
        x[0] = x[1]
    if ends == ENDS_PERIODIC:
        x[N + 1] = x[1]
        th[0] = th[N]
        th[N + 1] = th[1]
    else:
        if ends == ENDS_FIXED:
            x[N + 1] = 0.0
        else:
            x[N + 1] = x[N]
        th[0] = th[1]
        th[N + 1] = th[N]


@njit(cache=True, inline="always")
def _right_of_first(x, N, ends):
    """x_2 as block 1's force reads it (the ghost cell when N = 1; end drive)."""
    if N > 1:
        return x[2]
    if ends == ENDS_FIXED:
        return 0.0
    return x[1]
