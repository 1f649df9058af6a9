"""Benchmark: the same chain workload with the dense and the exact integrator, in one process.

Speed is reported as ratios measured in one run (the machines are shared and noisy), and
as nanoseconds per block-step: wall time divided by the block updates a dense run does
(N times the number of steps), so the two integrators are put on the same scale.
"""

from __future__ import annotations

import platform
import time
from typing import Any

from stickslip.chain import run_chain
from stickslip.params import ChainParams


def _warm(params: ChainParams, start: str) -> None:
    """Compile (or load from cache) both kernels so compilation is not timed."""
    small = params.replace(N=min(params.N, 3))
    for integrator in ("dense", "exact"):
        run_chain(small, 20 * small.dt, integrator=integrator, start=start)


def compare(params: ChainParams, t_end: float, *, start: str = "paper", repeat: int = 1) -> dict[str, Any]:
    """Time ``dense`` and ``exact`` on the chain of eq. (4) from ``start`` to ``t_end``.

    Returns the times (fastest of ``repeat``), their ratio, ns per block-step of each,
    and whether the two runs are identical (state hash, event table and first moves).
    """
    _warm(params, start)
    best: dict[str, float] = {}
    runs = {}
    for integrator in ("dense", "exact"):
        for _ in range(repeat):
            t0 = time.perf_counter()
            run = run_chain(params, t_end, integrator=integrator, start=start)
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
        "workload": {"N": params.N, "beta": params.beta, "t_end": t_end, "start": start,
                     "steps": d.steps, "block_steps": block_steps},
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


def format_result(r: dict[str, Any]) -> str:
    """Human-readable lines of :func:`compare`'s result."""
    w = r["workload"]
    ns = r["ns_per_block_step"]
    return "\n".join([
        f"workload   N={w['N']} beta={w['beta']:g} t_end={w['t_end']:g} start={w['start']} "
        f"({w['steps']} steps, {r['n_events']} events)",
        f"dense      {r['dense_seconds']:.3f} s   {ns['dense']:.3g} ns/block-step",
        f"exact      {r['exact_seconds']:.3f} s   {ns['exact']:.3g} ns/block-step "
        f"({r['exact_block_updates']} block updates in {r['exact_steps_computed']} computed steps)",
        f"speedup    {r['speedup']:.1f}x",
        f"identical  {'yes' if r['identical'] else 'NO'}   sha256 {r['state_sha256'][:16]}...",
    ])
