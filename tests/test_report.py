"""The reproduction report: report.json round trip and report.html content."""

from __future__ import annotations

import json
import re

import pytest
from markupsafe import escape
from matplotlib.figure import Figure

from chain_helpers import is_real_command
from stickslip.plotting.style import save_figure
from stickslip.report.writer import ReportFigure, ReportRow, read_report, write_report

# The last table of docs/model.md, as the reproduction reports it (values of an imagined run).
ROWS = [
    ReportRow(
        "sec. 2",
        "Hopf point of steady sliding, K = 10, beta = 0.08",
        "V_c = 0.106",
        0.10612,
        True,
        "|V_c - 0.106| <= 0.001",
        "stickslip stability block --K 10 --beta 0.08",
    ),
    ReportRow(
        "sec. 2",
        "steady sliding linearly stable for all V > 0",
        "K = 10, beta = 1",
        "max Re(lambda) < 0 for 1e-4 <= V <= 10",
        True,
        "all V on the grid",
        "stickslip stability block --K 10 --beta 1",
    ),
    ReportRow(
        "sec. 2",
        "inverse transition stick-slip -> sliding, V raised slowly",
        "V = 0.345",
        0.29,
        False,
        "|V - 0.345| <= 0.01",
        "stickslip hysteresis --K 10 --beta 1 --V-min 0.2 --V-max 0.4 --json",
    ),
    ReportRow(
        "eq. 3",
        "slip duration, force at stop",
        "1.035, Fs - K x' = -0.432",
        "1.0348, -0.4318",
        True,
        "3 digits",
        "stickslip slip-limit --json",
    ),
    ReportRow(
        "Fig. 3",
        "period T(V)",
        "T = 1.035 + 3.432 / (K V)",
        "max rel. dev. 0.2 %",
        True,
        "1 %",
        "stickslip block --fig3 --out DIR",
    ),
    ReportRow(
        "Fig. 4",
        "long-wave instability of the chain, K = 10, D = 5",
        "for beta <= 1 (beta = 1 critical)",
        "unstable for beta < 1.000",
        True,
        "grid step 0.01",
        "stickslip stability chain",
    ),
    ReportRow(
        "sec. 3",
        "final state",
        "steady sliding for beta > 1, stick-slip for beta <= 1",
        None,
        None,
        "",
        "stickslip reproduce --full --out DIR",
        na_reason="quick run",
    ),
    ReportRow(
        "Fig. 5",
        "snapshot at t = 2e7, beta = 1",
        "close to the steady sliding profile",
        None,
        None,
        "",
        "stickslip reproduce --full --out DIR",
        na_reason="quick run: t = 2e5, not 2e7",
    ),
    ReportRow(
        "Fig. 5b",
        "<L> vs beta",
        "continuous decrease below beta = 1",
        "monotone in 6 points",
        True,
        "monotone",
        "stickslip sweep chain --grid beta=0.2,0.4,0.6,0.8,1.0,1.2 --t-end 1e5 --out L",
    ),
    ReportRow(
        "Fig. 6",
        "rupture front speed in large events, beta = 1",
        "c = 1.43 (sqrt(K) = 3.16)",
        1.47,
        True,
        "|c - 1.43| <= 0.15",
        "stickslip reproduce --quick --out DIR",
    ),
    ReportRow(
        "Fig. 7",
        "slip-size distribution, beta = 1",
        "power law, exponent about 1.5, cut off by N",
        "tau = 1.52 +- 0.03",
        True,
        "|tau - 1.5| <= 0.1",
        "stickslip reproduce --quick --out DIR",
    ),
    ReportRow(
        "Fig. 8",
        "slip-size distribution, beta = 0.2",
        "about 1.6 for small S, excess of large events",
        "tau = 1.63 +- 0.05",
        True,
        "|tau - 1.6| <= 0.15",
        "stickslip reproduce --quick --out DIR",
        note="the paper's text says 'Figure 7' here; it means Fig. 8",
    ),
]


def _esc(text: str) -> str:
    """Text as the page writes it (jinja2's autoescape)."""
    return str(escape(text))


def test_commands_are_real(figures):
    for command in [r.command for r in ROWS] + [f.command for f in figures]:
        assert is_real_command(command), command


@pytest.mark.parametrize(
    "command",
    ["stickslip stability hopf --K 10", "stickslip block limit", "stickslip reproduce --only fig6", "make all"],
)
def test_command_check_refuses_what_does_not_exist(command):
    assert not is_real_command(command)


@pytest.fixture()
def figures(tmp_path):
    out = []
    for name in ("fig5a", "fig6"):
        fig = Figure(figsize=(2, 2))
        fig.subplots().plot([0, 1], [0, 1])
        save_figure(fig, tmp_path / "figures" / name, formats=("png", "pdf"))
        (tmp_path / "data").mkdir(exist_ok=True)
        (tmp_path / "data" / f"{name}.nc").write_bytes(b"")
        out.append(
            ReportFigure(
                f"Fig. {name[3:]}",
                f"figures/{name}.png",
                f"caption of {name} <x_i>",
                pdf=f"figures/{name}.pdf",
                data=(f"data/{name}.nc",),
                command=f"stickslip chain --t-end 2e5 --out DIR && stickslip plot DIR  (DIR/figures/{name}.png)",
            )
        )
    return out


def test_json_round_trips(tmp_path, figures):
    meta = {"mode": "quick", "command": "stickslip reproduce --quick --out x", "wall_seconds": 12.5}
    write_report(tmp_path, ROWS, figures, meta)
    report = read_report(tmp_path)
    assert report.rows == tuple(ROWS)
    assert report.figures == tuple(figures)
    assert report.meta["mode"] == "quick" and report.meta["wall_seconds"] == 12.5
    assert "version" in report.meta
    raw = json.loads((tmp_path / "report.json").read_text())
    assert [r["agreement"] for r in raw["rows"]][:3] == [
        "yes (|V_c - 0.106| <= 0.001)",
        "yes (all V on the grid)",
        "no (|V - 0.345| <= 0.01)",
    ]
    assert raw["rows"][6]["agreement"] == "n/a (quick run)"
    # a report read back and written again is the same document
    write_report(tmp_path / "again", report.rows, report.figures, report.meta)
    assert json.loads((tmp_path / "again" / "report.json").read_text()) == raw


def test_html_has_every_row_and_figure(tmp_path, figures):
    paths = write_report(tmp_path, ROWS, figures, {"mode": "quick"})
    page = paths["html"].read_text()
    body = re.search(r"<tbody>(.*)</tbody>", page, re.S).group(1)
    assert body.count("<tr>") == len(ROWS)
    for row in ROWS:
        assert _esc(row.quantity) in page
        assert _esc(row.paper) in page
        assert _esc(row.command) in page
        assert _esc(row.agreement) in page
    assert "1.47" in page and "not computed" in page
    assert 'class="no"' in page and page.count('class="na"') == 2
    assert "12 stated numbers: 9 agree, 1 disagree, 2 not settled at this run length." in page
    # figures embedded, PDF and data linked by relative paths
    assert page.count("data:image/png;base64,") == 2
    assert 'href="figures/fig5a.pdf"' in page and 'href="data/fig6.nc"' in page
    assert "caption of fig5a &lt;x_i&gt;" in page


def test_html_links_images_when_not_embedded(tmp_path, figures):
    page = write_report(tmp_path, ROWS[:1], figures, embed=False)["html"].read_text()
    assert 'src="figures/fig5a.png"' in page and "base64" not in page


def test_html_escapes_everything(tmp_path):
    nasty = '<script>alert("x")</script> & "quotes"'
    row = ReportRow("Fig. <1>", nasty, nasty, nasty, None, "", nasty, na_reason="<i>")
    fig = ReportFigure("Fig. 9", 'a" onerror="x.png', nasty)
    page = write_report(tmp_path, [row], [fig], {"note": nasty})["html"].read_text()
    assert "<script>" not in page and "<i>" not in page
    assert 'onerror="x.png' not in page
    assert _esc(nasty) in page


def test_rows_may_be_plain_dicts(tmp_path):
    write_report(tmp_path, [ROWS[0].to_dict()], [], {})
    assert read_report(tmp_path / "report.json").rows == (ROWS[0],)


def test_fig6_row_judges_the_paper_value_against_the_per_event_distribution():
    import numpy as np
    import pandas as pd

    from stickslip.report.rows import front_speed_row, front_speed_verdict

    rng = np.random.default_rng(5)
    centred = pd.DataFrame({"c_first_move": rng.normal(1.5, 0.1, 400), "c_leading_edge": rng.normal(1.45, 0.1, 400)})
    agrees, text = front_speed_verdict(centred, K=10.0)
    assert agrees is True and "percentile" in text
    # the paper's 1.43 below the 5th percentile of one definition: no agreement
    shifted = centred.assign(c_leading_edge=rng.normal(1.8, 0.05, 400))
    assert front_speed_verdict(shifted, K=10.0)[0] is False
    # median above the sound speed: no agreement
    assert front_speed_verdict(centred, K=1.0)[0] is False
    # no event: no verdict, and the row says why
    empty = pd.DataFrame({"c_first_move": [], "c_leading_edge": []})
    row = front_speed_row(empty, K=10.0, mode="full", command="x")
    assert row.agrees is None and "no event" in row.na_reason
    full = front_speed_row(centred, K=10.0, mode="full", command="x")
    assert full.agrees is True and "central 90%" in full.tolerance


def test_the_header_shows_lists_as_lines_not_json(tmp_path, figures):
    meta = {"mode": "quick", "experiments": ["fig1: runs/fig1, computed in 1.0 s", "fig4: runs/fig4, reused"]}
    meta["notes"] = ["a note <b>"]
    page = write_report(tmp_path, ROWS, figures, meta)["html"].read_text()
    header = re.search(r'<dl class="meta">(.*?)</dl>', page, re.S).group(1)
    assert "fig1: runs/fig1, computed in 1.0 s<br>fig4: runs/fig4, reused" in header
    assert "a note &lt;b&gt;" in header
    assert '["' not in header and "&#34;" not in header and "&quot;" not in header
