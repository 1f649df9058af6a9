"""The start-step search shared by the chain's plate path and the lattice's active-set path
(:func:`stickslip.kernels.triggers.first_start`): the first step whose own force exceeds the
threshold, against a plain-Python scan of the steps, whatever the guess; and runs of both paths
with the bits they had before the search was shared."""

from __future__ import annotations

import numpy as np
import pytest

from stickslip import chain_params, run_chain
from stickslip.kernels import lattice_sparse, triggers
from stickslip.kernels.entry import specialise_call
from stickslip.kernels.layout import _NEVER
from stickslip.models.drive import plate
from stickslip.run.lattice import run_lattice

K, KP, DT = 100.0, 1.0, 0.005


def _scan(force, thr, n0, n_cap):
    """The first step m in [n0, n_cap) with force(m) > thr, one step at a time."""
    for m in range(n0, n_cap):
        if force(m) > thr:
            return m
    return n_cap


def _chain_force(xl, xc, xr, V):
    # eq. (4) with the plate: K ((x_{i-1} - x_i) - (x_i - x_{i+1})) + Kp (V t_m - x_i), t_m = m dt
    return lambda m: K * ((xl - xc) - (xc - xr)) + KP * (V * (float(m) * DT) - xc)


def _cases(n=12, seed=3):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        xl, xc, xr = rng.uniform(-0.02, 0.02, 3)
        V = rng.choice([1e-2, 1e-1, 1.0])
        n0 = int(rng.integers(0, 50_000))
        f0 = K * ((xl - xc) - (xc - xr)) + KP * (V * (n0 * DT) - xc)
        thr = f0 + rng.uniform(0.0, 3000 * KP * V * DT)  # a start within about 3000 steps
        yield xl, xc, xr, V, n0, thr


@pytest.mark.parametrize("case", list(_cases()))
def test_the_chains_plate_start_is_the_first_step_that_fires(case):
    xl, xc, xr, V, n0, thr = case
    args = (xl, xc, xr, thr, K, plate.Params(KP), V, DT, n0, n0 + 10_000, plate.__name__, 3)
    expected = _scan(_chain_force(xl, xc, xr, V), thr, n0, n0 + 10_000)
    assert specialise_call(triggers._plate_trigger, args, {10}) == expected


@pytest.mark.parametrize("case", list(_cases(seed=4)))
def test_the_lattices_start_is_the_first_step_that_fires(case):
    xl, xc, xr, V, n0, thr = case
    lap = (xl - xc) - (xc - xr)
    args = (lap, xc, thr, K, V, DT, plate.Params(KP), n0, plate.__name__, 7)
    expected = _scan(lambda m: K * lap + KP * (V * (float(m) * DT) - xc), thr, n0, n0 + 10_000)
    assert specialise_call(lattice_sparse._trigger, args, {8}) == expected


def test_a_start_past_the_end_is_the_end_on_the_chain_and_never_on_the_lattice():
    args = (0.0, 0.0, 0.0, 1.0, K, plate.Params(KP), 1e-3, DT, 0, 100, plate.__name__, 1)
    assert specialise_call(triggers._plate_trigger, args, {10}) == 100  # fires at 200,000
    args = (0.0, 0.0, 1.0, K, 0.0, DT, plate.Params(KP), 0, plate.__name__, 1)  # V = 0: never
    assert specialise_call(lattice_sparse._trigger, args, {8}) == _NEVER


@pytest.mark.parametrize("rate_factor", [1.0, 0.5, 2.0, 1e-6, 1e6, 0.0, -1.0])
def test_the_search_is_exact_whatever_the_guess(rate_factor):
    # the guess from the rate is only a start: a wrong rate changes the probes, not the answer
    rng = np.random.default_rng(11)
    for xl, xc, xr, V, n0, thr in _cases(6, seed=5):
        fa = (xl, xc, xr, K, plate.Params(KP), V, DT, np.int64(2))
        rate = rate_factor * KP * V * DT
        cap = n0 + int(rng.integers(1, 20_000))
        args = ("stickslip.kernels.triggers", fa, plate.__name__, thr, rate, n0, cap)
        assert specialise_call(triggers.first_start, args, {0, 2}) == _scan(_chain_force(xl, xc, xr, V), thr, n0, cap)


# Recorded before the search was shared (the chain's and the lattice's own searches).
def test_the_chains_plate_run_keeps_its_bits():
    run = run_chain(chain_params("carlson-langer", N=20), 200.0, start="rest", perturbation=0.01)
    assert run.summary["state_sha256"].startswith("9d9756582eed")


@pytest.mark.parametrize(
    "V, t_end, sha, events",
    [(None, 3e3, "541143ee4f6555e4", 1981), (1e-4, 3e4, "1a03263cf03b9ad4", 5594)],
)
def test_the_lattices_runs_keep_their_bits(V, t_end, sha, events):
    p = chain_params("carlson-langer", lattice="square", shape=(16, 12), **({"V": V} if V else {}))
    run = run_lattice(p, t_end, start="rest", perturbation=0.01)
    assert run.summary["integrator"] == "exact"
    assert (run.summary["state_sha256"][:16], run.summary["events"]) == (sha, events)
