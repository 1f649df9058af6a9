"""The transition study's rung cache is verified (docs/limits.md, "Damaged cached rungs"): a rung
is replayed only if its record is as written and every file it needs is present with the
checksum recorded when it was written; otherwise it runs again, its row says why, and the rows
come back the same."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from stickslip.experiments.cache import damage, sealed
from stickslip.experiments.ladders import ladder_task
from stickslip.experiments.studies.transition import ladder_points

DAMAGED = 1  # a grid rung whose final state the next rung starts from


def _cfg():
    common, _ = ladder_points("tiny")
    return {**common, "N": 9, "direction": "up", "betas": [0.8, 2.0, 4.0], "cap_loads": 1.0}


@pytest.fixture(scope="module")
def ladder(tmp_path_factory):
    d = tmp_path_factory.mktemp("ladder") / "ladder"
    return d, ladder_task(_cfg(), d)["rows"]


def _rung(d, k=DAMAGED):
    return sorted((d / "rungs").iterdir())[k]


def _edit_record(change):
    def f(rung):
        rec = json.loads((rung / "rung.json").read_text())
        change(rec)
        (rung / "rung.json").write_text(json.dumps(rec))

    return f


def _truncate(name):
    def f(rung):
        data = (rung / name).read_bytes()
        (rung / name).write_bytes(data[: len(data) // 2])

    return f


def _other_state(rung):
    """Another rung's final state, a whole and valid state file: before, reused and it changed the table."""
    shutil.copy(_rung(rung.parent.parent, DAMAGED - 1) / "state.npz", rung / "state.npz")


def _other_state_recorded(rung):
    """Another state with its checksum put into the record, but the record not sealed again."""
    from stickslip.experiments.cache import file_sha256

    _other_state(rung)
    _edit_record(lambda r: r["files"].update({"state.npz": file_sha256(rung / "state.npz")}))(rung)


def _samples_changed(rung):
    with np.load(rung / "samples.npz") as z:
        arrays = {k: z[k] for k in z.files}
    arrays["L"] = arrays["L"] * 0.5
    np.savez(rung / "samples.npz", **arrays)


def _resealed_other_state(rung):
    """A record sealed again after its state was swapped: the files match their checksums, but the
    state is not the final state its row names."""
    from stickslip.experiments.cache import file_sha256

    _other_state(rung)
    rec = json.loads((rung / "rung.json").read_text())
    rec["files"]["state.npz"] = file_sha256(rung / "state.npz")
    (rung / "rung.json").write_text(json.dumps(sealed({k: v for k, v in rec.items() if k != "sha256"})))


# (case, damage to the rung's folder, words of the row's note)
DAMAGES = [
    ("state.npz another valid state", _other_state, "state.npz does not match its checksum"),
    ("state.npz truncated", _truncate("state.npz"), "state.npz does not match its checksum"),
    ("state.npz deleted", lambda r: (r / "state.npz").unlink(), "state.npz is missing"),
    ("state.npz swapped, its checksum too", _other_state_recorded, "changed after it was written"),
    ("state.npz swapped, record sealed again", _resealed_other_state, "not the final state its row records"),
    ("samples.npz deleted", lambda r: (r / "samples.npz").unlink(), "samples.npz is missing"),
    ("samples.npz truncated", _truncate("samples.npz"), "samples.npz does not match its checksum"),
    ("samples.npz changed", _samples_changed, "samples.npz does not match its checksum"),
    ("row edited", _edit_record(lambda r: r["row"].update(order_parameter=42.0)), "changed after it was written"),
    ("row's final hash edited", _edit_record(lambda r: r["row"].update(final_sha256="0" * 64)), "changed after"),
    ("record without checksums", _edit_record(lambda r: r.pop("files")), "records no checksums of its files"),
    ("record without its own checksum", _edit_record(lambda r: r.pop("sha256")), "no checksum of itself"),
    ("rung.json unreadable", lambda r: (r / "rung.json").write_text("{half"), "rung.json is unreadable"),
]


def _same(rows_a, rows_b):
    drop = ("wall_seconds", "note")
    return [{k: v for k, v in r.items() if k not in drop} for r in rows_a] == [
        {k: v for k, v in r.items() if k not in drop} for r in rows_b
    ]


@pytest.mark.parametrize("case, damage_rung, why", DAMAGES, ids=[d[0] for d in DAMAGES])
def test_damaged_rung_runs_again_and_says_why(case, damage_rung, why, ladder, tmp_path):
    base, rows = ladder
    d = tmp_path / "ladder"
    shutil.copytree(base, d)
    damage_rung(_rung(d))
    again = ladder_task(_cfg(), d)["rows"]
    assert _same(again, rows), "the rung run again gives the same row"
    notes = [r.get("note") for r in again]
    assert notes[DAMAGED] is not None and why in notes[DAMAGED], notes
    assert all(n is None for k, n in enumerate(notes) if k != DAMAGED), notes
    assert again[DAMAGED]["final_sha256"] == rows[DAMAGED]["final_sha256"]
    # the rung is whole again: the next call replays every rung, without a note
    third = ladder_task(_cfg(), d)["rows"]
    assert third == rows or _same(third, rows) and all("note" not in r for r in third)
    assert all("note" not in r for r in third)


def test_a_whole_ladder_replays_without_running(ladder, tmp_path):
    base, rows = ladder
    d = tmp_path / "ladder"
    shutil.copytree(base, d)
    stamps = {p: p.stat().st_mtime_ns for p in d.rglob("*") if p.is_file()}
    assert ladder_task(_cfg(), d)["rows"] == rows
    assert {p: p.stat().st_mtime_ns for p in stamps} == stamps


def test_an_edited_done_record_is_damage(tmp_path):
    """A study point's or a ladder's done.json is sealed: an edited summary (tau = 42, a row) is not
    reused."""
    (tmp_path / "a.txt").write_text("a")
    from stickslip.experiments.cache import file_digests

    record = sealed({"spec": {"x": 1}, "status": "ok", "summary": {"tau_int": 3.5, "rows": [{"m": 0.25}]}})
    record["files"] = file_digests(tmp_path)
    record = sealed({k: v for k, v in record.items() if k != "sha256"})
    assert damage(tmp_path, json.loads(json.dumps(record))) is None
    for change in (
        lambda r: r["summary"].update(tau_int=42),
        lambda r: r["summary"]["rows"][0].update(m=0.5),
        lambda r: r.update(status="failed"),
    ):
        edited = json.loads(json.dumps(record))
        change(edited)
        assert "changed after it was written" in damage(tmp_path, edited)


@pytest.fixture(scope="module")
def transition(tmp_path_factory):
    """A folder holding the tiny transition study, finished."""
    from stickslip.cli import main

    out = tmp_path_factory.mktemp("transition") / "out"
    assert main(["study", "transition", "--tiny", "--workers", "1", "--no-progress", "--out", str(out)]) == 0
    return out


def _rung_dir(out):
    return sorted(out.glob("runs/transition-*/points/*/rungs/*"))[0]


# (case, where the user's file goes); before, a file in a rung folder was accepted
FOREIGN = [
    ("a file in a rung folder", lambda out: _rung_dir(out) / "notes.txt"),
    ("a folder in a rung folder", lambda out: _rung_dir(out) / "mine" / "x.txt"),
    ("a file in a ladder folder", lambda out: _rung_dir(out).parent.parent / "notes.txt"),
    ("a file among the rungs", lambda out: _rung_dir(out).parent / "notes.txt"),
]


@pytest.mark.slow  # these read a tiny transition study run for them (about 35 s, measured)
@pytest.mark.parametrize("case, where", FOREIGN, ids=[c[0] for c in FOREIGN])
def test_a_foreign_file_in_a_ladder_is_refused(case, where, transition, tmp_path, capsys):
    from stickslip.cli import main

    out = tmp_path / "out"
    shutil.copytree(transition, out)
    path = where(out)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("mine")
    before = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
    capsys.readouterr()
    status = main(["study", "transition", "--tiny", "--workers", "1", "--no-progress", "--out", str(out)])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1 and "Traceback" not in err, err
    assert str(path.relative_to(out).parts[-1]) in err or "notes.txt" in err or "mine" in err, err
    assert {p: p.read_bytes() for p in out.rglob("*") if p.is_file()} == before


@pytest.mark.slow  # these read a tiny transition study run for them (about 35 s, measured)
def test_the_page_lists_a_rung_run_again(transition, tmp_path, capsys):
    """A damaged rung in a finished study: its ladder and the rung run again, and the page says so."""
    from stickslip.cli import main

    out = tmp_path / "out"
    shutil.copytree(transition, out)
    (_rung_dir(out) / "samples.npz").unlink()
    capsys.readouterr()
    assert main(["study", "transition", "--tiny", "--workers", "1", "--no-progress", "--out", str(out), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["damaged"] == 1 and data["findings"]["rungs_damaged"] == 1
    page = (out / "transition" / "index.html").read_text()
    assert "ran again because their files were damaged" in page and "samples.npz is missing" in page
