"""The loaded chain's state and its cache (stickslip.run.loaded).

The state read from the cache, or continued after an interruption, is the state of one
uninterrupted run of the engine; the loading check is compared with the slips of that run,
read directly from its event table.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from stickslip.models.params import ChainParams
from stickslip.run import loaded as L
from stickslip.run.driver import run_chain
from stickslip.run.errors import short_runs_expected
from stickslip.run.state import ChainState

P = ChainParams(N=9, beta=0.9)
T0 = 2e4


def _direct():
    with short_runs_expected():
        return run_chain(P, T0, sample_interval=T0)


def _same_state(a: ChainState, b: ChainState) -> bool:
    """Every array equal; of ist all but the time of the next L sample, which a continued run sets."""
    from stickslip.kernels import layout

    keep = np.ones(layout.IST_SIZE, bool)
    keep[layout.NEXT_SAMPLE] = False
    return all(np.array_equal(a.arrays()[k], b.arrays()[k]) for k in ChainState.ARRAYS if k != "ist") and (
        np.array_equal(a.ist[keep], b.ist[keep])
    )


def test_loading_summary_by_hand():
    out = L.loading_summary(100.0, 30.0, [2, 0], [5.0, 0.0], [4, 0], [1, 0])
    assert out["loaded"] is True and out["first_slip_reaching_block_N"] == 30.0 and out["slips"] == 2
    assert out["stretches"][0] == {
        "t_from": 0.0,
        "t_to": 50.0,
        "slips": 2,
        "mean_S": 2.5,
        "max_block": 4,
        "slips_reaching_block_N": 1,
    }
    assert out["stretches"][1]["mean_S"] is None
    assert L.loading_summary(100.0, 60.0, [1], [1.0], [1], [0])["loaded"] is False  # 100 < 2 x 60
    assert L.loading_summary(100.0, None, [1], [1.0], [1], [0])["loaded"] is False


def test_loaded_state_and_its_check_against_one_run(tmp_path):
    run = _direct()
    ev = run.events
    at_N = ev[ev["max_block"] == P.N]
    plain = L.loaded_state(P, T0)
    assert _same_state(plain.state, run.state)
    assert plain.info["first_slip_reaching_block_N"] == float(at_N["t_start"].iloc[0])
    assert plain.info["slips"] == len(ev) and plain.info["cached"] is False
    assert plain.info["loaded"] == (T0 >= 2 * float(at_N["t_start"].iloc[0]))
    last = ev[ev["t_start"] >= 0.8 * T0]
    assert plain.info["stretches"][-1]["slips"] == len(last)
    assert plain.info["stretches"][-1]["mean_S"] == pytest.approx(float(last["S"].mean()), rel=1e-12)

    first = L.loaded_state(P, T0, cache=tmp_path)
    assert _same_state(first.state, run.state) and first.info["cached"] is False
    assert {k: v for k, v in first.info.items() if k not in ("wall_seconds", "cached", "cache_file")} == {
        k: v for k, v in plain.info.items() if k not in ("wall_seconds", "cached", "cache_file")
    }
    again = L.loaded_state(P, T0, cache=tmp_path)
    assert again.info["cached"] is True and _same_state(again.state, run.state)
    assert again.state.model == run.state.model
    assert [p.name for p in tmp_path.iterdir()] == [f"{again.info['cache_file'].rsplit('/', 1)[1]}"]
    other = L.loaded_state(P.replace(beta=0.5), T0, cache=tmp_path)  # another model: another file
    assert other.info["cached"] is False and len(list(tmp_path.iterdir())) == 2


def test_a_damaged_cache_file_is_computed_again(tmp_path):
    first = L.loaded_state(P, T0, cache=tmp_path)
    path = tmp_path / first.info["cache_file"].rsplit("/", 1)[1]
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0xFF
    path.write_bytes(bytes(data))
    again = L.loaded_state(P, T0, cache=tmp_path)
    assert again.info["cached"] is False and again.info["state_sha256"] == first.info["state_sha256"]
    assert L.loaded_state(P, T0, cache=tmp_path).info["cached"] is True


def test_an_interrupted_transient_continues_from_its_last_chunk(tmp_path, monkeypatch):
    import stickslip.run.driver as driver

    class Stop(Exception):
        pass

    calls = []
    real = driver.run_chain

    def stopping(*args, **kw):
        calls.append(args[1])
        if len(calls) == 4:
            raise Stop
        return real(*args, **kw)

    monkeypatch.setattr(driver, "run_chain", stopping)
    with pytest.raises(Stop):
        L.loaded_state(P, T0, cache=tmp_path)
    assert len(list(tmp_path.glob("*.partial.npz"))) == 1
    calls.clear()
    monkeypatch.setattr(driver, "run_chain", lambda *a, **k: calls.append(a[1]) or real(*a, **k))
    out = L.loaded_state(P, T0, cache=tmp_path)
    assert len(calls) == L.CHUNKS - 3 and calls[0] == pytest.approx(4 * T0 / L.CHUNKS)
    assert _same_state(out.state, _direct().state) and not list(tmp_path.glob("*.partial.npz"))
    assert out.info["slips"] == len(_direct().events)


def test_cli_decorrelation_from_the_cache_gives_the_same_rows(capsys, tmp_path):
    from stickslip.cli import main

    argv = ["lyapunov", "--N", "9", "--beta", "0.9", "--decorrelation", "--transient", "2e4"]
    argv += ["--deltas", "1e-6,1e-2", "--events", "40", "--json"]
    outs = []
    for extra in ([], ["--state-cache", str(tmp_path)], ["--state-cache", str(tmp_path)]):
        assert main(argv + extra) in (0, None)
        outs.append(json.loads(capsys.readouterr().out))
    assert outs[0]["decorrelation"] == outs[1]["decorrelation"] == outs[2]["decorrelation"]
    assert [o["loading"]["cached"] for o in outs] == [False, False, True]
    assert outs[0]["loading"]["state_sha256"] == outs[2]["loading"]["state_sha256"]
    assert main(argv + ["--switches", "located", "--state-cache", str(tmp_path)]) == 2
    assert "--state-cache" in capsys.readouterr().err
