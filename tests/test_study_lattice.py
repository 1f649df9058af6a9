"""``stickslip study lattice`` (docs/studies/lattice.md): its pieces on tiny squares, checked
against closed forms, against one uninterrupted run, and on synthetic samples whose answers are
known by construction; a ladder and a size point of a few blocks end to end."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from stickslip.experiments.studies import Study, study
from stickslip.experiments.studies.lattice import (
    FULL_BUDGET,
    SECONDS_PER_BLOCK_STEP,
    describe,
    estimate_seconds,
    findings,
    size_fits,
)
from stickslip.experiments.studies.lattice_points import (
    CHECKPOINT,
    ladder_task,
    lattice_params,
    loading_time,
    run_segments,
    rung_order,
    sizes_task,
    steady_deficit,
)
from stickslip.run.errors import Interrupted
from stickslip.run.lattice import run_lattice


def test_the_steady_deficit_is_the_chains_profile_in_every_row():
    """d_ss from the sparse solve equals the chain's steady profile x_{i-1} - x_i = (c/K)(L - i + 1)
    summed from the load point (docs/model.md), with c = theta_0 + beta V = 1 - alpha V + beta V."""
    L, beta = 5, 0.7
    p = lattice_params({"L": L}, beta)
    c = 1.0 - p.alpha * p.V + beta * p.V
    lag = np.cumsum([c / p.K * (L - i + 1) for i in range(1, L + 1)])  # V t - x_i at every t
    assert steady_deficit(p) == pytest.approx(lag.mean(), rel=1e-10)


def test_loading_time_is_the_chains():
    assert loading_time(16) == pytest.approx(16 * 15 / (2 * 10.0 * 0.001))


def test_a_segmented_run_is_one_run_and_resumes_after_an_interruption(tmp_path):
    """Four segments with a checkpoint after each give the events, samples and final state of one
    run to the same end; stopped after the first segment and started again, the same."""
    p = lattice_params({"L": 4}, 0.6)
    t_end, every = 400.0, 10.0
    one = run_lattice(p, t_end, start="rest", perturbation=1e-3, sample_every=every)
    state, events, samples = run_segments(
        p, t_end, tmp_path / "a", start="rest", perturbation=1e-3, sample_every=every, segments=4, key="k"
    )
    assert state.sha256(p.lattice) == one.summary["state_sha256"]
    pd.testing.assert_frame_equal(events, one.events, check_dtype=False)
    pd.testing.assert_frame_equal(samples.reset_index(drop=True), one.samples, check_dtype=False)
    calls = iter([False, True])
    with pytest.raises(Interrupted):
        run_segments(
            p, t_end, tmp_path / "b", start="rest", perturbation=1e-3, sample_every=every, segments=4, key="k",
            stop=lambda: next(calls),
        )  # fmt: skip
    assert (tmp_path / "b" / CHECKPOINT).exists()
    state2, events2, _ = run_segments(
        p, t_end, tmp_path / "b", start="rest", perturbation=1e-3, sample_every=every, segments=4, key="k"
    )
    assert state2.sha256(p.lattice) == one.summary["state_sha256"]
    pd.testing.assert_frame_equal(events2, one.events, check_dtype=False)


def test_rung_order_of_steady_sliding_and_of_a_known_series():
    t = np.linspace(100.0, 200.0, 401)
    steady = pd.DataFrame({"t": t, "mean_slip_deficit": 2.0, "moving": 16})
    r = rung_order(steady, 2.0, 16, 100.0, 200.0, True)
    assert r["order_parameter"] == 0.0 and r["final_state"] == "steady" and r["stuck_fraction"] == 0.0
    # d alternating 1 and 3 around d_ss = 4: m = 1 - 2/4 = 0.5; a block stuck in every other sample
    d = np.where(np.arange(t.size) % 2 == 0, 1.0, 3.0)
    moving = np.where(np.arange(t.size) % 2 == 0, 16, 15)
    r = rung_order(pd.DataFrame({"t": t, "mean_slip_deficit": d, "moving": moving}), 4.0, 16, 100.0, 200.0, False)
    assert r["order_parameter"] == pytest.approx(0.5, abs=0.01)
    assert r["stuck_fraction"] == pytest.approx(0.5, abs=0.01)
    assert r["final_state"] == "stick-slip"


def _table(parts: dict[str, list[np.ndarray]]) -> pd.DataFrame:
    rows = []
    for part, samples in parts.items():
        for L, S in samples:
            spans = S >= 0.9 * S.max()
            rows.append({"part": part, "L": L, "N": L * L, "t_end": 1e4, "sizes": json.dumps(S.tolist()),
                         "spans": json.dumps(spans.tolist()), "n_all_rows": 0})  # fmt: skip
    return pd.DataFrame(rows)


def test_size_fits_recover_a_known_power_law_and_its_b_value():
    """Sizes drawn from p(S) ~ S^-1.5 on [1, 1e4] (inverse transform): the fit returns tau = 1.5 within
    its errors and the magnitudes' b-value is b = (3/2)(tau - 1) = 0.75 within its."""
    rng = np.random.default_rng(1)
    u = rng.random(2000)
    a, lo, hi = 0.5, 1.0, 1e4  # tau - 1
    S = (lo**-a - u * (lo**-a - hi**-a)) ** (-1.0 / a)
    fits = size_fits(_table({"sizes": [(16, S)], "chain": [(16, S[:30])]}), bootstrap=20)
    sq = next(f for f in fits if f["part"] == "sizes")
    assert abs(sq["tau"] - 1.5) < 4 * sq["tau_err"] + 0.02
    assert abs(sq["b"] - 0.75) < 4 * sq["b_err"] + 0.03
    ch = next(f for f in fits if f["part"] == "chain")
    assert math.isnan(ch["tau"]) and "fewer than 50" in ch["note"]


def test_each_modes_grid_and_costs():
    """Both ladders at every ladder L, sizes beside the chain at the same L, Carlson-Langer; --full
    reaches L = 256 (chain and Carlson-Langer) within its budget, and the paper's square at L = 256
    costs more than the budget for one loading time: L (L - 1) / (2 K V) / dt steps of L^2 blocks."""
    for mode in ("quick", "full"):
        spec = study("lattice", mode)
        parts = {p["part"] for p in spec.points}
        assert parts == {"ladder", "sizes", "chain", "cl"}
        ladders = [p for p in spec.points if p["part"] == "ladder"]
        for L in {p["L"] for p in ladders}:
            assert {p["direction"] for p in ladders if p["L"] == L} == {"up", "down"}
            betas = next(p["betas"] for p in ladders if p["L"] == L)
            assert min(betas) < 1.0 < max(betas)
        sizes_L = {p["L"] for p in spec.points if p["part"] == "sizes"}
        assert sizes_L <= {p["L"] for p in spec.points if p["part"] == "chain"}
    full = study("lattice", "full")
    assert sum(estimate_seconds(p) for p in full.points) <= FULL_BUDGET
    assert max(p["L"] for p in full.points if p["part"] == "cl") == 256
    assert max(p["L"] for p in full.points if p["part"] == "chain") == 256
    load_256 = 256 * 255 / (2 * 10.0 * 0.001) / 0.005 * 256**2 * SECONDS_PER_BLOCK_STEP["sizes"]
    assert load_256 > FULL_BUDGET
    assert f"a loading time of L = 256 costs about {load_256 / 3600:.0f} core-hours" in " ".join(describe().split())


def test_a_ladder_and_a_size_point_on_a_tiny_square(tmp_path):
    """A ladder of two rungs on the 3 x 3 square: rerun, it reuses its finished rungs (same numbers,
    no new run); its down ladder from steady sliding, above the finite lattice's linear threshold,
    stays steady (m = 0 to rounding). A size point returns as many sizes as events counted."""
    common = {"perturbation": 1e-3, "down_perturbation": 1e-5, "n_samples": 100, "segments": 2}
    down = {**common, "part": "ladder", "L": 3, "direction": "down", "betas": [1.5, 1.2], "rung_loads": 1.0}
    first = ladder_task(down, tmp_path / "down")
    rungs = json.loads(first["rungs"])
    assert [r["beta"] for r in rungs] == [1.5, 1.2]
    assert all(r["final_state"] == "steady" and abs(r["order_parameter"]) < 1e-8 for r in rungs)
    again = ladder_task(down, tmp_path / "down")
    assert again == first
    point = {**common, "part": "sizes", "L": 3, "beta": 0.5, "t_end": 2000.0}
    row = sizes_task(point, tmp_path / "sizes")
    assert row["n_events"] == len(json.loads(row["sizes"])) == len(json.loads(row["spans"]))
    assert row["N"] == 9 and row["n_events_total"] >= row["n_events"]


def test_findings_on_a_synthetic_table():
    """The ladders' brackets come from the rungs' final states; the finite lattice's threshold is
    below alpha = 1 (docs/lattice.md)."""
    up = [
        {
            "beta": b,
            "order_parameter": m,
            "order_parameter_err": 0.01,
            "err_reliable": True,
            "stuck_fraction": s,
            "final_state": st,
            "n_events": 10,
            "n_all_rows": 2,
        }
        for b, m, s, st in ((0.8, 0.3, 0.9, "stick-slip"), (1.0, 0.2, 0.8, "stick-slip"), (1.2, 0.0, 0.0, "steady"))
    ]
    down = [{**r, "final_state": "steady" if r["beta"] >= 1.0 else "stick-slip"} for r in up[::-1]]  # fmt: skip
    table = pd.DataFrame(
        [
            {"part": "ladder", "L": 8, "N": 64, "direction": d, "rungs": json.dumps(r)}
            for d, r in (("up", up), ("down", down))
        ]
    )
    spec = Study("lattice", "tiny", {"bootstrap": 20}, ())
    found = findings(spec, table)
    (edge,) = found["edges"]
    assert (edge["up_lo"], edge["up_hi"], edge["down_lo"], edge["down_hi"]) == (1.0, 1.2, 0.8, 1.0)
    assert edge["up_m_at_lo"] == 0.2
    assert 0.5 < edge["linear_threshold"] < 1.0  # below alpha by about 7.6 q_min at these parameters
    assert any("stick-slips up to beta = 1" in s for s in found["statements"])
    assert "one loading time at L = 256 costs about 463 core-hours" in found["statements"][-1]


def test_the_study_has_its_own_help(capsys):
    from stickslip.cli import main

    with pytest.raises(SystemExit) as stop:
        main(["study", "lattice", "--help"])
    assert stop.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    for words in ("usage: stickslip study lattice", "up and down ladders", "L = 256", "magnitudes", "index.html"):
        assert words in text, words


def test_log_binned_density_integrates_to_one_and_the_figures_draw():
    """p(S) on log bins times the bins' widths sums to 1 (every size falls in a bin); the
    size and magnitude figures have a panel per part."""
    from stickslip.plotting.lattice_study import log_binned_density, magnitudes_figure, sizes_figure

    S = np.random.default_rng(0).lognormal(0.0, 2.0, 500)
    x, p = log_binned_density(S, bins_per_decade=4)
    edges = 10.0 ** np.arange(np.floor(np.log10(S.min())), np.ceil(np.log10(S.max())) + 0.25, 0.25)
    widths = np.diff(edges)[np.histogram(S, edges)[0] > 0]
    assert np.sum(p * widths) == pytest.approx(1.0, rel=1e-9)
    runs = [{"L": 8, "S": S, "t": 100.0}]
    assert len(sizes_figure(runs, runs).axes) == 2
    assert len(magnitudes_figure({"sizes": runs, "chain": runs, "cl": runs}).axes) == 3
