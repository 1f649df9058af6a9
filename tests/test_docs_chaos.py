"""docs/studies/chaos.md states the numbers of decorrelation-grid.json and chaos-full.json.

The page's tables of n(delta), of delta* and of its fit against N are read back and compared
with the measured rows to the digits the page prints; delta* and the fit are computed here from
the rows by hand (the smallest decorrelating delta per window; least squares written out), not by
the functions that made the JSON.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

STUDIES = Path(__file__).resolve().parent.parent / "docs" / "studies"
KINDS = ("state", "Fs", "V")
DELTAS = [float(f"1e{k}") for k in range(-12, 0)]


def _page() -> str:
    return (STUDIES / "chaos.md").read_text()


def _grid() -> dict:
    return json.loads((STUDIES / "decorrelation-grid.json").read_text())


def _rows(table: str) -> list[list[str]]:
    """The body rows of a markdown table, as cells."""
    return [[c.strip() for c in line.strip().strip("|").split("|")] for line in table.strip().splitlines()[2:]]


def _section_table(heading: str) -> list[list[str]]:
    """The first table after a heading line."""
    text = _page()
    start = text.index(heading)
    m = re.search(r"((?:^\|.*\n)+)", text[start:], re.M)
    return _rows(m.group(1))


def _delta(text: str) -> float:
    return float(text)


def _per_seed(rows, seeds=3):
    """delta* per window by hand: the smallest delta whose twin disagreed (None: none did)."""
    out = []
    for s in range(seeds):
        hits = [r["delta"] for r in rows if r["seed"] == s and r["decorrelated"]]
        out.append(min(hits) if hits else None)
    return out


def test_the_n_tables_are_the_measured_rows():
    grid = _grid()
    blocks = re.findall(r"\*\*N = (\d+), beta = ([\d.]+)\*\* \(n for seeds[^\n]*\n\n((?:\|.*\n)+)", _page())
    points = {(r["N"], r["beta"]) for r in grid["rows"]}
    assert {(int(N), float(b)) for N, b, _ in blocks} == points and len(blocks) == len(points)
    for N, b, table in blocks:
        got = {}
        for cells in _rows(table):
            if " .. " in cells[0]:
                lo, hi = (_delta(x) for x in cells[0].split(" .. "))
                deltas = [d for d in DELTAS if lo <= d <= hi]
            else:
                deltas = [_delta(cells[0])]
            for d in deltas:
                for kind, cell in zip(KINDS, cells[1:], strict=True):
                    got[(d, kind)] = cell
        expected = {}
        for kind in KINDS:
            for d in DELTAS:
                rs = sorted(
                    (
                        r
                        for r in grid["rows"]
                        if r["N"] == int(N) and r["beta"] == float(b) and r["perturb"] == kind and r["delta"] == d
                    ),
                    key=lambda r: r["seed"],
                )
                expected[(d, kind)] = ", ".join(str(r["events"]) if r["decorrelated"] else "-" for r in rs)
        assert got == expected, (N, b)


def _threshold_cell(cell: str):
    m = re.fullmatch(r"(\S+)(?: \[(\S+)\])? \((.*)\)", cell)
    gm, err, seeds = m.groups()
    per = [None if s == "-" else _delta(s) for s in seeds.split(", ")]
    return (None if gm == "none" else float(gm)), (None if err is None else float(err)), per


def test_the_delta_star_table_is_that_of_the_rows():
    grid = _grid()
    table = _section_table("| N | beta | delta\\* of the state")
    keys = sorted({(r["N"], r["beta"]) for r in grid["rows"]})
    assert [(int(c[0]), float(c[1])) for c in table] == keys
    for cells in table:
        N, b = int(cells[0]), float(cells[1])
        for kind, cell in zip(KINDS, cells[2:], strict=True):
            gm, err, per = _threshold_cell(cell)
            rows = [r for r in grid["rows"] if r["N"] == N and r["beta"] == b and r["perturb"] == kind]
            assert per == _per_seed(rows), (N, b, kind)
            logs = np.log10([v for v in per if v is not None])
            assert gm == pytest.approx(float(f"{10 ** logs.mean():.1e}"), rel=1e-9), (N, b, kind)
            if logs.size > 1:
                assert err == pytest.approx(round(float(logs.std(ddof=1) / math.sqrt(logs.size)), 2), abs=1e-9)


def _slope(Ns, values):
    x, y = [], []
    for N, vals in zip(Ns, values, strict=True):
        for v in vals:
            if v is not None:
                x.append(math.log10(N))
                y.append(math.log10(v))
    x, y = np.array(x), np.array(y)
    sxx = ((x - x.mean()) ** 2).sum()
    slope = ((x - x.mean()) * (y - y.mean())).sum() / sxx
    resid = y - y.mean() - slope * (x - x.mean())
    return slope, math.sqrt((resid**2).sum() / (x.size - 2) / sxx)


def test_the_fit_of_delta_star_against_N_is_that_of_the_rows():
    grid = _grid()
    table = _section_table("| beta | slope, state")
    Ns = sorted({r["N"] for r in grid["rows"]})
    assert [float(c[0]) for c in table] == [0.5, 0.9, 1.0]
    for cells in table:
        b = float(cells[0])
        for kind, cell in zip(KINDS, cells[1:], strict=True):
            per = [
                _per_seed([r for r in grid["rows"] if r["N"] == N and r["beta"] == b and r["perturb"] == kind])
                for N in Ns
            ]
            slope, err = _slope(Ns, per)
            value, error = (float(x) for x in cell.split(" +- "))
            assert value == pytest.approx(round(slope, 2), abs=1e-9) and error == pytest.approx(round(err, 2), abs=1e-9)


def _full() -> dict:
    return json.loads((STUDIES / "chaos-full.json").read_text())


def _same(text: str, value: float) -> bool:
    """``text`` is ``value`` to the digits it shows."""
    mantissa = text.split("e")[0].lstrip("-+")
    decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
    exponent = int(text.split("e")[1]) if "e" in text else 0
    return math.isclose(float(text), value, abs_tol=0.5 * 10.0 ** (exponent - decimals) * (1 + 1e-9))


def test_the_study_measures_the_rows_of_the_commands():
    """``--full`` runs n(delta) inside the study from its own loaded states: its delta* per window
    are those of the 45 commands of decorrelation-grid.json, by hand."""
    grid = _grid()
    rows = [r for r in _full()["rows"] if r["model"] == "sakaguchi"]
    assert sorted((r["N"], r["beta"]) for r in rows) == sorted({(g["N"], g["beta"]) for g in grid["rows"]})
    for r in rows:
        for kind in KINDS:
            mine = [g for g in grid["rows"] if g["N"] == r["N"] and g["beta"] == r["beta"] and g["perturb"] == kind]
            got = [r[f"delta_star_{kind}_seed{s}"] for s in range(3)]
            assert got == _per_seed(mine), (r["N"], r["beta"], kind)


def test_the_verdict_table_is_that_of_the_full_study():
    rows = {(r["model"], r["N"]): r for r in _full()["rows"] if r["model"] != "sakaguchi"}
    rows |= {(r["N"], r["beta"]): r for r in _full()["rows"] if r["model"] == "sakaguchi"}
    table = _section_table("| model | N | beta | lambda_0 of the flow")
    assert len(table) == len(rows)
    for model, N, beta, lam, err, slips, window, verdict, bracket in table:
        r = rows[(int(N), float(beta))] if beta else rows[(model, int(N))]
        assert _same(lam, r["lyapunov_dt0"]) and _same(err, r["lyapunov_dt0_err"]), (model, N, beta)
        assert int(slips) == r["flow_slips"] and int(window) == r["window"] and verdict == r["verdict"]
        if r["verdict"] == "stable chaos":
            low, high = (float(x) for x in re.fullmatch(r"\((\S+), (\S+)\]", bracket).groups())
            assert (low, high) == (r["threshold_below"], r["threshold_low"])
        # the verdict's rule, from the row's own numbers
        if r["lyapunov_dt0"] > 2 * r["lyapunov_dt0_err"]:
            assert r["verdict"] == "chaotic"
        else:
            assert r["verdict"] in ("stable chaos", "regular", "undetermined")


def test_the_flows_delta_star_table_is_that_of_its_rows():
    flow = json.loads((STUDIES / "decorrelation-flow.json").read_text())
    grid = _grid()
    table = _section_table("| N | beta | delta\\* of the state, flow")
    assert [(int(c[0]), float(c[1])) for c in table] == sorted({(r["N"], r["beta"]) for r in flow["rows"]})
    for N, b, flow_cell, grid_cell in table:
        for data, cell in ((flow, flow_cell), (grid, grid_cell)):
            rows = [r for r in data["rows"] if r["N"] == int(N) and r["beta"] == float(b) and r["perturb"] == "state"]
            gm, _, per = _threshold_cell(cell)
            assert per == _per_seed(rows), (N, b)
            logs = np.log10([v for v in per if v is not None])
            assert gm == pytest.approx(float(f"{10 ** logs.mean():.1e}"), rel=1e-9), (N, b)
