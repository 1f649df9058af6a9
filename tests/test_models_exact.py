"""Every model of the family on the one engine: dense = exact = plain Python, bit for bit.

The oracle (``model_heun_step`` in tests/chain_helpers.py) is written from docs/model.md, section
"The family the paper stands in": ghost cells from the drive and the ends, the plate's leaf
spring, the three friction laws and the two thresholds. It shares no code with the package.
Presets run at their own parameters (shortened); hypothesis draws compositions and values.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from chain_helpers import assert_bits_equal, assert_same_run, model_heun_step, oracle_run, random_start
from stickslip.models.params import ChainParams
from stickslip.models.pieces import CompositionError, check_composition, names
from stickslip.models.presets import PRESETS, chain_params
from stickslip.run.driver import ChainState, run_chain

# The laws of docs/model.md, which the oracle knows; rate-and-state has tests/test_rate_state.py.
FRICTIONS = ("state", "weakening", "strengthening")
# The load-history drive has tests/test_drive_history.py (the oracle moves V t only); threshold
# none needs rate-and-state, so it is refused with every law here.
DRIVES = tuple(d for d in names("drive") if d != "history")
ALL = [
    (d, f, t, e)
    for d in DRIVES
    for f in FRICTIONS
    for t in names("threshold")
    for e in names("ends")
    if not (e == "periodic" and d == "end") and not (t == "state" and f != "state") and t != "none"
]
VALID = ALL
# Every choice of every piece, in the presets' compositions (compiled ahead by `stickslip compile`)
# and three more: fixed ends, and the force drives as tests/test_force_drives.py runs them (each
# compiled once in the default run). The rest of the 44, among them the interactions the fast
# path treats apart (the plate's interval path with theta and a state threshold on the ring, the
# force drives with theta), run with -m slow.
COVER = [
    ("end", "state", "constant", "free"),
    ("end", "state", "state", "free"),
    ("end", "strengthening", "constant", "free"),
    ("plate", "weakening", "constant", "periodic"),
    ("plate", "weakening", "constant", "free"),
    ("end", "state", "constant", "fixed"),
    ("constant-force", "strengthening", "constant", "free"),
    ("force-ramp", "strengthening", "constant", "free"),
]


def test_forty_four_compositions_are_valid_and_the_rest_refused():
    # end: 2 ends x 4 (friction, threshold); plate, constant-force, force-ramp: 3 ends x 4.
    assert len(ALL) == 44 and set(COVER) <= set(ALL)
    for d in DRIVES:
        for f in FRICTIONS:
            for t in names("threshold"):
                for e in names("ends"):
                    if (d, f, t, e) in ALL:
                        check_composition(d, f, t, e)
                    else:
                        with pytest.raises(CompositionError):
                            check_composition(d, f, t, e)


def _state(p, seed, pstop=0.6):
    return random_start(p, seed, pstop)


def _compare_with_oracle(p, start_arrays, steps):
    x, v, th, stopped = start_arrays
    ref = oracle_run(x.tolist(), v.tolist(), th.tolist(), (~stopped).tolist(), p, steps, step=model_heun_step)
    assert ref.nonfinite is None
    runs = {}
    for integrator in ("dense", "exact"):
        start = ChainState.from_blocks(x, v, th, stopped)
        run = run_chain(p, steps * p.dt, integrator=integrator, start=start, sample_interval=p.dt)
        b = run.state.blocks()
        assert_bits_equal(b["x"], ref.x, f"{integrator} x")
        assert_bits_equal(b["v"], ref.v, f"{integrator} v")
        assert_bits_equal(b["theta"], ref.th, f"{integrator} theta")
        assert b["stopped"].tolist() == [not m for m in ref.moving]
        assert_bits_equal(run.samples["L"].values, ref.L, f"{integrator} L(t_n)")
        assert len(run.events) == len(ref.events)
        for row, ev in zip(run.events.itertuples(), ref.events, strict=False):
            assert (row.step_start, row.step_end, row.start_block, row.max_block, row.n_blocks) == (
                ev["step_start"],
                ev["step_end"],
                ev["start_block"],
                ev["max_block"],
                ev["n_blocks"],
            )
            assert_bits_equal([row.S], [ev["S"]], "S")
        runs[integrator] = run
    assert_same_run(runs["dense"], runs["exact"])
    return ref


# Parameters that make every composition slip within a few thousand steps.
LIVELY = dict(
    K=5.0, V=0.2, Kp=1.0, beta=0.5, alpha=0.7, sigma=0.2, F0=0.5, D=2.0, Fs=0.9, dt=0.005, F=0.8, F_start=0.3, r=0.05
)


@pytest.mark.parametrize(
    "pieces", [pytest.param(c, id="-".join(c), marks=() if c in COVER else pytest.mark.slow) for c in ALL]
)
def test_every_composition_matches_plain_python(pieces):
    d, f, t, e = pieces
    p = ChainParams(N=6, drive=d, friction=f, threshold=t, ends=e, **LIVELY)
    start = _state(p, seed=3)
    ref = _compare_with_oracle(p, start, 3000)
    assert len(ref.events) >= 1 or any(ref.moving) or ref.x != start[0].tolist(), "the case must move"


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_presets_dense_equals_exact_and_plain_python(name):
    N = {"sakaguchi": 7, "train": 7, "carlson-langer": 9}.get(name)
    p = chain_params(name, **({"N": N} if N else {}))
    pr = PRESETS[name]
    start = ChainState.rest(p, **pr.start_options) if pr.start == "rest" else ChainState.paper(p)
    b = start.blocks()
    steps = 24000 if p.drive == "plate" else 4000  # the plate loads a block to its threshold at t ~ 100
    ref = _compare_with_oracle(p, (b["x"], b["v"], b["theta"], b["stopped"]), steps)
    assert ref.x != b["x"].tolist()


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    pieces=st.sampled_from(COVER),
    N=st.integers(1, 12),
    K=st.floats(0.5, 30.0),
    V=st.floats(0.01, 0.5),
    Kp=st.floats(0.2, 3.0),
    beta=st.floats(0.0, 2.0),
    alpha=st.floats(0.0, 3.0),
    sigma=st.floats(0.0, 0.6),
    F0=st.floats(0.0, 1.5),
    D=st.floats(0.0, 20.0),
    Fs=st.floats(0.2, 3.0),
    seed=st.integers(0, 2**16),
)
def test_drawn_compositions_dense_equals_exact(pieces, N, K, V, Kp, beta, alpha, sigma, F0, D, Fs, seed):
    d, f, t, e = pieces
    p = ChainParams(
        N=N,
        drive=d,
        friction=f,
        threshold=t,
        ends=e,
        K=K,
        V=V,
        Kp=Kp,
        beta=beta,
        alpha=alpha,
        sigma=sigma,
        F0=F0,
        D=D,
        Fs=Fs,
    )
    x, v, th, stopped = _state(p, seed)
    runs = [
        run_chain(p, 40.0, integrator=i, start=ChainState.from_blocks(x, v, th, stopped), sample_interval=0.5)
        for i in ("dense", "exact")
    ]
    assert_same_run(*runs)


def test_plate_drive_exact_skips_stuck_blocks_and_jumps():
    p = chain_params("carlson-langer")
    run = run_chain(p, 2000.0, start=ChainState.rest(p, 0.01, 0))
    s = run.summary
    assert len(run.events) > 10
    assert s["steps_computed"] < 0.8 * s["steps"]
    assert s["block_updates"] < 0.4 * s["steps"] * p.N


def test_train_model_is_the_paper_chain_with_alpha_zero_and_theta_one():
    # docs/model.md: the train model is the paper's chain with alpha = 0 and theta = F0 = 1.
    train = chain_params("train", N=9)
    paper = ChainParams(N=9, alpha=0.0, D=0.0)
    a = run_chain(
        train, 3000.0, start=ChainState.from_blocks(np.zeros(9), np.full(9, 0.1), np.zeros(9), np.zeros(9, bool))
    )
    b = run_chain(
        paper, 3000.0, start=ChainState.from_blocks(np.zeros(9), np.full(9, 0.1), np.ones(9), np.zeros(9, bool))
    )
    assert len(a.events) > 3
    assert_bits_equal(a.state.x, b.state.x, "x")
    assert a.events[["step_start", "step_end", "n_blocks"]].equals(b.events[["step_start", "step_end", "n_blocks"]])


def test_plate_drive_block_that_stops_while_all_slide_restarts_on_time():
    # Found by hypothesis: a single block on a ring stops in a step in which every block slid;
    # its first start step under the plate must be known before the next start.
    p = ChainParams(
        N=1,
        drive="plate",
        friction="weakening",
        ends="periodic",
        K=1.0,
        V=0.5,
        Kp=1.0,
        beta=0.0,
        alpha=0.0,
        sigma=0.0,
        F0=0.0,
        D=0.0,
        Fs=1.0,
    )
    x, v, th, stopped = _state(p, 0)
    runs = [
        run_chain(p, 40.0, integrator=i, start=ChainState.from_blocks(x, v, th, stopped), sample_interval=0.5)
        for i in ("dense", "exact")
    ]
    assert len(runs[0].events) >= 2
    assert_same_run(*runs)


def test_run_directory_records_the_model_everywhere(tmp_path):
    import json

    import pyarrow.parquet as pq

    from stickslip import io

    p = chain_params("carlson-langer", N=10)
    run_chain(p, 300.0, start=ChainState.rest(p, 0.01, 0), out_dir=tmp_path / "run")
    want = {
        "model": "carlson-langer",
        "drive": "plate",
        "friction": "weakening",
        "threshold": "constant",
        "ends": "periodic",
        "K": 100.0,
        "Kp": 1.0,
        "V": 0.01,
        "alpha": 2.5,
        "sigma": 0.01,
        "Fs": 1.0,
        "N": 10,
    }
    meta = io.read_json(tmp_path / "run" / "run.json")
    assert want.items() <= meta["params"].items()
    ds = io.read_dataset(tmp_path / "run" / "state.nc")
    assert want.items() <= json.loads(ds.attrs["params"]).items()
    for table in ("events.parquet", "first_move.parquet"):
        stored = json.loads(pq.read_schema(tmp_path / "run" / table).metadata[b"stickslip"])
        assert want.items() <= stored["params"].items()
    assert "D" not in meta["params"] and "beta" not in meta["params"]  # not read by CL


#: The pieces the oracle here does not know, each with a test of the default run that runs it in
#: both integrators (module, test function).
DEFAULT_ELSEWHERE = {
    ("drive", "history"): ("test_drive_history", "test_exact_equals_dense_with_a_history"),
    ("friction", "rate-state"): ("test_rate_state", "test_dense_and_exact_agree_bit_for_bit_on_a_chain"),
    ("friction", "rate-state-slip"): ("test_slip_law", "test_dense_and_exact_identical"),
    ("friction", "rate-state-prz"): ("test_prz_law", "test_dense_and_exact_bit_for_bit_and_steady_sliding_stays"),
    ("friction", "rate-state-nagata"): ("test_nagata_law", "test_dense_and_exact_bit_for_bit_and_steady_sliding_stays"),
    ("lattice", "square"): ("test_lattice_exact", "test_exact_equals_dense_across_calls_and_on_the_chain"),
    ("threshold", "none"): (
        "test_threshold_none",
        "test_inertial_slide_hold_slide_tends_to_the_quasi_static_one_linearly_in_the_mass",
    ),
}


def test_every_piece_has_a_test_in_the_default_run():
    """Each registered piece (models/pieces.py) and lattice (models/lattice) is in COVER or has a
    named test outside the slow run, so that leaving cross products to -m slow leaves no piece
    untested by default."""
    import importlib

    from stickslip.models.lattice import LATTICES

    kinds = ("drive", "friction", "threshold", "ends")
    covered = {(kind, c[k]) for c in COVER for k, kind in enumerate(kinds)} | {("lattice", "chain")}
    registered = {kind: names(kind) for kind in kinds} | {"lattice": LATTICES}
    for kind, choices in registered.items():
        for name in choices:
            if (kind, name) in covered:
                continue
            assert (kind, name) in DEFAULT_ELSEWHERE, f"{kind} {name}: no test of the default run"
            module, test = DEFAULT_ELSEWHERE[kind, name]
            fn = getattr(importlib.import_module(module), test)
            assert "slow" not in [m.name for m in getattr(fn, "pytestmark", [])], f"{module}.{test} is slow"
