"""Load histories on the square (docs/lattice.md, "Load histories"): the driven side's ghost
cells at the history's p(t_n), as the chain's block 1 reads it. The lattice reference equals a
plain numpy step of the 2-d equations with the history's load point, a square of one row is the
chain's history run bit for bit, the samples' slip deficit is read against p(t), and
``--history`` goes with ``--lattice square``."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd

from chain_helpers import run_cli
from stickslip import chain_params
from stickslip.lab.history import LoadHistory
from stickslip.models.drive import history as hist
from stickslip.run.driver import run_chain
from stickslip.run.lattice import LatticeState, initial_state, run_lattice
from stickslip.run.state import initial_state as chain_start
from test_lattice_per_block import _oracle

SIDES = ("top", "bottom", "left", "right")
# a slide, a hold at V = 0, a faster slide
STEPS = LoadHistory.steps([0.2, 0.0, 0.4], [3.0, 2.0, 5.0])


def test_square_step_with_a_history_equals_the_plain_numpy_equations():
    kinds = ("free", "fixed", "driven", "free")
    edges = dict(zip(SIDES, kinds, strict=True))
    p = chain_params("sakaguchi", lattice="square", shape=(3, 4), edges=edges, drive="history", history=STEPS, K=10.0)
    n_steps = 1600
    s0 = initial_state(p, "rest", amplitude=1.0, seed=4)
    f0 = s0.fields(p.lattice)
    run = run_lattice(p, n_steps * p.dt, start=s0)
    assert run.summary["integrator"] == "dense"
    tb = hist.table(STEPS)
    pull = lambda n: hist.pull_py(n, p.dt, tb)  # noqa: E731
    x, v, th, mov, n_events = _oracle(
        p, kinds, f0["x"], f0["v"], f0["theta"], np.where(f0["stopped"], 0.0, 1.0), n_steps, pull=pull
    )
    fin = run.state.fields(p.lattice)
    assert n_events >= 1 and len(run.events) == n_events
    for got, want in ((fin["x"], x), (fin["v"], v), (fin["theta"], th)):
        assert got.tobytes() == want.tobytes()


def test_a_row_of_the_square_is_the_chains_history_run():
    steps = LoadHistory.steps([0.2, 0.0, 0.4], [10.0, 5.0, 20.0])
    chain = chain_params("sakaguchi", N=10, drive="history", history=steps)
    ref = run_chain(chain, 35.0, integrator="dense")
    sq = chain_params("sakaguchi", lattice="square", shape=(1, 10), drive="history", history=steps)
    b = chain_start(chain, "paper").blocks()
    grid = lambda a: np.asarray(a).reshape(1, 10)  # noqa: E731
    start = LatticeState.from_blocks(sq.lattice, grid(b["x"]), grid(b["v"]), grid(b["theta"]), grid(b["stopped"]))
    run = run_lattice(sq, 35.0, start=start)
    assert ref.summary["n_events"] >= 2
    assert (run.summary["state_sha256"], len(run.events)) == (ref.summary["state_sha256"], ref.summary["n_events"])


def test_command_line_history_on_the_square(tmp_path, capsys):
    out = tmp_path / "run"
    code, _, err = run_cli(
        capsys, "chain", "--lattice", "square", "--shape", "3x4", "--history", "0.2:3,0:2,0.4:5",
        "--t-end", "10", "--sample-interval", "1", "--snapshot-every", "1", "--out", str(out),
    )  # fmt: skip
    assert code == 0, err
    meta = json.loads((out / "run.json").read_text())
    assert meta["params"]["drive"] == "history"
    samples = pd.read_csv(out / "samples.csv").set_index("t")
    # the load point of the steps, by hand: 0.2 t to t = 3, held at 0.6 to t = 5, then 0.6 + 0.4 (t - 5)
    load = {1.0: 0.2, 4.0: 0.6, 5.0: 0.6, 8.0: 1.8}
    import xarray as xr

    with xr.open_dataset(out / "state.nc", engine="h5netcdf") as ds:
        for t, p in load.items():
            x = ds["snapshot_x"].sel(time=t, method="nearest").values
            assert abs(samples.loc[t, "mean_slip_deficit"] - np.mean(p - x)) < 1e-12
