"""Which blocks get which stage in a step: the active set of the fast exact paths and the rules
that carry it from one step to the next (docs/performance.md, "One active set, three forms").

A step of Heun's scheme (eq. 4, :mod:`stickslip.kernels.laws`) gives each block one of these:

* **the start test and stage 1** (the candidates): stopped blocks whose force or threshold may
  have changed, and the blocks that moved; a stopped block that passes the test joins the movers;
* **stage 2 with the stop rule** (the movers): the blocks whose mid-step mask is set;
* **stage 1 and 2 of the state variable alone**: stopped blocks whose theta may change (laws with
  a state variable only);
* **nothing**: every other block keeps every bit, as the reference computes it, until its
  **trigger**, the first step at which the drive alone brings it to its threshold (a bisection on
  the step's own expression, :mod:`stickslip.kernels.triggers`).

The next step's set follows from this one's by the same three rules on every path:

1. a stopped block can start only if a neighbour moved (its force reads them) or its trigger is
   due: the candidates are the movers dilated by :data:`MOVE_REACH`, and the due triggers;
2. a block can change only if something within :data:`CHANGE_REACH` changed (stage 2 reads the
   neighbours' predictors, which read theirs);
3. a stopped block that leaves the candidates gets its trigger, and when the set is empty the
   kernel jumps to the earliest trigger, stopping at due outputs (:func:`due_step`).

The three paths hold the set in the form their loops run fastest on:

* the chain (:func:`stickslip.kernels.exact.run_exact`): intervals of blocks, ``[lo, hi]`` (any
  update), ``[ml, mh]`` (start test and full stage 1), and a run ``[ra, rb]`` of blocks that all
  move (full stages without the start rule); each stage is one branch-free loop over a contiguous
  interval, which the compiler vectorises. Rule 1 is :func:`dilate` by one, rule 2 by two;
* the plate-driven chain without a state variable (:func:`stickslip.kernels.plate.run_sparse`):
  lists, the movers and a queue of stopped candidates, with ``trig`` per block and the smallest
  pending trigger;
* the lattice (:func:`stickslip.kernels.lattice_sparse.run_lattice_sparse`): a candidate list
  deduplicated by the step that marked each block, the movers among them, triggers in a heap.

Why three forms and not one, measured (docs/performance.md, "One active set, three forms"):

* the interval against lists, on the chain: the interval's stages are branch-free loops over
  contiguous blocks that the compiler vectorises, 1.6 ns per block update against dense's 4.4 ns
  per block-step on the partly stuck chain, where lists cost 1.5 to 2.5 times dense's per block
  on the lattice (a gather from a dozen arrays per block); and with a state variable every
  stopped block of the interval changes its theta, so lists would skip nothing;
* the lattice's generic lists against the plate lists: the lattice path run on the
  Carlson-Langer chain (the chain as a lattice, the same bits) takes 2.4 times run_sparse's time
  (0.998 against 0.420 s for t = 0..2e4): run_sparse keeps its lists through the steps in which
  nothing starts or stops (80% of them), packs the movers' stages into vector loops and rebuilds
  its queue from what changed, where the lattice path gathers its candidates anew every step;
* the step's pause as one helper taking the kernel's arguments: even inlined, numba then counts
  references to every array of the arguments at every step, and the paper's chain's exact run
  took 1.25-1.34 s against 0.55-0.74 s; the helpers here take numbers, not arrays;
* the same pauses in run_sparse: with these helpers (taking numbers) its Carlson-Langer run
  measured 0.345-0.412 s against 0.319-0.359 s written out (best of 5 to 7, process time,
  alternated); its pause stays written out.

What the paths share is the rules above, the stencil's reaches (:data:`MOVE_REACH`,
:data:`CHANGE_REACH`) and, between run_exact and its sliding steps, the interval's bookkeeping:
:func:`dilate`, the step's pauses (:func:`outputs_due`, :func:`may_overflow`, :func:`due_step`)
and :func:`due_plate_starts`. Each is inlined where it is called (numba's ``inline="always"``),
so the kernels compile as if it were written out.
"""

from __future__ import annotations

from numba import njit

from stickslip.kernels.layout import _NEVER, _merge

#: A stopped block's force reads its neighbours: it can start only next to a block that moved.
MOVE_REACH = 1
#: A step reads blocks i-2..i+2 (stage 2 reads the neighbours' predictors, which read theirs).
CHANGE_REACH = 2


@njit(cache=True, _nrt=False, inline="always")
def dilate(lo, hi, d, N, ring):
    """The non-empty interval lo..hi of blocks widened by d on each side within 1..N (rules 1 and
    2 of the module docstring); on a ring an interval that would wrap is the whole chain."""
    if ring and (lo <= d or hi > N - d):
        return 1, N
    return (lo - d if lo > d else 1), (hi + d if hi < N - d else N)


@njit(cache=True, _nrt=False, inline="always")
def due_step(n_end, next_sample, next_profile, profile_every, active):
    """The first step at which the end ``n_end``, a sample or (while an event is ``active``) a
    profile row is due: where a jump over quiet steps stops."""
    t = n_end if n_end < next_sample else next_sample
    if profile_every > 0 and active and next_profile < t:
        t = next_profile
    return t


@njit(cache=True, _nrt=False, inline="always")
def outputs_due(n, next_sample, next_profile, profile_every, active):
    """Whether step n takes a sample or (while an event is ``active``) a profile row."""
    return n == next_sample or (profile_every > 0 and active and n == next_profile)


@njit(cache=True, _nrt=False, inline="always")
def may_overflow(ev_count, fm_count, p_count, N, cap_ev, cap_fm, cap_p, profile_every):
    """Whether the next step could overflow a buffer (filled to the counts given): an event row,
    N first moves, two profile rows."""
    return ev_count >= cap_ev or fm_count + N > cap_fm or (profile_every > 0 and p_count + 2 > cap_p)


@njit(cache=True, _nrt=False, inline="always")
def due_plate_starts(mov, trig, n, ml, mh):
    """Rule 3 for the plate drive at step n: the stopped blocks whose trigger is due join the
    interval ml..mh of start tests. Returns it and the smallest trigger still pending."""
    N = mov.shape[0] - 2
    t_next = _NEVER
    for i in range(1, N + 1):
        if mov[i] == 0.0:
            if trig[i] <= n:
                ml, mh = _merge(ml, mh, i, i)
            elif trig[i] < t_next:
                t_next = trig[i]
    return ml, mh, t_next
