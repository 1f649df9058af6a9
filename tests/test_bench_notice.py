"""`stickslip bench` says up front what it is about to cost and which integrator runs (before, the
default ran 75 s on a quiet machine, 8 minutes on a busy one, without a word); its JSON keeps its
fields."""

from __future__ import annotations

import json

from stickslip import chain_params
from stickslip.cli import main
from stickslip.run.bench import DENSE_NS_PER_BLOCK_STEP, expected_cost


def _said(err: str) -> list[str]:
    """The bench's own lines on stderr; not the heartbeat's, which a slow machine (a first
    compilation under load) adds every minute."""
    return [ln for ln in err.splitlines() if ln.startswith("stickslip bench: ") and " running for " not in ln]


def test_the_notice_states_the_work_and_its_cost():
    line = expected_cost(chain_params(), 2e5)
    # the default workload: N = 399 blocks, 4e7 steps of dt = 0.005, each block every step
    block_steps = 399 * 40_000_000
    assert f"{block_steps:.2g} block-steps" in line
    assert f"about {block_steps * DENSE_NS_PER_BLOCK_STEP * 1e-9:.0f} s" in line and "--t-end" in line
    assert "about 3 min" in expected_cost(chain_params(), 2e5, repeat=2)


def test_bench_says_what_it_runs_on_stderr_and_keeps_its_json(capsys):
    assert main(["bench", "--N", "5", "--t-end", "2", "--json"]) == 0
    out, err = capsys.readouterr()
    said = _said(err)
    assert said[0].startswith("stickslip bench: timing dense then exact on sakaguchi N=5 to t_end=2"), err
    assert said[1:] == ["stickslip bench: running dense", "stickslip bench: running exact"], err
    data = json.loads(out)
    for key in ("workload", "dense_seconds", "exact_seconds", "speedup", "identical", "ns_per_block_step"):
        assert key in data
    assert data["identical"] is True and data["workload"]["steps"] == 400


def test_repeats_alternate_the_integrators(capsys):
    """`--repeat 2`: dense, exact, dense, exact (a change of the machine's load meets both)."""
    assert main(["bench", "--N", "5", "--t-end", "2", "--repeat", "2", "--json"]) == 0
    out, err = capsys.readouterr()
    said = [ln.removeprefix("stickslip bench: ") for ln in _said(err)]
    assert said[1:] == [
        "running dense (1 of 2)",
        "running exact (1 of 2)",
        "running dense (2 of 2)",
        "running exact (2 of 2)",
    ], err
    assert json.loads(out)["identical"] is True
