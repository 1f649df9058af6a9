"""The Python API is as careful as the commands (docs/limits.md, "The Python API"): what the
command refuses the API refuses with the same words (ParameterError, or TypeError for a wrong
type), and ``run_chain(out_dir=DIR)`` owns its folder as ``stickslip chain --out`` does."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import pytest

from chain_helpers import cli_env, run_cli
from stickslip.models.params import ParameterError
from stickslip.models.presets import chain_params
from stickslip.run.driver import run_chain
from stickslip.run.rundir import RunDirBusy

P = dict(N=4, V=0.01)


def _p(**kw):
    return chain_params("sakaguchi", **{**P, **kw})


# (case, call, error type, words); before, the first ran no step, the type errors were an
# AttributeError from deep inside, the parameters not read were accepted and ignored.
REFUSED = [
    ("t_end 0", lambda: run_chain(_p(), 0), ParameterError, "t_end must be > 0 (got 0)"),
    ("t_end -1", lambda: run_chain(_p(), -1.0), ParameterError, "t_end must be > 0"),
    ("t_end nan", lambda: run_chain(_p(), math.nan), ParameterError, "t_end must be a finite number > 0"),
    ("t_end inf", lambda: run_chain(_p(), math.inf), ParameterError, "t_end must be a finite number > 0"),
    ("params a string", lambda: run_chain("chain", 10.0), TypeError, "params must be ChainParams"),
    ("params None", lambda: run_chain(None, 10.0), TypeError, "params must be ChainParams"),
    ("params a dict", lambda: run_chain({"N": 4}, 10.0), TypeError, "params must be ChainParams"),
    (
        "beta of Carlson-Langer",
        lambda: chain_params("carlson-langer", beta=0.3),
        ParameterError,
        "beta is not a parameter of this model (carlson-langer",
    ),
    ("D of the train model", lambda: chain_params("train", D=3.0), ParameterError, "D is not a parameter"),
    ("sigma of eq. (4)", lambda: chain_params("sakaguchi", sigma=0.5), ParameterError, "sigma is not a parameter"),
    ("l of eq. (4)", lambda: chain_params("sakaguchi", l=3.0), ParameterError, "l and nu are Carlson-Langer's"),
    ("model a number", lambda: chain_params(42), ParameterError, "model must be a preset's name"),
    ("model unknown", lambda: chain_params("nosuch"), ParameterError, "model must be one of"),
    ("start unknown", lambda: run_chain(_p(), 10.0, start="nowhere"), ParameterError, "start must be one of"),
    ("start a number", lambda: run_chain(_p(), 10.0, start=42), ParameterError, "start must be one of"),
    (
        "perturbation 1e308",
        lambda: run_chain(_p(), 10.0, start="steady", perturbation=1e308),
        ParameterError,
        "perturbation must be >= 0 and <= 1e+300",
    ),
]


@pytest.mark.parametrize("case, call, error, words", REFUSED, ids=[c[0] for c in REFUSED])
def test_api_refuses_in_one_line(case, call, error, words):
    with pytest.raises(error) as info:
        call()
    assert words in str(info.value), str(info.value)
    assert "\n" not in str(info.value)


def test_api_and_command_say_the_same(capsys):
    """The API's refusal of a parameter the model does not read is the command's, less the '--'."""
    with pytest.raises(ParameterError) as info:
        chain_params("carlson-langer", beta=0.3)
    status, out, err = run_cli(capsys, "chain", "--model", "carlson-langer", "--beta", "0.3", "--t-end", "10")
    assert status == 2 and out == ""
    assert err.strip() == f"stickslip chain: error: --{info.value}"


def test_t_end_before_the_start_state_is_refused():
    first = run_chain(_p(), 50.0)
    with pytest.raises(ParameterError, match="t_end must be after the start state's time 50"):
        run_chain(_p(), 50.0, start=first.state)
    with pytest.raises(ParameterError, match="t_end must be after the start state's time 50"):
        run_chain(_p(), 20.0, start=first.state)
    assert run_chain(_p(), 60.0, start=first.state).state.step == 12000


def _tree(path):
    return sorted(str(p.relative_to(path)) for p in path.rglob("*"))


def _foreign(d):
    d.mkdir()
    (d / "notes.txt").write_text("mine")


def _finished(d):
    run_chain(_p(beta=0.5), 20.0, out_dir=d)


def _checkpoint(d):
    run_chain(_p(), 20.0, out_dir=d, keep_checkpoint=True)
    (d / "run.json").unlink()


def _a_file(d):
    d.write_text("")


# (case, prepare the folder, words); before, each was written into (a finished run of other
# parameters replaced, results beside the user's notes).
OUT_DIRS = [
    ("the user's notes", _foreign, "holds files that a chain run does not write (notes.txt)"),
    ("a finished run of other parameters", _finished, "already holds a finished run"),
    ("a run with a checkpoint", _checkpoint, "already holds a run; continue it with resume_chain"),
    ("a file", _a_file, "is not a directory"),
]


@pytest.mark.parametrize("case, prepare, words", OUT_DIRS, ids=[c[0] for c in OUT_DIRS])
def test_run_chain_owns_its_folder(case, prepare, words, tmp_path):
    d = tmp_path / "out"
    prepare(d)
    before = {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}
    with pytest.raises(ParameterError) as info:
        run_chain(_p(), 30.0, out_dir=d)
    assert words in str(info.value) and "\n" not in str(info.value)
    assert {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()} == before


def _hold(d):
    """A process holding the lock of folder ``d`` (as a running command does), once it says so."""
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import sys, time\n"
            "from stickslip.run.rundir import owned_run_dir\n"
            f"with owned_run_dir({str(d)!r}):\n"
            "    print('held', flush=True)\n"
            "    time.sleep(60)\n",
        ],
        stdout=subprocess.PIPE,
        text=True,
        env=cli_env(),
    )
    assert holder.stdout.readline().strip() == "held"
    return holder


def test_run_chain_locks_its_folder(tmp_path, monkeypatch):
    """A folder another process holds is refused at once (the lock is tried, never waited for),
    naming the holder; a free one gets a run id and no lock is left behind."""
    from chain_helpers import record_lock_tries

    tries = record_lock_tries(monkeypatch)
    d = tmp_path / "held"
    holder = _hold(d)
    try:
        with pytest.raises(RunDirBusy, match=f"pid {holder.pid}"):
            run_chain(_p(), 30.0, out_dir=d)
        assert tries == [0], "the lock is tried once, without waiting"
    finally:
        holder.kill()
        holder.wait()
    free = tmp_path / "free"
    run = run_chain(_p(), 30.0, out_dir=free)
    names = {p.name for p in free.iterdir()}
    assert {"run.json", "state.nc", ".run_id"} <= names and not names & {".lock", ".lock.json"}
    assert json.loads((free / "run.json").read_text())["summary"]["state_sha256"] == run.summary["state_sha256"]


def test_resume_chain_locks_its_folder(tmp_path):
    """resume_chain(DIR) holds DIR's lock as chain --resume does: refused while another process
    holds it (before: two writers in one folder), and it finishes the run once free."""
    from stickslip.run.driver import resume_chain

    d = tmp_path / "run"
    run_chain(_p(), 20.0, out_dir=d, keep_checkpoint=True)
    holder = _hold(d)
    try:
        with pytest.raises(RunDirBusy, match=f"pid {holder.pid}"):
            resume_chain(d, t_end=40.0)
    finally:
        holder.kill()
        holder.wait()
    assert resume_chain(d, t_end=40.0).state.step == 8000
    assert not {p.name for p in d.iterdir()} & {".lock", ".lock.json"}
