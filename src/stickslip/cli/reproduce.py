"""`stickslip reproduce`: (to be filled in)."""

from __future__ import annotations


def register(sub) -> None:
    """Add the subcommand(s) of this module to the parser."""
