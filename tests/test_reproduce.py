"""`stickslip reproduce`: spec hashing and reuse, the report's rows and figures, the command line.

The whole pipeline runs once per module on the tiny spec set (``--tiny``) (chains of N = 19, a
coarse hysteresis sweep) on a local Dask cluster of two workers: about 15 s.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from chain_helpers import error_lines, is_real_command
from stickslip.cli import main
from stickslip.experiments import reproduce as rp
from stickslip.experiments.cache import spec_key
from stickslip.experiments.studies import MODES, Study, figs1_4, figs5_8
from stickslip.experiments.study_run import run_study
from stickslip.experiments.sweep import DONE_FILE
from stickslip.io import read_json, read_table
from stickslip.outcome import point_settings

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
#: The figures of a reproduction: the paper's Figs. 1-8 and the two of section 2.
FIGURES = {"fig1", "fig2", "fig3", "stability_map", "hysteresis", "fig4", "fig5a", "fig5b", "fig6", "fig7", "fig8"}
#: The experiments of section 2 and Fig. 4, in the order they run.
EXPERIMENTS = ["block", "slip-limit", "period-sweep", "stability-block", "hysteresis", "chain-modes"]


# ---------------------------------------------------------------------------------------------
# The paper's studies


def test_the_studies_of_every_mode():
    for mode in MODES:
        small = figs1_4.build(mode)
        assert small.name == "figs1-4" and small.mode == mode
        assert [p["experiment"] for p in small.points] == EXPERIMENTS
        names = [figs1_4.point_name(p) for p in small.points]
        assert len(set(names)) == len(names)
        chains = figs5_8.build(mode)
        assert chains.name == "figs5-8" and chains.dirname != small.dirname
    full = figs5_8.build("full")
    assert {p["N"] for p in full.points} == {399}
    assert full.common["t_end_by_N"] == {"399": 2e7}
    betas = sorted(p["beta"] for p in full.points)
    assert 0.2 in betas and 1.0 in betas and min(betas) <= 0.2 and max(betas) > 1.0
    assert sum(0.9 <= b <= 1.1 for b in betas) >= 5  # enough points around the transition
    quick = figs5_8.build("quick")
    assert {"N": 199, "beta": 1} in quick.points and {"N": 199, "beta": 0.2} in quick.points
    assert quick.common["t_end_by_N"] == {"99": 2e6, "199": 4e6}
    with pytest.raises(ValueError, match="mode"):
        rp.reproduce("never", "medium")


def test_an_experiments_folder_is_named_by_its_settings():
    block = figs1_4.build("quick").points[0]
    assert figs1_4.point_name(block) == f"block-{spec_key(block)}" and len(spec_key(block)) == 12
    assert figs1_4.point_name({**block, "t_end": 2001}) != figs1_4.point_name(block)
    assert figs1_4.point_name(figs1_4.build("tiny").points[0]) != figs1_4.point_name(block)


def test_chain_points_are_left_out_of_the_folder_key_but_not_the_spec():
    quick = figs5_8.build("quick")
    fewer = Study(quick.name, quick.mode, quick.common, quick.points[:2])
    assert fewer.dirname == quick.dirname and fewer.spec() != quick.spec()
    longer = Study(quick.name, quick.mode, {**quick.common, "t_end_by_N": {"99": 1e6, "199": 4e6}}, quick.points)
    assert longer.dirname != quick.dirname


# ---------------------------------------------------------------------------------------------
# Reuse of a single experiment


def _one(name, mode="tiny", **options):
    """The study of section 2 and Fig. 4 with only its experiment ``name`` (options changed)."""
    point = next(p for p in figs1_4.build(mode).points if p["experiment"] == name)
    if options:
        point = {**point, "options": {**point["options"], **options}}
    return Study("figs1-4", mode, {}, (point,)), point


def _done(out, spec, point):
    return out / "runs" / spec.dirname / "points" / figs1_4.point_name(point) / DONE_FILE


@pytest.mark.slow  # experiments run end to end (20-40 s each, measured)
def test_an_experiment_is_computed_once_and_reused(tmp_path):
    spec, point = _one("chain-modes")
    first = run_study(spec, tmp_path, n_workers=1, progress=False)
    done = _done(tmp_path, spec, point)
    stamp = done.stat().st_mtime_ns
    second = run_study(spec, tmp_path, n_workers=1, progress=False)
    assert (first["run"], first["reused"]) == (1, 0) and (second["run"], second["reused"]) == (0, 1)
    assert done.stat().st_mtime_ns == stamp
    assert second["rows"][0]["critical_beta"] == first["rows"][0]["critical_beta"]
    changed, other = _one("chain-modes", n_k=101)
    third = run_study(changed, tmp_path, n_workers=1, progress=False)
    assert third["run"] == 1 and _done(tmp_path, changed, other) != done
    assert done.stat().st_mtime_ns == stamp, "the other settings' result stays"
    assert run_study(spec, tmp_path, n_workers=1, progress=False)["reused"] == 1


@pytest.mark.slow  # experiments run end to end (20-40 s each, measured)
@pytest.mark.parametrize(
    "damage",
    [
        "summary edited",
        *(pytest.param(d, marks=pytest.mark.slow) for d in ("file changed", "file deleted", "no checksums")),
    ],
)
def test_a_damaged_result_is_run_again(tmp_path, damage):
    spec, point = _one("slip-limit")
    run_study(spec, tmp_path, n_workers=1, progress=False)
    path = _done(tmp_path, spec, point)
    record = read_json(path)
    summary = record["summary"]
    assert record["files"], "the record lists the files it stands for"
    rel = sorted(record["files"])[0]
    if damage == "summary edited":
        key = sorted(record["summary"])[0]
        record["summary"] = {**summary, key: 42}
        path.write_text(json.dumps(record))
    elif damage == "file changed":
        with open(path.parent / rel, "ab") as fh:
            fh.write(b" ")
    elif damage == "file deleted":
        (path.parent / rel).unlink()
    else:
        del record["files"], record["sha256"]
        path.write_text(json.dumps(record))
    again = run_study(spec, tmp_path, n_workers=1, progress=False)
    assert (again["run"], again["reused"], again["damaged"]) == (1, 0, 1)
    assert read_json(path)["summary"] == summary
    assert "damaged" in (tmp_path / "figs1-4" / "index.html").read_text()
    assert run_study(spec, tmp_path, n_workers=1, progress=False)["reused"] == 1


@pytest.mark.slow  # experiments run end to end (20-40 s each, measured)
def test_a_result_of_another_spec_in_the_same_directory_is_not_reused(tmp_path):
    spec, point = _one("slip-limit")
    run_study(spec, tmp_path, n_workers=1, progress=False)
    path = _done(tmp_path, spec, point)
    record = read_json(path)
    record["spec"]["version"] = "0.0.0-other"
    path.write_text(json.dumps(record))
    assert run_study(spec, tmp_path, n_workers=1, progress=False)["reused"] == 0


def test_chain_task_continues_from_a_checkpoint(tmp_path, monkeypatch):
    from stickslip.run import driver as chain

    spec = figs5_8.build("tiny")
    point = {**spec.common, "N": 19, "beta": 1.0}
    first = figs5_8.chain_point_task(point, tmp_path / "done")
    assert (tmp_path / "done" / "run.json").is_file()
    assert not (tmp_path / "done" / "checkpoint").exists(), "a finished point keeps no checkpoint"
    # A run killed while writing its results: the checkpoint is there, the results are not.
    params, t_end, options = point_settings(point)
    killed = tmp_path / "killed"  # a folder of its own: run_chain refuses one holding other files
    chain.run_chain(params, t_end, out_dir=killed, keep_checkpoint=True, **options)
    assert (killed / "checkpoint" / "state.npz").is_file()
    for name in ("run.json", "state.nc", "events.parquet"):
        (killed / name).unlink()

    def no_fresh_run(*a, **k):
        raise AssertionError("a run with a checkpoint must continue from it")

    monkeypatch.setattr(chain, "run_chain", no_fresh_run)
    again = figs5_8.chain_point_task(point, killed)
    assert again["state_sha256"] == first["state_sha256"]
    assert again["n_events"] == first["n_events"]
    assert (killed / "run.json").is_file()


# ---------------------------------------------------------------------------------------------
# The whole pipeline (the tiny spec set)


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("repro")
    import contextlib
    import io as _io

    buf = _io.StringIO()
    with contextlib.redirect_stdout(buf):
        status = main(["reproduce", "--tiny", "--out", str(out), "--workers", "2", "--no-progress", "--json"])
    assert status == 0
    return out, json.loads(buf.getvalue())


@pytest.mark.slow  # the tiny set (minutes on 2 cores); tests/test_report.py checks the report
def test_report_has_a_row_for_every_stated_number(tiny_run):
    out, printed = tiny_run
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
    # the tiny chains settle nothing
    assert all(r["agrees"] is None for r in rows[7:])
    assert printed["rows"] == rows
    html = (out / "report.html").read_text()
    for where, _ in MODEL_ROWS:
        assert where in html


@pytest.mark.slow  # the tiny set (minutes on 2 cores); tests/test_report.py checks the report
def test_every_figure_is_drawn_with_png_pdf_and_data(tiny_run):
    out, printed = tiny_run
    report = read_json(out / "report.json")
    assert not printed["figures_not_drawn"]
    assert "figures_not_drawn" not in report["meta"]
    images = {Path(f["image"]).stem for f in report["figures"]}
    assert images == FIGURES and len(report["figures"]) == len(FIGURES)
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


@pytest.mark.slow
def test_second_call_reuses_every_result_and_only_redraws(tiny_run, monkeypatch):
    out, _ = tiny_run

    def boom(*a, **k):
        raise AssertionError("a stored result was computed again")

    import stickslip.experiments.sweep

    monkeypatch.setattr(stickslip.experiments.sweep, "_client", boom)  # no point is sent to Dask
    before = read_json(out / "report.json")
    result = rp.reproduce(out, "tiny", progress=False)
    assert [s["study"] for s in result["studies"]] == ["figs1-4", "figs5-8"]
    assert all(s["reused"] == s["points"] and s["run"] == 0 for s in result["studies"])
    after = read_json(out / "report.json")
    assert [r["value"] for r in after["rows"]] == [r["value"] for r in before["rows"]]


@pytest.mark.slow  # the tiny set (minutes on 2 cores); tests/test_report.py checks the report
def test_chain_runs_of_the_tiny_set_are_on_disk_per_point(tiny_run):
    out, _ = tiny_run
    spec = figs5_8.build("tiny")
    points = out / "runs" / spec.dirname / "points"
    for p in spec.points:
        d = points / f"beta={p['beta']:g}_N={p['N']}"
        assert (d / "done.json").is_file() and (d / "run.json").is_file()
    table = read_table(points / "summary.parquet")
    assert set(zip(table["N"], table["beta"], strict=True)) == {(p["N"], p["beta"]) for p in spec.points}


@pytest.mark.slow  # the tiny set (minutes on 2 cores); tests/test_report.py checks the report
def test_each_study_of_the_paper_has_its_page(tiny_run):
    out, _ = tiny_run
    small = {"fig1", "fig2", "fig3", "stability_map", "hysteresis", "fig4"}
    for name, stems, rows in (("figs1-4", small, MODEL_ROWS[:7]), ("figs5-8", FIGURES - small, MODEL_ROWS[7:])):
        found = read_json(out / name / "study.json")
        assert [r["where"] for r in found["findings"]["rows"]] == [w for w, _ in rows], name
        assert {f["name"] for f in found["figures"]} == stems, name
        assert (out / name / "table.parquet").is_file()
        page = (out / name / "index.html").read_text()
        assert "stickslip reproduce --tiny --out DIR" in page and "The paper&#39;s stated numbers" in page


@pytest.mark.slow
def test_a_failed_chain_run_is_named_and_run_again(tiny_run, tmp_path):
    import shutil

    out = tmp_path / "repro"
    shutil.copytree(tiny_run[0], out)
    spec = figs5_8.build("tiny")
    point = out / "runs" / spec.dirname / "points" / "beta=1_N=19"
    shutil.rmtree(point)
    point.mkdir()
    (point / "state.nc").mkdir()  # where the run writes its final state: it fails
    with pytest.raises(rp.ReproduceError, match=r"1 run\(s\) failed \(figs5-8/beta=1_N=19: .*state.nc"):
        rp.reproduce(out, "tiny", n_workers=1, progress=False)
    assert (point / "error.json").is_file()
    (point / "state.nc").rmdir()
    result = rp.reproduce(out, "tiny", n_workers=1, progress=False)
    assert [(s["run"], s["reused"]) for s in result["studies"]] == [(0, 6), (1, 2)]
    assert (point / "done.json").is_file() and len(result["rows"]) == len(MODEL_ROWS)


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
    assert (
        "--quick" in text
        and "--full" in text
        and "--scheduler" in text
        and "--tiny" not in text
        and "--smoke" not in text
    )


@pytest.mark.slow  # the default run compares plot and catalog in tests/test_catalog.py
def test_plot_reproduce_and_catalog_give_the_same_tau_on_the_same_run(tiny_run, tmp_path, capsys):
    """One stationary window (analysis.stats.chain_runs.stationary_from) and one fit for all three."""
    out, _ = tiny_run
    spec = figs5_8.build("tiny")
    points = out / "runs" / spec.dirname / "points"
    a = figs5_8.DESIGN.load(spec, read_table(points / "summary.parquet"), points).analysis
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


@pytest.mark.slow  # experiments run end to end (20-40 s each, measured)
def test_a_study_of_the_paper_runs_alone_with_its_help(tmp_path, capsys):
    """`stickslip study figs1-4` runs the study of section 2 and Fig. 4 by itself, with the page
    `stickslip reproduce` writes for it; its --help says its grid, its cost and its outputs."""
    with pytest.raises(SystemExit) as exc:
        main(["study", "figs5-8", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert exc.value.code == 0 and "Grid: --quick" in text and "Outputs in DIR/figs5-8/" in text
    out = tmp_path / "studies"
    assert main(["study", "figs1-4", "--tiny", "--out", str(out), "--workers", "1", "--no-progress", "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["study"] == "figs1-4" and printed["points"] == len(EXPERIMENTS) and printed["failed"] == 0
    assert {Path(f).stem for f in printed["figures"]} == {"fig1", "fig2", "fig3", "stability_map", "hysteresis", "fig4"}
    found = read_json(out / "figs1-4" / "study.json")
    assert [r["where"] for r in found["findings"]["rows"]] == [w for w, _ in MODEL_ROWS[:7]]
