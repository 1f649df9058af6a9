"""docs/studies/lattice.md states what `--full` found: the findings kept beside it
(``lattice-full.json``) are those the study draws from the rows kept beside it
(``lattice-full-table.parquet``), and the page's three tables are those findings' numbers."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import pandas as pd

from chain_helpers import same_findings
from stickslip.experiments.studies import lattice, study

STUDIES = Path(__file__).resolve().parent.parent / "docs" / "studies"
FULL = json.loads((STUDIES / "lattice-full.json").read_text())
TABLE = pd.read_parquet(STUDIES / "lattice-full-table.parquet")
PAGE = (STUDIES / "lattice.md").read_text()
FOUND = re.search(r"^## What `--full` found\n(.*?)(?=^## )", PAGE, re.S | re.M).group(1)


def _rows(ncells: int) -> list[list[str]]:
    """The body rows of the section's tables with ``ncells`` cells (no header, no rule)."""
    out = []
    for line in FOUND.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        body = line.startswith("|") and not set(line) <= set("|- ") and cells[0] not in ("L", "run")
        if body and len(cells) == ncells:
            out.append(cells)
    return out


def _num(cell: str) -> float:
    return float(cell) if cell not in ("", "none") else math.nan


def _close(cell: str, value, digits: int = 3) -> bool:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return cell in ("", "none")
    return cell == f"{float(value):.{digits}g}"


def test_the_kept_findings_are_those_of_the_kept_rows():
    assert FULL["mode"] == "full" and FULL["failed"] == 0
    assert len(TABLE) == FULL["points"] == len(study("lattice", "full").points)
    again = json.loads(json.dumps(lattice.findings(study("lattice", "full"), TABLE)))
    for key in ("statements", "edges", "rungs", "fits"):
        assert same_findings(again[key], FULL["findings"][key], none_is_nan=True), key


def test_the_pages_edges_table_is_the_findings():
    rows = _rows(6)
    edges = FULL["findings"]["edges"]
    assert [int(r[0]) for r in rows] == [e["L"] for e in edges] == [16, 32]
    for r, e in zip(rows, edges, strict=True):
        assert r[1] == f"{e['linear_threshold']:.3f}"
        assert _close(r[2], e.get("up_lo")) and _close(r[3], e.get("up_hi"))
        assert _close(r[4], e.get("down_lo")) and _close(r[5], e.get("down_hi"))


def test_the_pages_rungs_are_the_findings():
    rows = _rows(9)
    rungs = FULL["findings"]["rungs"]
    assert len(rows) == len(rungs) == 2 * 12 + 2 * 5
    for r, g in zip(rows, rungs, strict=True):
        assert (int(r[0]), r[1], float(r[2])) == (g["L"], g["direction"], g["beta"])
        assert _close(r[3], g["order_parameter"]) and _close(r[4], g["order_parameter_err"], 2)
        assert _close(r[5], g["stuck_fraction"], 2) and r[6] == g["final_state"]
        assert (int(r[7]), int(r[8])) == (g["n_events"], g["n_all_rows"])


def test_the_pages_fits_are_the_findings():
    rows = _rows(11)
    fits = FULL["findings"]["fits"]
    assert len(rows) == len(fits) == 3 + 5 + 4
    for r, f in zip(rows, fits, strict=True):
        assert r[0].endswith(f"= {f['L']}") and (int(r[1]), int(r[2])) == (f["events"], f["spanning"])
        assert _close(r[4], f["tau"]) and _close(r[5], f["tau_err"], 2)
        assert _close(r[8], f["b"]) and _close(r[9], f["b_err"], 2) and _close(r[10], f["b_from_tau"])
        if math.isfinite(_num(r[4])):
            assert r[7] == str(f["n_fit"])
