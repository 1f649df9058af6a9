"""The single block as a model of the family: the paper's and the Batista-Carlson reading.

The single block runs on the chain's reference kernel at N = 1 (end drive, state friction, free
end); the chain's driver, on its fast exact kernel (tests/test_models_exact.py holds it to plain
Python), must give the same trajectory bit for bit, with either threshold.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from stickslip.cli import main
from stickslip.models.params import BlockParams, ParameterError
from stickslip.models.presets import block_params, chain_params
from stickslip.run.block import BlockState, simulate_block
from stickslip.run.driver import ChainState, run_chain


@pytest.mark.parametrize("model, t_end", [("sakaguchi", 400.0), ("batista-carlson", 200.0)])
def test_single_block_kernel_equals_the_chain_at_N_1(model, t_end):
    bp = block_params(model, V=0.05)
    cp = chain_params(model, N=1, V=0.05, D=0.0)
    blk = simulate_block(bp, t_end, initial=BlockState(x=0.0, v=0.0, theta=0.1, stopped=True))
    chn = run_chain(cp, t_end, start=ChainState.from_blocks([0.0], [0.0], [0.1], [True]))
    b = chn.state.blocks()
    assert len(blk.slips) >= 2
    assert blk.series["x"].values[-1] == b["x"][0]
    assert blk.series["v"].values[-1] == b["v"][0]
    assert blk.series["theta"].values[-1] == b["theta"][0]
    assert len(chn.events) in (len(blk.slips), len(blk.slips) + 1)


def test_batista_carlson_starts_below_a_constant_threshold():
    # With the state threshold the block starts when K (V t - x) first exceeds theta (< 1),
    # long before the paper's Fs = 3 would let it.
    bc = simulate_block(block_params("batista-carlson"), 50.0)
    paper = simulate_block(BlockParams(K=10.0, V=0.05, beta=0.08), 50.0)
    assert bc.slips["t_c"].iloc[0] < 2.0 < paper.slips["t_c"].iloc[0]


def test_block_and_hysteresis_take_the_model(capsys, tmp_path):
    assert main(["block", "--model", "batista-carlson", "--t-end", "100", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["params"]["threshold"] == "state" and "Batista" in data["note"]
    assert (
        main(
            [
                "hysteresis",
                "--model",
                "batista-carlson",
                "--V-min",
                "0.05",
                "--V-max",
                "0.2",
                "--dV",
                "0.05",
                "--time-per-step",
                "50",
                "--json",
            ]
        )
        == 0
    )
    assert json.loads(capsys.readouterr().out)


def test_only_single_block_presets_make_a_block():
    with pytest.raises(ParameterError):
        block_params("carlson-langer")
    assert np.isclose(block_params("sakaguchi").Fs, 3.0)
