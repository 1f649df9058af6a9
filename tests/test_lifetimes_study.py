"""The lifetimes study (issue 51, item 2 of its build list): one start's lifetime against a plain
run, the findings against the survival fits, refusals, and the tiny study end to end."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

import stickslip
from stickslip.analysis.stats.periodicity import periodicity
from stickslip.analysis.stats.survival import exponential_fit
from stickslip.experiments.studies import lifetimes, study
from stickslip.experiments.study_run import run_study
from stickslip.experiments.sweep_points import point_params
from stickslip.models.params import ParameterError

_RULE = {"rtol": 1e-6, "max_period": 500, "repeats": 3, "until_steady": 1e-6, "perturbation": 0.05}


def test_a_start_ends_where_its_plain_run_settles():
    # N = 5, beta = 1 from a perturbed paper start: the lifetime is the start of the orbit that a
    # plain run to the same length, read by the detector, finds
    cfg = {"model": "sakaguchi", "N": 5, "beta": 1.0, "start": "paper", "seed": 3, "budget": 5e5, **_RULE}
    params = point_params("chain", cfg)
    row = lifetimes.lifetime_point(cfg, params)
    state = lifetimes.start_state(params, "paper", 0.05, 3)
    # the draw by hand: x_i = 0 moved by numpy's uniform draw with the seed
    expected = np.random.default_rng(3).uniform(-0.05, 0.05, 5)
    assert np.array_equal(state.x, expected)
    plain = stickslip.run_chain(params, 5e5, start=state, progress=False)
    found = periodicity(plain.events)
    assert found.period_slips is not None and row["ended"] and row["end"] == "periodic"
    assert row["lifetime"] == found.settled_from_t and row["period_slips"] == found.period_slips
    assert row["t_start"] == 0.0 and row["t_reached"] < 5e5


def test_a_loaded_start_counts_from_twice_the_loading_time():
    cfg = {"model": "sakaguchi", "N": 3, "beta": 1.0, "start": "loaded", "seed": 0, "budget": 2e5, **_RULE}
    row = lifetimes.lifetime_point(cfg, point_params("chain", cfg))
    # L_ss / V for N = 3 (docs/model.md): L_ss = 0.3, V = 0.001, so twice 300
    assert row["t_start"] == pytest.approx(600.0)
    assert row["lifetime"] >= 0.0


def _table(rng):
    rows = []
    for beta, growth in ((0.5, 0.6), (1.0, 0.3)):
        for N in (3, 5, 7, 9):
            tau = 1e3 * math.exp(growth * N)
            life = rng.exponential(tau, 40)
            budget = 3 * 1e3 * math.exp(0.3 * 9)
            for k, T in enumerate(life):
                ended = T <= budget
                rows.append(
                    {
                        "status": "ok",
                        "model": "sakaguchi",
                        "N": N,
                        "beta": beta,
                        "start": "paper",
                        "seed": k,
                        "lifetime": min(T, budget),
                        "ended": ended,
                        "end": "periodic" if ended else "censored",
                        "period_slips": 4 if ended else None,
                        "slips": 100,
                        "t_reached": budget,
                        "budget": budget,
                    }
                )
    return pd.DataFrame(rows)


def test_findings_are_the_survival_fits_of_each_point():
    table = _table(np.random.default_rng(0))
    found = lifetimes.conclusions(None, table)
    for p in found["points"]:
        g = table[(table["beta"] == p["beta"]) & (table["N"] == p["N"])]
        fit = exponential_fit(g["lifetime"], g["ended"])
        assert p["ended"] == int(g["ended"].sum()) and p["starts"] == 40
        if fit.ended:
            assert p["mean_T"] == pytest.approx(fit.mean)
        if g["ended"].all():  # none censored: the sample mean and its standard error
            T = g["lifetime"].to_numpy()
            assert p["mean_T"] == pytest.approx(T.mean())
            assert p["mean_T_err"] == pytest.approx(T.std(ddof=1) / math.sqrt(T.size))
        elif fit.ended:
            assert p["mean_T_err"] == pytest.approx(fit.mean_err)
    fits = {f["beta"]: f for f in found["fits"]}
    # the planted growth rates per block, within three errors
    for beta, growth in ((0.5, 0.6), (1.0, 0.3)):
        e = fits[beta]["exponential"]
        assert abs(e["slope"] - growth) < 3 * e["slope_err"] + 0.05
        assert e["at"] == 399 and e["T_at_low"] < e["T_at"] < e["T_at_high"]
    assert any("Extrapolated to N = 399" in s for s in found["statements"])


def test_bad_points_are_refused():
    base = {"model": "sakaguchi", "N": 3, "beta": 1.0, "seed": 0, "budget": 1e3, **_RULE}
    with pytest.raises(ParameterError, match="start"):
        lifetimes.check_point({**base, "start": "steady"})
    with pytest.raises(ParameterError, match="budget"):
        lifetimes.check_point({**base, "start": "paper", "budget": -1.0})


@pytest.mark.slow
def test_tiny_lifetimes_study_end_to_end(tmp_path):
    spec = study("lifetimes", "tiny")
    first = run_study(spec, tmp_path, n_workers=1, progress=False)
    # the chain's six starts, one start of two blocks, the exponents of the chain and of two blocks
    assert first["failed"] == 0 and first["run"] == len(spec.points) == 9
    rows = [r for r in first["rows"] if r.get("measure") != "exponent"]
    assert len(rows) == 7
    assert all(r["end"] in ("periodic", "steady", "censored") for r in rows)
    assert all((r["end"] != "censored") == r["ended"] for r in rows)
    # each point's cost, its worker's own CPU time beside its wall time (the cost of --full is
    # estimated from these on a shared machine)
    assert all(0.0 < r["point_cpu_seconds"] for r in first["rows"])
    for name in ("survival", "lifetime_vs_N", "exponent_vs_N"):
        assert (tmp_path / "lifetimes" / f"{name}.png").is_file()
    found = first["findings"]
    assert sorted((p["model"], p["beta"], p["N"]) for p in found["points"]) == [
        ("sakaguchi", 1.0, 3),
        ("sakaguchi", 1.0, 5),
        ("two-blocks", None, 2),
    ]
    assert sorted((e["model"], e["N"]) for e in found["exponents"]) == [("sakaguchi", 3), ("two-blocks", 2)]
    verdicts = {(v["model"], v["N"]): v["verdict"] for v in found["verdicts"]}
    assert set(verdicts) == {("sakaguchi", 3), ("sakaguchi", 5), ("two-blocks", 2)}
    assert all(v in ("periodic", "steady", "chaotic", "stable chaos", "undetermined") for v in verdicts.values())
    second = run_study(spec, tmp_path, n_workers=1, progress=False)
    assert second["run"] == 0 and second["reused"] == 9


def _chaos_rows():
    base = {"seeds": 1, "loaded": True, "flow_slips": 300, "lyapunov_dt0_err": 2e-6}
    base |= {"threshold_below": 1e-4, "threshold_low": 1e-3}
    return pd.DataFrame(
        [
            {**base, "model": "sakaguchi", "N": 49, "beta": 1.0, "lyapunov_dt0": -1e-6}
            | {"verdict": "stable chaos", "verdict_text": "stable chaos: text"},
            {**base, "model": "two-blocks", "N": 2, "beta": float("nan"), "lyapunov_dt0": 0.026}
            | {"verdict": "chaotic", "verdict_text": "chaotic: text"},
        ]
    )


def test_the_chaos_study_reports_the_lifetimes_verdicts(tmp_path):
    from stickslip import io
    from stickslip.experiments.studies import chaos

    spec = study("chaos", "quick")
    points_dir = spec.runs_dir(tmp_path) / "points"
    alone = chaos.conclusions(spec, chaos.load(spec, _chaos_rows(), points_dir))
    assert alone["lifetimes"]["found"] is False
    assert any("stickslip study lifetimes" in s for s in alone["statements"])
    # the lifetimes study's page in the same folder: its verdicts and bounds, its figures
    table = _table(np.random.default_rng(1))
    found = lifetimes.conclusions(None, table)
    page = tmp_path / "lifetimes"
    page.mkdir()
    table.to_parquet(page / "table.parquet")
    io.write_json(page / "study.json", {"meta": {"mode": "quick"}, "findings": found})
    loaded = chaos.load(spec, _chaos_rows(), points_dir)
    out = chaos.conclusions(spec, loaded)
    told = out["lifetimes"]
    assert told["found"] is True and told["mode"] == "quick"
    assert sum(len(v) for v in told["verdicts"].values()) == len(found["verdicts"]) == 8
    by_beta = {f["beta"]: f["T_399_low95"] for f in found["fits"]}
    assert {b["beta"]: b["T_399_low95"] for b in told["bounds_399"]} == by_beta
    # the bound is the lesser of the two laws' one-sided 95 % bounds, by hand
    for f in found["fits"]:
        low = min(f[k]["log10_T_at"] - 1.6449 * f[k]["log10_T_at_err"] for k in ("exponential", "power"))
        assert f["T_399_low95"] == pytest.approx(10.0**low)
    assert any(s.startswith("Extrapolated from the chain's lifetimes") for s in out["statements"])
    assert out["verdicts"] == {"stable chaos": ["beta = 1 (N = 49)"], "chaotic": ["two blocks (N = 2)"]}
    # its own points judged again with the lifetimes' growth at the same beta (b = 0.3 planted)
    revised = {(v["model"], v["N"]): v for v in told["revised_verdicts"]}
    assert revised[("sakaguchi", 49)]["verdict"] == "stable chaos"
    assert "b = 0.29" in revised[("sakaguchi", 49)]["verdict_text"]
    assert revised[("two-blocks", 2)]["verdict"] == "chaotic"
    names = [name for name, *_ in chaos.figures(spec, loaded, tmp_path / "chaos")]
    assert names == ["lifetimes_survival", "lifetimes_lifetime_vs_N"]


def test_a_rest_start_is_the_presets_draw_by_hand():
    # docs/model.md, Carlson-Langer: x_i(0) = -A u_i, u_i = default_rng(seed).random(N), every block stuck
    params = point_params("chain", {"model": "carlson-langer", "N": 8})
    state = lifetimes.start_state(params, "rest", 0.01, 4)
    assert np.array_equal(state.x, -0.01 * np.random.default_rng(4).random(8))
    assert not state.v.any()


def test_the_relatives_points_are_checked():
    base = {"model": "carlson-langer", "N": 8, "seed": 0, "budget": 1e3, **_RULE}
    lifetimes.check_point({**base, "start": "rest"})
    # the plate loads every block at once: no L_ss / V, so a loaded start needs its load_t
    with pytest.raises(ParameterError, match="load_t"):
        lifetimes.check_point({**base, "start": "loaded"})
    lifetimes.check_point({**base, "start": "loaded", "load_t": 2e3})
    with pytest.raises(ParameterError, match="measure"):
        lifetimes.check_point({**base, "start": "rest", "measure": "spectrum"})
    exp = {"model": "two-blocks", "N": 2, "measure": "exponent", "transient": 100.0, "flow_t": 200.0}
    with pytest.raises(ParameterError, match="deltas"):
        lifetimes.check_point({**exp, "events": 10, "windows": 1, "deltas": []})


def test_two_blocks_outlast_a_short_budget():
    # two blocks are chaotic: over 2e3 time units (some 70 slips) a rest start does not settle
    cfg = {"model": "two-blocks", "N": 2, "start": "rest", "seed": 1, "budget": 2e3, **_RULE, "perturbation": 0.01}
    row = lifetimes.lifetime_point(cfg, point_params("chain", cfg))
    assert row["end"] == "censored" and not row["ended"] and row["lifetime"] == pytest.approx(2e3)
    assert row["slips"] > 30


def test_a_point_with_a_single_lifetime_is_drawn_without_an_error_bar():
    # a point of one start that ended has <T> but no error (per_point gives None): the figure of
    # <T> against N drew nothing and raised before
    from stickslip.plotting.lifetimes import lifetime_figure

    table = pd.DataFrame(
        [
            {"status": "ok", "model": "sakaguchi", "N": N, "beta": 1.0, "lifetime": T, "ended": True}
            | {"end": "periodic", "period_slips": 10, "budget": 1e6, "slips": 100, "t_reached": T}
            for N, T in ((3, 2e4), (5, 3e4), (5, 3.5e4))
        ]
    )
    points = lifetimes.per_point(table)
    assert [p["mean_T_err"] is None for p in points] == [True, False]
    fig = lifetime_figure([{**p, "series": "eq. (4)"} for p in points], [])
    (bars,) = [c for c in fig.axes[0].containers]
    assert len(bars.lines[0].get_xdata()) == 2
