"""The HTML page of the transition study by continuation (``OUT/transition/index.html``): the
command, wall time and cores, what the data say, the figures, the per-N table and the rungs."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from stickslip import pages

__all__ = ["write_page", "ROW_COLUMNS", "PER_N_COLUMNS"]

#: The leading columns of the study's rows and of its per-N table.
ROW_COLUMNS = [
    "N",
    "beta",
    "branch",
    "replica",
    "order_parameter",
    "order_parameter_err",
    "stuck_fraction",
    "stuck_fraction_err",
    "final_state",
    "branch_state",
    "t_end",
    "loads",
    "tau_int_loads",
    "t_cut_loads",
    "err_reliable",
    "role",
    "start",
    "final_reason",
    "wall_seconds",
]
PER_N_COLUMNS = [
    "N",
    "beta_t",
    "beta_t_err",
    "lower_edge",
    "lower_edge_err",
    "step",
    "step_err",
    "step_phi",
    "step_phi_err",
    "beta_t_spread",
    "replicas",
]


def write_page(path: Path, data: dict[str, Any]) -> None:
    """Write the page of one run of the study (``data`` as in ``study.json``) from
    stickslip/templates/transition.html.j2; undecided rungs are marked."""
    pages.write_page(
        path,
        "transition.html.j2",
        meta=data["meta"],
        statements=data["statements"],
        figures=[{"name": name, "src": pages.image_src(name, path.parent)} for name in data["figures"]],
        per_n=data["per_N"],
        per_n_cols=PER_N_COLUMNS + ["undecided", "rungs"],
        rows=[{**r, "_class": "undecided" if r.get("final_state") == "undecided" else ""} for r in data["rows"]],
        row_cols=ROW_COLUMNS,
        damaged=data.get("damaged", []),
    )
