"""Every `stickslip` command line shown in README.md and docs/ parses, and runs cleanly.

The command lines of the docs' code blocks are collected from the pages (usage synopses with
brackets and placeholders are left out). Each must parse with the real parser; each runs in a
fresh directory (``DIR`` becomes a directory there) and must end with status 0 and no warning.
Those that run the paper's full lengths, many points or Dask clusters are marked slow; one that
needs an outside Dask scheduler is only parsed. The Python blocks of the same pages run through
sybil (conftest.py at the repository root).
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from stickslip.cli import build_parser, main

ROOT = Path(__file__).resolve().parent.parent
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")), *sorted((ROOT / "docs").glob("*/*.md"))]
_SYNOPSIS = re.compile(r"[\[\]{}|]|RUN_DIR|NAME|\.\.\.")
_SLOW_COMMANDS = {"reproduce", "study", "sweep", "lyapunov", "bench"}


def _commands(page: Path) -> list[tuple[int, list[str]]]:
    """(line, argv) of each `stickslip ...` command in an indented or fenced block of the page."""
    found, lines, k = [], page.read_text().splitlines(), 0
    while k < len(lines):
        m = re.match(r"^(?: {4,}|\$ )(?:\$ )?stickslip (.*)$", lines[k])
        start = k
        if m:
            text = m.group(1)
            while text.endswith("\\") and k + 1 < len(lines):
                k += 1
                text = text[:-1] + " " + lines[k].strip()
            if not _SYNOPSIS.search(text) and not text.split()[0].endswith(":"):  # not a line of output
                found.append((start + 1, shlex.split(text, comments=True)))
        k += 1
    return found


#: Commands measured at 20 s or more each in the default run on a busy two-core machine (mostly
#: long chains and the compilation of a composition no other default test needs): run with -m slow.
_MEASURED_SLOW = (
    "chain --N 49 --Fs uniform(2.5, 3.5) --t-end 5e5",
    "chain --N 49 --beta normal(1, 0.1)",
    "chain --N 49 --Fs asperities(3, 6, p=0.1)",
    "chain --model sakaguchi --friction strengthening --F0 1 --N 49 --t-end 5e5",
    "chain --drive constant-force --friction strengthening",
    "chain --drive force-ramp --friction strengthening",
    "chain --drive plate --friction state --ends periodic",
    "chain --model carlson-langer --t-end 2e4",
    "chain --model carlson-langer --l 10",
    "chain --model train --json",
    "chain --model carlson-langer --ends free --N 50 --t-end 2e4",
    "chain --model batista-carlson",
    "chain --model carlson-langer --friction strengthening --F0 0.5 --beta 1 --lattice square",
    "lab shs",
    "block --out fig-block --fig3",
    # a single block on each rate-and-state law (each composition compiled here first; the laws'
    # default-run tests are in tests/test_rate_state.py, test_prz_law.py, test_nagata_law.py)
    "chain --friction rate-state --N 1 --K 20 --t-end 2000",
    "chain --friction rate-state-prz --N 1 --K 20 --start steady",
    "chain --friction rate-state-nagata --N 1 --K 20 --start steady",
    "lab step --a 0.005 --b 0.01 --Dc 10",
    # the square's first runs (tests/test_lattice_exact.py runs the square by default)
    "chain --lattice square --shape 16x32",
    "chain --model carlson-langer --lattice square --shape 16x16",
    "chain --lattice square --shape 4x8 --history",
)


def _slow(argv: list[str]) -> bool:
    if argv[0] in _SLOW_COMMANDS:
        return True
    if " ".join(argv).startswith(_MEASURED_SLOW):
        return True
    if "--t-end" in argv and float(argv[argv.index("--t-end") + 1]) >= 1e6:
        return True
    return False


CASES = [
    pytest.param(
        argv,
        id=f"{page.relative_to(ROOT)}:{line}",
        marks=[pytest.mark.slow] if _slow(argv) else [],
    )
    for page in PAGES
    for line, argv in _commands(page)
]


def test_the_docs_show_commands():
    assert len(CASES) >= 20
    documented = [" ".join(c.values[0]) for c in CASES]
    stale = [m for m in _MEASURED_SLOW if not any(d.startswith(m) for d in documented)]
    assert not stale, f"no documented command starts with {stale}"
    assert any(c.values[0][:1] == ["chain"] for c in CASES)


@pytest.mark.parametrize("argv", [c.values[0] for c in CASES], ids=[c.id for c in CASES])
def test_documented_command_parses(argv):
    parser = build_parser()
    args, extra = parser.parse_known_args([a if a != "DIR" else "out" for a in argv])
    assert extra == []
    assert callable(args.handler)


@pytest.mark.filterwarnings("always::stickslip.run.errors.ShortRunWarning")
@pytest.mark.parametrize("argv", CASES)
def test_documented_command_runs(argv, tmp_path, monkeypatch, capsys):
    if "--scheduler" in argv:
        pytest.skip("needs an outside Dask scheduler (parsed by test_documented_command_parses)")
    monkeypatch.chdir(tmp_path)
    status = main([a if a != "DIR" else str(tmp_path / "out") for a in argv])
    err = capsys.readouterr().err
    assert status == 0, err
    assert "warning" not in err.lower(), err
