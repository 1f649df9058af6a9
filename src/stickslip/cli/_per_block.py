"""Command-line options of per-block parameters (docs/model.md, "Per-block parameters"): every
parameter option of the chain takes a number, ``file:PATH`` or a distribution expression
(``--Fs "uniform(2.5, 3.5)"``), and ``--disorder-seed`` seeds the draws."""

from __future__ import annotations

import argparse
from typing import Any


def may_vary(f) -> bool:
    """Whether a ChainParams field may differ from block to block (docs/model.md, "Per-block
    parameters")."""
    from stickslip.models.disorder import NOT_PER_BLOCK

    return not f.metadata.get("integer") and not f.metadata.get("text") and f.name not in NOT_PER_BLOCK


def per_block_arg(name: str, allowed: str = ""):
    """An argparse type for a parameter that may be per block: a number, ``file:PATH`` or a
    distribution expression such as ``uniform(2.5, 3.5)`` (:func:`stickslip.models.disorder.parse`);
    the values are drawn and checked when the parameters are built."""
    from stickslip.models.disorder import DisorderError, parse

    def convert(text: str):
        try:
            return parse(text)
        except DisorderError as exc:
            raise argparse.ArgumentTypeError(f"{name} must be {allowed} at every block: {exc}") from None

    convert.__name__ = name
    return convert


def add_disorder_seed(group, convert) -> None:
    """``--disorder-seed S``: the seed of the values drawn from a distribution (default 0)."""
    group.add_argument(
        "--disorder-seed",
        dest="disorder_seed",
        type=convert,
        default=0,
        metavar="S",
        help="seed of the per-block values drawn from a distribution, e.g. --Fs 'uniform(2.5, 3.5)' "
        "(default 0; docs/chain.md, per-block parameters)",
    )


def seeded(value: Any, seed: int) -> Any:
    """A distribution given on the command line without its own seed takes ``--disorder-seed``."""
    from stickslip.models.disorder import Quenched

    if isinstance(value, Quenched) and value.seed is None:
        return Quenched(value.dist, *value.args, p=value.p, seed=seed)
    return value
