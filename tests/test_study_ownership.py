"""A study's folder holds only what its studies wrote: a file of the user's inside a point's
folder or its checkpoint is foreign (refused, kept by --overwrite), a checkpoint is removed
without the user's files in it, and a point stopped at its first write by a full disk does not
make the study refuse its own folder."""

from __future__ import annotations

import hashlib
import json

import pytest

from stickslip.experiments.studies import study
from stickslip.experiments.study_run import foreign_files, remove_study_files
from stickslip.models.presets import chain_params
from stickslip.run import run_chain


def _sha(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture
def folder(tmp_path):
    """A chaos study's folder as its points leave it: a finished point (done.json recording its
    files), a point with a checkpoint, and a point a full disk stopped at its point.json."""
    out = tmp_path / "out"
    spec = study("chaos", "tiny")
    runs = spec.runs_dir(out)
    (runs / "points").mkdir(parents=True)
    (runs / "study-spec.json").write_text("{}")
    done = runs / "points" / "done-point"
    (done / "parts").mkdir(parents=True)
    (done / "point.json").write_text("{}")
    (done / "flow.json").write_text('{"x": 1}')
    (done / "parts" / "decorrelation-state.json").write_text("{}")
    files = {rel: _sha(done / rel) for rel in ("flow.json", "parts/decorrelation-state.json")}
    (done / "done.json").write_text(json.dumps({"spec": {}, "summary": {}, "files": files}))
    running = runs / "points" / "running-point"
    (running / "checkpoint").mkdir(parents=True)
    (running / "point.json").write_text("{}")
    (running / "checkpoint" / "state.npz").write_bytes(b"x")
    (running / "checkpoint" / "part-000000.npz").write_bytes(b"x")
    (runs / "points" / "stopped-point").mkdir()  # mkdir done, point.json hit the full disk
    return out, spec


def test_the_studys_own_folder_is_not_foreign(folder):
    """Nor the folder of a point that a full disk stopped before its point.json: the study goes
    on there, without --overwrite (which would remove its finished points)."""
    out, _ = folder
    assert foreign_files(out) == []


def test_a_users_file_in_a_point_or_its_checkpoint_is_foreign(folder):
    out, _ = folder
    points = out / "runs" / study("chaos", "tiny").runs_dir(out).name / "points"
    (points / "done-point" / "notes.txt").write_text("mine")
    (points / "done-point" / "parts" / "plot.py").write_text("mine")
    (points / "running-point" / "checkpoint" / "mine.txt").write_text("mine")
    rel = points.relative_to(out).as_posix()
    assert sorted(foreign_files(out)) == [
        f"{rel}/done-point/notes.txt",
        f"{rel}/done-point/parts/plot.py",
        f"{rel}/running-point/checkpoint/mine.txt",
    ]


def test_overwrite_removes_the_studys_files_and_keeps_the_users(folder):
    out, spec = folder
    points = spec.runs_dir(out) / "points"
    (points / "done-point" / "notes.txt").write_text("mine")
    (points / "running-point" / "checkpoint" / "mine.txt").write_text("mine")
    remove_study_files(out, spec)
    left = sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file())
    rel = points.relative_to(out).as_posix()
    assert left == [f"{rel}/done-point/notes.txt", f"{rel}/running-point/checkpoint/mine.txt"]


def test_a_finished_run_removes_its_checkpoint_but_not_a_users_file_in_it(tmp_path):
    out = tmp_path / "run"
    (out / "checkpoint").mkdir(parents=True)
    (out / "checkpoint" / "notes.txt").write_text("mine")
    run_chain(chain_params(N=4), 50.0, out_dir=out, checkpoint_interval=1e-9, progress=False)
    assert sorted(p.name for p in (out / "checkpoint").iterdir()) == ["notes.txt"]
    assert (out / "run.json").is_file()
