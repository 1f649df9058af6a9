"""A study owns its output folder as a chain run owns its directory; a damaged cached point runs
again; nothing of a local cluster listens beyond 127.0.0.1 (docs/limits.md, "Faults")."""

from __future__ import annotations

import json
import shlex
import shutil
import subprocess
import sys
import threading

import pytest

from chain_helpers import cli_env
from stickslip.cli import main
from stickslip.experiments.studies import study
from stickslip.experiments.study_run import MANIFEST, run_study

TINY = study("phase-diagram", "tiny")
ARGV = ["study", "phase-diagram", "--tiny", "--workers", "1", "--no-progress", "--json"]


def _tree(path):
    return sorted(str(p.relative_to(path)) for p in path.rglob("*")) if path.exists() else None


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """A folder holding the tiny phase-diagram study, finished."""
    out = tmp_path_factory.mktemp("study") / "out"
    assert main([*ARGV, "--out", str(out)]) == 0
    return out


def _put(rel: str):
    def put(out):
        path = out / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("the user's own")

    return put


# (what is in the folder, extra options, what the one line names)
REFUSED = [
    ("notes.txt beside a fresh study", None, _put("notes.txt"), [], "notes.txt"),
    ("the user's table.csv where the page goes", None, _put("phase-diagram/table.csv"), [], "phase-diagram/table.csv"),
    ("the user's index.html", None, _put("phase-diagram/index.html"), [], "phase-diagram/index.html"),
    ("a file in the runs folder", None, _put("runs/mine.txt"), [], "runs/mine.txt"),
    (
        "a file beside a finished study's page",
        "finished",
        _put("phase-diagram/notes.txt"),
        [],
        "phase-diagram/notes.txt",
    ),
    (
        "a file among the points",
        "finished",
        _put(f"runs/{TINY.dirname}/points/mine.txt"),
        [],
        "points/mine.txt",
    ),
    (
        "--overwrite never writes over the user's table.csv",
        None,
        _put("phase-diagram/table.csv"),
        ["--overwrite"],
        "phase-diagram/table.csv",
    ),
]


@pytest.mark.parametrize("what, base, put, extra, named", REFUSED, ids=[c[0] for c in REFUSED])
def test_foreign_files_refused_before_the_first_point(
    what, base, put, extra, named, tmp_path, finished, capsys, monkeypatch
):
    from stickslip.experiments import sweep

    def no_points(*args, **kwargs):
        raise AssertionError("the points ran before the refusal")

    monkeypatch.setattr(sweep, "run_sweep", no_points)
    out = tmp_path / "out"
    if base == "finished":
        shutil.copytree(finished, out)
    else:
        out.mkdir()
    put(out)
    before = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
    capsys.readouterr()
    status = main([*ARGV, "--out", str(out), *extra])
    stdout, err = capsys.readouterr()
    assert status == 2 and stdout == "", err
    assert err.count("\n") == 1 and "Traceback" not in err and named in err, err
    assert {p: p.read_bytes() for p in out.rglob("*") if p.is_file()} == before, "nothing written, nothing removed"


@pytest.mark.slow
def test_overwrite_removes_only_the_studys_own_files(tmp_path, finished, capsys):
    out = tmp_path / "out"
    shutil.copytree(finished, out)
    (out / "notes.txt").write_text("mine")
    capsys.readouterr()
    assert main([*ARGV, "--out", str(out)]) == 2
    assert main([*ARGV, "--out", str(out), "--overwrite"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["run"] == len(TINY.points) and data["reused"] == 0, "the study's own files were replaced"
    assert (out / "notes.txt").read_text() == "mine"
    assert (out / "phase-diagram" / "table.csv").is_file() and (out / MANIFEST).is_file()


def test_a_study_run_again_reuses_its_own_folder(tmp_path, finished, capsys):
    out = tmp_path / "out"
    shutil.copytree(finished, out)
    capsys.readouterr()
    assert main([*ARGV, "--out", str(out)]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["run"] == 0 and data["reused"] == len(TINY.points) and data["damaged"] == 0


def test_second_study_into_the_same_folder_refused_at_once(tmp_path):
    """Two studies with the same --out: the second is refused at once, naming the first."""
    out = tmp_path / "out"
    code = (
        "import sys, time\nfrom stickslip.run.rundir import owned_run_dir\n"
        "with owned_run_dir(sys.argv[1], run_id=False):\n"
        "    print('held', flush=True)\n    time.sleep(600)\n"
    )
    holder = subprocess.Popen([sys.executable, "-c", code, str(out)], stdout=subprocess.PIPE, text=True, env=cli_env())
    try:
        assert holder.stdout.readline().strip() == "held"
        before = _tree(out)
        # refused at once: waiting for the holder (600 s) would meet the timeout, running points
        # would change the tree
        proc = subprocess.run(
            [sys.executable, "-m", "stickslip.cli", *ARGV, "--out", str(out)],
            capture_output=True,
            text=True,
            env=cli_env(),
            timeout=120,
        )
        assert proc.returncode == 2 and proc.stdout == "", proc.stderr
        assert proc.stderr.count("\n") == 1 and f"pid {holder.pid}" in proc.stderr, proc.stderr
        assert _tree(out) == before
    finally:
        holder.kill()
        holder.wait()


@pytest.mark.parametrize(
    "argv",
    [
        "study transition --tiny --scheduler tcp://127.0.0.1:1 --out o",
        "study transition --tiny --scheduler 127.0.0.1:70000 --out o",
        "sweep block --t-end 10 --out o --scheduler tcp://127.0.0.1:99999",
        "study transition --tiny --out afile",
    ],
)
def test_refused_study_writes_nothing(argv, tmp_path, monkeypatch, capsys):
    (tmp_path / "afile").write_text("")
    monkeypatch.chdir(tmp_path)
    before = _tree(tmp_path)
    try:
        status = main(shlex.split(argv))
    except SystemExit as exc:
        status = exc.code
    out, err = capsys.readouterr()
    assert status == 2 and out == "" and err.count("\n") == 1 and "Traceback" not in err, err
    assert _tree(tmp_path) == before


# ---------------------------------------------------------------------------------------------
# Damaged cached points run again


def _point(out):
    return sorted((out / "runs" / TINY.dirname / "points").glob("*/done.json"))[0].parent


def _edit_done(change):
    def damage(point):
        record = json.loads((point / "done.json").read_text())
        change(record)
        (point / "done.json").write_text(json.dumps(record))

    return damage


def _truncate(name):
    def damage(point):
        data = (point / name).read_bytes()
        (point / name).write_bytes(data[: len(data) // 2])

    return damage


DAMAGES = [
    ("summary missing", _edit_done(lambda r: r.pop("summary")), "summary is missing"),
    ("events.parquet deleted", lambda p: (p / "events.parquet").unlink(), "events.parquet is missing"),
    ("state.nc deleted", lambda p: (p / "state.nc").unlink(), "state.nc is missing"),
    ("state.nc truncated", _truncate("state.nc"), "state.nc does not match"),
    ("run.json changed", lambda p: (p / "run.json").write_text("{}"), "run.json does not match"),
    ("done.json unreadable", lambda p: (p / "done.json").write_text("{half"), "done.json is unreadable"),
    ("no checksums recorded", _edit_done(lambda r: r.pop("files")), "no checksums"),
    # before: an edited summary (tau = 42) was reused and went into the table
    ("summary edited", _edit_done(lambda r: r["summary"].update(tau_int=42)), "changed after it was written"),
    ("record without its own checksum", _edit_done(lambda r: r.pop("sha256")), "no checksum of itself"),
]


# each damaged point is run again (20-30 s, measured): -m slow; tests/test_rung_cache.py checks a
# damaged rung in the default run
_DEFAULT_DAMAGES: set[str] = set()


@pytest.mark.parametrize(
    "what, damage, why",
    [pytest.param(*d, id=d[0], marks=() if d[0] in _DEFAULT_DAMAGES else pytest.mark.slow) for d in DAMAGES],
)
def test_damaged_cached_point_runs_again(what, damage, why, tmp_path, finished):
    out = tmp_path / "out"
    shutil.copytree(finished, out)
    damage(_point(out))
    result = run_study(TINY, out, n_workers=1, progress=False)
    assert result["run"] == 1 and result["reused"] == len(TINY.points) - 1 and result["damaged"] == 1
    assert all(r["order_parameter"] is not None and r["status"] == "ok" for r in result["rows"])
    page = (out / "phase-diagram" / "index.html").read_text()
    assert "ran again because their files were damaged" in page and why in page
    again = run_study(TINY, out, n_workers=1, progress=False)
    assert again["run"] == 0 and again["damaged"] == 0, "the point run again is whole"


# ---------------------------------------------------------------------------------------------
# Nothing of a local cluster listens beyond the machine


def _listening(proc) -> set[tuple[str, int]]:
    import psutil

    found = set()
    for p in [proc, *proc.children(recursive=True)]:
        try:
            conns = p.net_connections(kind="inet")
        except (psutil.NoSuchProcess, psutil.AccessDenied):
            continue
        found |= {(c.laddr.ip, c.laddr.port) for c in conns if c.status == psutil.CONN_LISTEN}
    return found


@pytest.mark.slow  # a local Dask cluster started per case (10 s each, measured)
@pytest.mark.parametrize("dashboard", [False, True], ids=["default", "--dashboard"])
def test_local_sweep_listens_on_loopback_only(dashboard, tmp_path, capsys):
    import psutil

    from stickslip.experiments.sweep import demo_task, run_sweep

    done = threading.Event()

    def sweep():
        try:
            run_sweep(demo_task, [{"sleep": 4.0}], tmp_path / "s", n_workers=1, progress=False, dashboard=dashboard)
        finally:
            done.set()

    thread = threading.Thread(target=sweep)
    thread.start()
    seen: set[tuple[str, int]] = set()
    me = psutil.Process()
    while not done.wait(0.2):
        seen |= _listening(me)
    thread.join()
    assert seen, "the scheduler was seen listening"
    assert {ip for ip, _ in seen} <= {"127.0.0.1"}, seen
    err = capsys.readouterr().err
    if dashboard:
        assert "dashboard: http://127.0.0.1:" in err
    else:
        assert "dashboard" not in err


# ---------------------------------------------------------------------------------------------
# The transition study (run by continuation in beta) owns its folder the same way


@pytest.mark.slow  # a transition study run twice (about 40 s, measured)
def test_transition_study_owns_its_folder(tmp_path, capsys):
    argv = ["study", "transition", "--tiny", "--workers", "1", "--no-progress", "--json"]
    out = tmp_path / "out"
    _put("transition/table.csv")(out)
    assert main([*argv, "--out", str(out)]) == 2, "the user's table.csv where the page goes is refused"
    assert "transition/table.csv" in capsys.readouterr().err
    assert (out / "transition" / "table.csv").read_text() == "the user's own"
    (out / "transition" / "table.csv").unlink()
    assert main([*argv, "--out", str(out)]) == 0
    first = json.loads(capsys.readouterr().out)
    assert first["run"] == 3 and first["reused"] == 0
    assert main([*argv, "--out", str(out)]) == 0, "its own page, manifest and ladders are not foreign"
    again = json.loads(capsys.readouterr().out)
    assert again["run"] == 0 and again["reused"] == 3
    assert main([*argv, "--out", str(out), "--overwrite"]) == 0
    assert json.loads(capsys.readouterr().out)["run"] == 3, "--overwrite ran its ladders again"
