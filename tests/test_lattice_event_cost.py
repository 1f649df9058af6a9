"""`stickslip bench --lattice square --workload events` (stickslip.run.lattice_bench): its
per-event accounting against counts made here from the runs' event tables, and its refusals.
No timing is asserted."""

from __future__ import annotations

import json

import numpy as np
import pytest

from stickslip import chain_params
from stickslip.cli import main
from stickslip.models.params import ParameterError
from stickslip.run import lattice_bench as lb
from stickslip.run.lattice import run_lattice

SIZES = (8, 12)
WORKLOAD = dict(v64=1e-6, loading_times=0.4, timed_loading_times=0.3, repeat=1)


@pytest.fixture(scope="module")
def result():
    p = chain_params("carlson-langer", lattice="square", shape=(8, 8))
    return p, lb.event_cost(p, SIZES, **WORKLOAD)


def _window(p, L):
    """The bench's window for L, run here on its own: the prepared state and the window's run."""
    q = chain_params("carlson-langer", lattice="square", shape=(L, L), V=1e-6 * (64 / L) ** 2)
    assert q.V == lb.sized(p, L, 1e-6).V
    prep = run_lattice(q, 0.4 / q.V, start="rest", perturbation=0.01)
    t0 = prep.summary["t_end"]
    return q, prep, run_lattice(q, t0 + 0.3 / q.V, start=prep.state)


def test_the_per_event_accounting_matches_the_event_tables(result):
    p, r = result
    assert [s["L"] for s in r["sizes"]] == list(SIZES)
    for row in r["sizes"]:
        q, prep, run = _window(p, row["L"])
        ev = run.events
        steps = run.summary["steps"] - prep.summary["steps"]
        assert row["events"] == len(ev) > 20
        assert row["area_total"] == ev["area"].sum()
        assert row["area_mean"] == pytest.approx(ev["area"].mean(), rel=1e-12)
        assert row["area_max"] == ev["area"].max()
        assert row["steps"] == steps
        busy = (ev["step_end"] - ev["step_start"] + 1).sum() / steps
        assert row["busy_fraction"] == pytest.approx(busy, rel=1e-12)
        assert row["busy_fraction"] < 0.05  # the events are apart
        assert row["prepare_events"] == len(prep.events)
        assert row["state_sha256"] == run.summary["state_sha256"]
        assert row["V"] == pytest.approx(1e-6 * (64 / row["L"]) ** 2, rel=1e-12)


def test_each_events_work_adds_up_to_the_runs_block_updates(result):
    p, _ = result
    q, prep, run = _window(p, 12)
    work = lb.event_work(q, prep.state, run.summary["t_end"])
    ev = run.events
    assert work.drop(columns=["block_updates", "steps_computed"]).equals(ev)
    # up to the end of the last event, the run's own counters
    last = int(ev["step_end"].iloc[-1])
    upto = run_lattice(q, (last + 1) * q.dt, start=prep.state)
    assert work["block_updates"].sum() == upto.summary["block_updates"] - prep.summary["block_updates"]
    assert work["steps_computed"].sum() == upto.summary["steps_computed"] - prep.summary["steps_computed"]
    # an event of area A computes at least its A blocks in each of its steps with one moving
    assert (work["block_updates"] >= work["area"]).all()


def test_the_area_bins_count_the_events(result):
    _, r = result
    for row in r["sizes"]:
        bins = {b["area_from"]: b for b in row["area_bins"]}
        assert sum(b["events"] for b in bins.values()) == row["events"] - 1  # the first left out
        for a, b in bins.items():
            assert a & (a - 1) == 0  # a power of two
            assert a <= b["area_mean"] < 2 * a
            assert b["block_updates_per_area"] == pytest.approx(b["block_updates_mean"] / b["area_mean"])


def test_the_slope_is_a_power_laws_exponent():
    x = np.array([1.0, 4.0, 16.0, 64.0])
    assert lb._slope(x, 3.0 * x**1.5) == pytest.approx(1.5)
    assert lb._slope([2.0, 2.0], [1.0, 3.0]) is None


def test_the_exponents_are_fitted_on_the_rows(result):
    _, r = result
    rows = r["sizes"]
    L = np.log([s["L"] for s in rows])
    per_event = np.log([s["seconds_per_event"] for s in rows])
    assert r["exponents"]["seconds_per_event_on_L"] == pytest.approx((per_event[1] - per_event[0]) / (L[1] - L[0]))
    text = lb.format_event_cost(r)
    assert "fitted exponents" in text and "L = 12" in text


def test_refusals():
    with pytest.raises(ParameterError, match="plate-driven"):
        lb.event_cost(chain_params(lattice="square", shape=(8, 8)), (8,))
    with pytest.raises(ParameterError, match="square"):
        lb.event_cost(chain_params("carlson-langer", lattice="chain", shape=8), (8,))
    with pytest.raises(ParameterError, match="size"):
        lb.event_cost(chain_params("carlson-langer", lattice="square", shape=(8, 8)), (2,))


@pytest.mark.parametrize(
    "argv, says",
    [
        (["--workload", "events"], "--workload events and --sizes go with --lattice square"),
        (["--model", "carlson-langer", "--lattice", "square", "--workload", "events", "--sizes", "8,x"], "--sizes"),
        (["--model", "carlson-langer", "--lattice", "square", "--workload", "events", "--sizes", "2"], "--sizes"),
        (["--model", "carlson-langer", "--lattice", "square", "--workload", "events", "--shape", "8x8"], "--shape"),
        (["--model", "carlson-langer", "--lattice", "square", "--shape", "8x8", "--sizes", "8"], "--sizes"),
        (["--lattice", "square", "--workload", "events", "--sizes", "8"], "plate-driven"),
    ],
)
def test_the_command_refuses_in_one_line(argv, says, capsys):
    assert main(["bench", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and says in err, err


def test_the_command_prints_the_table_and_its_json(capsys):
    argv = ["bench", "--model", "carlson-langer", "--lattice", "square", "--workload", "events", "--sizes", "8,6"]
    assert main([*argv, "--repeat", "1", "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert [s["L"] for s in r["sizes"]] == [6, 8]
    assert r["V64"] == 1e-6 and r["loading_times"] == lb.EVENTS["loading_times"]
    assert all(s["events"] > 0 and s["block_updates"] > 0 for s in r["sizes"])
    assert set(r["exponents"]) >= {"block_updates_per_event_on_area", "seconds_per_event_on_L"}
