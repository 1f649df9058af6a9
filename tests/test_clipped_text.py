"""Text shown to a reader is wrapped or abbreviated at word boundaries, never cut mid-word: the
reproduce summary's agreement column; and ordinals read as English ("every 2nd window")."""

from __future__ import annotations

import re

import pytest

from stickslip.cli.reproduce import AGREEMENT_WIDTH, _text

LONG = (
    "agrees within the stated tolerance of two percent once the chain has loaded, as the paper "
    "states for Fig. 5(b) at beta = 0.2 and N = 399"
)


def _result(agreement: str) -> dict:
    return {
        "mode": "quick",
        "wall_seconds": 1.0,
        "rows": [{"where": "Fig. 5b", "agreement": agreement, "quantity": "<L>"}],
        "studies": [],
        "figures": [],
        "figures_not_drawn": {},
        "report_html": "report.html",
    }


def test_the_agreement_column_keeps_every_word_whole():
    text = _text(_result(LONG))
    shown = re.findall(r"[\w().=<>-]+", text)
    for word in LONG.split():
        assert word in text.split(), f"{word!r} cut: {shown}"
    lines = text.splitlines()
    assert lines[1].rstrip().endswith("<L>") and len(lines) > 3
    assert all(len(line) <= 2 + len("Fig. 5b") + 2 + AGREEMENT_WIDTH + 2 + 3 for line in lines[1:-2])


@pytest.mark.parametrize(
    "n, text",
    [(1, "1st"), (2, "2nd"), (3, "3rd"), (4, "4th"), (11, "11th"), (12, "12th"), (13, "13th"), (21, "21st"),
     (22, "22nd"), (23, "23rd"), (101, "101st"), (111, "111th"), (112, "112th")],
)  # fmt: skip
def test_ordinals(n, text):
    from stickslip.plotting.style import ordinal

    assert ordinal(n) == text


def test_no_figure_writes_an_ordinal_by_hand():
    """The class, not the one case: no f-string in the plotting code appends "th" to a number."""
    from pathlib import Path

    import stickslip.plotting

    for path in Path(stickslip.plotting.__file__).parent.glob("*.py"):
        assert not re.search(r"\}th\b", path.read_text()), path.name


def _catalog_summary(paper_beta):
    fit = {"tau": 1.5, "tau_err": 0.05, "s_min": 0.1, "s_max": 10.0, "n": 500}
    return {
        "paper_beta": paper_beta,
        "sizes": {"whole_range": fit, "below_spanning": {**fit, "excess": 3.0}},
        "frequency_magnitude": {},
        "distributions": {},
        "goodness_of_fit": {},
        "recurrence": {},
    }


@pytest.mark.parametrize("paper_beta", [1.0, 0.2, 0.5, None])
def test_a_catalogue_cites_only_what_the_paper_says_of_its_own_run(paper_beta):
    """A catalogue of the paper's chain at beta = 1 cites the paper's tau at beta = 1, not its
    beta = 0.2 result; a run the paper did not make cites nothing of it."""
    from stickslip.report.catalog_page import catalog_statements

    text = " ".join(catalog_statements(_catalog_summary(paper_beta)))
    assert ("at beta = 1)" in text) == (paper_beta == 1.0)
    assert ("at beta = 0.2" in text) == (paper_beta == 0.2)
    assert ("the paper" in text) == (paper_beta in (1.0, 0.2))
