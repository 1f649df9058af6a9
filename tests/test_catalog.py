"""`stickslip catalog RUN_DIR`: the catalogue of a chain run, its files, its page, and bad input."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from chain_helpers import error_lines
from stickslip.cli import main


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("catalog") / "run"
    argv = ["chain", "--N", "20", "--t-end", "1e5", "--profile-window", "20", "--profile-min-blocks", "10"]
    assert main([*argv, "--out", str(out), "--no-progress"]) == 0
    return out


def _json(capsys, argv) -> dict:
    capsys.readouterr()
    assert main([*argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.fixture(scope="module")
def catalog(run_dir, tmp_path_factory):
    out = tmp_path_factory.mktemp("catalog_out")
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        assert main(["catalog", str(run_dir), "--out", str(out), "--gof-sims", "20", "--json"]) == 0
    return out, json.loads(buf.getvalue())


def test_catalogue_rows_are_the_slips_of_the_stationary_window(run_dir, catalog):
    out, data = catalog
    events = pd.read_parquet(run_dir / "events.parquet")
    run = json.loads((run_dir / "run.json").read_text())
    t_from = run["summary"]["L_mean_from"]
    assert t_from == pytest.approx(0.5e5)  # the <L> window: second half of the run
    window = events[events["t_start"] >= t_from]
    table = pd.read_parquet(out / "catalog.parquet")
    assert pd.read_csv(out / "catalog.csv").shape == table.shape
    assert list(table["event"]) == list(window["event"]) and len(table) == data["n_events"]
    np.testing.assert_allclose(table["magnitude"], 2.0 / 3.0 * np.log10(window["S"].to_numpy()), rtol=1e-12)
    assert list(table["epicentre"]) == list(window["start_block"])
    assert list(table["extent"]) == list(window["n_blocks"])
    # the end-driven chain is spanned by the slips that reach its free end, block N = 20
    assert list(table["spans"]) == list(window["max_block"] == 20)
    assert data["n_spanning"] == int((window["max_block"] == 20).sum())


def test_every_part_is_in_the_json_and_the_page(catalog):
    out, data = catalog
    for key in ("sizes", "frequency_magnitude", "distributions", "goodness_of_fit", "recurrence", "moment_rate"):
        assert key in data, key
    fm = data["frequency_magnitude"]
    assert fm["b_value"]["b"] > 0 and fm["b_value"]["b_err_shi_bolt"] > 0
    # the doubly truncated Gutenberg-Richter law on the tau fit's range is tau's law
    assert fm["truncated_gr"]["b"] == pytest.approx(1.5 * (data["sizes"]["whole_range"]["tau"] - 1.0), abs=1e-6)
    assert {c["alternative"] for c in data["distributions"]["comparisons"]} == {
        "power_law_exp_cutoff",
        "lognormal",
        "exponential",
        "stretched_exponential",
    }
    assert 0.0 <= data["goodness_of_fit"]["p"] <= 1.0 and data["goodness_of_fit"]["sims"] == 20
    assert data["recurrence"]["all"]["best"] in ("exponential", "gamma", "weibull", "bpt")
    # the moment rate integrates to the slip its windows cover: at most S, most of it
    for e in data["moment_rate"]["events"]:
        assert 0.5 < e["covered_fraction"] <= 1.0 + 1e-9
    for name in ("catalog.json", "index.html", "moment_rate.parquet"):
        assert (out / name).is_file(), name
    for f in data["figures"]:
        assert [p.rsplit(".", 1)[1] for p in f["files"]] == ["png", "pdf"], f
        for p in f["files"]:
            assert (out / p).stat().st_size > 1000
    assert sorted(data["outputs"]) == sorted(str(out / p.name) for p in out.iterdir() if not p.name.startswith("."))
    html = (out / "index.html").read_text()
    assert html.count("data:image/png;base64,") == 4
    assert "b-value" in html and "Which distribution" in html
    assert json.loads((out / "catalog.json").read_text())["sizes"] == data["sizes"]


def test_a_fit_that_cannot_be_made_says_why(catalog):
    _, data = catalog
    # too few spanning slips for the recurrence of spanning slips is said, not raised
    spanning = data["recurrence"]["spanning"]
    if spanning["n"] < 10:
        assert spanning["fits"] == [] and "a fit needs at least 10" in spanning["reason"]


@pytest.mark.slow  # a run of its own for its catalogue (13 s, measured)
def test_without_profiles_the_moment_rate_says_why(tmp_path, capsys):
    run = tmp_path / "run"
    assert main(["chain", "--N", "10", "--t-end", "4e4", "--out", str(run), "--no-progress"]) == 0
    data = _json(capsys, ["catalog", str(run), "--gof-sims", "0", "--bootstrap", "0"])
    assert data["moment_rate"]["events"] == [] and "--profile-window" in data["moment_rate"]["reason"]
    assert data["goodness_of_fit"]["reason"].startswith("not computed")
    assert (run / "catalog" / "catalog.csv").is_file()
    skipped = {f["figure"]: f.get("skipped") for f in data["figures"]}
    assert "--profile-window" in skipped["moment_rate"]


@pytest.mark.slow  # a second catalogue and a plot of the run (25 s, measured)
def test_plot_and_catalog_give_the_same_tau(run_dir, catalog, tmp_path, capsys):
    _, data = catalog
    plot = _json(capsys, ["plot", str(run_dir), "--out", str(tmp_path / "fig")])
    sizes = next(r for r in plot["figures"] if r["figure"] == "sizes")["numbers"]
    whole = data["sizes"]["whole_range"]
    assert sizes["tau"] == whole["tau"] and sizes["tau_err"] == whole["tau_err"]
    assert sizes["s_min"] == whole["s_min"] and sizes["t_from"] == data["window"]["t_from"]
    if "tau" in data["sizes"]["below_spanning"]:
        assert sizes["tau_below_span"] == data["sizes"]["below_spanning"]["tau"]


@pytest.mark.parametrize(
    ("make", "expected"),
    [
        (lambda p: p, "is not a directory"),
        (lambda p: (p.mkdir(), p)[1], "is not a chain run directory"),
        (
            lambda p: (p.mkdir(), (p / "run.json").write_text("{}"), (p / "events.parquet").write_text("x"), p)[3],
            "state.nc is missing",
        ),
    ],
    ids=["missing", "empty", "damaged"],
)
def test_a_folder_that_is_not_a_run_gets_one_line(tmp_path, capsys, make, expected):
    target = make(tmp_path / "notarun")
    assert main(["catalog", str(target)]) == 2
    lines = error_lines(capsys.readouterr().err)
    assert len(lines) == 1 and lines[0].startswith("stickslip catalog: error:") and expected in lines[0], lines
    assert not (tmp_path / "notarun" / "catalog").exists()


def test_a_run_with_too_few_slips_gets_one_line(tmp_path, capsys):
    run = tmp_path / "short"
    assert main(["chain", "--N", "10", "--t-end", "2e3", "--out", str(run), "--no-progress"]) == 0
    capsys.readouterr()
    assert main(["catalog", str(run)]) == 2
    lines = error_lines(capsys.readouterr().err)
    assert len(lines) == 1 and "a catalogue's fits need at least 50" in lines[0], lines
    assert not (run / "catalog").exists()


@pytest.mark.parametrize("argv", [["--dm", "-1"], ["--gof-sims", "-2"], ["--seed", "-1"]])
def test_bad_options_get_one_line(run_dir, capsys, argv):
    assert main(["catalog", str(run_dir), *argv]) == 2
    assert len(error_lines(capsys.readouterr().err)) == 1


def test_magnitude_of_non_positive_sizes_is_nan():
    from stickslip.analysis.stats.magnitudes import magnitude

    assert np.isnan(magnitude([0.0, -1.0])).all() and magnitude([1000.0])[0] == pytest.approx(2.0)
    assert math.isclose(float(magnitude(10.0**1.5)), 1.0)
