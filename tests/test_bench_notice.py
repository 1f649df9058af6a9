"""`stickslip bench` says up front what it is about to cost and which integrator runs (before, the
default ran 75 s on a quiet machine, 8 minutes on a busy one, without a word); its JSON keeps its
fields."""

from __future__ import annotations

import json

from stickslip import chain_params
from stickslip.cli import main
from stickslip.run.bench import DENSE_NS_PER_BLOCK_STEP, expected_cost


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
    said = [ln for ln in err.splitlines() if ln.startswith("stickslip bench: ")]
    assert said[0].startswith("stickslip bench: timing dense then exact on sakaguchi N=5 to t_end=2"), err
    assert said[1:] == ["stickslip bench: running dense", "stickslip bench: running exact"], err
    data = json.loads(out)
    for key in ("workload", "dense_seconds", "exact_seconds", "speedup", "identical", "ns_per_block_step"):
        assert key in data
    assert data["identical"] is True and data["workload"]["steps"] == 400
