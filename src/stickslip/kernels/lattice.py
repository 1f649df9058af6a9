"""The reference integrator of a model on any lattice (docs/lattice.md): the Heun step, start
and stop rules and events of :func:`stickslip.kernels.dense.run_dense`, with the springs' force
and the state variable's diffusion read through the lattice's Laplacian.

One step from t_n = n dt to t_{n+1}, at every block k of the lattice (docs/model.md):

1. the lattice's ghost cells from the load point p(t_n) (``fill``); a stopped block with
   f_k > threshold moves (with v = 0) for this step, ``mm`` the step's mask;
2. stage 1 at t_n: f_k = the drive's ``force_lap(K lap(x)_k, ...)`` (K times the lattice's
   Laplacian of x, plus the drive's own term), a_k = mm (f_k - friction), b_k = the law's
   ``rate_lap(lap(theta)_k, ...)``; predictors xs = x + dt v, vs = v + dt a, ths = th + dt b;
3. ghost cells of the predictors from p(t_{n+1}); stage 2 and the corrector
   x += dt/2 (v + vs), v += dt/2 (a + a2), th += dt/2 (b + b2);
4. a moving block whose new v <= 0 stops with v = 0.

Events as in :mod:`stickslip.kernels.events` (an event starts with the first step in which a block
moves after a step that ended with every block stopped, and ends with the first step that ends
with every block stopped): its epicentre is the first block in the lattice's order to move, and
at its end the lattice's ``extent`` gives the area (blocks that slipped), the moment (their total
slip) and the bounding box. The lattice is a literal module path like the pieces
(:mod:`stickslip.models.lattice`), so each lattice and composition is its own machine code; on the
chain lattice the step is :func:`~stickslip.kernels.dense.run_dense`'s, bit for bit.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from stickslip.kernels.laws import _accel, _pull, _threshold, at, call
from stickslip.kernels.layout import (
    _BIG,
    BAD_BLOCK,
    BLOCK_UPDATES,
    DONE,
    EV_ACTIVE,
    EV_COUNT,
    EV_N_MOVED,
    EV_START_BLOCK,
    EV_START_STEP,
    EVENTS_FULL,
    N_EVENTS,
    N_MOVING,
    NONFINITE,
    STEP,
    STEPS_COMPUTED,
)

# Columns of the lattice's int64 event buffer ``ev_int`` (the moment is ``ev_moment``).
(
    L_ID,
    L_START_STEP,
    L_END_STEP,
    L_EPICENTRE,
    L_AREA,
    L_ROW_MIN,
    L_ROW_MAX,
    L_COL_MIN,
    L_COL_MAX,
) = range(9)
LATTICE_EV_COLS = 9


class LatticeArgs(NamedTuple):
    """What a lattice kernel works on besides the pieces: flat padded arrays of the lattice's
    layout (:meth:`stickslip.models.lattice.square.Square.geometry`), parameters and buffers."""

    x: np.ndarray  # float64, padded flat: positions at t_n, ghost ring set each stage
    v: np.ndarray
    th: np.ndarray
    mov: np.ndarray  # 1.0 moving, 0.0 stopped
    xs: np.ndarray  # scratch: stage-1 predictors, the step's mask, stage-1 rates
    vs: np.ndarray
    ths: np.ndarray
    mm: np.ndarray
    a1: np.ndarray
    b1: np.ndarray
    first_step: np.ndarray  # int64: step of each block's first move in the event (-1: none)
    x0ev: np.ndarray  # x of each block at its first move
    geo: np.ndarray  # int64: the lattice's geometry vector
    ist: np.ndarray  # int64 state vector (indices of stickslip.kernels.layout)
    par: np.ndarray  # float64: K, V, dt (stickslip.kernels.layout.P_K, P_V, P_DT)
    dp: tuple  # the drive's, the threshold's and the friction law's parameters (named tuples)
    tp: tuple
    law: tuple
    mass: object  # None (unit masses) or a float M
    ev_int: np.ndarray  # event buffer (columns above) and each event's moment
    ev_moment: np.ndarray
    n_end: int  # the call ends at this step


@njit(cache=True)
def _first_moves(n, x, mm, first_step, x0ev, ist, geo):
    """Event start and first moves before stage 2 (x holds t_n): an event opens at the first block
    in the lattice's order whose mask is set, after a step that ended with every block stopped."""
    R, C, W, base = geo[0], geo[1], geo[2], geo[3]
    if ist[EV_ACTIVE] == 0:
        if ist[N_MOVING] != 0:
            return
        first = -1
        for r in range(R):
            row = base + r * W
            for k in range(row, row + C):
                if mm[k] != 0.0:
                    first = k
                    break
            if first >= 0:
                break
        if first < 0:
            return
        ist[EV_ACTIVE] = 1
        ist[EV_START_STEP] = n
        ist[EV_START_BLOCK] = first
        ist[EV_N_MOVED] = 0
    for r in range(R):
        row = base + r * W
        for k in range(row, row + C):
            if mm[k] != 0.0 and first_step[k] < 0:
                first_step[k] = n
                x0ev[k] = x[k]
                ist[EV_N_MOVED] += 1


@njit(cache=True, inline="always")
def _end(n, args, lattice):
    """Close the event that ended in step n (x holds t_{n+1}): its row, from the lattice's extent."""
    ist, ev_int = args.ist, args.ev_int
    area, moment, r0, r1, c0, c1 = call(lattice, "extent", args.first_step, args.x, args.x0ev, args.geo)
    eid = ist[N_EVENTS]
    r = ist[EV_COUNT]
    ev_int[r, L_ID] = eid
    ev_int[r, L_START_STEP] = ist[EV_START_STEP]
    ev_int[r, L_END_STEP] = n
    ev_int[r, L_EPICENTRE] = ist[EV_START_BLOCK]
    ev_int[r, L_AREA] = area
    ev_int[r, L_ROW_MIN] = r0
    ev_int[r, L_ROW_MAX] = r1
    ev_int[r, L_COL_MIN] = c0
    ev_int[r, L_COL_MAX] = c1
    args.ev_moment[r] = moment
    ist[EV_COUNT] = r + 1
    ist[EV_ACTIVE] = 0
    ist[N_EVENTS] = eid + 1


@njit(cache=True)
def run_lattice_dense(args, drive, friction, threshold, lattice):
    """Reference integrator of a model on a lattice (module docstring): Heun over every block at
    every step, the springs and the state's diffusion through the lattice's Laplacian.

    ``args`` is a :class:`LatticeArgs`; ``drive``, ``friction``, ``threshold`` and ``lattice``
    the import paths of the pieces' and the lattice's modules, compile-time constants. Advances
    the state to step ``n_end`` or until the event buffer is full; returns a status code
    (:mod:`stickslip.kernels.layout`).
    """
    x, v, th, mov, xs = args.x, args.v, args.th, args.mov, args.xs
    vs, ths, mm, a1, b1 = args.vs, args.ths, args.mm, args.a1, args.b1
    ist, geo, par = args.ist, args.geo, args.par
    R, C, W, base = geo[0], geo[1], geo[2], geo[3]
    K, V, dt = par[0], par[1], par[2]
    dp, tp, lp = args.dp, args.tp, args.law
    mp = (K, dp, tp, lp, args.mass)
    h2 = 0.5 * dt
    cap_ev = args.ev_int.shape[0]
    while True:
        n = ist[STEP]
        if n >= args.n_end:
            return DONE
        if ist[EV_COUNT] >= cap_ev:
            return EVENTS_FULL
        p1 = _pull(V, n, dt, dp, drive)
        call(lattice, "fill", x, th, geo, p1)
        for r in range(R):
            row = base + r * W
            for k in range(row, row + C):
                f = call(drive, "force_lap", call(lattice, "lap", x, k, W), x[k], K, p1, at(dp, k))
                if mov[k] != 0.0 or f > _threshold(th[k], tp, threshold, k):
                    mm[k] = 1.0
                else:
                    mm[k] = 0.0
                a1[k] = _accel(f, th[k], v[k], mm[k], mp, friction, k)
                b1[k] = call(friction, "rate_lap", call(lattice, "lap", th, k, W), th[k], v[k], at(lp, k))
                xs[k] = x[k] + dt * v[k]
                vs[k] = v[k] + dt * a1[k]
                ths[k] = th[k] + dt * b1[k]
        p2 = _pull(V, n + 1, dt, dp, drive)
        call(lattice, "fill", xs, ths, geo, p2)
        _first_moves(n, x, mm, first_step=args.first_step, x0ev=args.x0ev, ist=ist, geo=geo)
        n_moving = 0
        bad = 0
        for r in range(R):
            row = base + r * W
            for k in range(row, row + C):
                f2 = call(drive, "force_lap", call(lattice, "lap", xs, k, W), xs[k], K, p2, at(dp, k))
                a2 = _accel(f2, ths[k], vs[k], mm[k], mp, friction, k)
                b2 = call(friction, "rate_lap", call(lattice, "lap", ths, k, W), ths[k], vs[k], at(lp, k))
                th[k] = th[k] + h2 * (b1[k] + b2)
                if mm[k] != 0.0:
                    x[k] = x[k] + h2 * (v[k] + vs[k])
                    vn = v[k] + h2 * (a1[k] + a2)
                    if vn <= 0.0:
                        v[k] = 0.0
                        mov[k] = 0.0
                    else:
                        v[k] = vn
                        mov[k] = 1.0
                        n_moving += 1
                else:
                    v[k] = 0.0
                    mov[k] = 0.0
                if bad == 0 and not (abs(x[k]) <= _BIG and abs(v[k]) <= _BIG and abs(th[k]) <= _BIG):
                    bad = k
        ist[N_MOVING] = n_moving
        ist[BLOCK_UPDATES] += R * C
        ist[STEPS_COMPUTED] += 1
        ist[STEP] = n + 1
        if bad > 0:
            ist[BAD_BLOCK] = bad
            return NONFINITE
        if ist[EV_ACTIVE] == 1 and n_moving == 0:
            _end(n, args, lattice)
