"""One shared look for every figure, and saving a figure with the data behind it."""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

# Figures are drawn off screen; in a Jupyter kernel the notebook's own backend stays, so that
# its figures go on showing inline.
if "ipykernel" not in sys.modules:
    matplotlib.use("Agg", force=False)
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

if "ipykernel" in sys.modules:
    # Settle the backend now: the notebook's inline backend, once loaded, shows a Figure that
    # ends a cell (the figures here are made without pyplot, which would load it only later).
    plt.switch_backend(matplotlib.get_backend())

RC = {
    "figure.dpi": 110,
    "savefig.dpi": 150,
    "font.size": 10,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "legend.frameon": False,
}

SIM = {"color": "C0", "lw": 1.2}  # simulation of the model: solid
THEORY = {"color": "C3", "lw": 1.2, "ls": "--"}  # analytic/limit curves: dashed, as in the paper
PAPER = {"color": "0.4", "lw": 1.0, "ls": ":"}  # the paper's own formula where it differs


def ordinal(n: int) -> str:
    """``n`` as an English ordinal (1st, 2nd, 3rd, 4th, 11th, 12th, 13th, 21st, 112th), for a
    figure's words (Fig. 6: "every 2nd window")."""
    n = int(n)
    suffix = "th" if n % 100 in (11, 12, 13) else {1: "st", 2: "nd", 3: "rd"}.get(n % 10, "th")
    return f"{n}{suffix}"


def new_figure(nrows: int = 1, ncols: int = 1, *, width: float = 5.0, height: float = 3.6, **kw):
    """A Figure and its axes in the project's style; no pyplot state is kept.

    Parameters
    ----------
    nrows, ncols : int
        The grid of Axes.
    width, height : float
        Size of one panel, inches.
    **kw
        Passed on to :meth:`matplotlib.figure.Figure.subplots` (``sharex``, ``gridspec_kw``, ...).

    Returns
    -------
    tuple of (matplotlib.figure.Figure, Axes or array of Axes)
    """
    with matplotlib.rc_context(RC):
        fig = Figure(figsize=(width * ncols, height * nrows), layout="constrained")
        axes = fig.subplots(nrows, ncols, squeeze=True, **kw)
    return fig, axes


def fit_titles(fig: Figure) -> Figure:
    """Let the titles of ``fig`` (its suptitle, each Axes' titles) wrap at the figure's edges, as
    matplotlib wraps a text with ``wrap=True`` when it draws it, instead of running past them (a
    model's parameters make long titles: Fig. 5(a)'s was cut at both edges). Returns ``fig``."""
    texts = list(fig.texts)
    for ax in fig.axes:
        texts += [t for t in (ax.title, getattr(ax, "_left_title", None), getattr(ax, "_right_title", None)) if t]
    for text in texts:
        text.set_wrap(True)
    return fig


#: Every figure is saved in these formats: PNG to look at, PDF to print or put in a paper.
FIGURE_FORMATS = ("png", "pdf")


def save_figure(fig: Figure, path: str | Path, *, formats: tuple[str, ...] = FIGURE_FORMATS) -> list[Path]:
    """Save ``fig`` as PATH.png and PATH.pdf (or ``formats``), each file rendered in memory and
    written atomically (:func:`stickslip.io.write_bytes`), so a full disk leaves no half-written
    image.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    path : str or Path
        The path without format: the format is added to the whole name (``lam_beta0.9`` gives
        ``lam_beta0.9.png``).
    formats : tuple of str
        File formats.

    Returns
    -------
    list of Path
        The files written.
    """
    import io as _io

    from stickslip.io import write_bytes

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fit_titles(fig)
    written = []
    with matplotlib.rc_context(RC):
        for fmt in formats:
            out = path.parent / f"{path.name}.{fmt}"  # the whole name: 'lam_beta0.9' has no suffix to drop
            buf = _io.BytesIO()
            fig.savefig(buf, format=fmt)
            write_bytes(out, buf.getvalue())
            written.append(out)
    return written


__all__ = [
    "new_figure",
    "save_figure",
    "fit_titles",
    "ordinal",
    "FIGURE_FORMATS",
    "plt",
    "SIM",
    "THEORY",
    "PAPER",
    "RC",
]
