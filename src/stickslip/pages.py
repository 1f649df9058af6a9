"""HTML pages: the reproduction report (``report.html``) and the study pages (``index.html``).

Every page is a jinja2 template shipped with the package (``stickslip/templates``), rendered with
autoescape on, so text from a run (a caption, an error message, a command) can never become
markup. The report (:mod:`stickslip.report.writer`) and the studies
(:mod:`stickslip.experiments.study_run`) write their pages through :func:`write_page`.
"""

from __future__ import annotations

import base64
import functools
import math
from pathlib import Path
from typing import Any

import jinja2

from stickslip import io

__all__ = ["cell", "image_src", "render", "write_page"]


def cell(value: Any) -> str:
    """A table cell: empty for a missing or non-finite value, four significant digits for a float."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return ""
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def image_src(image: str, folder: str | Path, embed: bool = True) -> str:
    """The ``src`` of an image: the PNG at ``folder/image`` embedded as a data URL when ``embed``
    and the file is there (the page then stands alone), else the relative path ``image``."""
    path = Path(folder) / image
    if embed and path.is_file() and path.suffix.lower() == ".png":
        return "data:image/png;base64," + base64.b64encode(path.read_bytes()).decode("ascii")
    return image


@functools.cache
def _environment() -> jinja2.Environment:
    """The package's templates, every value escaped; an undefined name is an error, not a blank."""
    env = jinja2.Environment(
        loader=jinja2.PackageLoader("stickslip", "templates"),
        autoescape=True,
        keep_trailing_newline=True,
        undefined=jinja2.StrictUndefined,
    )
    env.filters["cell"] = cell
    return env


def render(template: str, **context: Any) -> str:
    """The page ``template`` (a file of ``stickslip/templates``) rendered with ``context``."""
    return _environment().get_template(template).render(**context)


def write_page(path: str | Path, template: str, **context: Any) -> Path:
    """Render ``template`` with ``context`` and write it to ``path`` atomically (UTF-8)."""
    return io.write_bytes(path, render(template, **context).encode("utf-8"))
