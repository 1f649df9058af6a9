"""The gallery (docs/gallery): every page's code cells run in order and draw their figures (the
documentation build executes them too). How long a page takes is a matter for the benchmarks, not
for a test that a loaded machine would fail."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

GALLERY = Path(__file__).resolve().parent.parent / "docs" / "gallery"
CELL = re.compile(r"^```\{code-cell\}[^\n]*\n(.*?)^```", re.S | re.M)
#: Pages left to -m slow for the default run's time (10-20 s each on a busy two-core machine);
#: the documentation build executes every page as well.
SLOW: set[str] = {"transition", "sweep_dask", "sizes_two_models", "stick_slip_inversion", "rate_state"}


def pages() -> list:
    return [
        pytest.param(p, marks=pytest.mark.slow, id=p.stem) if p.stem in SLOW else pytest.param(p, id=p.stem)
        for p in sorted(GALLERY.glob("*.md"))
        if p.stem != "index"
    ]


def test_every_page_is_in_the_gallery_toctree():
    index = (GALLERY / "index.md").read_text()
    for page in GALLERY.glob("*.md"):
        if page.stem != "index":
            assert f"\n{page.stem}\n" in index, page.stem


def run_cell(source: str, namespace: dict, name: str):
    """Run a cell as a notebook does: its last line, if an expression, gives the cell's value
    (what the notebook shows: a Figure drawn without pyplot, a table)."""
    tree = ast.parse(source, name)
    last = tree.body.pop() if tree.body and isinstance(tree.body[-1], ast.Expr) else None
    exec(compile(tree, name, "exec"), namespace)
    if last is None:
        return None
    return eval(compile(ast.Expression(last.value), name, "eval"), namespace)


@pytest.mark.parametrize("page", pages())
def test_gallery_page_runs_and_draws(page, tmp_path, monkeypatch):
    import matplotlib
    import matplotlib.pyplot as plt

    matplotlib.use("Agg")
    monkeypatch.chdir(tmp_path)
    cells = CELL.findall(page.read_text())
    assert cells, f"{page.name} has no code cells"
    namespace: dict = {"__name__": "__main__"}
    plt.close("all")
    shown = [run_cell(cell, namespace, page.name) for cell in cells]
    figures = [v for v in [*namespace.values(), *shown] if isinstance(v, matplotlib.figure.Figure)]
    drawn = plt.get_fignums() or figures
    assert drawn, f"{page.name} draws no figure"
    plt.close("all")
