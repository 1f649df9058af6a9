"""Chain run outputs (run.json, state.nc, event tables, snapshots), steady sliding, and the
error raised when the state turns non-finite."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
import xarray as xr

import stickslip
from chain_helpers import assert_bits_equal, assert_same_run
from stickslip.models import physics
from stickslip.models.params import ChainParams
from stickslip.run.driver import ChainRunError, initial_state, load_run, run_chain, steady_deviation, write_run

P = ChainParams(N=6, V=0.01)
SNAPS = (123.45, 400.0, 0.0)


@pytest.fixture(scope="module")
def run_and_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("chain") / "run"
    run = run_chain(P, 600.0, integrator="exact", snapshot_times=SNAPS, profile_window=0.2,
                    sample_interval=2.5, out_dir=d)  # fmt: skip
    assert run.summary["n_events"] >= 5
    return run, d


def test_load_run_round_trip(run_and_dir, tmp_path):
    run, d = run_and_dir
    for where in (d, write_run(run, tmp_path / "copy")):
        back = load_run(where)
        assert back.params == run.params
        assert back.options == run.options
        assert back.integrator == run.integrator
        assert back.start == run.start
        assert back.summary == run.summary
        assert back.state.sha256() == run.state.sha256() == run.summary["state_sha256"]
        assert back.steps == run.steps
        assert_same_run(back, run, state=False)


def test_run_json_has_parameters_integrator_version_and_summary(run_and_dir):
    run, d = run_and_dir
    meta = json.loads((d / "run.json").read_text())
    assert meta["params"] == P.to_dict()
    assert meta["params"]["N"] == 6 and meta["params"]["V"] == 0.01 and meta["params"]["K"] == 10.0
    assert meta["integrator"] == "exact"
    assert meta["version"] == stickslip.__version__
    assert meta["options"]["t_end"] == 600.0 and meta["options"]["profile_window"] == 0.2
    assert sorted(meta["options"]["snapshot_times"]) == sorted(SNAPS)
    assert meta["start"]["kind"] == "paper"
    s = meta["summary"]
    assert s["n_events"] == len(run.events) and s["state_sha256"] == run.summary["state_sha256"]
    assert s["steps"] == 120000 and s["t_end"] == pytest.approx(600.0)
    assert s["L_final"] == run.state.x[0] - run.state.x[P.N - 1]


def test_event_tables_are_readable_parquet(run_and_dir):
    run, d = run_and_dir
    events = pd.read_parquet(d / "events.parquet")
    assert events.equals(run.events)
    assert list(events.columns) == ["event", "step_start", "step_end", "t_start", "t_end", "duration", "S",
                                    "start_block", "max_block", "n_blocks"]  # fmt: skip
    moves = pd.read_parquet(d / "first_move.parquet")
    assert moves.equals(run.first_move)
    assert list(moves.columns) == ["event", "block", "step", "t_first"]
    # one first-move row per moved block of each event, inside the event, the start block first
    assert moves.groupby("event").size().tolist() == events["n_blocks"].tolist()
    for _, ev in events.iterrows():
        m = moves[moves["event"] == ev["event"]]
        assert m["step"].between(ev["step_start"], ev["step_end"]).all()
        assert m.loc[m["block"] == ev["start_block"], "step"].item() == ev["step_start"]
        assert m["block"].max() == ev["max_block"]
        assert ev["t_end"] > ev["t_start"] and ev["S"] > 0


def test_state_nc_holds_labelled_arrays(run_and_dir):
    run, d = run_and_dir
    with xr.open_dataset(d / "state.nc", engine="h5netcdf") as ds:
        ds = ds.load()
    assert ds["block"].values.tolist() == list(range(1, P.N + 1))
    b = run.state.blocks()
    for name in ("x", "v", "theta"):
        assert ds[name].dims == ("block",)
        assert_bits_equal(ds[name].values, b[name], name)
    assert ds["stopped"].values.astype(bool).tolist() == b["stopped"].tolist()
    assert ds["L"].dims == ("t",)
    assert_bits_equal(ds["t"].values, run.samples["t"].values, "t")
    assert ds["snapshot_x"].dims == ("snapshot_time", "block")
    assert ds["profile_dx"].dims == ("profile_row", "block")
    assert json.loads(ds.attrs["params"]) == P.to_dict()
    assert ds.attrs["integrator"] == "exact" and ds.attrs["version"] == stickslip.__version__


def test_snapshots_equal_runs_stopped_at_those_times(run_and_dir):
    run, _ = run_and_dir
    times = run.snapshots["snapshot_time"].values
    assert times.tolist() == sorted(times.tolist())
    assert len(times) == len(SNAPS) + 1  # the requested times and the final state
    for i, t in enumerate(sorted(SNAPS)):
        # at t = 0 the start itself (run_chain refuses a run of no steps)
        stopped_there = run_chain(P, t).state if t > 0 else initial_state(P)
        assert times[i] == pytest.approx(t, abs=0.5 * P.dt)
        assert_bits_equal(run.snapshots.values[i], stopped_there.x, f"snapshot at t = {t}")
    assert_bits_equal(run.snapshots.values[-1], run.state.x, "final snapshot")


def test_samples_are_L_on_the_sampling_grid(run_and_dir):
    run, _ = run_and_dir
    t = run.samples["t"].values
    np.testing.assert_allclose(t, np.arange(len(t)) * 2.5, rtol=1e-12, atol=1e-9)
    assert t[-1] == pytest.approx(600.0)
    assert run.samples["L"].values[-1] == run.summary["L_final"]
    later = t >= 300.0 - 1e-9
    assert run.summary["L_mean"] == pytest.approx(run.samples["L"].values[later].mean(), rel=1e-12)


# --------------------------------------------------------------------------------------
# Steady sliding (beta > 1) stays steady


@pytest.mark.parametrize("integrator", ["exact", "dense"])
@pytest.mark.parametrize("N, t_end, beta", [(50, 1000.0, 1.5), (399, 200.0, 1.5), (20, 2000.0, 1.2)])
def test_steady_sliding_stays_steady(integrator, N, t_end, beta):
    """Exact discrete steady sliding is a fixed point of the Heun step in exact arithmetic
    (x linear in t, v and theta constant), so only rounding moves the state: relative errors
    of about eps = 2.2e-16 on positions up to L_ss per step. For beta > 1 steady sliding is
    linearly stable (Fig. 4), so they do not grow; the bound for L allows them to add up
    linearly over every step, and v, theta are held to 1e-9, a millionth of the deviation
    O(V) = 1e-3 that any stick-slip would cause, and well above the observed ~1e-10."""
    p = ChainParams(N=N, beta=beta)
    run = run_chain(p, t_end, integrator=integrator, start="steady")
    b = run.state.blocks()
    assert not b["stopped"].any(), "every block keeps sliding"
    assert run.summary["n_moving"] == N
    assert run.summary["n_events"] == 0 and not run.summary["event_in_progress"]
    assert np.max(np.abs(b["v"] - p.V)) < 1e-9
    assert np.max(np.abs(b["theta"] - (1.0 - p.V))) < 1e-9
    L_ss = physics.chain_steady_length(p)
    c = 1.0 - (1.0 - beta) * p.V  # docs/model.md: friction of steady sliding
    assert L_ss == pytest.approx(c / p.K * N * (N - 1) / 2, rel=1e-14)
    tol_L = run.steps * 4 * np.finfo(float).eps * L_ss
    assert abs(run.summary["L_final"] - L_ss) < tol_L
    assert np.max(np.abs(run.samples["L"].values - L_ss)) < tol_L
    # the whole profile: x_i = V t - (c/K) sum_{j<=i} (N - j + 1)
    t = run.steps * p.dt
    i = np.arange(1, N + 1)
    x_ss = p.V * t - c / p.K * np.cumsum(N - i + 1.0)
    assert np.max(np.abs(b["x"] - x_ss)) < tol_L + 1e-12 * abs(p.V * t)


def test_until_steady_stops_at_a_state_within_the_tolerance():
    p = ChainParams(N=30, beta=1.5)
    tol = 1e-6
    runs = [run_chain(p, 3000.0, integrator=i, start="steady", perturbation=1e-4, seed=3, until_steady=tol)
            for i in ("dense", "exact")]  # fmt: skip
    assert_same_run(*runs)
    run = runs[0]
    s = run.summary
    assert s["stopped_early"] and run.steps * p.dt < 3000.0
    b = run.state.blocks()
    c = 1.0 - (1.0 - p.beta) * p.V
    ext = -np.diff(np.concatenate(([p.V * run.steps * p.dt], b["x"])))
    dev = max(np.abs(b["v"] - p.V).max(), np.abs(b["theta"] - (1 - p.V)).max(),
              np.abs(ext - c / p.K * (p.N - np.arange(1, p.N + 1) + 1.0)).max())  # fmt: skip
    assert not b["stopped"].any()
    assert dev <= tol
    assert s["steady_deviation"] == pytest.approx(dev, rel=1e-6, abs=1e-15)
    assert steady_deviation(run.state, p) == pytest.approx(dev, rel=1e-6, abs=1e-15)
    # one sampling interval earlier the state was not yet within the tolerance
    earlier = run_chain(p, run.steps * p.dt - 10.0, start="steady", perturbation=1e-4, seed=3)
    assert steady_deviation(earlier.state, p) > tol


# --------------------------------------------------------------------------------------
# Non-finite state


@pytest.mark.parametrize("integrator", ["dense", "exact"])
def test_blow_up_names_time_and_block(integrator):
    p = ChainParams(N=399, K=1e6)
    with pytest.raises(ChainRunError) as info:
        run_chain(p, 100.0, integrator=integrator)
    msg = str(info.value)
    assert "t =" in msg and "block" in msg and "non-finite" in msg
    assert "\n" not in msg


def test_blow_up_message_is_the_same_for_both_integrators():
    msgs = []
    for integrator in ("dense", "exact"):
        for kw in (dict(N=7, K=2e5), dict(N=30, K=5e4, beta=0.2)):
            with pytest.raises(ChainRunError) as info:
                run_chain(ChainParams(**kw), 200.0, integrator=integrator)
            msgs.append(str(info.value))
    assert msgs[:2] == msgs[2:]


def _moving_in_pieces(p, state, times):
    """The moving blocks at each of ``times``, from runs that stop there (the kernels' sampling
    not involved: each count is taken from the returned state)."""
    counts = []
    for t in times:
        if t > state.step * p.dt:
            state = run_chain(p, t, start=state).state
        counts.append(int(np.count_nonzero(state.mov[1:-1])))
    return counts


@pytest.mark.parametrize(
    "model, integrator, t0",
    [("sakaguchi", "exact", 3240.0), ("sakaguchi", "dense", 3240.0), ("carlson-langer", "exact", 3500.0)],
)
def test_moving_samples_count_the_moving_blocks_of_each_sampled_state(monkeypatch, model, integrator, t0):
    """n_moving (sample_moving) at each sample time is the number of moving blocks of the state
    there: counted by the kernels along with L (the interval path, the reference and the plate
    drive's sparse path), checked against runs stopped at each sample time, in one kernel call.
    The window (t0, t0 + 30) holds one slip of the loaded chain."""
    from stickslip.models.presets import chain_params

    p = chain_params(model, N=6)
    warm = run_chain(p, t0, integrator=integrator)
    calls = _count_kernel_calls(monkeypatch)
    run = run_chain(p, t0 + 30.0, integrator=integrator, start=warm.state, sample_interval=0.25, sample_moving=True)
    assert len(calls) <= 2, "the kernel is not stopped at each of the 121 samples"
    t = run.samples["t_moving"].values
    assert np.array_equal(t, run.samples["t"].values)
    assert np.allclose(t, t0 + 0.25 * np.arange(121), rtol=0, atol=1e-9)
    n = run.samples["n_moving"].values
    assert n.max() >= 3 and n.min() == 0, "the window should hold a slip and rests"
    assert list(n) == _moving_in_pieces(p, warm.state, t)


def test_moving_samples_of_a_start_off_the_sampling_grid():
    """A run that starts between two multiples of the sampling interval samples L from its start
    and the moving blocks at the multiples (the driver counts them then)."""
    from stickslip.models.presets import chain_params

    p = chain_params("sakaguchi", N=6)
    warm = run_chain(p, 3240.1)
    run = run_chain(p, 3270.0, start=warm.state, sample_interval=0.25, sample_moving=True)
    t = run.samples["t_moving"].values
    assert np.allclose(t, 3240.25 + 0.25 * np.arange(120), rtol=0, atol=1e-9)
    assert run.samples["t"].values[0] == pytest.approx(3240.1)
    assert run.samples["n_moving"].values.max() >= 3
    assert list(run.samples["n_moving"].values) == _moving_in_pieces(p, warm.state, t)


def _count_kernel_calls(monkeypatch):
    from stickslip.run import driver

    calls = []
    call = driver._Kernel.__call__

    def counted(self, state, target):
        calls.append(target)
        return call(self, state, target)

    monkeypatch.setattr(driver._Kernel, "__call__", counted)
    return calls


@pytest.mark.parametrize("integrator", ["exact", "dense"])
def test_until_steady_stops_at_the_first_sampled_steady_state(monkeypatch, integrator):
    """until_steady stops at the first multiple of the sampling interval at which the state is
    within the tolerance of steady sliding (found here by runs stopped at each multiple), and the
    kernel is not stopped at the samples at which some block is stuck (only then can the chain
    slide steadily): a chain knocked off steady sliding slips a few times before it settles."""
    p = ChainParams(N=8, beta=5.0)
    start = initial_state(p, "steady", amplitude=1e-3, seed=1)
    calls = _count_kernel_calls(monkeypatch)
    run = run_chain(p, 5e3, integrator=integrator, start=start, until_steady=1e-6, sample_interval=10.0)
    n_calls = len(calls)
    assert run.summary["stopped_early"] and run.summary["n_events"] >= 2
    t_steady = run.summary["t_steady"]
    state, t = start, 0.0
    while steady_deviation(state, p) > 1e-6:
        t += 10.0
        state = run_chain(p, t, integrator=integrator, start=state).state
    assert t_steady == pytest.approx(t, abs=1e-9) and 1000.0 < t < 3000.0
    assert len(run.samples["L"]) == int(t_steady / 10.0) + 1
    # a kernel call per sample would be 184; the kernel returns only at the samples with every
    # block moving (17 calls in all here)
    assert n_calls < 0.3 * t_steady / 10.0
