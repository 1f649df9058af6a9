"""The HTML pages: a study page and the transition page rendered from small fixtures."""

from __future__ import annotations

import math
import re

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure

from stickslip.experiments.studies import Study, design
from stickslip.experiments.studies.transition import PER_N_COLUMNS, ROW_COLUMNS
from stickslip.experiments.study_run import _write_page
from stickslip.pages import cell
from stickslip.plotting.style import save_figure

NASTY = '<script>alert("x")</script> & "quotes"'
ESCAPED = "&lt;script&gt;alert(&#34;x&#34;)&lt;/script&gt; &amp; &#34;quotes&#34;"


def _cells(page: str, table: int = -1) -> list[list[str]]:
    """The text of each body cell of the ``table``-th table of ``page``, row by row."""
    body = re.findall(r"<tbody>(.*?)</tbody>", page, re.S)[table]
    return [re.findall(r"<td>(.*?)</td>", tr) for tr in re.findall(r"<tr[^>]*>(.*?)</tr>", body, re.S)]


@pytest.fixture()
def study_page(tmp_path):
    spec = Study("phase-diagram", "tiny", common={"N": 5}, points=({"beta": 0.5},), note=f"note {NASTY}")
    table = pd.DataFrame(
        {
            "N": [5, 5],
            "alpha": [2.0, 2.0],
            "D": [0.01, 0.01],
            "beta": [0.5, 1.25],
            "start": ["slide", "stick"],
            "final_state": ["sliding", "failed"],
            "order_parameter": [0.123456789, np.nan],
            "order_parameter_err": [0.00012345, None],
            "status": ["ok", "error"],
            "error": [None, f"ValueError: {NASTY}"],
            "point_dir": ["p0", "p1"],
            "note": [None, "state.nc is missing"],
        }
    )
    fig = Figure(figsize=(1, 1))
    fig.subplots().plot([0, 1], [0, 1])
    save_figure(fig, tmp_path / "order", formats=("png", "pdf"))
    figures = [{"name": "order", "image": "order.png", "pdf": "order.pdf", "caption": NASTY, "command": "stickslip"}]
    meta = {
        "command": "stickslip study phase-diagram --tiny",
        "points": 2,
        "run": 1,
        "reused": 0,
        "failed": 1,
        "wall_seconds": 3.5,
        "compute_seconds": 2.0,
        "version": "9.9",
        "runs": "runs/x",
    }
    path = tmp_path / "index.html"
    _write_page(path, spec, design("phase-diagram"), meta, {"statements": [f"beta_t {NASTY}"]}, figures, table, table)
    return path.read_text()


def test_study_page_table_holds_the_values(study_page):
    head = re.search(r"<thead><tr>(.*?)</tr></thead>", study_page).group(1)
    cols = re.findall(r"<th>(.*?)</th>", head)
    assert cols == ["N", "alpha", "D", "beta", "start", "final_state", "order_parameter", "order_parameter_err"] + [
        "status",
        "error",
    ]
    rows = _cells(study_page)
    # four significant digits for floats, blanks for missing values, integers as they are
    assert rows[0] == ["5", "2", "0.01", "0.5", "slide", "sliding", "0.1235", "0.0001234", "ok", ""]
    assert rows[1][:8] == ["5", "2", "0.01", "1.25", "stick", "failed", "", ""]
    assert rows[1][8] == "error"
    assert re.search(r'<tr class="failed">', study_page) and study_page.count('class="failed"') == 1
    assert "2 points: 1 run now, 0 reused, 1 failed; 3.5 s wall" in study_page
    assert "1 cached points ran again because their files were damaged" in study_page
    assert "p1: state.nc is missing" in study_page
    assert study_page.count("data:image/png;base64,") == 1 and 'href="order.pdf"' in study_page


def test_study_page_escapes_text(study_page):
    assert "<script>" not in study_page
    # the note, the statement, the caption and the error, each escaped
    assert study_page.count(ESCAPED) == 4
    assert _cells(study_page)[1][9] == f"ValueError: {ESCAPED}"


def test_transition_page(tmp_path):
    """The transition's page: its per-N table before the rungs, an undecided rung marked, a rung
    run again because its files were damaged listed."""
    row = dict.fromkeys(ROW_COLUMNS)
    rows = pd.DataFrame(
        [
            {**row, "N": 40, "beta": 0.9, "final_state": "sliding", "order_parameter": 0.987654, "note": None},
            {**row, "N": 40, "beta": 1.1, "final_state": "undecided", "role": NASTY, "note": "samples.npz is missing"},
        ]
    )
    per_n = [{**dict.fromkeys(PER_N_COLUMNS), "N": 40, "beta_t": 1.0123456, "undecided": 1, "rungs": 2}]
    meta = {"command": "stickslip study transition --tiny", "points": 1, "run": 1, "reused": 0, "failed": 0}
    meta |= {"wall_seconds": 1.0, "compute_seconds": 0.5, "version": "9.9", "runs": "runs/x"}
    points = pd.DataFrame({"point_dir": ["ladder"], "status": ["ok"], "note": [None]})
    spec = Study("transition", "tiny", note="tiny")
    figures = [{"name": "loops", "image": "loops.png", "pdf": "loops.pdf", "caption": "loops", "command": "c"}]
    path = tmp_path / "index.html"
    found = {"statements": [NASTY], "per_N": per_n}
    _write_page(path, spec, design("transition"), meta, found, figures, points, rows)
    page = path.read_text()
    assert page.index("<h2>Per N</h2>") < page.index("<h2>Table</h2>")
    per_n_cells = _cells(page, 0)
    assert per_n_cells[0][:2] == ["40", "1.012"] and per_n_cells[0][-2:] == ["1", "2"]
    rung_cells = _cells(page, 1)
    assert [r[:2] for r in rung_cells] == [["40", "0.9"], ["40", "1.1"]]
    assert rung_cells[0][ROW_COLUMNS.index("order_parameter")] == "0.9877"
    assert rung_cells[1][ROW_COLUMNS.index("role")] == ESCAPED
    assert page.count('<tr class="undecided">') == 1
    assert "1 cached points ran again because their files were damaged" in page
    assert "row 1: samples.npz is missing" in page
    assert "<script>" not in page and page.count(ESCAPED) == 2
    assert 'src="loops.png"' in page  # no PNG there: linked, not embedded


@pytest.mark.parametrize(
    "value, text",
    [(None, ""), (math.nan, ""), (math.inf, ""), (np.float64(2.5e-7), "2.5e-07"), (3, "3"), ("a<b", "a<b")],
)
def test_cell(value, text):
    # the cell is text; escaping is the template's
    assert cell(value) == text
