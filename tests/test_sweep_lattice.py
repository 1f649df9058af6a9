"""`stickslip sweep chain --lattice square` (docs/sweeps.md, "On a lattice"): each point's numbers
equal those read with pandas from a `stickslip chain --lattice square` run of the same point, the
steady slip deficit the chain's steady profile in every row written out here; an interrupted
point goes on from its checkpoint to the bits of one run while finished points are kept; what
does not go with a lattice is one line, exit status 2."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from chain_helpers import one_line_error, run_cli
from stickslip import chain_params
from stickslip.io import read_json

T_END, SAMPLE, SHAPE = 60.0, 2.0, "6x6"


def _chain_run(capsys, tmp_path, model: str) -> tuple[dict, pd.DataFrame, pd.DataFrame]:
    """The point run alone by `stickslip chain --lattice square`: its summary, events and samples."""
    out = tmp_path / f"alone-{model}"
    argv = ["chain", "--model", model, "--lattice", "square", "--shape", SHAPE, "--t-end", str(T_END),
            "--sample-interval", str(SAMPLE), "--out", str(out), "--json"]  # fmt: skip
    status, stdout, _ = run_cli(capsys, *argv)
    assert status == 0
    return json.loads(stdout), pd.read_csv(out / "events.csv"), pd.read_csv(out / "samples.csv")


def _steady_deficit_by_hand(K: float, V: float, alpha: float, beta: float, cols: int) -> float:
    """V t - x averaged over the blocks in steady sliding of eq. (4) pulled at the left side: every
    row the chain's profile x_{i-1} - x_i = (c/K)(C - i + 1), c = 1 - alpha V + beta V
    (docs/model.md, docs/lattice.md)."""
    c = 1.0 - alpha * V + beta * V
    return float(np.mean(np.cumsum([c / K * (cols - i + 1) for i in range(1, cols + 1)])))


@pytest.mark.slow  # each point run again alone (about 13 s, measured)
def test_each_point_measures_what_its_run_alone_gives(tmp_path, capsys):
    out = tmp_path / "sweep"
    argv = ["sweep", "chain", "--lattice", "square", "--shape", SHAPE, "--grid", "model=sakaguchi,carlson-langer",
            "--set", f"sample_interval={SAMPLE}", "--t-end", str(T_END), "--out", str(out), "--workers", "1",
            "--no-progress", "--json"]  # fmt: skip
    status, stdout, _ = run_cli(capsys, *argv)
    assert status == 0
    data = json.loads(stdout)
    rows = {row["point_dir"]: row for row in data["points"]}
    assert set(rows) == {"model=sakaguchi", "model=carlson-langer"}
    for model in ("sakaguchi", "carlson-langer"):
        row = rows[f"model={model}"]
        assert row["status"] == "ok" and row["shape"] == SHAPE and row["lattice"] == "square"
        alone, events, samples = _chain_run(capsys, tmp_path, model)
        assert row["state_sha256"] == alone["state_sha256"]
        assert row["n_events"] == alone["events"] == len(events)
        late = events[events["t_start"] >= T_END / 2]
        assert row["n_events_window"] == len(late)
        if len(late):
            assert row["moment_max"] == late["moment"].max()
            assert row["moment_mean"] == pytest.approx(late["moment"].mean(), rel=1e-12)
            assert row["area_max"] == late["area"].max()
        d = samples.loc[samples["t"] >= T_END / 2, "mean_slip_deficit"]
        assert len(d) == T_END / 2 / SAMPLE + 1
        assert row["mean_slip_deficit"] == pytest.approx(d.mean(), rel=1e-12)
        # the point's folder holds what the run alone wrote
        stored = pd.read_csv(out / f"model={model}" / "events.csv")
        pd.testing.assert_frame_equal(stored, events)
        assert not (out / f"model={model}" / "lattice-checkpoint.npz").exists()
    # carlson-langer's events are in the window; eq. (4) still loads from the paper's start
    assert rows["model=carlson-langer"]["n_events_window"] > 10
    assert rows["model=carlson-langer"]["integrator"] == "exact" and rows["model=sakaguchi"]["integrator"] == "dense"
    paper = rows["model=sakaguchi"]
    p = chain_params("sakaguchi")  # the preset's K, V, alpha, beta
    d_ss = _steady_deficit_by_hand(p.K, p.V, p.alpha, p.beta, 6)
    assert paper["steady_slip_deficit"] == pytest.approx(d_ss, rel=1e-10)
    assert paper["order_parameter"] == pytest.approx(1.0 - paper["mean_slip_deficit"] / d_ss, rel=1e-10)
    # run again: every point reused
    status, stdout, _ = run_cli(capsys, *argv)
    assert status == 0 and json.loads(stdout)["n_reused"] == 2


def test_an_interrupted_point_continues_and_finished_points_are_kept(tmp_path, monkeypatch):
    from dask.distributed import LocalCluster

    import stickslip.experiments.sweep as sweep_module
    import stickslip.run.lattice as run_lattice_module
    from stickslip.experiments.sweep import run_sweep
    from stickslip.experiments.sweep_lattice import SEGMENTS, lattice_run_task
    from stickslip.run.errors import Interrupted

    common = {"model": "carlson-langer", "lattice": "square", "shape": "5x5", "t_end": 40.0}
    points = [{"V": 0.01}, {"V": 0.02}]
    with LocalCluster(n_workers=1, processes=False, dashboard_address=None) as cluster:
        first = run_sweep(lattice_run_task, points, tmp_path, common=common, scheduler=cluster.scheduler_address,
                          progress=False)  # fmt: skip
        assert first.n_failed == 0
        done = first.table.set_index("point_dir")
        stamp = (tmp_path / "V=0.01" / "done.json").stat().st_mtime_ns

        # the second point interrupted after three of its segments, as a sweep stopped then leaves it
        (tmp_path / "V=0.02" / "done.json").unlink()
        asked = iter([False, False, False, True])
        monkeypatch.setattr(sweep_module, "stop_requested", lambda point_dir: lambda: next(asked))
        with pytest.raises(Interrupted):
            lattice_run_task({**common, **points[1]}, tmp_path / "V=0.02")
        monkeypatch.undo()
        assert (tmp_path / "V=0.02" / "lattice-checkpoint.npz").is_file()

        starts = []
        original = run_lattice_module.run_lattice

        def recording(p, t_end, *, start="paper", **kw):
            starts.append(start if isinstance(start, str) else start.step * p.dt)
            return original(p, t_end, start=start, **kw)

        monkeypatch.setattr(run_lattice_module, "run_lattice", recording)
        again = run_sweep(lattice_run_task, points, tmp_path, common=common, scheduler=cluster.scheduler_address,
                          progress=False)  # fmt: skip
    table = again.table.set_index("point_dir")
    assert again.n_reused == 1 and again.n_run == 1 and again.n_failed == 0
    assert (tmp_path / "V=0.01" / "done.json").stat().st_mtime_ns == stamp
    assert starts[0] == pytest.approx(3 * 40.0 / SEGMENTS)  # went on from its checkpoint
    assert len(starts) == SEGMENTS - 3
    for name in ("V=0.01", "V=0.02"):
        assert table.loc[name, "state_sha256"] == done.loc[name, "state_sha256"]
        assert table.loc[name, "n_events"] == done.loc[name, "n_events"] > 0
    assert not (tmp_path / "V=0.02" / "lattice-checkpoint.npz").exists()
    assert read_json(tmp_path / "V=0.02" / "run.json")["summary"]["state_sha256"] == done.loc["V=0.02", "state_sha256"]


def test_samples_further_apart_than_a_segment_are_those_of_one_run(tmp_path):
    """A sample interval longer than the run's segments (t_end / 8): the point's samples are
    those of one run (t = 0, 10, 20), none lost at a segment without one; and the docstring's example."""
    import doctest

    from stickslip.experiments import sweep_lattice
    from stickslip.experiments.sweep_lattice import lattice_run_task
    from stickslip.run.lattice import run_lattice

    summary = lattice_run_task({"lattice": "square", "shape": "3x3", "t_end": 20.0}, tmp_path)
    one = run_lattice(chain_params(lattice="square", shape=(3, 3)), 20.0, sample_every=10.0)
    stored = pd.read_csv(tmp_path / "samples.csv")
    assert stored["t"].tolist() == [0.0, 10.0, 20.0]
    np.testing.assert_array_equal(stored.to_numpy(dtype=float), one.samples.to_numpy(dtype=float))
    assert summary["mean_slip_deficit"] == np.mean(one.samples["mean_slip_deficit"].to_numpy()[1:])
    assert summary["state_sha256"] == one.summary["state_sha256"]
    assert doctest.testmod(sweep_lattice, optionflags=doctest.ELLIPSIS).failed == 0


@pytest.mark.parametrize(
    "extra, names",
    [
        (["sweep", "block", "--lattice", "square", "--shape", "4x4"], ["--lattice square", "sweep chain"]),
        (["--lattice", "square"], ["--shape"]),
        (["--shape", "4x4"], ["--shape", "--lattice square"]),
        (["--lattice", "square", "--shape", "4x0"], ["shape"]),
        (["--lattice", "square", "--shape", "4x4", "--grid", "shape=8x8"], ["shape", "more than once"]),
        (["--lattice", "square", "--shape", "4x4", "--grid", "N=4,5"], ["N", "--lattice square"]),
        (["--lattice", "square", "--shape", "4x4", "--set", "profile_window=1"], ["profile_window", "profiles"]),
        (["--lattice", "square", "--shape", "4x4", "--set", "integrator=located"], ["integrator", "exact or dense"]),
        (["--lattice", "square", "--shape", "4x4", "--set", "start=loaded"], ["start", "paper, steady, rest"]),
        (["--lattice", "square", "--shape", "4x4", "--set", "seed=3"], ["seed", "start steady or rest"]),
        (["--lattice", "square", "--shape", "4x4", "--set", "average_from=20"], ["average_from"]),
        (["--lattice", "square", "--shape", "4x4", "--set", "sample_interval=0"], ["sample_interval"]),
        (["--lattice", "square", "--shape", "4x4", "--edges", "right=fixed", "--set", "start=steady"], ["fixed"]),
        (["--lattice", "square", "--shape", "4x4", "--set", "model=carlson-langer", "--grid", "beta=1,2"], ["beta"]),
    ],
)
def test_what_does_not_go_with_a_lattice_is_one_line_exit_2(extra, names, tmp_path, capsys):
    from stickslip.cli import main

    out = tmp_path / "sweep"
    if extra[0] == "sweep":
        argv = [*extra, "--grid", "V=0.01"]
    else:
        argv = ["sweep", "chain", *([] if "--grid" in extra else ["--grid", "beta=0.5,1.5"]), *extra]
    assert main([*argv, "--t-end", "10", "--out", str(out)]) == 2
    one_line_error(capsys, *names)
    assert not out.exists()
