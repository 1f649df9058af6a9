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
