"""`stickslip models`: the presets of the model family, their pieces, equations and parameters."""

from __future__ import annotations

import argparse

from stickslip.cli._common import Result, add_json_option


def register(sub) -> None:
    """Add the `models` subcommand."""
    p = sub.add_parser(
        "models",
        help="list the models: the paper's chain and its relatives (presets and pieces)",
        description="The presets of docs/model.md's model family, and the pieces any composition is made of.",
    )
    add_json_option(p)
    p.set_defaults(handler=run_models_command)


def per_block_names() -> list[str]:
    """The parameters that may differ from block to block: K (per bond), M and every numeric
    parameter a piece reads (not N, V, dt)."""
    import dataclasses

    from stickslip.cli._per_block import may_vary
    from stickslip.models.params import ChainParams

    return [f.name for f in dataclasses.fields(ChainParams) if "choices" not in f.metadata and may_vary(f)]


def run_models_command(args: argparse.Namespace) -> Result:
    """Handler of `stickslip models`."""
    from stickslip.models.pieces import PIECES, RULES
    from stickslip.models.presets import PRESETS

    data = {
        "presets": [p.describe() for p in PRESETS.values()],
        "pieces": {
            kind: [{"name": p.name, "meaning": p.meaning, "reads": list(p.reads)} for p in choices]
            for kind, choices in PIECES.items()
        },
        "rules": list(RULES),
        "per_block": per_block_names(),
    }
    lines = []
    for pr in PRESETS.values():
        lines.append(f"{pr.name}: {pr.title}")
        lines.append("  pieces     " + ", ".join(f"{k} {v}" for k, v in pr.pieces.items()))
        lines.append("  equations  " + pr.equations)
        lines.append("  params     " + " ".join(f"{k}={v:g}" for k, v in pr.params.items()))
        start = pr.start + ("".join(f" {k}={v:g}" for k, v in pr.start_options.items()))
        lines.append(f"  start      {start}")
        if pr.note:
            lines.append("  note       " + pr.note)
        lines.append("")
    lines.append("pieces (compose any allowed choice with --drive --friction --threshold --ends):")
    for kind, choices in PIECES.items():
        for p in choices:
            reads = f"  [reads {', '.join(p.reads)}]" if p.reads else ""
            lines.append(f"  {kind:9s} {p.name:13s} {p.meaning}{reads}")
    lines.append("rules: " + "; ".join(data["rules"]))
    lines.append(
        "per block (a number, an array, or e.g. --Fs 'uniform(2.5, 3.5)' with --disorder-seed S; "
        "docs/model.md, per-block parameters): " + ", ".join(data["per_block"])
    )
    return Result(data, "\n".join(lines))
