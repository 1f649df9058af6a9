"""docs/studies/index.md states the numbers of the study outputs kept beside it.

Each table of the page is read back and compared with ``docs/studies/NAME-quick.json`` (the
``--json`` output of ``stickslip study NAME --quick``) to the digits the page prints.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import pytest

STUDIES = Path(__file__).resolve().parent.parent / "docs" / "studies"
SHORT = {"ss": "stick-slip", "st": "steady"}


def _section(name: str) -> str:
    text = (STUDIES / "index.md").read_text()
    return re.search(rf"^## {re.escape(name)}\n(.*?)(?=^## |\Z)", text, re.S | re.M).group(1)


def _tables(name: str) -> list[tuple[list[str], list[list[str]]]]:
    """The markdown tables of a section: (header cells, rows of cells), the rule left out."""
    tables, rows = [], []
    for line in _section(name).splitlines() + [""]:
        if line.startswith("|"):
            rows.append([c.strip() for c in line.strip("|").split("|")])
        elif rows:
            tables.append((rows[0], rows[2:]))
            rows = []
    return tables


def _rows(name: str) -> list[dict]:
    return json.loads((STUDIES / f"{name}-quick.json").read_text())["rows"]


def _same(text: str, value: float) -> bool:
    """``text`` is ``value`` to the digits it shows."""
    digits = text.split("e")[0].lstrip("-").split(".")
    decimals = len(digits[1]) if len(digits) > 1 else 0
    exponent = int(text.split("e")[1]) if "e" in text else 0
    return math.isclose(float(text), value, abs_tol=0.5 * 10.0 ** (exponent - decimals) * (1 + 1e-9))


def test_exponents_table():
    ((_, table),) = _tables("exponents")
    rows = _rows("exponents")
    assert len(table) == len(rows)
    for cells, row in zip(table, rows, strict=True):
        model, N, beta, tau, err, _, fitted, excess = cells
        assert (model, int(N)) == (row["model"], row["N"])
        assert (beta == "") == (row["beta"] is None) and (not beta or float(beta) == row["beta"])
        assert _same(tau, row["tau"]) and _same(err, row["tau_err"]), cells
        assert fitted == f"{row['n_fit']} / {row['n_events']}"
        ratio, observed, expected = re.match(r"(\S+) \((\d+) / (\S+)\)", excess).groups()
        assert _same(ratio, row["excess"]) and int(observed) == row["observed"] and _same(expected, row["expected"])


def _threshold(cell: str, row: dict, kind: str) -> None:
    """A cell "G (L .. H)" of delta*: the geometric mean over the windows and the range."""
    if row.get(f"delta_star_{kind}_censored") is None:
        assert cell == "", (kind, cell)
        return
    gm, low, high = re.fullmatch(r"(\S+) \((\S+) \.\. (\S+)\)", cell).groups()
    assert gm == f"{row[f'delta_star_{kind}']:.1e}".replace("e-0", "e-"), (kind, cell)
    assert float(low) == row[f"delta_star_{kind}_low"] and float(high) == row[f"delta_star_{kind}_high"], (kind, cell)


def test_chaos_table():
    ((_, table),) = _tables("chaos")
    rows = {(r["model"], r["N"], r["beta"]): r for r in _rows("chaos")}
    assert len(table) == len(rows)
    for model, N, beta, lam, err, slips, state, fs, v, verdict in table:
        row = rows[(model, int(N), float(beta) if beta else None)]
        assert verdict == row["verdict"], (model, N, beta)
        assert _same(lam, row["lyapunov_dt0"]) and _same(err, row["lyapunov_dt0_err"]), (model, N, beta)
        assert int(slips) == row["flow_slips"]
        for kind, cell in zip(("state", "Fs", "V"), (state, fs, v), strict=True):
            _threshold(cell, row, kind)


@pytest.mark.parametrize("which", [0, 1])
def test_phase_diagram_states(which):
    header, table = _tables("phase-diagram")[which]
    lead = 2 - which  # alpha and D, or D alone
    betas = [float(h.split()[-1]) for h in header[lead:]]
    states = {(r["alpha"], r["D"], r["beta"], r["start"]): r["final_state"] for r in _rows("phase-diagram")}
    for cells in table:
        alpha, D = (float(cells[0]), float(cells[1])) if which == 0 else (1.0, float(cells[0]))
        for beta, cell in zip(betas, cells[lead:], strict=True):
            paper, steady = cell.strip("*").split(" / ")
            assert SHORT[paper] == states[(alpha, D, beta, "paper")], (alpha, D, beta)
            assert SHORT[steady] == states[(alpha, D, beta, "steady")], (alpha, D, beta)
