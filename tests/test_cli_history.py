"""``--history`` on the command line (issue: a load history could be run from Python only):
velocity steps ``V:T,...`` and a lab record CSV give the run that ``run_chain`` gives with the
same :class:`~stickslip.lab.LoadHistory`; bad specs are the one-line error, exit 2."""

from __future__ import annotations

import json

import numpy as np
import pytest

from chain_helpers import run_cli
from stickslip import chain_params, run_chain
from stickslip.lab import LoadHistory


def _python(history, t_end):
    return run_chain(chain_params(N=5, drive="history", history=history), t_end, progress=False)


@pytest.mark.slow  # steps run twice, by the command and in Python (about 90 s, measured)
def test_steps_on_the_command_line_are_the_pythons_history(capsys):
    status, out, _ = run_cli(capsys, "chain", "--history", "1:20,0:10,2:20", "--N", "5", "--t-end", "50", "--json")
    assert status == 0
    shown = json.loads(out)
    assert shown["drive"] == "history"
    expected = _python(LoadHistory.steps([1.0, 0.0, 2.0], [20.0, 10.0, 20.0]), 50.0)
    assert shown["state_sha256"] == expected.summary["state_sha256"]


def test_a_csv_record_is_the_same_table(capsys, tmp_path):
    # positions at the breakpoints of 1:20, 0:10, 2:20 (0, 20, 20, 60): the steps' own table
    path = tmp_path / "record.csv"
    path.write_text("time,load_point\n0,0\n20,20\n30,20\n50,60\n")
    status, out, _ = run_cli(capsys, "chain", "--history", str(path), "--N", "5", "--t-end", "50", "--json")
    assert status == 0
    table = LoadHistory.table(np.array([0.0, 20.0, 30.0, 50.0]), np.array([0.0, 20.0, 20.0, 60.0]))
    assert json.loads(out)["state_sha256"] == _python(table, 50.0).summary["state_sha256"]


@pytest.mark.parametrize(
    ("argv", "names"),
    [
        (["--history", "1:20,x:3"], ["--history", "V:T"]),
        (["--history", "1:20:3"], ["--history", "each step is V:T"]),
        (["--history", "1:0"], ["--history", "durations must be > 0"]),
        # a value that starts with a minus is the value, named by its own check
        (["--history", "-1:20"], ["--history", "velocities must be >= 0"]),
        (["--history", "missing.csv"], ["--history", "no such file"]),
        (["--drive", "plate", "--history", "1:10"], ["--history is not a parameter"]),
        (["--drive", "history"], ["--drive history needs --history"]),
    ],
)
def test_bad_histories_are_one_line_errors(capsys, tmp_path, monkeypatch, argv, names):
    monkeypatch.chdir(tmp_path)
    status, out, err = run_cli(capsys, "chain", *argv, "--N", "3", "--t-end", "10")
    assert status == 2 and out == "" and err.count("\n") == 1 and "Traceback" not in err, err
    assert all(name in err for name in names), err
