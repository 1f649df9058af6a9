"""docs/studies/lifetimes.md states what `--full` found: the findings kept beside it
(``lifetimes-full.json``) are those the study draws from the rows kept beside it
(``lifetimes-full-table.parquet``), and the page's tables, fits, bounds and cost are those
findings' numbers."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pandas as pd

from chain_helpers import same_findings
from stickslip.experiments.studies import lifetimes

STUDIES = Path(__file__).resolve().parent.parent / "docs" / "studies"
FULL = json.loads((STUDIES / "lifetimes-full.json").read_text())
TABLE = pd.read_parquet(STUDIES / "lifetimes-full-table.parquet")
PAGE = (STUDIES / "lifetimes.md").read_text()
FOUND = re.search(r"^## What `--full` found\n(.*?)(?=^## )", PAGE, re.S | re.M).group(1)
ANSWER = re.search(r"^## The answer, in short\n(.*?)(?=^## )", PAGE, re.S | re.M).group(1)


def _flat(text: str) -> str:
    return " ".join(text.split())


def test_the_kept_findings_are_those_of_the_kept_rows():
    assert FULL["meta"]["mode"] == "full" and FULL["meta"]["failed"] == 0
    assert len(TABLE) == FULL["meta"]["points"] == len(lifetimes.build("full").points)
    again = json.loads(json.dumps(lifetimes.conclusions(None, TABLE)))
    for key in ("points", "exponents", "verdicts", "fits", "statements"):
        assert same_findings(again[key], FULL["findings"][key]), key


def _chain_rows() -> dict[tuple[float, int], list[str]]:
    rows = {}
    for line in FOUND.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 7 and re.fullmatch(r"[\d.]+", cells[0]) and cells[1].isdigit():
            rows[(float(cells[0]), int(cells[1]))] = cells
    return rows


def test_the_chains_table_is_the_findings():
    rows = _chain_rows()
    points = [p for p in FULL["findings"]["points"] if p["model"] == "sakaguchi"]
    assert len(rows) == len(points) == 40
    for p in points:
        cells = rows[(p["beta"], p["N"])]
        assert int(cells[2]) == p["ended"]
        assert cells[6] == ", ".join(map(str, p["periods"]))
        if p["ended"]:
            assert cells[3] == f"{p['mean_T']:.3g} +- {p['mean_T_err']:.2g}"
        else:
            assert cells[3] == f"> {p['mean_T_low95']:.3g} (95 %)"
        if p["weibull_shape"] is not None:
            assert cells[4] == f"{p['weibull_shape']:.2f}"


def test_the_fits_and_the_bounds_at_n_399_are_stated():
    text, answer = _flat(FOUND), _flat(ANSWER)
    for f in FULL["findings"]["fits"]:
        if f["model"] != "sakaguchi" or "exponential" not in f:
            continue
        e, pw = f["exponential"], f["power"]
        assert f"{e['slope']:.3g} +- {e['slope_err']:.2g}" in text
        assert f"{pw['slope']:.3g} +- {pw['slope_err']:.2g}" in text
        assert f"{e['chi2']:.3g} / {pw['chi2']:.3g} ({e['dof']})" in text
        assert f"| {f['T_399_low95']:.3g} |" in text
        # the answer's table rounds the same bound to two digits
        assert f"| {f['beta']:g} | {f['T_399_low95']:.1e} |".replace("e+0", "e") in answer


def test_the_exponents_are_stated_in_units_of_1e_4():
    text = _flat(FOUND)
    for e in FULL["findings"]["exponents"]:
        if e["model"] == "sakaguchi":
            assert f"{e['lyapunov'] * 1e4:+.2f} +- {e['lyapunov_err'] * 1e4:.2f}" in text


def test_the_cost_is_the_measured_one():
    meta = FULL["meta"]
    section = _flat(re.search(r"^### What `--full` costs\n(.*?)(?=^## )", PAGE, re.S | re.M).group(1))
    assert f"{meta['points']} points run, 0 failed, **{meta['wall_seconds']:.0f} s" in section
    cpu = TABLE["point_cpu_seconds"].sum()
    assert f"sums to {cpu:.0f} s" in section
    # two free cores: the points' CPU time over two, and a few minutes more for compiling
    assert f"some {cpu / 120:.0f} minutes of point work" in section and "**about 40 minutes**" in section
    assert lifetimes.COST["full"].startswith("about 40 minutes on two free cores")
