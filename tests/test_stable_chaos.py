"""Fronts of finite and infinitesimal perturbations, and the lifetime of stick-slip (Politi and
Torcini, arXiv 0902.2545; issue 26, item 3)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stickslip.analysis.dynamics.stable_chaos import front_position, perturbation_front, steady_lifetime
from stickslip.models.params import ChainParams, ParameterError
from stickslip.run.located import LocatedState


def test_front_position_counts_blocks_from_the_perturbed_one():
    diff = np.array([0.0, 0.0, 1e-3, 0.0, 5e-3, 0.0, 0.0])
    assert front_position(diff, 2, 1e-4) == 3  # blocks 2..4
    assert front_position(diff, 6, 1e-4) == 5  # blocks 6 down to 2
    assert front_position(diff, 2, 1e-2) == 0


def _stuck_chain(N: int = 20) -> tuple[ChainParams, LocatedState]:
    """Every block stuck at u = 0, springs unstretched: the first block's force K V t reaches
    Fs = 3 only at t = 3 / (K V) = 300 (eq. 4, K = 10, V = 0.001)."""
    p = ChainParams(N=N, beta=0.5)
    z = np.zeros(N)
    return p, LocatedState.from_blocks(z, z, np.full(N, 0.1), np.ones(N, dtype=bool))


def test_an_infinitesimal_perturbation_of_a_stuck_chain_stays_on_its_block():
    # a stuck block moved by 1e-8 changes its neighbours' forces by K 1e-8, far below Fs - 0:
    # nothing starts before t = 300, so only the perturbed block differs, by exactly its delta
    p, start = _stuck_chain()
    res = perturbation_front(p, start, (-1e-8, 1e-8), t_max=50.0, block=0, check=1.0)
    for row in res.rows:
        assert row["reach"] == 1 and row["speed"] == 0.0
        assert abs(row["log_growth"]) < 1e-6
    assert np.all(res.fronts[-1e-8] == 1)


def test_a_finite_perturbation_starts_slips_that_carry_it_along_the_chain():
    # moved by -1 (u = x - V t: away from the drive), block 0 feels K * 1 = 10 > Fs = 3 and slips;
    # its slip of order (10 - 1) / K loads block 1 beyond Fs: the difference spreads
    p, start = _stuck_chain()
    res = perturbation_front(p, start, (-1.0, -1e-8), t_max=50.0, block=0, check=1.0)
    finite, small = res.rows
    assert finite["reach"] >= 2 and finite["speed"] > 0.0
    assert small["reach"] == 1
    assert res.to_dict()["fronts"] == res.rows


def test_bad_input_is_refused():
    p, start = _stuck_chain(4)
    with pytest.raises(ParameterError):
        perturbation_front(p, start, (0.0,), t_max=1.0)
    with pytest.raises(ParameterError):
        perturbation_front(p, start, (1e-3,), t_max=1.0, block=4)


def test_steady_lifetime_of_one_block_above_the_instability():
    # one block at V = 0.5 slides steadily; from the paper's start (v = 0.1, theta = 0.1) its
    # deviation of about 0.4 decays at the rate 0.4865 of eq. (2) (docs/lyapunov.md): within
    # 1e-6 after about ln(0.4 / 1e-6) / 0.4865 = 26.5 (oscillating, so within a factor of 1.5)
    out = steady_lifetime(ChainParams(N=1, beta=1.0, V=0.5), 200.0, sample_interval=0.5)
    assert out["t_steady"] is not None
    assert 26.5 / 1.5 < out["t_steady"] < 26.5 * 1.5
    assert out["events"] == 0


def test_steady_lifetime_is_none_while_the_chain_still_sticks_and_slips():
    out = steady_lifetime(ChainParams(N=5, beta=0.5), 2000.0)
    assert out["t_steady"] is None and out["events"] > 0 and math.isfinite(out["wall_seconds"])


def test_cli_fronts_and_lifetimes_json(capsys):
    import json

    from stickslip.cli import main

    argv = ["lyapunov", "--N", "9", "--switches", "located", "--fronts", "--transient", "2000", "--t-end", "2200"]
    assert main([*argv, "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)["fronts"]
    assert [r["delta"] for r in rows] == [1e-10, 1e-6, 1e-3, 1e-2]
    assert all(1 <= r["reach"] <= 9 or r["reach"] == 0 for r in rows)
    # one block at V = 0.5 slides steadily after about 26 time units (see above); the loading
    # time of N = 1 is 0, so the cap is --loads time units
    assert main(["lyapunov", "--V", "0.5", "--lifetimes", "1", "--loads", "200", "--json"]) == 0
    (row,) = json.loads(capsys.readouterr().out)["lifetimes"]
    assert row["N"] == 1 and 26.5 / 1.5 < row["t_steady"] < 26.5 * 1.5
    assert main(["lyapunov", "--N", "9", "--fronts"]) == 2
    assert "--fronts goes with --switches located" in capsys.readouterr().err
