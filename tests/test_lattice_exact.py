"""The active-set exact path of lattices (stickslip.kernels.lattice_sparse) against the lattice
reference: the same state bits and the same events, for the compositions whose stopped blocks
keep every bit (a drive on every block, a friction without theta) on squares with every kind of
edge, on the chain lattice, across calls (snapshots) and from every start."""

from __future__ import annotations

import pytest

from stickslip.models.presets import chain_params
from stickslip.run.lattice import run_lattice, sparse_path

CASES = [
    # (preset, overrides, shape, edges, t_end, start, perturbation)
    ("carlson-langer", dict(), (6, 7), "periodic", 150.0, "rest", 0.01),
    ("carlson-langer", dict(), (5, 4), "free", 150.0, "rest", 0.02),
    ("carlson-langer", dict(), (4, 6), "top=fixed,bottom=fixed", 150.0, "rest", 0.01),
    ("carlson-langer", dict(), (1, 9), "left=free,right=free", 150.0, "paper", 0.0),
    # other compositions: each compiles its own pair of kernels
    pytest.param(
        "carlson-langer",
        dict(friction="strengthening", F0=0.5, beta=1.0),
        (5, 5),
        "free",
        100.0,
        "rest",
        0.05,
        marks=pytest.mark.slow,
    ),
    pytest.param(
        "carlson-langer",
        dict(drive="force-ramp", F_start=0.0, r=0.01),
        (4, 5),
        "periodic",
        150.0,
        "rest",
        0.01,
        marks=pytest.mark.slow,
    ),
    pytest.param(
        "carlson-langer",
        dict(drive="constant-force", F=0.5),
        (4, 4),
        "fixed",
        50.0,
        "rest",
        0.5,
        marks=pytest.mark.slow,
    ),
]


def _same(p, t_end, start, amplitude, **kw):
    dense = run_lattice(p, t_end, start=start, perturbation=amplitude, seed=2, integrator="dense", **kw)
    exact = run_lattice(p, t_end, start=start, perturbation=amplitude, seed=2, integrator="exact", **kw)
    assert exact.summary["integrator"] == "exact"
    assert exact.summary["state_sha256"] == dense.summary["state_sha256"]
    assert exact.events.equals(dense.events)
    for name in ("xg", "vg", "thg", "mov", "first_step", "x0ev"):
        assert getattr(exact.state, name).tobytes() == getattr(dense.state, name).tobytes(), name
    return dense, exact


@pytest.mark.parametrize("preset, overrides, shape, edges, t_end, start, amplitude", CASES)
def test_exact_equals_dense(preset, overrides, shape, edges, t_end, start, amplitude):
    p = chain_params(preset, lattice="square", shape=shape, edges=edges, **overrides)
    assert sparse_path(p)
    dense, exact = _same(p, t_end, start, amplitude)
    assert len(dense.events) > 0
    # the work it skips: fewer block updates than dense's every block at every step
    assert exact.summary["block_updates"] < dense.summary["block_updates"]


def test_exact_equals_dense_across_calls_and_on_the_chain():
    p = chain_params("carlson-langer", lattice="square", shape=(5, 6), edges="periodic")
    dense, exact = _same(p, 100.0, "rest", 0.01, snapshot_every=7.5)
    assert exact.snapshots.equals(dense.snapshots)
    ring = chain_params("carlson-langer", lattice="chain", shape=30)
    from stickslip.models.lattice.params import on_lattice

    _same(on_lattice(ring, "chain"), 150.0, "rest", 0.01)


def test_exact_falls_back_to_dense_with_theta():
    p = chain_params(lattice="square", shape=(3, 4))
    assert not sparse_path(p)
    run = run_lattice(p, 1.0, integrator="exact")
    assert run.summary["integrator"] == "dense"


@pytest.mark.parametrize("draw", range(8))
def test_exact_equals_dense_on_drawn_lattices(draw):
    """Carlson-Langer on squares of drawn shape and edges, from drawn rest states."""
    import numpy as np

    rng = np.random.default_rng(100 + draw)
    rows, cols = (int(n) for n in rng.integers(1, 8, 2))
    kinds = {}
    for a, b in (("top", "bottom"), ("left", "right")):
        if rng.random() < 0.4:
            kinds[a] = kinds[b] = "periodic"
        else:
            kinds[a], kinds[b] = rng.choice(["free", "fixed"], 2)
    edges = ",".join(f"{side}={kind}" for side, kind in kinds.items())
    p = chain_params("carlson-langer", lattice="square", shape=(rows, cols), edges=edges)
    _same(p, float(rng.uniform(20.0, 120.0)), "rest", float(rng.uniform(0.005, 0.05)))


def test_exact_continues_an_event_in_progress():
    """A state handed over in the middle of an event (from either path) continues as dense does:
    the event's moved blocks are recovered from their first moves."""
    from stickslip.kernels import layout

    p = chain_params("carlson-langer", lattice="square", shape=(6, 6), edges="periodic")
    for t in (40.0, 45.0, 50.0, 55.0, 60.0, 65.0, 70.0):
        prep = run_lattice(p, t, start="rest", perturbation=0.01, integrator="exact")
        if prep.state.ist[layout.EV_ACTIVE] == 1:
            break
    assert prep.state.ist[layout.EV_ACTIVE] == 1
    dense = run_lattice(p, t + 30.0, start=prep.state, integrator="dense")
    exact = run_lattice(p, t + 30.0, start=prep.state, integrator="exact")
    assert exact.summary["state_sha256"] == dense.summary["state_sha256"]
    assert exact.events.equals(dense.events) and len(exact.events) > 0


def test_exact_equals_dense_under_slow_loading():
    """The bench's regime (nu = 0.001, docs/lattice.md "Speed"): long stick phases, during which
    the exact path jumps from trigger to trigger, and events of a few blocks between them."""
    p = chain_params("carlson-langer", lattice="square", shape=(8, 8), nu=0.001)
    dense, exact = _same(p, 1500.0, "rest", 0.01)
    assert len(dense.events) > 10
    assert exact.summary["steps_computed"] < dense.summary["steps_computed"] == dense.summary["steps"]
    assert exact.summary["moving_block_updates"] <= exact.summary["block_updates"]
