"""`stickslip reproduce`: spec hashing and reuse, the report's rows and figures, the command line.

The whole pipeline runs once per module on the tiny ``smoke`` spec set (chains of N = 19, a
coarse hysteresis sweep) on a local Dask cluster of two workers: about 15 s.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from chain_helpers import error_lines, is_real_command
from stickslip.cli import main
from stickslip.experiments import reproduce as rp
from stickslip.experiments import specs as ex
from stickslip.experiments.sweep import DONE_FILE
from stickslip.io import read_json, read_table

#: docs/model.md, last table: (where, a word of the quantity) for every number the paper states;
#: eq. 3 states two numbers and gets two rows.
MODEL_ROWS = [
    ("sec. 2", "Hopf point"),
    ("sec. 2", "stable for all V"),
    ("sec. 2", "inverse transition"),
    ("eq. 3", "duration"),
    ("eq. 3", "force"),
    ("Fig. 3", "period"),
    ("Fig. 4", "long-wave"),
    ("sec. 3", "final state"),
    ("Fig. 5(a)", "snapshot"),
    ("Fig. 5(b)", "<L>"),
    ("Fig. 6", "front speed"),
    ("Fig. 7", "beta = 1"),
    ("Fig. 8", "beta = 0.2"),
]


# ---------------------------------------------------------------------------------------------
# Specs


def test_spec_key_depends_on_what_the_result_depends_on_only():
    e = ex.Experiment("a", "chain_modes", {"K": 10.0, "D": 5.0}, options={"betas": [0.5, 1.0]})
    assert (
        e.key()
        == ex.Experiment(
            "b", "chain_modes", {"D": 5, "K": 10}, options={"betas": (0.5, 1.0)}, figures=("fig4",), note="label"
        ).key()
    )
    assert len(e.key()) == 12 and e.dirname == f"a-{e.key()}"
    assert e.key() != ex.Experiment("a", "chain_modes", {"K": 10.0, "D": 4.0}, options={"betas": [0.5, 1.0]}).key()
    assert e.key() != ex.Experiment("a", "chain_modes", {"K": 10.0, "D": 5.0}, options={"betas": [0.5]}).key()
    assert (
        e.key()
        != ex.Experiment("a", "chain_modes", {"K": 10.0, "D": 5.0}, t_end=1.0, options={"betas": [0.5, 1.0]}).key()
    )
    assert e.key() != ex.Experiment("a", "block_run", {"K": 10.0, "D": 5.0}, options={"betas": [0.5, 1.0]}).key()


def test_spec_key_includes_the_package_version(monkeypatch):
    e = ex.Experiment("a", "slip_limit", {"K": 10.0})
    before = e.key()
    monkeypatch.setattr(ex, "__version__", "999.0")
    assert e.key() != before and e.spec()["version"] == "999.0"


def test_chain_points_are_left_out_of_the_directory_key_but_not_the_spec():
    e1 = ex.Experiment("c", "chain_runs", {"K": 10.0}, options={"points": [{"N": 9, "beta": 1.0}], "x": 1})
    e2 = ex.Experiment(
        "c", "chain_runs", {"K": 10.0}, options={"points": [{"N": 9, "beta": 1.0}, {"N": 9, "beta": 0.5}], "x": 1}
    )
    assert e1.key() == e2.key()
    assert e1.spec() != e2.spec()


def test_spec_sets_of_every_mode():
    for mode in ex.MODES:
        specs = ex.experiments(mode)
        names = [e.name for e in specs]
        assert len(set(names)) == len(names)
        assert {e.kind for e in specs} == set(ex.KINDS)
        drawn = {stem for e in specs for stem in e.figures}
        assert drawn == {stem for stem, _ in ex.FIGURES}
    full = ex.experiment("full", "chain-runs")
    assert {p["N"] for p in full.options["points"]} == {399}
    assert full.options["t_end_by_N"] == {"399": 2e7}
    betas = sorted(p["beta"] for p in full.options["points"])
    assert 0.2 in betas and 1.0 in betas and min(betas) <= 0.2 and max(betas) > 1.0
    assert sum(0.9 <= b <= 1.1 for b in betas) >= 5  # enough points around the transition
    quick = ex.experiment("quick", "chain-runs")
    assert {"N": 199, "beta": 1.0} in quick.options["points"] and {"N": 199, "beta": 0.2} in quick.options["points"]
    with pytest.raises(ValueError, match="mode"):
        ex.experiments("medium")
    with pytest.raises(ValueError, match="kind"):
        ex.Experiment("x", "nonsense")


# ---------------------------------------------------------------------------------------------
# Reuse of a single experiment


def test_run_experiment_computes_once_and_reuses(tmp_path):
    exp = ex.experiment("smoke", "chain-modes")
    first = rp.run_experiment(exp, tmp_path, n_workers=1)
    done = tmp_path / exp.dirname / DONE_FILE
    stamp = done.stat().st_mtime_ns
    second = rp.run_experiment(exp, tmp_path, n_workers=1)
    assert not first.reused and second.reused and done.stat().st_mtime_ns == stamp
    assert second.summary == first.summary
    changed = ex.Experiment(exp.name, exp.kind, exp.params, options={**exp.options, "n_k": 101})
    third = rp.run_experiment(changed, tmp_path, n_workers=1)
    assert not third.reused and third.run_dir != first.run_dir
    assert done.stat().st_mtime_ns == stamp


@pytest.mark.parametrize("damage", ["summary edited", "file changed", "file deleted", "no checksums"])
def test_a_damaged_result_is_run_again(tmp_path, damage):
    exp = ex.experiment("smoke", "slip-limit")
    first = rp.run_experiment(exp, tmp_path)
    path = tmp_path / exp.dirname / DONE_FILE
    record = read_json(path)
    assert record["files"], "the record lists the files it stands for"
    rel = sorted(record["files"])[0]
    if damage == "summary edited":
        key = sorted(record["summary"])[0]
        record["summary"][key] = 42
        path.write_text(json.dumps(record))
    elif damage == "file changed":
        with open(tmp_path / exp.dirname / rel, "ab") as fh:
            fh.write(b" ")
    elif damage == "file deleted":
        (tmp_path / exp.dirname / rel).unlink()
    else:
        del record["files"], record["sha256"]
        path.write_text(json.dumps(record))
    lines = []
    again = rp.run_experiment(exp, tmp_path, log=lines.append)
    assert not again.reused and again.summary == first.summary
    assert any("not reused" in line for line in lines)
    assert rp.run_experiment(exp, tmp_path).reused


def test_a_result_of_another_spec_in_the_same_directory_is_not_reused(tmp_path):
    exp = ex.experiment("smoke", "slip-limit")
    rp.run_experiment(exp, tmp_path)
    record = read_json(tmp_path / exp.dirname / DONE_FILE)
    record["spec"]["version"] = "0.0.0-other"
    (tmp_path / exp.dirname / DONE_FILE).write_text(json.dumps(record))
    assert not rp.run_experiment(exp, tmp_path).reused


def test_chain_task_continues_from_a_checkpoint(tmp_path, monkeypatch):
    from stickslip.run import driver as chain

    exp = ex.experiment("smoke", "chain-runs")
    point = {**rp._chain_common(exp), "N": 19, "beta": 1.0}
    first = rp.chain_point_task(point, tmp_path / "done")
    assert (tmp_path / "done" / "run.json").is_file()
    assert not (tmp_path / "done" / "checkpoint").exists(), "a finished point keeps no checkpoint"
    # A run killed while writing its results: the checkpoint is there, the results are not.
    params, t_end, options = rp._point_settings(point)
    killed = tmp_path / "killed"  # a folder of its own: run_chain refuses one holding other files
    chain.run_chain(params, t_end, out_dir=killed, keep_checkpoint=True, **options)
    assert (killed / "checkpoint" / "state.npz").is_file()
    for name in ("run.json", "state.nc", "events.parquet"):
        (killed / name).unlink()

    def no_fresh_run(*a, **k):
        raise AssertionError("a run with a checkpoint must continue from it")

    monkeypatch.setattr(chain, "run_chain", no_fresh_run)
    again = rp.chain_point_task(point, killed)
    assert again["state_sha256"] == first["state_sha256"]
    assert again["n_events"] == first["n_events"]
    assert (killed / "run.json").is_file()


# ---------------------------------------------------------------------------------------------
# The whole pipeline (smoke spec set)


@pytest.fixture(scope="module")
def smoke(tmp_path_factory):
    out = tmp_path_factory.mktemp("repro")
    import contextlib
    import io as _io

    buf = _io.StringIO()
    with contextlib.redirect_stdout(buf):
        status = main(["reproduce", "--smoke", "--out", str(out), "--workers", "2", "--no-progress", "--json"])
    assert status == 0
    return out, json.loads(buf.getvalue())


def test_report_has_a_row_for_every_stated_number(smoke):
    out, printed = smoke
    report = read_json(out / "report.json")
    rows = report["rows"]
    assert len(rows) == len(MODEL_ROWS)
    for (where, word), row in zip(MODEL_ROWS, rows, strict=False):
        assert row["where"] == where and word in row["quantity"], (where, word, row)
        assert row["paper"] and row["value"] is not None
        assert is_real_command(row["command"]), row["command"]
        agreement = row["agreement"]
        assert agreement.startswith(("yes (", "no (", "n/a ("))
        if agreement.startswith("n/a"):
            assert row["na_reason"]
        else:
            assert row["tolerance"]
    # section 2, eq. 3, Fig. 4: the same numbers in every mode
    by = {(r["where"], r["quantity"].split(",")[0]): r for r in rows}
    assert by[("sec. 2", "Hopf point of steady sliding")]["agrees"] is True
    assert by[("Fig. 4", "long-wave instability of steady sliding of the chain")]["agrees"] is True
    # the smoke chains settle nothing
    assert all(r["agrees"] is None for r in rows[7:])
    assert printed["rows"] == rows
    html = (out / "report.html").read_text()
    for where, _ in MODEL_ROWS:
        assert where in html


def test_every_figure_is_drawn_with_png_pdf_and_data(smoke):
    out, printed = smoke
    report = read_json(out / "report.json")
    assert not printed["figures_not_drawn"]
    assert "figures_not_drawn" not in report["meta"]
    images = {Path(f["image"]).stem for f in report["figures"]}
    assert images == {stem for stem, _ in ex.FIGURES}
    for f in report["figures"]:
        assert (out / f["image"]).stat().st_size > 1000
        assert (out / f["pdf"]).stat().st_size > 1000
        assert f["data"], f["figure"]
        for d in f["data"]:
            assert (out / d).is_file(), d
        assert is_real_command(f["command"]), f["command"]
        # The command under a figure is one that draws it.
        assert "--out DIR" in f["command"], f["figure"]
        if f["command"].startswith("stickslip chain "):
            assert "&& stickslip plot DIR" in f["command"], f["figure"]
    html = (out / "report.html").read_text()
    assert html.count("data:image/png;base64,") == len(report["figures"])


def test_second_call_reuses_every_result_and_only_redraws(smoke, monkeypatch):
    out, _ = smoke

    def boom(*a, **k):
        raise AssertionError("a stored result was computed again")

    for kind, runner in list(rp._RUNNERS.items()):
        monkeypatch.setitem(rp._RUNNERS, kind, rp._Runner(boom, runner.load))
    import stickslip.experiments.sweep

    monkeypatch.setattr(stickslip.experiments.sweep, "_compute", boom)  # no point is sent to Dask
    before = read_json(out / "report.json")
    result = rp.reproduce(out, "smoke", progress=False)
    assert all(e["reused"] for e in result["experiments"])
    after = read_json(out / "report.json")
    assert [r["value"] for r in after["rows"]] == [r["value"] for r in before["rows"]]


def test_chain_runs_of_the_smoke_set_are_on_disk_per_point(smoke):
    out, _ = smoke
    exp = ex.experiment("smoke", "chain-runs")
    points = out / "runs" / exp.dirname / "points"
    for p in exp.options["points"]:
        d = points / f"beta={p['beta']:g}_N={p['N']}"
        assert (d / "done.json").is_file() and (d / "run.json").is_file()
    table = read_table(points / "summary.parquet")
    assert set(zip(table["N"], table["beta"], strict=True)) == {(p["N"], p["beta"]) for p in exp.options["points"]}


# ---------------------------------------------------------------------------------------------
# Command line


@pytest.mark.parametrize(
    "argv",
    [
        ["--workers", "0"],
        ["--workers", "two"],
        ["--quick", "--full"],
        ["--scheduler", " "],
        ["--fast"],
    ],
)
def test_bad_input_exits_2_and_writes_nothing(argv, tmp_path, capsys):
    out = tmp_path / "never"
    try:
        status = main(["reproduce", "--out", str(out), *argv])
    except SystemExit as exc:
        status = exc.code
    assert status == 2
    err = error_lines(capsys.readouterr().err)
    assert len(err) == 1 and "error" in err[0]
    assert not out.exists()


def test_help_lists_the_modes(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["reproduce", "--help"])
    assert exc.value.code == 0
    text = capsys.readouterr().out
    assert "--quick" in text and "--full" in text and "--scheduler" in text and "--smoke" not in text


def test_plot_reproduce_and_catalog_give_the_same_tau_on_the_same_run(smoke, tmp_path, capsys):
    """One stationary window (analysis.chain_runs.stationary_from) and one fit for all three."""
    from stickslip.analysis.chain_runs import chain_analysis

    out, _ = smoke
    exp = ex.experiment("smoke", "chain-runs")
    a = chain_analysis(rp.run_experiment(exp, out / "runs"))
    points = out / "runs" / exp.dirname / "points"
    for beta, key, reading in ((1.0, "sizes1", "whole_range"), (0.2, "sizes02", "below_spanning")):
        run_dir = points / f"beta={beta:g}_N={a['figure_N']}"
        tau = a[key]["fit"].tau
        capsys.readouterr()
        assert main(["plot", str(run_dir), "--out", str(tmp_path / f"plot{beta:g}"), "--json"]) == 0
        plotted = next(r for r in json.loads(capsys.readouterr().out)["figures"] if r["figure"] == "sizes")
        assert (
            main(["catalog", str(run_dir), "--out", str(tmp_path / f"cat{beta:g}"), "--gof-sims", "0", "--json"]) == 0
        )
        catalog = json.loads(capsys.readouterr().out)
        assert catalog["window"]["t_from"] == plotted["numbers"]["t_from"] == a["t_from"]
        assert catalog["sizes"][reading]["tau"] == tau
        assert plotted["numbers"]["tau" if reading == "whole_range" else "tau_below_span"] == tau
