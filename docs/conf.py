"""Sphinx configuration of the stickslip documentation (MyST pages, executed tutorial, API)."""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "src"))

from stickslip import __version__  # noqa: E402

project = "stickslip"
author = "the stickslip authors"
copyright = "stickslip authors, MIT licence"
release = __version__

extensions = [
    "myst_nb",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
]
source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}
exclude_patterns = ["_build", "**/.ipynb_checkpoints", "**/_tutorial_runs"]
html_theme = "furo"
html_title = f"stickslip {release}"

myst_enable_extensions = ["dollarmath", "colon_fence"]
myst_heading_anchors = 3
# Headings that skip a level (a page's sections start at ###) are allowed; a link to a missing
# page or heading is an error (the build runs with -W).
suppress_warnings = ["myst.header"]

nb_execution_mode = "force"
nb_execution_timeout = 300
nb_execution_raise_on_error = True
nb_execution_show_tb = True

autosummary_generate = True
autosummary_imported_members = False
autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": False}
autodoc_typehints = "none"
autodoc_member_order = "bysource"
nitpicky = False

# The public names carry numpydoc sections (Parameters, Returns, Examples); those docstrings, and
# only those, are turned into reST fields by napoleon's numpy parser. The others are reST already.
NUMPYDOC_SECTIONS = {"Parameters", "Returns", "Attributes", "Raises", "Examples"}
TYPE_ALIASES = {
    "ChainRun": "~stickslip.run.outputs.ChainRun",
    "ChainState": "~stickslip.run.state.ChainState",
    "ChainParams": "~stickslip.models.params.ChainParams",
    "BlockParams": "~stickslip.models.params.BlockParams",
    "BlockRun": "~stickslip.run.block.BlockRun",
    "BlockState": "~stickslip.run.block.BlockState",
    "RunOptions": "~stickslip.run.outputs.RunOptions",
}


def _numpydoc(app, what, name, obj, options, lines):
    from sphinx.ext.napoleon import Config
    from sphinx.ext.napoleon.docstring import NumpyDocstring

    sections = {a.strip() for a, b in zip(lines, lines[1:], strict=False) if b.strip() and set(b.strip()) == {"-"}}
    if not sections & NUMPYDOC_SECTIONS:
        return
    config = Config(
        napoleon_use_ivar=True,
        napoleon_use_rtype=False,
        napoleon_preprocess_types=True,
        napoleon_type_aliases=TYPE_ALIASES,
    )
    lines[:] = NumpyDocstring(lines, config, app, what, name, obj, options).lines()


def setup(app):
    app.connect("autodoc-process-docstring", _numpydoc)
