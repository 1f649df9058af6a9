"""Layout of the chain kernels' arrays: the indices of the int64 state vector ``ist`` and the
float64 parameter vector ``par``, the event buffer's columns and the status codes (eq. 4 and its
relatives, docs/model.md).

A model is a choice of four pieces (docs/model.md, "The family the paper stands in"), each a
module of :mod:`stickslip.models` that holds the compiled functions the kernels call
(:mod:`stickslip.kernels.laws`). A kernel is compiled for one composition: it gets the four
modules' import paths as literal strings, so each composition is its own machine code, and each
piece's parameters as its module's ``Params`` named tuple:

* drive, :mod:`stickslip.models.drive` (``end``: a pulling point x_0 = V t joined to block 1,
  eq. 4; ``plate``: every block joined to a plate at V t by a leaf spring Kp, Burridge-Knopoff,
  Carlson-Langer), its parameters ``ChainArgs.dp``;
* friction of a moving block, :mod:`stickslip.models.friction`, ``ChainArgs.law``;
* static threshold, :mod:`stickslip.models.threshold` (Fs, or theta_i), ``ChainArgs.tp``;
* ends, :mod:`stickslip.models.ends` (free: x_{N+1} = x_N; fixed: x_{N+1} = 0; periodic:
  x_0 = x_N, x_{N+1} = x_1), no parameters.

Blocks i = 1..N live at index i of arrays of length N + 2; index 0 and N + 1 are ghost cells
set from the drive and the ends (:func:`stickslip.kernels.laws._set_ghosts`). The state
variable has no-flux ends, th[0] = th[1] and th[N+1] = th[N] (periodic ends: th[0] = th[N],
th[N+1] = th[1]); models without a state variable leave theta untouched. ``mov`` holds 1.0
for a moving block and 0.0 for a stopped one, so a stopped block's acceleration is
``0 * (...)``.

A kernel takes one :class:`ChainArgs` (the arrays, integers and the pieces' parameters) and the
four pieces' module paths.
Kernels return a status code; the driver empties the output buffers and calls again. All
state lives in the arrays passed in, so a run can stop and resume at any step boundary.

The kernels of the chain: :mod:`~stickslip.kernels.laws` (the step's expressions),
:mod:`~stickslip.kernels.events` (outputs and event bookkeeping),
:mod:`~stickslip.kernels.triggers` (which stopped block the drive starts, and when),
:mod:`~stickslip.kernels.dense` (the reference), :mod:`~stickslip.kernels.stages` and
:mod:`~stickslip.kernels.exact` (the fast interval path), :mod:`~stickslip.kernels.plate`
(the fast sparse path of the plate drive) and :mod:`~stickslip.kernels.entry` (one compiled
entry point per model).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit, types
from numba.extending import overload

# Indices into the int64 state vector ``ist``.
STEP = 0  # n: the state held is at t_n = n dt
N_MOVING = 1  # blocks moving at t_n
EV_ACTIVE = 2  # 1 while an event is in progress
EV_START_STEP = 3  # step in which the event's first block moved
EV_START_BLOCK = 4
EV_MAX_BLOCK = 5  # farthest block moved so far in the event
EV_N_MOVED = 6  # blocks moved so far in the event
ACT_LO = 7  # blocks that may change in the next step: [ACT_LO, ACT_HI] (empty if lo > hi)
ACT_HI = 8
N_EVENTS = 9  # events completed since the start of the run (the next event's id)
EV_COUNT = 10  # rows filled in the event buffer
FM_COUNT = 11  # rows filled in the first-move buffer
S_COUNT = 12  # samples filled in the sample buffer
P_COUNT = 13  # rows filled in the profile buffer
EV_P_FIRST = 14  # first profile row of the current event in the buffer
NEXT_PROFILE = 15  # next step at which a profile row is due
BAD_BLOCK = 16  # block found non-finite (status NONFINITE)
BLOCK_UPDATES = 17  # block updates performed (stage 2), for profiling
STEPS_COMPUTED = 18  # steps actually computed (not jumped over)
NEXT_SAMPLE = 19  # next step at which L = x_1 - x_N is sampled
MECH_LO = 20  # blocks that may move in the next step: [MECH_LO, MECH_HI] (exact only)
MECH_HI = 21
FULL_UPDATES = 22  # block updates of exact that were full (the rest updated the state variable alone)
IST_SIZE = 23

# Indices into the float64 parameter vector ``par``: the springs and the drive (the threshold's and
# the friction law's parameters travel as their modules' named tuples, ``ChainArgs.tp`` and
# ``ChainArgs.law``).
P_K, P_V, P_DT = range(3)
PAR_SIZE = 3

# Columns of the int64 event buffer ``ev_int``.
E_ID, E_START_STEP, E_END_STEP, E_START_BLOCK, E_MAX_BLOCK, E_N_BLOCKS = range(6)
EV_INT_COLS = 6

# Status codes returned by the kernels.
DONE = 0
EVENTS_FULL = 1
FIRST_MOVES_FULL = 2
SAMPLES_FULL = 3
PROFILES_FULL = 4
NONFINITE = 5
ALL_MOVING = 6  # a sample taken with every block moving (``stop_all_moving``): the driver looks


class ChainArgs(NamedTuple):
    """What a chain kernel works on besides the pieces: the state, scratch, parameter and output
    arrays and the integers of one call (numba passes a named tuple as one argument)."""

    x: np.ndarray  # float64 (N + 2): positions at t_n, ghost cells at 0 and N + 1
    v: np.ndarray  # velocities
    th: np.ndarray  # state variable theta
    mov: np.ndarray  # 1.0 moving, 0.0 stopped
    xs: np.ndarray  # scratch: stage-1 predictors of x, v, theta
    vs: np.ndarray
    ths: np.ndarray
    mm: np.ndarray  # scratch: the step's mask of moving blocks
    a1: np.ndarray  # scratch: stage-1 accelerations and theta derivatives
    b1: np.ndarray
    trig: np.ndarray  # int64 scratch: the plate drive's first start step of each stopped block
    first_step: np.ndarray  # int64: step of each block's first move in the current event (-1: none)
    x0ev: np.ndarray  # x of each block at its first move
    ist: np.ndarray  # int64 state vector (indices above)
    par: np.ndarray  # float64 parameter vector (indices above)
    dp: tuple  # the drive's parameters (its module's Params named tuple)
    tp: tuple  # the threshold's parameters (its module's Params named tuple)
    law: tuple  # the friction law's parameters (its module's Params named tuple)
    kb: object  # None (every spring K, par[P_K]), or float64 (N + 2): kb[i] the spring between blocks i-1 and i
    mass: object  # None (unit masses), or float64 (N + 2): the mass of block i at i
    ev_int: np.ndarray  # event buffer (columns above) and each event's S
    ev_S: np.ndarray
    fm: np.ndarray  # first moves: (event, block, step)
    samp_L: np.ndarray  # samples of L, their steps and the blocks moving then (int64)
    samp_step: np.ndarray
    samp_moving: np.ndarray
    prof_x: np.ndarray  # profile rows and their (event, step)
    prof_meta: np.ndarray
    n_end: int  # the call ends at this step
    sample_every: int
    profile_every: int  # 0: no profiles
    profile_min_blocks: int
    stop_all_moving: int  # 1: return ALL_MOVING after a sample at which every block moves
    trace: object = None  # None, or a Trace: every block's state at every few steps (the reference only)


class Trace(NamedTuple):
    """Every block's state after each ``every``-th step (from ``count[1]`` on), and the range of v over every
    step (the single block's series, Figs. 1-2): written by the reference kernel
    (:func:`stickslip.kernels.dense.run_dense`, :func:`stickslip.kernels.events._trace`) where
    ``ChainArgs.trace`` is one; None (every chain) compiles to nothing."""

    every: int  # record the state after steps every, 2 every, ...
    x: np.ndarray  # float64 (rows, N): x_1..x_N at the recorded steps
    v: np.ndarray
    th: np.ndarray
    mov: np.ndarray  # 1.0 moving, 0.0 stopped
    step: np.ndarray  # int64 (rows): the recorded steps
    count: np.ndarray  # int64 (2): rows filled (a full buffer is left as it is) and the next step due
    v_range: np.ndarray  # float64 (2): least and greatest v_i over the blocks and every step so far


_BIG = np.float64(1.7976931348623157e308)
_NEVER = np.int64(9223372036854775807)


@njit(cache=True, inline="always")
def _merge(a_lo, a_hi, b_lo, b_hi):
    """Hull of two intervals of blocks, either of which may be empty (lo > hi)."""
    if b_lo > b_hi:
        return a_lo, a_hi
    if a_lo > a_hi:
        return b_lo, b_hi
    return min(a_lo, b_lo), max(a_hi, b_hi)


def _springs_of(par, kb):
    """K from the parameter vector, or the springs per bond ``kb``."""
    return kb


@overload(_springs_of)
def _springs_of_impl(par, kb):
    if isinstance(kb, types.NoneType):
        return lambda par, kb: par[P_K]
    return lambda par, kb: kb


@njit(cache=True, inline="always")
def _unpack(par, dp, tp, law, kb, mass):
    """mp = (K, the drive's, the threshold's and the law's parameters, the masses), V and dt from
    the parameter vector and the pieces' named tuples; K is the float par[P_K], or the springs
    per bond ``kb`` where the chain has them; the masses are None for unit masses."""
    return (_springs_of(par, kb), dp, tp, law, mass), par[P_V], par[P_DT]
