"""Ownership of a run directory by the commands that read it: `catalog` and `plot` take the run's
lock (a `chain --resume` writing into it and they exclude each other), `chain --overwrite` removes
the replaced run's catalogue and figures, and a stopped `catalog` leaves no half catalogue."""

from __future__ import annotations

import json
import shutil
import signal
import subprocess
import sys
import time

import pytest

from chain_helpers import cli_env
from stickslip.cli import main
from stickslip.run.ownership import CATALOG_FILES

FAST = ["--bootstrap", "0", "--gof-sims", "0"]
# a run of some 700 slips in a fraction of a second
RUN = ["chain", "--model", "two-blocks", "--t-end", "2e4", "--no-progress"]


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("own") / "run"
    assert main([*RUN, "--out", str(out)]) == 0
    return out


@pytest.fixture
def run(run_dir, tmp_path):
    copy = tmp_path / "run"
    shutil.copytree(run_dir, copy)
    return copy


def _tree(path):
    return sorted(str(p.relative_to(path)) for p in path.rglob("*"))


@pytest.mark.slow  # commands raced against a held or stopped run (15-50 s each, measured)
@pytest.mark.timeout(300)
@pytest.mark.parametrize("command", ["catalog", "plot"])
def test_a_reader_is_refused_while_a_run_holds_the_directory(command, run, capsys):
    code = (
        "import sys, time\nfrom stickslip.run.rundir import owned_run_dir\n"
        "with owned_run_dir(sys.argv[1], run_id=False):\n"
        "    print('held', flush=True)\n    time.sleep(600)\n"
    )
    proc = subprocess.Popen([sys.executable, "-c", code, str(run)], stdout=subprocess.PIPE, text=True, env=cli_env())
    try:
        assert proc.stdout.readline().strip() == "held"
        before = _tree(run)
        capsys.readouterr()
        assert main([command, str(run), *(FAST if command == "catalog" else [])]) == 2
        out, err = capsys.readouterr()
        assert out == "" and err.count("\n") == 1 and "in use by another run" in err and f"pid {proc.pid}" in err, err
        assert _tree(run) == before  # nothing read into it, nothing written
    finally:
        proc.kill()
        proc.wait()
    # the run finished: the reader goes ahead, and leaves the run's lock as it found it
    assert main([command, str(run), *(FAST if command == "catalog" else [])]) == 0
    assert not (run / ".lock").exists()


@pytest.mark.slow  # commands raced against a held or stopped run (15-50 s each, measured)
@pytest.mark.timeout(300)
def test_chain_overwrite_removes_the_replaced_runs_catalogue(run, capsys):
    assert main(["catalog", str(run), *FAST]) == 0
    assert (run / "catalog" / "catalog.json").is_file()
    argv = ["chain", "--N", "5", "--t-end", "10", "--out", str(run), "--no-progress", "--overwrite"]
    assert main(argv) == 0
    assert not (run / "catalog").exists()
    # a catalogue folder with a file of the user's: the catalogue goes, the user's file stays
    assert main([*RUN, "--out", str(run), "--overwrite"]) == 0
    assert main(["catalog", str(run), *FAST]) == 0
    (run / "catalog" / "notes.txt").write_text("mine")
    assert main(argv) == 0
    assert sorted(p.name for p in (run / "catalog").iterdir()) == ["notes.txt"]


@pytest.mark.slow  # commands raced against a held or stopped run (15-50 s each, measured)
def test_catalog_stopped_while_writing_leaves_the_folder_as_it_was(run, monkeypatch, capsys):
    """A stop (KeyboardInterrupt, as SIGINT raises) while the figures are drawn: no catalogue
    file appears; the next catalogue is whole and the staging folder is gone."""
    import stickslip.report.catalog_page as page

    calls = []
    real = page.save_figure

    def stop_at_second(fig, path, **kw):
        calls.append(path)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(fig, path, **kw)

    monkeypatch.setattr(page, "save_figure", stop_at_second)
    assert main(["catalog", str(run), *FAST]) == 130  # "stickslip: interrupted"
    assert len(calls) == 2
    left = [p.name for p in (run / "catalog").iterdir()] if (run / "catalog").exists() else []
    assert not set(left) & CATALOG_FILES, left
    monkeypatch.setattr(page, "save_figure", real)
    assert main(["catalog", str(run), *FAST]) == 0
    names = {p.name for p in (run / "catalog").iterdir()}
    assert {"catalog.json", "catalog.parquet", "index.html"} <= names and names <= CATALOG_FILES
    written = json.loads((run / "catalog" / "catalog.json").read_text())["outputs"]
    assert set(written) == names


@pytest.mark.timeout(300)
def test_catalog_killed_by_sigterm_leaves_no_half_catalogue(run):
    proc = subprocess.Popen(
        [sys.executable, "-m", "stickslip", "catalog", str(run), *FAST],
        env=cli_env(),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )
    try:
        deadline = time.monotonic() + 240
        while not list((run / "catalog").glob(".staging.*")) and proc.poll() is None:
            assert time.monotonic() < deadline
            time.sleep(0.02)
        proc.send_signal(signal.SIGTERM)
        proc.wait(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode != 0, "stopped before it finished"
    folder = run / "catalog"
    names = {p.name for p in folder.iterdir()} & CATALOG_FILES if folder.exists() else set()
    # the folder it made, emptied, is gone or holds no catalogue file: never a part of one
    assert not names, names
