"""`.ci/run` fails when any step of the README's test command fails, not only the last: it is run
here with every program it calls replaced by a stub that records its call, and one step failing."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
README_TEST = (
    'python3 -m venv .venv && .venv/bin/pip install ".[test]" && .venv/bin/stickslip compile && '
    ".venv/bin/python -m pytest"
)

STUB = """#!/usr/bin/env bash
echo "$(basename "$0") $*" >> "{log}"
case "$(basename "$0") $*" in
  "{fail}"*) exit 3 ;;
esac
exit 0
"""

# python3 -m venv .venv: makes the stubs of the virtual environment's programs
VENV = """#!/usr/bin/env bash
echo "python3 $*" >> "{log}"
mkdir -p .venv/bin
for name in pip stickslip python ruff; do
  cp "{stub}" .venv/bin/$name
  chmod +x .venv/bin/$name
done
"""


def _run_ci(tmp_path: Path, fail: str) -> tuple[int, list[str]]:
    tree = tmp_path / "tree"
    (tree / ".ci").mkdir(parents=True)
    shutil.copy(ROOT / ".ci" / "run", tree / ".ci" / "run")
    log = tmp_path / "calls.log"
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    stub = tmp_path / "stub"
    stub.write_text(STUB.format(log=log, fail=fail))
    (bin_dir / "python3").write_text(VENV.format(log=log, stub=stub))
    (bin_dir / "python3").chmod(0o755)
    env = {**os.environ, "PATH": f"{bin_dir}:{os.environ['PATH']}"}
    done = subprocess.run(["bash", str(tree / ".ci" / "run")], env=env, capture_output=True, text=True, timeout=60)
    return done.returncode, log.read_text().splitlines() if log.exists() else []


def test_ci_runs_the_readmes_test_command():
    assert README_TEST in (ROOT / ".ci" / "run").read_text()
    assert README_TEST in (ROOT / "README.md").read_text()


def test_every_step_runs_when_none_fails(tmp_path):
    rc, calls = _run_ci(tmp_path, fail="no-such-call")
    assert rc == 0
    assert [c.split()[0] for c in calls] == ["python3", "pip", "stickslip", "python", "ruff", "ruff", "pip", "python"]


@pytest.mark.parametrize("fail", ["pip install .[test]", "stickslip compile", "python -m pytest", "python -m sphinx"])
def test_a_failing_step_fails_ci_and_stops_it(tmp_path, fail):
    rc, calls = _run_ci(tmp_path, fail=fail)
    assert rc != 0, calls
    assert calls[-1].startswith(fail.split()[0] + " " + " ".join(fail.split()[1:])), calls  # nothing after it
