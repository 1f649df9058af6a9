"""Shared test fixtures."""

from __future__ import annotations

import os

import matplotlib

matplotlib.use("Agg")
os.environ.setdefault("MPLBACKEND", "Agg")

# The one-line notice that kernels are being compiled (stickslip.kernels._cache) would come first
# in whichever test compiles a model; tests of a command's stderr are not about it, and
# tests/test_first_use.py checks the notice in a process of its own.
from stickslip.kernels import _cache  # noqa: E402

_cache.NOTICE.said = True
