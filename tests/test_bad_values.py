"""Values that overflowed into a traceback, and options that were ignored or refused late, are
refused in one line before anything runs (docs/limits.md, "Bad inputs accepted before")."""

from __future__ import annotations

import shlex

import pytest

from chain_helpers import error_lines
from stickslip.cli import main

LOCATED = "lyapunov --switches located --N 5 --t-end 200 --finite-size"

# (command, words of the one line); before, each was a traceback (OverflowError)
OVERFLOWS = [
    ("chain --start steady --perturbation 1e308 --N 5 --t-end 10", "perturbation must be >= 0 and <= 1e+300"),
    ("chain --start rest --perturbation 1e308 --N 5 --t-end 10", "perturbation must be >= 0 and <= 1e+300"),
    ("chain --start steady --perturbation 1e308 --N 5 --t-end 10 --out o", "perturbation"),
    ("lyapunov --start steady --perturbation 1e308 --N 5", "perturbation must be >= 0 and <= 1e+300"),
    (f"{LOCATED} --check 1e300", "check must be >= 0.005 and <= 200"),
    (f"{LOCATED} --delta-min 1e-300 --delta-max 1e300", "delta_max / delta_min must be <= ratio^199"),
]


def _tree(path):
    return sorted(str(p.relative_to(path)) for p in path.rglob("*"))


def _refused(argv, words, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    before = _tree(tmp_path)
    try:
        status = main(shlex.split(argv))
    except SystemExit as exc:
        status = exc.code
    out, err = capsys.readouterr()
    assert status == 2, err
    assert out == "" and "Traceback" not in err, err
    assert len(error_lines(err)) == 1, err
    assert words in err, err
    assert _tree(tmp_path) == before


@pytest.mark.parametrize("argv, words", OVERFLOWS, ids=[c for c, _ in OVERFLOWS])
def test_huge_values_are_one_line(argv, words, tmp_path, monkeypatch, capsys):
    _refused(argv, words, tmp_path, monkeypatch, capsys)
