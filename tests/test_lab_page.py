"""The page of a laboratory protocol run: `stickslip lab step|shs|fit --out DIR` writes index.html."""

from __future__ import annotations

import base64
import json
from html.parser import HTMLParser

from stickslip.cli import main

OPTS = ["--a", "0.005", "--b", "0.01", "--Dc", "10", "--mu0", "0.6", "--V0", "1", "--k", "1e-3"]


class _Page(HTMLParser):
    """The page's tables (rows of cell texts, under the heading before each), images and text."""

    def __init__(self):
        super().__init__()
        self.tables: dict[str, list[list[str]]] = {}
        self.images: list[str] = []
        self.text: list[str] = []
        self._heading = ""
        self._in: str | None = None
        self._row: list[str] | None = None

    def handle_starttag(self, tag, attrs):
        if tag in ("h2", "td", "th", "code", "li"):
            self._in = tag
            if tag in ("td", "th"):
                self._row.append("")
        elif tag == "tr":
            self._row = []
        elif tag == "table":
            self.tables[self._heading] = []
        elif tag == "img":
            self.images.append(dict(attrs)["src"])

    def handle_endtag(self, tag):
        if tag == "tr":
            self.tables[self._heading].append(self._row)
        if tag == self._in:
            self._in = None

    def handle_data(self, data):
        self.text.append(data)
        if self._in == "h2":
            self._heading = data
        elif self._in in ("td", "th"):
            self._row[-1] += data


def _page(path) -> _Page:
    page = _Page()
    page.feed(path.read_text(encoding="utf-8"))
    return page


def _run(capsys, *argv):
    assert main([*argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_step_page_shows_the_json_numbers_the_figure_and_the_command(capsys, tmp_path):
    out = tmp_path / "a <b> dir"  # text of the command: escaped, never markup
    d = _run(capsys, "lab", "step", *OPTS, "--V", "1,10,1", "--out", str(out))
    assert d["outputs"][-1] == str(out / "index.html")
    page = _page(out / "index.html")
    head, *rows = page.tables["Steps"]
    assert head[:3] == ["t", "V_before", "V_after"]
    assert len(rows) == len(d["steps"]) == 2
    for row, st in zip(rows, d["steps"], strict=True):
        cells = dict(zip(head, row, strict=True))
        for key in ("mu_peak", "mu_ss_closed_form", "a_minus_b_from_run"):
            assert float(cells[key]) == float(f"{st[key]:.4g}")
    # the figure embedded is the PNG the command wrote
    assert page.images == ["data:image/png;base64," + base64.b64encode((out / "step.png").read_bytes()).decode()]
    raw = (out / "index.html").read_text(encoding="utf-8")
    assert "a &lt;b&gt; dir" in raw and "<b>" not in raw
    assert any(t.startswith("stickslip lab step --a 0.005") for t in page.text)


def test_shs_page_has_one_row_per_hold_and_the_healing_rate(capsys, tmp_path):
    out = tmp_path / "shs"
    d = _run(capsys, "lab", "shs", *OPTS[:-2], "--k", "1e-2", "--V", "10", "--holds", "10,100,1000", "--out", str(out))
    page = _page(out / "index.html")
    head, *rows = page.tables["Holds"]
    assert [float(r[head.index("t_hold")]) for r in rows] == [10.0, 100.0, 1000.0]
    assert [float(r[head.index("delta_mu")]) for r in rows] == [float(f"{h['delta_mu']:.4g}") for h in d["holds"]]
    assert any("healing rate" in t for t in page.text)
    # --overwrite replaces the page with the command's other files
    again = ["--holds", "10,100", "--out", str(out), "--overwrite"]
    _run(capsys, "lab", "shs", *OPTS[:-2], "--k", "1e-2", "--V", "10", *again)
    assert len(_page(out / "index.html").tables["Holds"]) == 3  # a header and two holds
