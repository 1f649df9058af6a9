"""Both chain integrators against an independent plain-Python Heun step of eq. (4).

The oracle (tests/chain_helpers.py) is written from docs/model.md ("Chain, eq. (4)", "Slip events
of the chain") with the ghost cells and expression order of the kernel module's docstring;
it shares no code with the package. Final state and L = x_1 - x_N after every step must agree
bit for bit, and the event and first-move tables must be those derived from the oracle's own
step loop.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from chain_helpers import assert_bits_equal, oracle_run
from stickslip.models.params import ChainParams
from stickslip.run.driver import ChainRunError, ChainState, run_chain

# (N, seed, steps, x amplitude, probability of a stopped block, parameters)
CASES = {
    "interior-start": (5, 1, 10000, 0.3, 1.0, dict(V=0.2)),
    "mixed-moving": (6, 0, 10000, 0.3, 0.7, dict(V=0.1, beta=0.5)),
    "soft-springs": (3, 2, 6000, 0.05, 0.6, dict(V=0.2, K=5.0)),
    "other-friction": (4, 4, 8000, 0.3, 1.0, dict(V=0.15, beta=1.2, alpha=0.7, Fs=2.0, D=2.0)),
    "stiff-low-beta": (6, 5, 8000, 0.05, 0.6, dict(V=0.2, beta=0.2, K=20.0)),
    "no-diffusion": (5, 4, 8000, 0.3, 1.0, dict(V=0.2, D=0.0)),
}


def _initial(N, seed, xamp, pstop):
    rng = np.random.default_rng(seed)
    x = rng.uniform(-xamp, xamp, N)
    v = rng.uniform(0.0, 0.2, N)
    th = rng.uniform(0.3, 1.0, N)
    stopped = rng.random(N) < pstop
    return x, np.where(stopped, 0.0, v), th, stopped


@pytest.fixture(scope="module", params=sorted(CASES))
def oracle_case(request):
    N, seed, steps, xamp, pstop, kw = CASES[request.param]
    p = ChainParams(N=N, **kw)
    x, v, th, stopped = _initial(N, seed, xamp, pstop)
    ref = oracle_run(x.tolist(), v.tolist(), th.tolist(), (~stopped).tolist(), p, steps)
    assert ref.nonfinite is None
    start = ChainState.from_blocks(x, v, th, stopped)
    return request.param, p, steps, start, ref


@pytest.mark.parametrize("integrator", ["dense", "exact"])
def test_state_and_L_match_plain_python_bit_for_bit(oracle_case, integrator):
    _, p, steps, start, ref = oracle_case
    run = run_chain(p, steps * p.dt, integrator=integrator, start=start, sample_interval=p.dt)
    b = run.state.blocks()
    assert run.steps == steps
    assert_bits_equal(b["x"], ref.x, "x")
    assert_bits_equal(b["v"], ref.v, "v")
    assert_bits_equal(b["theta"], ref.th, "theta")
    assert b["stopped"].tolist() == [not m for m in ref.moving]
    # L after every step: the whole trajectory of the end blocks, not just its end point
    assert_bits_equal(run.samples["L"].values, ref.L, "L(t_n)")
    assert_bits_equal(run.samples["t"].values, np.arange(steps + 1) * p.dt, "sample times")


@pytest.mark.parametrize("integrator", ["dense", "exact"])
def test_events_match_the_definition_of_model_md(oracle_case, integrator):
    name, p, steps, start, ref = oracle_case
    assert len(ref.events) >= 2, "the case must contain slip events"
    run = run_chain(p, steps * p.dt, integrator=integrator, start=start, sample_interval=p.dt)
    ev = run.events
    assert len(ev) == len(ref.events)
    for col in ("event", "step_start", "step_end", "start_block", "max_block", "n_blocks"):
        assert ev[col].tolist() == [e[col] for e in ref.events], col
    assert_bits_equal(ev["S"].to_numpy(), [e["S"] for e in ref.events], "S")
    starts = np.array([e["step_start"] for e in ref.events])
    ends = np.array([e["step_end"] for e in ref.events]) + 1  # the event ends at t_{n+1}
    np.testing.assert_allclose(ev["t_start"], starts * p.dt, rtol=1e-14, atol=0)
    np.testing.assert_allclose(ev["t_end"], ends * p.dt, rtol=1e-14, atol=0)
    np.testing.assert_allclose(ev["duration"], (ends - starts) * p.dt, rtol=1e-12, atol=0)
    fm = run.first_move
    assert list(zip(fm["event"], fm["block"], fm["step"], strict=False)) == ref.first_moves
    np.testing.assert_allclose(fm["t_first"], fm["step"] * p.dt, rtol=1e-14, atol=0)
    assert run.summary["n_events"] == len(ref.events)
    if name == "interior-start":
        # the first event starts inside the chain and skips blocks: start/max/count all matter
        first = ref.events[0]
        assert first["start_block"] > 1 and first["n_blocks"] < first["max_block"]


def test_oracle_cases_cover_multi_block_events():
    sizes = set()
    for N, seed, steps, xamp, pstop, kw in CASES.values():
        p = ChainParams(N=N, **kw)
        x, v, th, stopped = _initial(N, seed, xamp, pstop)
        ref = oracle_run(x.tolist(), v.tolist(), th.tolist(), (~stopped).tolist(), p, min(steps, 6000))
        sizes |= {e["n_blocks"] for e in ref.events}
    assert max(sizes) >= 4 and 1 in sizes


@pytest.mark.parametrize("integrator", ["dense", "exact"])
@pytest.mark.parametrize("N, K", [(5, 1e6), (4, 1e5)])
def test_nonfinite_state_is_reported_at_the_oracles_time_and_block(integrator, N, K):
    """A stiff spring makes the explicit step unstable; the run stops with time and block."""
    p = ChainParams(N=N, K=K)
    ref = oracle_run([0.0] * N, [0.1] * N, [0.1] * N, [True] * N, p, 2000)
    assert ref.nonfinite is not None, "the oracle must blow up for this case"
    step, block = ref.nonfinite
    with pytest.raises(ChainRunError) as info:
        run_chain(p, 10.0, integrator=integrator)
    msg = str(info.value)
    assert "non-finite" in msg
    t = re.search(r"t = ([-+0-9.eE]+)", msg)
    b = re.search(r"block (\d+)", msg)
    assert t and b, msg
    assert float(t.group(1)) == pytest.approx(step * p.dt, rel=1e-5)
    assert int(b.group(1)) == block
