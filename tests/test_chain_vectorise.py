"""The exact integrator's block loops compile to SIMD code (issue: per-block speed).

Reads the LLVM IR numba generates for the kernel and looks for vector arithmetic on doubles;
a per-block branch or a negative-index check inside the loops would make LLVM give up on
vectorising them and this test would fail.
"""

from __future__ import annotations

import re

import numba
import numpy as np
import pytest

from stickslip.chain import run_chain
from stickslip.kernels import chain as K
from stickslip.params import ChainParams


@pytest.fixture(scope="module")
def exact_ir() -> str:
    """LLVM IR of run_exact, compiled afresh (code loaded from numba's cache cannot be inspected)."""
    run_chain(ChainParams(N=4), 0.05, integrator="exact")
    sig = K.run_exact.signatures[0]
    fresh = numba.njit(K.run_exact.py_func)
    fresh.compile(sig)
    return fresh.inspect_llvm(sig)


def test_exact_kernel_uses_vector_arithmetic_on_doubles(exact_ir):
    ir = exact_ir
    ops = re.findall(r"= (fadd|fsub|fmul) <(\d+) x double>", ir)
    assert ops, "no vector floating-point arithmetic in run_exact"
    widths = {int(w) for _, w in ops}
    assert max(widths) >= 2
    # Every stage loop (full, state-variable-only, all-moving) contributes a dozen or more vector
    # subtractions and multiplications; one loop falling back to scalar code drops below these.
    assert sum(1 for op, _ in ops if op == "fsub") >= 70
    assert sum(1 for op, _ in ops if op == "fmul") >= 70


def test_vector_compare_and_select_for_the_stop_rule(exact_ir):
    ir = exact_ir
    # The stop rule and the start rule are selects on vectors, not branches.
    assert re.search(r"fcmp \w+ <\d+ x double>", ir)
    assert re.search(r"select <\d+ x i1>", ir)


def test_no_fast_math_flags(exact_ir):
    ir = exact_ir
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
