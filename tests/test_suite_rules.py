"""Rules of the test suite itself: no test asserts how long something took. A loaded machine
stretches any duration (a gallery page took 80 s against a 60 s bound on a busy 2-core machine);
speed belongs in the benchmarks, and "refused at once" is shown by what was not done (no file
written, a lock tried without waiting, a function never called)."""

from __future__ import annotations

import ast
from pathlib import Path

TESTS = Path(__file__).resolve().parent

#: Clocks whose difference is a duration.
CLOCKS = {"perf_counter", "monotonic", "time", "perf_counter_ns", "monotonic_ns", "process_time"}
#: Names a test gives to a duration.
DURATIONS = {"elapsed", "took", "waited", "wall", "duration", "seconds", "dt_wall"}


def _is_clock(node: ast.AST) -> bool:
    return isinstance(node, ast.Call) and (
        (isinstance(node.func, ast.Attribute) and node.func.attr in CLOCKS)
        or (isinstance(node.func, ast.Name) and node.func.id in CLOCKS)
    )


def _is_duration(node: ast.AST) -> bool:
    """A clock's reading less another, or a name that holds one."""
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Sub):
        return any(_is_clock(n) for n in ast.walk(node))
    return isinstance(node, ast.Name) and node.id in DURATIONS


def duration_asserts(folder: Path) -> list[str]:
    """``file:line`` of each ``assert`` that bounds a duration from above (``took < 60``)."""
    found = []
    for path in sorted(folder.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.Assert):
                continue
            for cmp in (n for n in ast.walk(node.test) if isinstance(n, ast.Compare)):
                left, rights = cmp.left, cmp.comparators
                for op, right in zip(cmp.ops, rights, strict=True):
                    below = isinstance(op, (ast.Lt, ast.LtE)) and _is_duration(left)
                    above = isinstance(op, (ast.Gt, ast.GtE)) and _is_duration(right)
                    if below or above:
                        found.append(f"{path.name}:{node.lineno}")
                    left = right
    return found


def test_the_rule_finds_a_duration_bound(tmp_path):
    (tmp_path / "test_x.py").write_text(
        "import time\nt0 = time.perf_counter()\nassert time.perf_counter() - t0 < 5\n"
        "waited = 3\nassert waited < 8.0, 'slow'\nassert 30 > time.monotonic() - t0\n"
        "deadline = time.monotonic() + 60\nassert time.monotonic() < deadline\n"
    )
    assert duration_asserts(tmp_path) == ["test_x.py:3", "test_x.py:5", "test_x.py:6"]


def test_no_test_asserts_a_wall_clock_duration():
    assert duration_asserts(TESTS) == []
