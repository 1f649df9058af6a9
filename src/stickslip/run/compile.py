"""Compiling the kernels ahead of time (``stickslip compile``).

numba compiles a kernel on its first call and caches it on disk
(:mod:`stickslip.kernels._cache`); a short run of each integrator of a model makes that first
call, so that later runs, tests and the workers of a sweep load the kernels instead of compiling
them, each on its own.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable

from stickslip.models.presets import PRESETS, SINGLE_BLOCK, block_params, chain_params
from stickslip.run.block import simulate_block
from stickslip.run.driver import INTEGRATORS, run_chain
from stickslip.run.errors import short_runs_expected


def compile_models(models: Iterable[str] | None = None, log: Callable[[str], None] | None = None) -> dict[str, float]:
    """Compile (or load from the cache) every kernel of the named presets (default all): both
    integrators of the chain (eq. 4 and its relatives, from the preset's start) and, for the
    presets that are also a single block (eq. 1), the block's Heun. Returns the seconds each
    model took; ``log`` gets one line per model."""
    names = list(PRESETS) if models is None else list(models)
    took: dict[str, float] = {}
    for name in names:
        t0 = time.perf_counter()
        params = chain_params(name)
        params = params.replace(N=min(params.N, 8))
        preset = PRESETS[name]
        with short_runs_expected():
            for integrator in INTEGRATORS:
                run_chain(params, 20 * params.dt, integrator=integrator, start=preset.start)
        if name in SINGLE_BLOCK:
            bp = block_params(name)
            simulate_block(bp, t_end=20 * bp.dt)
        took[name] = time.perf_counter() - t0
        if log is not None:
            log(f"{name}: ready ({took[name]:.1f} s)")
    return took
