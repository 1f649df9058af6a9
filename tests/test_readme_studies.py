"""The README's line on the studies says what each study's own module declares: its summary, the
largest N of its full grid and the wall time of each mode (before, it said `--full` 25 min for a
study whose help said about 45 minutes, and 300 slips and N up to 399 for one that counts some
1800 slips and goes to N = 799)."""

from __future__ import annotations

from pathlib import Path

import pytest

from stickslip.experiments.studies import STUDIES, design, study

README = (Path(__file__).resolve().parent.parent / "README.md").read_text()
LINE = next(line for line in README.splitlines() if line.startswith("| `stickslip study NAME`"))


def _max_n(name: str) -> int:
    s = study(name, "full")
    return max(int(v) for p in s.points for v in [p.get("N", s.common.get("N"))] if v is not None)


@pytest.mark.parametrize("name", STUDIES)
def test_the_readme_states_each_studys_own_summary_grid_and_cost(name):
    d = design(name)
    assert set(d.cost) == {"quick", "full"}
    fragment = f"`{name}` ({d.summary}; N up to {_max_n(name)}; `--quick` {d.cost['quick']}, `--full` {d.cost['full']})"
    assert fragment in LINE


@pytest.mark.parametrize("name", STUDIES)
def test_the_help_states_the_same_cost(name):
    d = design(name)
    text = d.describe()
    assert d.cost["quick"] in text and d.cost["full"] in text
