"""The HTML page of the transition study by continuation (``OUT/transition/index.html``): the
command, wall time and cores, what the data say, the figures, the per-N table and the rungs."""

from __future__ import annotations

import base64
import html
import math
from pathlib import Path
from typing import Any

from stickslip import io

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

_CSS = """
body { font-family: system-ui, sans-serif; margin: 2em auto; max-width: 76em; padding: 0 1em; color: #222; }
table { border-collapse: collapse; font-size: 0.85em; } th, td { border: 1px solid #ccc; padding: 0.25em 0.45em; }
th { background: #f3f3f3; } figure { display: inline-block; margin: 0.8em; max-width: 70em; }
figure img { max-width: 100%; border: 1px solid #ddd; } td.undecided { background: #fbefd5; }
"""


def _cell(v: Any) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return ""
    if isinstance(v, float):
        return f"{v:.4g}"
    return html.escape(str(v))


def _table(records: list[dict[str, Any]], cols: list[str], mark: str | None = None) -> str:
    parts = ["<table><thead><tr>" + "".join(f"<th>{html.escape(c)}</th>" for c in cols) + "</tr></thead><tbody>"]
    for r in records:
        cls = ' class="undecided"' if mark and r.get(mark) == "undecided" else ""
        parts.append(f"<tr{cls}>" + "".join(f"<td>{_cell(r.get(c))}</td>" for c in cols) + "</tr>")
    return "".join(parts) + "</tbody></table>"


def write_page(path: Path, data: dict[str, Any]) -> None:
    """Write the page of one run of the study (``data`` as in ``study.json``)."""
    meta = data["meta"]
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>Study: transition ({html.escape(meta['mode'])})</title><style>{_CSS}</style></head><body>",
        f"<h1>Study: transition at beta = 1 by continuation ({html.escape(meta['mode'])})</h1>",
        f"<p><code>{html.escape(meta['command'])}</code>: {meta['ladders']} ladders ({meta['ladders_run']} run, "
        f"{meta['ladders_reused']} reused, "
        f"{meta.get('ladders_damaged', 0)} run again because their files were damaged, "
        f"{meta['failed']} failed), {meta['rungs']} rungs, {meta['undecided']} "
        f"undecided; {meta['wall_seconds']} s wall on {meta['workers']} workers, {meta['cores']} cores; "
        f"stickslip {html.escape(meta['version'])}.</p><h2>What the data say</h2><ul>",
    ]
    parts += [f"<li>{html.escape(s)}</li>" for s in data["statements"]]
    parts.append("</ul><h2>Figures</h2>")
    for name in data["figures"]:
        png = path.parent / name
        src = "data:image/png;base64," + base64.b64encode(png.read_bytes()).decode() if png.is_file() else name
        parts.append(f'<figure><img src="{src}" alt="{html.escape(name)}"></figure>')
    parts.append("<h2>Per N</h2>" + _table(data["per_N"], PER_N_COLUMNS + ["undecided", "rungs"]))
    parts.append(
        '<h2>Rungs</h2><p>Data: <a href="table.parquet">table.parquet</a>, <a href="table.csv">table.csv</a>, '
    )
    parts.append('<a href="study.json">study.json</a>.</p>' + _table(data["rows"], ROW_COLUMNS, "final_state"))
    parts.append("</body></html>\n")
    io.write_bytes(path, "\n".join(parts).encode("utf-8"))
