"""docs/studies/lifetimes.md, "What `--full` costs", states the numbers of the measured slice kept
beside it (``docs/studies/lifetimes-full-slice.json``): the starts it saw censored, the cost per
time unit re-derived from its rows, and the estimate's sums and minutes."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from stickslip.experiments.studies import lifetimes

STUDIES = Path(__file__).resolve().parent.parent / "docs" / "studies"
SLICE = json.loads((STUDIES / "lifetimes-full-slice.json").read_text())
PAGE = (STUDIES / "lifetimes.md").read_text()
SECTION = re.search(r"^### What `--full` costs\n(.*?)(?=^## )", PAGE, re.S | re.M).group(1)


def _text() -> str:
    return " ".join(SECTION.split())


def test_the_slice_is_of_full_and_its_censored_starts_are_those_the_page_names():
    full = lifetimes.build("full")
    keys = {(p["model"], p["N"], p.get("beta")) for p in full.points}
    rows = [r for r in SLICE["slice"] if r["measure"] == "lifetime"]
    assert len(SLICE["slice"]) == 31 and all((r["model"], r["N"], r["beta"]) in keys for r in rows)
    censored = {(r["N"], r["beta"]) for r in rows if r["model"] == "sakaguchi" and r["end"] == "censored"}
    stated = {(N, 0.9) for N in (15, 17, 19, 21)} | {(17, 1.0), (19, 1.0), (17, 1.1)}
    stated |= {(N, 0.5) for N in (5, 13, 21)}
    assert censored == stated
    assert all(r["lifetime"] == 4e6 for r in rows if r["model"] == "sakaguchi" and r["end"] == "censored")
    settled = [r["lifetime"] for r in rows if r["model"] == "sakaguchi" and r["end"] == "periodic"]
    assert min(settled) == pytest.approx(8.6e4, rel=0.01) and max(settled) == pytest.approx(3.0e5, rel=0.01)


def test_the_cost_per_time_unit_is_the_line_through_zero_of_the_rows():
    rows = [r for r in SLICE["slice"] if r["measure"] == "lifetime" and r["model"] == "sakaguchi"]
    t = [r["t_reached"] for r in rows]
    c = [r["point_cpu_seconds"] for r in rows]
    rate = sum(a * b for a, b in zip(t, c, strict=True)) / sum(a * a for a in t) * 1e6
    assert len(rows) == 15 and rate == pytest.approx(SLICE["rates_cpu_seconds_per_1e6"]["eq. (4)"], abs=0.01)
    assert f"{rate:.1f} s per 1e6 time units" in _text()


def test_the_page_states_the_estimate():
    est = SLICE["estimate"]
    text = _text()
    central, upper = est["total_cpu_seconds"]["central"], est["total_cpu_seconds"]["upper"]
    assert f"{round(central, -2):.0f} s of CPU time" in text and f"{round(upper, -2):.0f} s" in text
    assert f"{round(central / 120)} minutes on two workers" in text.replace("or ", "")
    assert f"{round(upper / 120)} minutes" in text
    shares = {k: v["central"] / central for k, v in est["parts_cpu_seconds"].items()}
    exps = sum(v for k, v in shares.items() if k.startswith("exp"))
    assert f"{100 * exps:.0f} %" in text
    assert f"{100 * shares['life sakaguchi beta=0.5']:.0f} %" in text
    cal = SLICE["calibration"]
    factor = cal["quick_measured_cpu_seconds_free_cores"] / cal["quick_estimated_cpu_seconds"]
    assert f"a factor of {factor:.2f}" in text and cal["factor"] == round(factor, 2)
    # about 45 minutes: the central minutes times the factor, to the nearest five
    assert 5 * round(central / 120 * factor / 5) == 45 and "about 45 minutes on two free cores" in text
    assert lifetimes.COST["full"].startswith("about 45 minutes on two free cores")
