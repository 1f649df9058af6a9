"""``stickslip study disorder`` (docs/studies/disorder.md): its points, its tiny mode end to end,
and its findings on synthetic tables whose answers are known by construction."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from stickslip.experiments.studies import Study, study
from stickslip.experiments.studies.disorder import findings, part_a, part_c, qew_tau, ramp_fits
from stickslip.experiments.studies.disorder_points import depinning_force, seeded_point
from stickslip.experiments.study_run import run_study
from stickslip.models.disorder import Quenched


def test_qew_tau_from_zeta():
    # 2 - 2 / (1 + 1.25) = 10 / 9; d tau / d zeta = 2 / (1 + zeta)^2 = 8 / 20.25
    tau, err = qew_tau()
    assert tau == pytest.approx(10.0 / 9.0, abs=1e-12)
    assert err == pytest.approx(0.005 * 8.0 / 20.25, rel=1e-12)


def test_a_point_draws_its_expressions_with_its_disorder_seed():
    point = {"part": "b", "Fs": "uniform(2, 4)", "beta": "uniform(0.5, 1.5, seed=7)", "F0": 2.0, "disorder_seed": 3}
    out = seeded_point(point)
    assert out["Fs"] == Quenched("uniform", 2.0, 4.0, seed=3)
    assert out["beta"] == "uniform(0.5, 1.5, seed=7)"  # its own seed kept (ChainParams draws with it)
    assert out["F0"] == 2.0 and out["part"] == "b" and point["Fs"] == "uniform(2, 4)"


def test_quick_and_full_cover_the_brief():
    quick, full = study("disorder", "quick"), study("disorder", "full")
    for spec in (quick, full):
        a = [p for p in spec.points if p["part"] == "a"]
        assert sorted({p["w"] for p in a}) == [0.0, 0.05, 0.1, 0.2, 0.4]
        betas = {p["beta"] for p in a if p["analysis"] == "order"}
        assert min(betas) < 1.0 < max(betas)
        # Fs_i uniform on [3 (1 - w), 3 (1 + w)]
        assert {p["Fs"] for p in a if p["w"] == 0.2} == {"uniform(2.4, 3.6)"}
        b = [p for p in spec.points if p["part"] == "b"]
        assert {p["drive"] for p in b} == {"force-ramp"} and {p["friction"] for p in b} == {"strengthening"}
        assert min(p["beta"] for p in b) <= 0.2 and max(p["beta"] for p in b) >= 10.0
        c = [p for p in spec.points if p["part"] == "c"]
        assert {p["friction"] for p in c} == {"strengthening", "weakening"}
    assert max(p["N"] for p in full.points if p["part"] == "b") >= 3199


def test_depinning_force_is_the_first_sample_with_every_block_moving():
    t = np.array([0.0, 10.0, 20.0, 30.0])
    assert depinning_force(t, [0, 3, 8, 8], 8, 2.0, 0.01) == pytest.approx(2.2)
    assert math.isnan(depinning_force(t, [0, 3, 7, 7], 8, 2.0, 0.01))


@pytest.mark.slow  # a ramp run to depinning (about 45 s, measured)
def test_a_ramp_run_ends_where_the_chain_depins_and_loses_nothing(tmp_path):
    """A point of part b stops at the first sample with every block moving; the run to the
    ramp's end without the stop has the same event sizes and F_c (no event ends after depinning:
    F is above F0, so no sliding block stops), and it is still sliding everywhere at its end."""
    from stickslip.experiments.studies.disorder import MEDIUM, RAMP_END, RAMP_START
    from stickslip.experiments.studies.disorder_points import _run_from_rest, ramp_task

    point = {"part": "b", **MEDIUM, "F_start": RAMP_START, "r": 0.004, "K": 10.0, "N": 16, "beta": 1.0}
    point["t_end"] = (RAMP_END - RAMP_START) / point["r"]
    row = ramp_task(point, tmp_path / "stopped")
    params, full = _run_from_rest(point, tmp_path / "full", point["t_end"])
    assert row["t_stop"] < 0.9 * point["t_end"] and math.isfinite(row["F_c"])
    assert row["F_end"] == pytest.approx(row["F_c"], rel=1e-12)
    S_full = full.events["S"].to_numpy(dtype=float)
    assert json.loads(row["sizes"]) == S_full.tolist() and len(S_full) > 5
    samples = full.samples
    assert row["F_c"] == depinning_force(
        samples["t"].values, samples["n_moving"].values, params.N, RAMP_START, point["r"]
    )
    assert not full.state.blocks()["stopped"].any()


def _power_law(tau: float, n: int, s_min: float, s_max: float, seed: int) -> np.ndarray:
    """Inverse CDF of p(S) ~ S^-tau on [s_min, s_max]."""
    u = np.random.default_rng(seed).uniform(size=n)
    a, b = s_min ** (1 - tau), s_max ** (1 - tau)
    return (a + u * (b - a)) ** (1 / (1 - tau))


def _synthetic() -> pd.DataFrame:
    rows = []
    # (a): w = 0 leaves stick-slip between 1.1 and 1.2, w = 0.2 between 1.0 and 1.1 (brackets that
    # touch: not moved), w = 0.4 between 0.9 and 1.0 (moved); tau = 1.5 + w exactly
    for w, last in ((0.0, 1.1), (0.2, 1.0), (0.4, 0.9)):
        for b in (0.9, 1.0, 1.1, 1.2):
            state = "stick-slip" if b <= last else "steady"
            m = 0.3 * (last + 0.05 - b) if b <= last else 0.0
            rows.append(
                {"part": "a", "analysis": "order", "w": w, "beta": b, "final_state": state, "order_parameter": m}
            )
        rows.append({"part": "a", "analysis": "sizes", "w": w, "beta": 0.4, "tau": 1.5 + w, "tau_err": 0.02})
    # (b): three seeds of sizes from p(S) ~ S^-1.11 on [1e-3, 10]; one seed never depins
    for s, Fc in enumerate((2.3, 2.5, math.nan)):
        S = _power_law(1.11, 1500, 1e-3, 10.0, seed=s)
        rows.append({"part": "b", "N": 256, "beta": 0.5, "F_c": Fc, "sizes": json.dumps(S.tolist())})
    # (c): strengthening, F0 = 2, beta = 1: pinned up to 2.2, then (F - F0) / beta
    for F in (2.1, 2.2, 2.3, 2.4):
        v = F - 2.0 if F >= 2.3 else 0.0
        rows.append({
            "part": "c", "friction": "strengthening", "F": F, "F0": 2.0, "beta": 1.0, "v_mean": v, "v_end": v,
            "moving_fraction": 1.0 if v else 0.1,
        })  # fmt: skip
    return pd.DataFrame(rows)


def test_findings_on_a_synthetic_table():
    table = _synthetic()
    a = {r["w"]: r for r in part_a(table)["per_w"]}
    assert (a[0.0]["beta_lo"], a[0.0]["beta_hi"]) == (1.1, 1.2) and (a[0.2]["beta_lo"], a[0.2]["beta_hi"]) == (1.0, 1.1)
    assert a[0.0]["m_step"] == pytest.approx(0.3 * 0.05) and a[0.2]["tau"] == pytest.approx(1.7)

    (fit,) = ramp_fits(table, bootstrap=20)
    assert (fit["seeds"], fit["events"], fit["pinned_runs"]) == (3, 4500, 1)
    assert fit["F_c"] == pytest.approx(2.4) and fit["F_c_sd"] == pytest.approx(math.sqrt(0.02))
    # the pooled sizes come from tau = 1.11: the fit finds it within a few of its errors
    assert abs(fit["tau"] - 1.11) < max(4 * fit["tau_err"], 0.03)

    (c,) = part_c(table)
    assert (c["F_lo"], c["F_hi"]) == (2.2, 2.3) and c["F_c"] == pytest.approx(2.25)
    assert c["jump_closed_form"] == pytest.approx(0.3) and c["closed_form_dev"] == pytest.approx(0.0, abs=1e-12)

    spec = study("disorder", "tiny")
    found = findings(Study("disorder", "tiny", {**spec.common, "bootstrap": 20}, spec.points), table)
    text = "\n".join(found["statements"])
    assert "moved by -0.1 from w = 0" in text and "moved by -0.2 from w = 0" in text
    assert "it moves beyond the brackets' widths at w = 0.4;" not in text
    assert "it moves beyond the brackets' widths at w = 0.4" in text
    assert "tau at beta = 0.4 changes by +1.00 +- 0.07 per unit w" in text
    assert "qEW's 1.111" in text and "no power law (F - F_c)^theta" in text


@pytest.fixture(scope="module")
def cluster():
    from dask.distributed import LocalCluster

    lc = LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0")
    yield lc.scheduler_address
    lc.close()


@pytest.mark.slow  # its parts run by default: points, findings, the ramp's stop
def test_tiny_disorder_study_end_to_end(tmp_path, cluster):
    spec = study("disorder", "tiny")
    first = run_study(spec, tmp_path, scheduler=cluster, progress=False)
    assert first["failed"] == 0 and first["run"] == len(spec.points)
    rows = first["rows"]
    assert {r["part"] for r in rows} == {"a", "b", "c"}
    ramp = [r for r in rows if r["part"] == "b"]
    # two disorder seeds draw two media: their events differ
    assert len({r["sizes"] for r in ramp}) == len(ramp) == 2
    assert all(r["n_events"] == len(json.loads(r["sizes"])) for r in ramp)
    assert [f["name"] for f in first["figures"]] == ["order_beta", "ramp_tau", "force_velocity"]
    assert (tmp_path / "disorder" / "index.html").read_text().count("qEW") >= 1
    second = run_study(spec, tmp_path, scheduler=cluster, progress=False)
    assert second["run"] == 0 and second["reused"] == len(spec.points)
    assert second["findings"]["statements"] == first["findings"]["statements"]


def test_the_study_has_its_own_help(capsys):
    from stickslip.cli import main

    with pytest.raises(SystemExit) as stop:
        main(["study", "disorder", "--help"])
    assert stop.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    for words in ("usage: stickslip study disorder", "qEW's 1.11", "87 runs", "299 runs", "ramp_tau", "index.html"):
        assert words in text, words
