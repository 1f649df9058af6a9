"""A figure's titles stay inside it: long titles (a model's parameters) wrap at the figure's
edges instead of running past them (Fig. 5(a)'s title was cut at both edges)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402

from stickslip import chain_params  # noqa: E402
from stickslip.models.physics import chain_steady_state  # noqa: E402
from stickslip.plotting.chain import snapshot_figure  # noqa: E402
from stickslip.plotting.style import new_figure, save_figure  # noqa: E402


def _outside(fig) -> list[str]:
    """The titles of ``fig`` whose drawn extent leaves the figure (in pixels, half a pixel slack)."""
    FigureCanvasAgg(fig)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    texts = list(fig.texts) + [t for ax in fig.axes for t in (ax.title, ax._left_title, ax._right_title)]
    box = fig.bbox
    return [
        t.get_text()
        for t in texts
        if t.get_text()
        and (t.get_window_extent(renderer).x0 < box.x0 - 0.5 or t.get_window_extent(renderer).x1 > box.x1 + 0.5)
    ]


def test_fig5a_title_fits_the_figure():
    p = chain_params(beta=0.2)  # the paper's run: "Fig. 5(a): ..." and every parameter
    fig = snapshot_figure(chain_steady_state(p, 1e6)["x"], p, 1e6)
    assert "Fig. 5(a)" in fig.texts[0].get_text()
    assert _outside(fig) == []


def test_any_saved_figure_wraps_its_titles(tmp_path):
    """The class: a title set without ``wrap`` by any plot is wrapped when the figure is saved."""
    fig, ax = new_figure(1, 1, width=4.0, height=3.0)
    ax.set_title("a title longer than the four inches of this figure, as a model's parameters make", loc="left")
    fig.suptitle("a suptitle longer than the four inches of this figure, as a model's parameters make it")
    save_figure(fig, tmp_path / "long", formats=("png",))
    assert _outside(fig) == []
