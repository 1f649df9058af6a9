"""The fast chain integrator (`exact`) equals the reference (`dense`) bit for bit.

Same final x, v, theta and stopped flags, same event-bookkeeping state, same event and
first-move tables, L samples, snapshots and profiles, across beta, N, end times, starts and
other parameters. Cases where stick-slip is expected are checked to contain events, so the
comparison is not vacuous.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from chain_helpers import assert_same_run, oracle_run
from stickslip.kernels import layout
from stickslip.models.params import ChainParams
from stickslip.models.presets import chain_params
from stickslip.run.driver import ChainRunError, ChainState, run_chain

BETAS = [0.2, 0.5, 1.0, 1.2]

# (N, t_end, extra parameters, events expected). N = 399 only for short runs: the first slip
# of the paper's chain comes near t = 312, so V = 0.05 brings slips into 200 time units.
SHAPES = [
    (1, 3000.0, {}, True),
    (2, 4000.0, {}, True),
    (5, 2500.0, {}, True),
    (5, 5000.0, {}, True),
    (399, 50.0, {}, False),
    (399, 200.0, {}, False),
    (399, 200.0, {"V": 0.05}, True),
]


def _both(p, t_end, **kw):
    return run_chain(p, t_end, integrator="dense", **kw), run_chain(p, t_end, integrator="exact", **kw)


@pytest.mark.parametrize("beta", BETAS)
@pytest.mark.parametrize(
    "N, t_end, extra, expect_events",
    SHAPES,
    ids=[f"N{n}-t{t:g}" + "".join(f"-{k}{v:g}" for k, v in e.items()) for n, t, e, _ in SHAPES],
)
def test_dense_equals_exact_from_the_paper_start(beta, N, t_end, extra, expect_events):
    p = ChainParams(N=N, beta=beta, **extra)
    options = dict(sample_interval=5.0, snapshot_times=(t_end / 3, t_end / 2), profile_window=0.5,
                   profile_min_blocks=1 if N < 399 else 2)  # fmt: skip
    dense, exact = _both(p, t_end, **options)
    assert dense.integrator == "dense" and exact.integrator == "exact"
    assert_same_run(dense, exact)
    if expect_events:
        assert dense.summary["n_events"] > 0
        assert len(dense.profiles["profile_dx"]) > 0
    # between slips the exact integrator skips work (otherwise this would not test its shortcuts)
    if expect_events:
        assert exact.summary["block_updates"] < dense.summary["block_updates"]


@pytest.mark.parametrize("beta", [0.5, 1.0, 1.2])
@pytest.mark.parametrize("N, t_end, amplitude, seed", [(5, 2000.0, 0.05, 1), (50, 1000.0, 0.05, 2),
                                                       (399, 200.0, 0.05, 3)])  # fmt: skip
def test_dense_equals_exact_from_perturbed_steady_sliding(beta, N, t_end, amplitude, seed):
    p = ChainParams(N=N, beta=beta)
    dense, exact = _both(p, t_end, start="steady", perturbation=amplitude, seed=seed, profile_window=1.0)
    assert_same_run(dense, exact)
    assert dense.summary["n_events"] > 0  # the perturbation stops blocks: slips follow
    assert dense.start == {"kind": "steady", "perturbation": amplitude, "seed": seed}


def test_a_run_ending_inside_an_event_matches():
    """End in the middle of the largest event: the in-progress bookkeeping must agree too."""
    p = ChainParams(N=20)
    probe = run_chain(p, 4000.0)
    big = probe.events.loc[probe.events["n_blocks"].idxmax()]
    assert big["n_blocks"] >= 3
    t_mid = (big["step_start"] + big["step_end"]) // 2 * p.dt
    dense, exact = _both(p, t_mid, profile_window=0.1)
    assert_same_run(dense, exact)
    assert dense.state.ist[layout.EV_ACTIVE] == 1 and dense.summary["event_in_progress"]
    assert (dense.state.first_step[1:-1] >= 0).sum() == dense.state.ist[layout.EV_N_MOVED] > 0
    # the event in progress is not in the table yet
    assert len(dense.events) == big["event"]


def test_dense_equals_exact_with_other_parameters():
    cases = [
        dict(N=7, K=4.0, D=0.0, V=0.003, beta=0.8, alpha=0.5, Fs=2.0),
        dict(N=7, K=30.0, D=20.0, V=0.02, beta=1.0, alpha=1.5, Fs=4.0),
        dict(N=12, K=10.0, D=5.0, V=0.0, beta=1.0),  # no pulling: everything comes to rest
        dict(N=9, K=10.0, D=1.0, V=0.01, beta=0.0, Fs=0.5),
        dict(N=3, K=10.0, D=5.0, V=0.001, beta=1.0, dt=0.01),
    ]
    for kw in cases:
        p = ChainParams(**kw)
        dense, exact = _both(p, 1500.0, profile_window=0.25)
        assert_same_run(dense, exact)
        if p.V > 0:
            assert dense.summary["n_events"] > 0, kw


@settings(max_examples=25, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(
    N=st.integers(1, 12),
    K_=st.floats(1.0, 50.0),
    D=st.floats(0.0, 20.0),
    V=st.one_of(st.just(0.0), st.floats(1e-4, 0.1)),
    beta=st.floats(0.0, 2.0),
    alpha=st.floats(0.0, 2.0),
    Fs=st.floats(0.3, 5.0),
    start=st.sampled_from(["paper", "steady"]),
    amplitude=st.floats(0.0, 0.1),
    t_end=st.floats(50.0, 1500.0),
)
def test_dense_equals_exact_hypothesis(N, K_, D, V, beta, alpha, Fs, start, amplitude, t_end):
    p = ChainParams(N=N, K=K_, D=D, V=V, beta=beta, alpha=alpha, Fs=Fs)
    kw = dict(start=start, sample_interval=1.0, profile_window=0.05)
    if start != "paper":  # the paper's start draws nothing: a perturbation or seed is refused with it
        kw.update(perturbation=amplitude, seed=N)
    results = []
    for integrator in ("dense", "exact"):
        try:
            results.append(run_chain(p, t_end, integrator=integrator, **kw))
        except ChainRunError as exc:
            results.append(str(exc))
    dense, exact = results
    if isinstance(dense, str) or isinstance(exact, str):
        assert dense == exact
    else:
        assert_same_run(dense, exact)


@pytest.mark.slow
@pytest.mark.parametrize("beta", [0.2, 1.0])
def test_dense_equals_exact_benchmark_length(beta):
    """The paper's chain over 2e4 time units (dozens of slips, many of several blocks)."""
    p = ChainParams(N=399, beta=beta)
    dense, exact = _both(p, 2e4, profile_window=20.0, profile_min_blocks=5)
    assert_same_run(dense, exact)
    assert dense.summary["n_events"] > 20


def test_a_partly_stuck_slide_equals_dense():
    """The paper's chain loading at beta = 1.3 (`stickslip bench --workload partly-stuck`):
    blocks 1..83 slide for thousands of steps while the rest stick, then block 84 starts and
    blocks stop. The exact path takes the sliding steps in its tight loop (kernels/exact.py,
    _slide_steps) and leaves it for the start and the stops; every bit is the reference's."""
    p = chain_params("sakaguchi", N=199, beta=1.3)
    prep = run_chain(p, 4.162e5, start="paper")
    assert (np.flatnonzero(prep.state.mov[1:-1]) + 1).tolist() == list(range(1, 84))
    dense, exact = _both(p, 4.164e5, start=prep.state, sample_interval=0.5, sample_moving=True)
    assert_same_run(dense, exact)
    n_moving = dense.samples["n_moving"].values
    assert n_moving.max() == 84 and n_moving[-1] == 80  # a start, then stops, in the window
    assert (exact.samples["n_moving"].values == n_moving).all()


@pytest.mark.parametrize("V", [0.0, 2e-3])
def test_a_block_whose_start_rule_fires_without_moving(V):
    """With Fs < theta a stopped block with Fs < f < theta starts, is pushed back by friction and
    stops again within each step; once the step's displacement is below half an ulp of x it
    changes nothing (alpha = D = 0 keep theta at its fixed point 1), yet it moves in every step
    by the start rule, so every step is a slip event (docs/model.md). The exact integrator, which
    skips blocks whose neighbourhood did not change, must still record every one of them."""
    p = ChainParams(N=5, K=1000.0, Fs=0.5, V=V, D=0.0, alpha=0.0)
    x = np.array([1e6, 1e6, 1e6 - 4e-4, 1e6, 1e6])
    start = ChainState.from_blocks(x, np.zeros(5), np.ones(5), np.ones(5, bool))
    ref = oracle_run(x.tolist(), [0.0] * 5, [1.0] * 5, [False] * 5, p, 1500)
    stuck = [e for e in ref.events if e["step_start"] >= 1000]
    assert len(stuck) == 500 and all(e["step_end"] == e["step_start"] and e["start_block"] == 3 for e in stuck)
    assert ref.x[2] == oracle_run(x.tolist(), [0.0] * 5, [1.0] * 5, [False] * 5, p, 1000).x[2]
    dense, exact = _both(p, 100.0, start=start)
    assert_same_run(dense, exact)
    assert dense.summary["n_events"] >= 19000


@pytest.mark.parametrize("integrator", ["dense", "exact"])
def test_every_block_whose_start_rule_fires_is_in_the_event(integrator):
    """Two stopped blocks with f = 1 > Fs = 0.5 and friction theta = 1: both start in every step
    (start rule) and stop again without moving, so every step is an event of both blocks
    (docs/model.md), as the plain-Python oracle finds. Block 2 lies outside the range of blocks
    whose neighbourhood changed, which must not hide its start."""
    p = ChainParams(N=2, K=1.0, D=0.0, V=0.0, beta=0.0, alpha=0.0, Fs=0.5)
    x = [-2.0, -3.0]
    ref = oracle_run(x, [0.0, 0.0], [1.0, 1.0], [False, False], p, 3)
    assert [(e["start_block"], e["max_block"], e["n_blocks"]) for e in ref.events] == [(1, 2, 2)] * 3
    run = run_chain(p, 3 * p.dt, integrator=integrator, start=ChainState.from_blocks(x, [0, 0], [1, 1], [True] * 2))
    assert run.events["n_blocks"].tolist() == [2, 2, 2]
    assert run.events["max_block"].tolist() == [2, 2, 2]
    assert (
        list(zip(run.first_move["event"], run.first_move["block"], run.first_move["step"], strict=False))
        == ref.first_moves
    )
