"""The located integrator's fast form (stickslip.kernels.located_fast) against its dense form.

Independent references:
- the dense form (stickslip.kernels.located.advance), which steps every block at every step: the
  fast form must give the same bits (state and event table), on several models, through slips,
  across calls that end inside events and with an event buffer that fills;
- a plain-Python loop of w = w + c for the lemma the fast form rests on (a stuck block's u after
  k full steps in one addition).
"""

from __future__ import annotations

import numpy as np
import pytest

from stickslip.kernels.located_lazy import _advance_lazy, _segment
from stickslip.models.disorder import Quenched
from stickslip.models.params import ChainParams, ParameterError
from stickslip.models.presets import chain_params
from stickslip.run.driver import run_chain
from stickslip.run.located import FORMS, LocatedState, LocatedStepper, run_located


def _plain(w: float, c: float, k: int) -> float:
    for _ in range(k):
        w = w + c
    return w


@pytest.mark.parametrize("c", [-5e-6, -0.5 * 0.005 * 2e-3, 3.1e-7, -1.0 / 3.0 * 1e-4, -(2.0**-20), 0.0])
def test_many_steps_in_one_addition_equal_the_steps(c):
    rng = np.random.default_rng(7)
    # Across binades, near their edges, through zero, huge and tiny values.
    ws = list(rng.uniform(-400, 400, 40)) + [256.0 - 3e-6, -128.0 + 1e-5, 1e-5, -2e-6, 0.0, -0.0, 3e-300, 1e12]
    for w in ws:
        for k in (0, 1, 2, 17, 999, 20000):
            got = _advance_lazy(w, k, c)
            want = _plain(w, c, k)
            assert got == want and np.signbit(got) == np.signbit(want), (w, k, c, got, want)


def test_a_segment_is_refused_where_c_is_halfway():
    q = 2.0**-44  # the spacing of floats in [256, 512)
    d, L = _segment(300.0, -(2.5 * q))  # exactly halfway between two multiples of q
    assert L == 0
    d, L = _segment(300.0, -(2.25 * q))
    assert L > 1000 and d == -2 * q


def _loaded(params: ChainParams, t: float) -> LocatedState:
    """The engine's state at t from the model's start, in the drive's frame."""
    return LocatedState.from_chain_state(run_chain(params, t).state, params)


def _both(params, start, ends, *, capacity=4096):
    """Both forms from ``start``, advanced to the steps ``ends`` in turn: {form: (state, events, stepper)}."""
    out = {}
    for form in FORMS:
        stepper = LocatedStepper(params, capacity=capacity, form=form)
        state = start.copy()
        parts = []
        for end in ends:
            state, ev = stepper.advance(state, end)
            parts.append(ev)
        out[form] = (state, np.concatenate(parts), stepper)
    return out


def _assert_same(out):
    (a, ea, _), (b, eb, _) = out["fast"], out["dense"]
    for name in ("u", "v", "th"):
        assert np.array_equal(getattr(a, name)[1:-1], getattr(b, name)[1:-1]), name
    for name in ("mov", "moved", "ist", "evf"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert ea.shape == eb.shape and np.array_equal(ea, eb)


# name: (parameters, loading time, span, whether the fast form can skip there)
CASES = {
    "eq4-beta0.5": (chain_params("sakaguchi", N=16, beta=0.5, V=0.01), 300.0, 400.0, True),
    "eq4-beta1.5": (chain_params("sakaguchi", N=16, beta=1.5, V=0.01), 300.0, 400.0, True),
    "train": (chain_params("train", N=12, V=0.01), 300.0, 300.0, True),
    "carlson-langer": (chain_params("carlson-langer", N=16), 20.0, 300.0, True),
    "two-blocks": (chain_params("two-blocks"), 20.0, 300.0, True),
    # The aging law changes every stuck block's theta at every step; a state threshold moves
    # with theta: both are stepped at every step (and are the same bits).
    "rate-state": (ChainParams(N=8, K=5.0, friction="rate-state", V=0.05), 50.0, 200.0, False),
    "state-threshold": (chain_params("batista-carlson"), 100.0, 150.0, False),
    # Fixed ends read t in their ghost cells: the fast form runs the dense one.
    "fixed-ends": (chain_params("sakaguchi", N=10, V=0.01, ends="fixed"), 200.0, 200.0, False),
    # Per-block thresholds and friction (docs/model.md, "Per-block parameters").
    "eq4-disordered": (
        chain_params("sakaguchi", N=16, V=0.01, Fs=Quenched("uniform", 2.5, 3.5), beta=Quenched("normal", 0.5, 0.05)),
        300.0,
        400.0,
        True,
    ),
    # Thresholds above the friction at v = 0+ (1 - sigma), as in the uniform model.
    "carlson-langer-disordered": (
        chain_params("carlson-langer", N=16, Fs=Quenched("uniform", 1.0, 1.4), Kp=Quenched("uniform", 0.8, 1.2)),
        20.0,
        300.0,
        True,
    ),
}


#: The default run's case (each case compiles both forms for its composition, about a minute on
#: two cores; the paper's chain is compiled for the floors too, tests/test_floors.py); the others
#: run with the slow tests (a disordered located chain is also in the default run through
#: tests/test_disorder_analysis.py, a rate-and-state law through tests/test_slip_law.py).
DEFAULT_CASES = ("eq4-beta0.5",)


@pytest.mark.parametrize("name", [n if n in DEFAULT_CASES else pytest.param(n, marks=pytest.mark.slow) for n in CASES])
def test_fast_equals_dense_bit_for_bit(name):
    params, t_load, t, skips = CASES[name]
    start = _loaded(params, t_load)
    out = _both(params, start, [start.step + round(t / params.dt)])
    _assert_same(out)
    assert len(out["dense"][1]) >= 2, "the workload passes through slips"
    work = out["fast"][2].work
    if skips:
        # Fewer steps stepped than the run has, and jumps over steps where only the drive moves.
        assert work["stepped"] + work["switch_steps"] < round(t / params.dt) and work["jumps"] > 0, work


@pytest.mark.parametrize(
    "name",
    [
        n if n in DEFAULT_CASES else pytest.param(n, marks=pytest.mark.slow)
        for n in ("eq4-beta0.5", "carlson-langer", "rate-state")
    ],
)
def test_calls_that_end_inside_events_and_a_full_event_buffer(name):
    params, t_load, t, _ = CASES[name]
    start = _loaded(params, t_load)
    n_end = start.step + round(t / params.dt)
    ev = LocatedStepper(params, form="dense").advance(start.copy(), n_end)[1]
    # Each call but the last ends in the middle of a slip.
    ends = sorted({round(0.5 * (a + b) / params.dt) for a, b in ev[:, :2]} - {n_end}) + [n_end]
    assert len(ends) >= 3
    out = _both(params, start, ends, capacity=6)
    _assert_same(out)
    assert np.array_equal(out["dense"][1], ev)
    # One call whose event buffer fills (the kernels return every second event to be emptied).
    out = _both(params, start, [n_end], capacity=5)
    _assert_same(out)
    assert np.array_equal(out["fast"][1], ev)


@pytest.mark.slow  # a composition of its own (per-block thresholds and leaf springs), both forms
@pytest.mark.parametrize("form", ["fast", "dense"])
def test_switches_that_repeat_at_one_time_are_refused_not_looped(form):
    """Thresholds below the friction at v = 0+ (Fs_i < 1 - sigma): blocks 11 and 16 of this chain
    start, decelerate at once and stop, each restarting the other's step at a time 1e-123 later;
    the integrator names the step instead of repeating it without end."""
    params = chain_params("carlson-langer", N=16, Fs=Quenched("uniform", 0.8, 1.2), Kp=Quenched("uniform", 0.8, 1.2))
    start = _loaded(params, 20.0)
    with pytest.raises(FloatingPointError, match="no progress in step 16571"):
        LocatedStepper(params, form=form).advance(start, start.step + 60_000)


def test_the_paper_chain_from_its_loaded_state():
    """N = 99, beta = 0.5 from the engine's state at t = 5e4 (the bench's workload, shorter)."""
    params = chain_params("sakaguchi", N=99, beta=0.5)
    start = _loaded(params, 5e4)
    out = _both(params, start, [start.step + k * 100_000 for k in (1, 2, 3)])
    _assert_same(out)
    assert out["fast"][2].work["jumps"] > 0


def test_run_located_takes_the_form():
    p = chain_params("sakaguchi", N=6, V=0.01)
    a = run_located(p, 150.0, form="fast")
    b = run_located(p, 150.0, form="dense")
    assert a.events.equals(b.events) and np.array_equal(a.state.u[1:-1], b.state.u[1:-1])
    with pytest.raises(ParameterError, match="form must be one of"):
        LocatedStepper(p, form="sparse")


def test_bench_located_json_and_text(capsys):
    import hashlib
    import json

    from chain_helpers import run_cli

    status, out, _ = run_cli(capsys, "bench", "--switches", "located", "--N", "20", "--t-end", "300", "--json")
    assert status == 0
    data = json.loads(out)
    w = data["workload"]
    assert (w["N"], w["beta"], w["steps"]) == (20, 0.5, 60000)
    assert w["t_prepare"] == pytest.approx(5e5 * (20 / 99) ** 2)
    assert data["identical"] is True
    assert data["ratio"] == pytest.approx(data["dense_seconds"] / data["fast_seconds"])
    assert data["fast_work"]["jumps"] > 0 and data["n_events"] >= 1
    # The state hash of the timed run, from the dense form run here.
    params = chain_params("sakaguchi", N=20, beta=0.5)
    start = _loaded(params, w["t_prepare"])
    state, ev = LocatedStepper(params, form="dense").advance(start, start.step + 60000)
    h = hashlib.sha256()
    for a in (state.u[1:-1], state.v[1:-1], state.th[1:-1], state.mov, state.moved, state.ist, state.evf):
        h.update(a.tobytes())
    assert data["state_sha256"] == h.hexdigest() and data["n_events"] == len(ev)
    status, out, _ = run_cli(capsys, "bench", "--switches", "located", "--N", "12", "--t-end", "50")
    assert status == 0
    for field in ("dense ", "fast ", "fast work", "ratio ", "identical  yes"):
        assert field in out


def test_bench_located_refuses_what_it_does_not_take(capsys):
    from chain_helpers import run_cli

    status, out, err = run_cli(capsys, "bench", "--switches", "located", "--profile", "--json")
    assert status == 2 and out == "" and err.count("\n") == 1 and "--switches located" in err
