"""The exact integrator's block loops compile to SIMD code (issue: per-block speed).

Reads the LLVM IR numba generates for the kernel and looks for vector arithmetic on doubles;
a per-block branch or a negative-index check inside the loops would make LLVM give up on
vectorising them and this test would fail. The stages written as eight-block lanes
(kernels/lanes.py) must compile to arithmetic on 8 doubles with masked loads and stores.
"""

from __future__ import annotations

import re

import numba
import numpy as np
import pytest

from stickslip.kernels import dense, exact, stages
from stickslip.models.drive import end as end_drive
from stickslip.models.friction import state as state_law
from stickslip.models.params import ChainParams
from stickslip.models.threshold import constant as constant_threshold
from stickslip.run.driver import run_chain

# The block loops: separate compiled functions, and the all-moving ones inlined in run_exact.
STAGES = (
    "_stage1",
    "_stage2",
    "_stage1_theta_loop",
    "_stage1_theta_only_loop",
    "_stage2_theta_loop",
    "_stage1_run_loop",
    "_stage2_run_loop",
)
# The same stages as lanes of 8 blocks (what the pieces with PIECE.lanes get).
LANES = (
    "_stage1_theta_lanes",
    "_stage1_theta_only_lanes",
    "_stage2_theta_lanes",
    "_stage1_run_lanes",
    "_stage2_run_lanes",
)


def _fresh_ir(kernel, args=None) -> str:
    """LLVM IR of a kernel compiled afresh with its own options (code loaded from numba's cache
    cannot be inspected); ``args`` are example arguments when it has no recorded signature."""
    # njit implies nopython (passing it again only warns).
    options = {k: v for k, v in kernel.targetoptions.items() if k not in ("cache", "nopython")}
    fresh = numba.njit(**options)(kernel.py_func)
    if args is None:
        assert kernel.signatures, "kernel was not compiled by the workloads"
        fresh.compile(kernel.signatures[0])
    else:
        # The model's pieces (their modules' paths) are compile-time literals in the engine.
        sig = tuple(numba.types.literal(a) if isinstance(a, str) else numba.typeof(a) for a in args)
        fresh.compile(sig)
    return fresh.inspect_llvm(fresh.signatures[0])


def _example_args(name: str) -> tuple:
    name = name.removesuffix("_loop").removesuffix("_lanes")
    a = [np.linspace(0.5, 1.5, 12) for _ in range(10)]
    lo, hi = 1, 10
    dt, p, q = 0.005, 0.0, 0.0
    # The paper's model: K, the end drive, the threshold's Fs, eq. (4)'s law (beta, alpha, D), unit masses;
    # pieces as literals (their modules' paths).
    mp = (10.0, end_drive.Params(), constant_threshold.Params(3.0), state_law.Params(1.0, 1.0, 5.0), None)
    end, state, constant = end_drive.__name__, state_law.__name__, constant_threshold.__name__
    return {
        # q: the drive's velocity, read by a law with a context only (0.0 in the engine otherwise)
        "_stage1": (*a, lo, hi, p, q, mp, dt, end, state, constant),
        "_stage2": (*a, lo, hi, p, q, mp, 0.5 * dt, end, state),
        "_stage1_theta": (*a[:8], lo, hi, q, mp, dt, end, state),
        "_stage1_theta_only": (*a[:4], lo, hi, q, mp, dt, end, state),
        "_stage2_theta": (*a[:5], lo, hi, q, mp, 0.5 * dt, end, state),
        "_stage1_run": (*a[:8], lo, hi, p, q, mp, dt, end, state),
        "_stage2_run": (*a[:8], lo, hi, p, q, mp, 0.5 * dt, end, state),
    }[name]


@pytest.fixture(scope="module")
def irs() -> dict[str, str]:
    run_chain(ChainParams(N=8), 1.0, integrator="exact")
    run_chain(ChainParams(N=8), 1.0, integrator="dense")
    out = {name: _fresh_ir(getattr(stages, name), _example_args(name)) for name in STAGES + LANES}
    out["run_exact"] = _fresh_ir(exact.run_exact)
    out["run_dense"] = _fresh_ir(dense.run_dense)
    return out


def _vector_ops(ir: str) -> list[tuple[str, int]]:
    return [(op, int(w)) for op, w in re.findall(r"= (fadd|fsub|fmul) <(\d+) x double>", ir)]


@pytest.mark.slow  # the kernels compiled afresh for their IR (about 85 s, measured)
@pytest.mark.parametrize("name", STAGES + ("run_exact",))
def test_block_loops_use_vector_arithmetic_on_doubles(irs, name):
    ops = _vector_ops(irs[name])
    assert ops, f"no vector floating-point arithmetic in {name}"
    assert min(w for _, w in ops) >= 2
    # Each loop evaluates the stencils with several subtractions and multiplications; a loop
    # left scalar has none of them in vector form.
    assert sum(1 for op, _ in ops if op == "fsub") >= 4
    assert sum(1 for op, _ in ops if op == "fmul") >= 4


@pytest.mark.slow  # the kernels compiled afresh for their IR (about 85 s, measured)
@pytest.mark.parametrize("name", ("_stage1", "_stage2", "run_exact"))
def test_start_and_stop_rules_are_vector_selects(irs, name):
    ir = irs[name]
    assert re.search(r"fcmp \w+ <\d+ x double>", ir)
    assert re.search(r"select <\d+ x i1>", ir)


@pytest.mark.slow  # the kernels compiled afresh for their IR (about 85 s, measured)
@pytest.mark.parametrize("name", LANES)
def test_lanes_are_arithmetic_on_eight_doubles_with_masked_loads_and_stores(irs, name):
    ir = irs[name]
    ops = _vector_ops(ir)
    eight = [op for op, w in ops if w == 8]
    # Each stage evaluates the state law's rate, a*(1 - b) - ... (and the runs the force and accel).
    assert sum(1 for op in eight if op == "fsub") >= 3, ops
    assert sum(1 for op in eight if op == "fmul") >= 3, ops
    assert "fadd" in eight, ops
    # The last group of an interval is masked (a group of 8 may compile to plain vector loads).
    assert re.search(r"call <8 x double> @llvm\.masked\.load\.v8f64", ir)
    assert re.search(r"call void @llvm\.masked\.store\.v8f64", ir)


@pytest.mark.slow  # the kernels compiled afresh for their IR (about 85 s, measured)
@pytest.mark.parametrize("name", STAGES + LANES + ("run_exact", "run_dense"))
def test_no_fast_math_flags(irs, name):
    ir = irs[name]
    for flag in ("fast ", "reassoc", "contract", "nnan", "ninf"):
        assert not re.search(rf"= f(add|sub|mul|div) {flag}", ir), flag
    assert "llvm.fma" not in ir and "llvm.fmuladd" not in ir


def test_dense_and_exact_agree_on_a_vector_length_workload():
    # A range of lengths around the vector width and its remainders.
    for N in (3, 4, 7, 8, 9, 17):
        p = ChainParams(N=N, beta=1.5)
        a = run_chain(p, 50.0, integrator="dense", start="steady", perturbation=1e-4, seed=N)
        b = run_chain(p, 50.0, integrator="exact", start="steady", perturbation=1e-4, seed=N)
        assert a.summary["state_sha256"] == b.summary["state_sha256"]
        assert np.array_equal(a.state.x, b.state.x)
