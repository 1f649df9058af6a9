"""The Python code blocks of README.md and docs/*.md run as tests (sybil).

Each page runs its blocks in order in one namespace, in a fresh temporary directory (the examples
write run directories there), with ``__name__ == "__main__"`` as in a script. A block whose
preceding line is ``<!-- slow -->`` gets the ``slow`` marker (left out of the default run). The
tutorial's cells run in the documentation build (myst-nb), and the command lines of the docs in
tests/test_docs_commands.py.
"""

from __future__ import annotations

import os
import shutil
import tempfile

import pytest
from sybil import Sybil
from sybil.parsers.markdown import PythonCodeBlockParser, SkipParser

SLOW_MARK = "<!-- slow -->"


def _setup(namespace: dict) -> None:
    namespace["__name__"] = "__main__"
    namespace["_cwd"] = os.getcwd()
    namespace["_tmp"] = tempfile.mkdtemp(prefix="stickslip-docs-")
    os.chdir(namespace["_tmp"])
    import matplotlib

    matplotlib.use("Agg")


def _teardown(namespace: dict) -> None:
    os.chdir(namespace["_cwd"])
    shutil.rmtree(namespace["_tmp"], ignore_errors=True)


pytest_collect_file = Sybil(
    parsers=[PythonCodeBlockParser(), SkipParser()],
    patterns=["README.md", "docs/*.md", "docs/*/*.md"],
    excludes=["docs/tutorial.md"],
    setup=_setup,
    teardown=_teardown,
).pytest()


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config, items):
    """The ``slow`` marker for the code blocks announced as slow, before ``-m`` selects."""
    for item in items:
        example = getattr(item, "example", None)
        if example is None:
            continue
        before = example.document.text[: example.region.start].rstrip().rsplit("\n", 1)[-1]
        if before.strip() == SLOW_MARK:
            item.add_marker(pytest.mark.slow)
