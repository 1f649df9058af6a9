"""Benchmark: the same chain workload with the dense and the exact integrator, in one process.

Speed is reported as ratios measured in one run (the machines are shared and noisy), and
as nanoseconds per block-step: wall time divided by the block updates a dense run does
(N times the number of steps), so the two integrators are put on the same scale.
"""

from __future__ import annotations

import platform
import time
from collections.abc import Callable
from typing import Any

from stickslip.models.params import ChainParams
from stickslip.run.driver import run_chain
from stickslip.run.errors import short_runs_expected


def _warm(params: ChainParams, start: str) -> None:
    """Compile (or load from cache) both kernels so compilation is not timed."""
    n = min(params.N, 3)
    small = params.replace(N=n, **{k: v.values[:n] for k, v in params.per_block().items()})
    for integrator in ("dense", "exact"):
        run_chain(small, 20 * small.dt, integrator=integrator, start=start)


@short_runs_expected()  # a fixed workload, short of the loading time on purpose
def compare(
    params: ChainParams,
    t_end: float,
    *,
    start: str = "paper",
    repeat: int = 1,
    perturbation: float = 0.0,
    seed: int = 0,
    say: Callable[[str], None] | None = None,
) -> dict[str, Any]:
    """Time ``dense`` and ``exact`` on the chain of eq. (4), or any model of the family, from
    ``start`` (with ``perturbation`` and ``seed``) to ``t_end``.

    Returns the times (fastest of ``repeat``), their ratio, ns per block-step of each,
    and whether the two runs are identical (state hash, event table and first moves).
    ``say`` is told, in a line, which integrator runs now.
    """
    _warm(params, start)
    best: dict[str, float] = {}
    runs = {}
    for k in range(repeat):  # alternated, as the help says: a change of load then meets both
        for integrator in ("dense", "exact"):
            if say is not None:
                say(f"running {integrator}" + (f" ({k + 1} of {repeat})" if repeat > 1 else ""))
            t0 = time.perf_counter()
            run = run_chain(params, t_end, integrator=integrator, start=start, perturbation=perturbation, seed=seed)
            elapsed = time.perf_counter() - t0
            best[integrator] = min(best.get(integrator, float("inf")), elapsed)
            runs[integrator] = run
    d, e = runs["dense"], runs["exact"]
    identical = (
        d.summary["state_sha256"] == e.summary["state_sha256"]
        and d.events.equals(e.events)
        and d.first_move.equals(e.first_move)
        and bool((d.samples["L"].values == e.samples["L"].values).all())
    )
    block_steps = params.N * d.steps
    return {
        "workload": {
            "model": params.model,
            "N": params.N,
            "beta": params.beta,
            "t_end": t_end,
            "start": start,
            "steps": d.steps,
            "block_steps": block_steps,
        },
        "params": params.to_dict(),
        "skipped": {
            "steps_computed_fraction": e.summary["steps_computed"] / max(e.steps, 1),
            "block_updates_fraction": e.summary["block_updates"] / max(block_steps, 1),
            "full_block_updates_fraction": e.summary["full_block_updates"] / max(block_steps, 1),
        },
        "dense_seconds": best["dense"],
        "exact_seconds": best["exact"],
        "speedup": best["dense"] / best["exact"] if best["exact"] > 0 else float("inf"),
        "identical": identical,
        "dense_ns_per_block_step": 1e9 * best["dense"] / block_steps if block_steps else None,
        "exact_ns_per_block_step": 1e9 * best["exact"] / block_steps if block_steps else None,
        "ns_per_block_step": {
            "dense": 1e9 * best["dense"] / block_steps if block_steps else None,
            "exact": 1e9 * best["exact"] / block_steps if block_steps else None,
        },
        "exact_block_updates": e.summary["block_updates"],
        "exact_steps_computed": e.summary["steps_computed"],
        "n_events": e.summary["n_events"],
        "state_sha256": e.summary["state_sha256"],
        "machine": platform.processor() or platform.machine(),
    }


#: Rough cost of the dense integrator per block-step on one quiet core (ns; docs/performance.md
#: measures 4-5), for the notice of what a benchmark will cost before it starts.
DENSE_NS_PER_BLOCK_STEP = 5.0


def expected_cost(params: ChainParams, t_end: float, repeat: int = 1) -> str:
    """One line of what :func:`compare` is about to do and about how long it takes: the dense
    reference visits every block at every step (N x steps block-steps), the exact path a small
    part of them."""
    steps = int(round(t_end / params.dt))
    block_steps = params.N * steps
    seconds = repeat * block_steps * DENSE_NS_PER_BLOCK_STEP * 1e-9
    shown = f"{seconds:.0f} s" if seconds < 120 else f"{seconds / 60:.0f} min"
    return (
        f"timing dense then exact on {params.model} N={params.N} to t_end={t_end:g} ({block_steps:.2g} "
        f"block-steps): about {shown} on a quiet core, longer on a busy machine (--t-end shortens it)"
    )


def format_result(r: dict[str, Any]) -> str:
    """Human-readable lines of :func:`compare`'s result."""
    w = r["workload"]
    ns = r["ns_per_block_step"]
    return "\n".join(
        [
            f"workload   {w['model']} N={w['N']} beta={w['beta']:g} t_end={w['t_end']:g} start={w['start']} "
            f"({w['steps']} steps, {r['n_events']} events)",
            f"dense      {r['dense_seconds']:.3f} s   {ns['dense']:.3g} ns/block-step",
            f"exact      {r['exact_seconds']:.3f} s   {ns['exact']:.3g} ns/block-step "
            f"({r['exact_block_updates']} block updates in {r['exact_steps_computed']} computed steps)",
            f"speedup    {r['speedup']:.1f}x",
            f"identical  {'yes' if r['identical'] else 'NO'}   sha256 {r['state_sha256'][:16]}...",
        ]
    )


def _unit_costs(params: ChainParams) -> dict[str, float]:
    """Seconds per computed step (fixed part), per full block update and per state-variable update.

    Measured in this process on three small workloads of the exact integrator: one sliding
    block (the fixed cost of a step), the whole chain sliding (full updates), and the whole
    chain stopped with its state variables relaxing (state-variable-only updates).
    """
    import numpy as np

    from stickslip.run.state import ChainState

    def timed(p, t_end, start):
        """Best time of three runs, less that of a one-step run (the driver's fixed cost)."""
        run_chain(p, 20 * p.dt, start=start)  # compile or load
        best = {}
        for length in (p.dt, t_end):
            best[length] = float("inf")
            for _ in range(3):
                t0 = time.perf_counter()
                run = run_chain(p, length, start=start)
                best[length] = min(best[length], time.perf_counter() - t0)
        return max(best[t_end] - best[p.dt], 0.0), run.summary

    one = params.replace(N=1, beta=max(params.beta, 1.5))
    t1, s1 = timed(one, 500.0, "steady")
    per_step = t1 / s1["steps_computed"]
    slide = params.replace(beta=max(params.beta, 1.5))
    t2, s2 = timed(slide, 200.0, "steady")
    per_full = max(t2 - s2["steps_computed"] * per_step, 0.0) / s2["block_updates"]
    per_theta = 0.0
    if params.friction_piece.has_state:
        # Without a state variable a stopped block never changes: no such updates.
        still = params.replace(V=0.0)
        rng = np.random.default_rng(0)
        relax = ChainState.from_blocks(
            np.zeros(params.N), np.zeros(params.N), rng.uniform(0.2, 0.9, params.N), np.ones(params.N, bool)
        )
        t3, s3 = timed(still, 20.0, relax)
        per_theta = max(t3 - s3["steps_computed"] * per_step, 0.0) / max(s3["block_updates"], 1)
    return {"step": per_step, "full_update": per_full, "theta_update": per_theta}


@short_runs_expected()
def profile(
    params: ChainParams, t_end: float, *, start: str = "paper", perturbation: float = 0.0, seed: int = 0
) -> dict[str, Any]:
    """Where the exact integrator of eq. (4) spends its time on one workload.

    Counts its work (steps computed and jumped over, full and state-variable-only block
    updates) and splits the measured wall time with unit costs measured in this process.
    """
    costs = _unit_costs(params)
    t0 = time.perf_counter()
    run = run_chain(params, t_end, start=start, perturbation=perturbation, seed=seed)
    wall = time.perf_counter() - t0
    s = run.summary
    theta_updates = s["block_updates"] - s["full_block_updates"]
    parts = {
        "fixed cost of computed steps": s["steps_computed"] * costs["step"],
        "full block updates": s["full_block_updates"] * costs["full_update"],
        "state-variable-only updates": theta_updates * costs["theta_update"],
    }
    parts["rest (jumps, events, driver)"] = max(wall - sum(parts.values()), 0.0)
    return {
        "workload": {
            "model": params.model,
            "N": params.N,
            "beta": params.beta,
            "t_end": t_end,
            "start": start,
            "steps": s["steps"],
        },
        "wall_seconds": wall,
        "steps_computed": s["steps_computed"],
        "steps_jumped": s["steps"] - s["steps_computed"],
        "fraction_computed": s["steps_computed"] / s["steps"] if s["steps"] else 0.0,
        "blocks_per_computed_step": s["block_updates"] / s["steps_computed"] if s["steps_computed"] else 0.0,
        "full_block_updates": s["full_block_updates"],
        "theta_only_updates": theta_updates,
        # Without a state variable the other updates are stopped candidates: start rule alone.
        "partial_updates": "state variable only" if params.friction_piece.has_state else "start rule only (stopped)",
        "n_events": s["n_events"],
        "unit_costs_ns": {k: 1e9 * v for k, v in costs.items()},
        "seconds": parts,
    }


def format_profile(r: dict[str, Any]) -> str:
    """Human-readable lines of :func:`profile`'s result."""
    w = r["workload"]
    u = r["unit_costs_ns"]
    lines = [
        f"workload   {w['model']} N={w['N']} beta={w['beta']:g} t_end={w['t_end']:g} start={w['start']} "
        f"({w['steps']} steps, {r['n_events']} events)",
        f"wall       {r['wall_seconds']:.3f} s (exact)",
        f"steps      {r['steps_computed']} computed ({100 * r['fraction_computed']:.2f}%), "
        f"{r['steps_jumped']} jumped over",
        f"updates    {r['blocks_per_computed_step']:.1f} blocks per computed step: "
        f"{r['full_block_updates']} full, {r['theta_only_updates']} {r['partial_updates']}",
        f"unit cost  {u['step']:.0f} ns per computed step, {u['full_update']:.2f} ns per full update, "
        f"{u['theta_update']:.2f} ns per state-variable update",
        "time split",
    ]
    total = r["wall_seconds"]
    for name, sec in r["seconds"].items():
        lines.append(f"  {name:32s} {sec:8.3f} s  {100 * sec / total:5.1f}%")
    return "\n".join(lines)


#: The partly stuck workload: the paper's chain loading at beta = 1.3, where a few tens of
#: percent of the blocks slide and the rest stick (docs/performance.md, "A partly stuck chain").
PARTLY_STUCK = {"N": 199, "beta": 1.3, "t_prepare": 4e5, "t_timed": 1e4}

#: Timings of the exact run per timing of the dense one in each round of :func:`partly_stuck`: the
#: exact run lasts a tenth as long, and on a shared machine a short timing lands in a slow spell
#: whole where a long one averages over it (docs/performance.md, "The partly stuck benchmark").
EXACT_TIMINGS = 5


@short_runs_expected()  # the loading phase on purpose
def partly_stuck(params: ChainParams, *, t_prepare: float, t_timed: float, repeat: int = 1) -> dict[str, Any]:
    """Time ``dense`` and ``exact`` on a chain of eq. (4) that loads while partly stuck.

    The state is prepared by the exact integrator from the paper's start to ``t_prepare``;
    both integrators then continue it for ``t_timed``. The exact path's cost is per block
    update (what it computes), the dense path's per block-step (N per step): their ratio is
    the cost of the exact path's bookkeeping and general step on a partly stuck chain. Each of
    ``repeat`` rounds times the dense run once and the exact run :data:`EXACT_TIMINGS` times;
    the least time of each counts.
    """
    t0 = time.perf_counter()
    prep = run_chain(params, t_prepare, start="paper")
    prepare_seconds = time.perf_counter() - t0
    _warm(params, "paper")
    best: dict[str, float] = {}
    runs = {}
    t_end = t_prepare + t_timed
    # Alternated, and in CPU time of this process: on a shared machine the other processes'
    # load then changes the two integrators' times alike.
    for _ in range(repeat):
        for integrator in ("dense",) + ("exact",) * EXACT_TIMINGS:
            t0 = time.process_time()
            run = run_chain(params, t_end, integrator=integrator, start=prep.state, sample_moving=True)
            best[integrator] = min(best.get(integrator, float("inf")), time.process_time() - t0)
            runs[integrator] = run
    d, e = runs["dense"], runs["exact"]
    identical = (
        d.summary["state_sha256"] == e.summary["state_sha256"]
        and d.events.equals(e.events)
        and bool((d.samples["L"].values == e.samples["L"].values).all())
    )
    steps = d.state.step - prep.state.step
    block_steps = params.N * steps
    updates = e.summary["block_updates"] - prep.summary["block_updates"]  # counted from t = 0
    ns_exact = 1e9 * best["exact"] / max(updates, 1)
    ns_dense = 1e9 * best["dense"] / max(block_steps, 1)
    return {
        "workload": {
            "name": "partly-stuck",
            "model": params.model,
            "N": params.N,
            "beta": params.beta,
            "t_prepare": t_prepare,
            "t_timed": t_timed,
            "steps": steps,
            "block_steps": block_steps,
        },
        "prepare_seconds": prepare_seconds,
        "timer": "process CPU time, least of each integrator's timings, the integrators alternated",
        "repeat": repeat,
        "exact_timings": repeat * EXACT_TIMINGS,
        "moving_fraction": float(e.samples["n_moving"].values.mean()) / params.N,
        "dense_seconds": best["dense"],
        "exact_seconds": best["exact"],
        "exact_block_updates": updates,
        "updates_per_step": updates / max(steps, 1),
        "ns_per_update_exact": ns_exact,
        "ns_per_block_step_dense": ns_dense,
        "ratio": ns_exact / ns_dense,
        "identical": identical,
        "n_events": e.summary["n_events"],
        "state_sha256": e.summary["state_sha256"],
        "machine": platform.processor() or platform.machine(),
    }


def format_partly_stuck(r: dict[str, Any]) -> str:
    """Human-readable lines of :func:`partly_stuck`'s result."""
    w = r["workload"]
    return "\n".join(
        [
            f"workload   partly stuck: {w['model']} N={w['N']} beta={w['beta']:g}, prepared to t={w['t_prepare']:g} "
            f"in {r['prepare_seconds']:.1f} s, timed {w['t_timed']:g} ({w['steps']} steps, {r['n_events']} events)",
            f"moving     {100 * r['moving_fraction']:.1f}% of the blocks on average, "
            f"{r['updates_per_step']:.1f} block updates per step",
            f"dense      {r['dense_seconds']:.3f} s CPU   {r['ns_per_block_step_dense']:.3g} ns/block-step",
            f"exact      {r['exact_seconds']:.3f} s CPU   {r['ns_per_update_exact']:.3g} ns/block update",
            f"ratio      {r['ratio']:.3f} (exact per update / dense per block-step; CPU time, best of {r['repeat']} "
            f"dense and {r['exact_timings']} exact timings)",
            f"identical  {'yes' if r['identical'] else 'NO'}   sha256 {r['state_sha256'][:16]}...",
        ]
    )


#: The located workload: the paper's chain in stick-slip at beta = 0.5, continued for 5000 time
#: units (about 19 slips at N = 99) from the engine's state at t = 5e5 from the paper's start.
LOCATED = {"N": 99, "beta": 0.5, "t_prepare": 5e5, "t_timed": 5000.0}


def _located_hash(state) -> str:
    import hashlib

    h = hashlib.sha256()
    for a in (state.u[1:-1], state.v[1:-1], state.th[1:-1], state.mov, state.moved, state.ist, state.evf):
        h.update(a.tobytes())
    return h.hexdigest()


@short_runs_expected()  # the loading phase on purpose
def located(params: ChainParams, *, t_prepare: float, t_timed: float, repeat: int = 1) -> dict[str, Any]:
    """Time the located integrator's dense and fast forms (:mod:`stickslip.kernels.located`,
    :mod:`stickslip.kernels.located_fast`) on one workload of eq. (4) or a relative.

    The start is the engine's state at ``t_prepare`` from the paper's start, computed here (not
    timed); both forms then continue it for ``t_timed``, alternated, in CPU time of this process,
    the fastest of ``repeat``. ``identical``: the same state hash and event table.
    """
    from stickslip.models.params import steps_for
    from stickslip.run.located import LocatedState, LocatedStepper

    t0 = time.perf_counter()
    prep = run_chain(params, t_prepare, start="paper")
    prepare_seconds = time.perf_counter() - t0
    start = LocatedState.from_chain_state(prep.state, params)
    steps = steps_for(t_timed, params.dt, "t-end")
    steppers = {form: LocatedStepper(params, form=form) for form in ("dense", "fast")}
    for st in steppers.values():
        st.advance(start.copy(), start.step + 1)  # compile or load, and type the entry once
    best: dict[str, float] = {}
    runs = {}
    for _ in range(repeat):
        for form, st in steppers.items():
            st.work = dict.fromkeys(st.work, 0)
            state = start.copy()
            t0 = time.process_time()
            state, events = st.advance(state, start.step + steps)
            best[form] = min(best.get(form, float("inf")), time.process_time() - t0)
            runs[form] = (state, events)
    (d, de), (f, fe) = runs["dense"], runs["fast"]
    sha = _located_hash(f)
    work = steppers["fast"].work
    return {
        "workload": {
            "name": "located",
            "model": params.model,
            "N": params.N,
            "beta": params.beta,
            "start": f"the engine's state at t = {t_prepare:g} from the paper's start (computed here)",
            "t_prepare": t_prepare,
            "t_timed": t_timed,
            "steps": steps,
        },
        "prepare_seconds": prepare_seconds,
        "timer": "process CPU time, best of repeat, the forms alternated",
        "repeat": repeat,
        "dense_seconds": best["dense"],
        "fast_seconds": best["fast"],
        "ratio": best["dense"] / best["fast"] if best["fast"] > 0 else float("inf"),
        "identical": _located_hash(d) == sha and de.shape == fe.shape and bool((de == fe).all()),
        "dense_ns_per_step": 1e9 * best["dense"] / max(steps, 1),
        "fast_ns_per_step": 1e9 * best["fast"] / max(steps, 1),
        "fast_work": {**work, "stepped_fraction": (work["stepped"] + work["switch_steps"]) / max(steps, 1)},
        "n_events": int(len(fe)),
        "state_sha256": sha,
        "machine": platform.processor() or platform.machine(),
    }


def format_located(r: dict[str, Any]) -> str:
    """Human-readable lines of :func:`located`'s result."""
    w, k = r["workload"], r["fast_work"]
    return "\n".join(
        [
            f"workload   located switches: {w['model']} N={w['N']} beta={w['beta']:g}, {w['start']} "
            f"in {r['prepare_seconds']:.1f} s, timed {w['t_timed']:g} ({w['steps']} steps, {r['n_events']} events)",
            f"dense      {r['dense_seconds']:.3f} s CPU   {r['dense_ns_per_step']:.4g} ns/step",
            f"fast       {r['fast_seconds']:.4f} s CPU   {r['fast_ns_per_step']:.4g} ns/step",
            f"fast work  {k['switch_steps']} switch steps (the dense step), {k['stepped']} stepped on the moving "
            f"blocks' neighbourhood or theta alone ({100 * k['stepped_fraction']:.1f}% of the steps), "
            f"{k['jumps']} jumps, {k['start_tests']} start tests redone",
            f"ratio      {r['ratio']:.1f}x (CPU time, best of {r['repeat']})",
            f"identical  {'yes' if r['identical'] else 'NO'}   sha256 {r['state_sha256'][:16]}...",
        ]
    )


#: The disordered workload: the paper's chain from its start with thresholds Fs uniform in
#: [2.5, 3.5] and beta normal about its value (10%), against the same chain with the means.
DISORDERED = {"N": 199, "t_timed": 2e4, "Fs": ("uniform", 2.5, 3.5), "beta_width": 0.1}
#: The exact runs of the disordered workload are timed over this many times its t_end.
EXACT_LONGER = 10


def disordered_pair(params: ChainParams, seed: int = 0) -> tuple[ChainParams, ChainParams]:
    """(uniform, disordered): ``params`` with per-block values, and the same chain with each
    per-block value replaced by its mean; where ``params`` has none, the disorder of
    :data:`DISORDERED` (Fs uniform in [2.5, 3.5], beta normal with 10% width, seed ``seed``)."""
    from stickslip.models.disorder import Quenched

    if params.per_block():
        return params.replace(**{k: float(v.values.mean()) for k, v in params.per_block().items()}), params
    disorder = {"Fs": Quenched(*DISORDERED["Fs"], seed=seed)}
    if "beta" in params.used() and params.beta > 0:
        disorder["beta"] = Quenched("normal", params.beta, DISORDERED["beta_width"] * params.beta, seed=seed)
    return params, params.replace(**disorder)


@short_runs_expected()  # a fixed workload, short of the loading time on purpose
def disordered(params: ChainParams, t_end: float, *, repeat: int = 1, seed: int = 0) -> dict[str, Any]:
    """Time per block update of a disordered chain against the uniform one (docs/model.md,
    "Per-block parameters"), both integrators, in one process.

    The four runs (uniform and disordered, dense and exact) are alternated, in CPU time of this
    process, the fastest of ``repeat``. The exact runs are timed over :data:`EXACT_LONGER` times
    ``t_end`` (at ``t_end`` they last a few hundredths of a second, of which the run's setting up
    and tables are a tenth and more); the dense runs and the check of dense = exact go to
    ``t_end``. ``ratio_to_uniform``: the disordered chain's exact ns per block update over the
    uniform chain's; ``ratio_dense``: the same for dense per block-step (the same work per step
    whatever the dynamics). ``identical``: dense = exact on each chain.
    """
    chains = dict(zip(("uniform", "disordered"), disordered_pair(params, seed), strict=True))
    for p in chains.values():
        _warm(p, "paper")
    horizon = {"dense": t_end, "exact": EXACT_LONGER * t_end}
    best: dict[tuple[str, str], float] = {}
    runs = {}
    for _ in range(repeat):
        for name, p in chains.items():
            for integrator in ("dense", "exact"):
                t0 = time.process_time()
                run = run_chain(p, horizon[integrator], integrator=integrator, start="paper")
                key = (name, integrator)
                best[key] = min(best.get(key, float("inf")), time.process_time() - t0)
                runs[key] = run
    out: dict[str, Any] = {}
    for name, p in chains.items():
        d, timed = runs[(name, "dense")], runs[(name, "exact")]
        e = run_chain(p, t_end, integrator="exact", start="paper")  # dense's horizon, for the check
        block_steps = p.N * d.steps
        out[name] = {
            "per_block": {k: v.describe() for k, v in p.per_block().items()},
            "dense_seconds": best[(name, "dense")],
            "exact_seconds": best[(name, "exact")],
            "exact_t_end": horizon["exact"],
            "exact_block_updates": timed.summary["block_updates"],
            "ns_per_update_exact": 1e9 * best[(name, "exact")] / max(timed.summary["block_updates"], 1),
            "ns_per_block_step_dense": 1e9 * best[(name, "dense")] / max(block_steps, 1),
            "identical": d.summary["state_sha256"] == e.summary["state_sha256"]
            and d.events.equals(e.events)
            and bool((d.samples["L"].values == e.samples["L"].values).all()),
            "n_events": e.summary["n_events"],
            "state_sha256": e.summary["state_sha256"],
        }
    u, g = out["uniform"], out["disordered"]
    return {
        "workload": {
            "name": "disordered",
            "model": params.model,
            "N": params.N,
            "t_end": t_end,
            "start": "paper",
            "steps": runs[("uniform", "dense")].steps,
        },
        "timer": "process CPU time, best of repeat, the four runs alternated",
        "repeat": repeat,
        **out,
        "ratio_to_uniform": g["ns_per_update_exact"] / u["ns_per_update_exact"],
        "ratio_dense": g["ns_per_block_step_dense"] / u["ns_per_block_step_dense"],
        "identical": bool(u["identical"] and g["identical"]),
        "machine": platform.processor() or platform.machine(),
    }


def format_disordered(r: dict[str, Any]) -> str:
    """Human-readable lines of :func:`disordered`'s result."""
    w = r["workload"]
    lines = [
        f"workload   disordered against uniform: {w['model']} N={w['N']} t_end={w['t_end']:g} from the paper's "
        f"start ({w['steps']} steps)"
    ]
    for name in ("uniform", "disordered"):
        c = r[name]
        spec = ", ".join(f"{k} {v['spec']}" for k, v in c["per_block"].items()) or "every block alike"
        lines.append(
            f"{name:10s} exact {c['ns_per_update_exact']:.3g} ns/block update ({c['exact_block_updates']} updates "
            f"to t = {c['exact_t_end']:g}), "
            f"dense {c['ns_per_block_step_dense']:.3g} ns/block-step, {c['n_events']} events; {spec}"
        )
    lines += [
        f"ratio      {r['ratio_to_uniform']:.3f} exact per block update, {r['ratio_dense']:.3f} dense per block-step "
        f"(CPU time, best of {r['repeat']})",
        f"identical  {'yes' if r['identical'] else 'NO'} (dense = exact on both chains)",
    ]
    return "\n".join(lines)
