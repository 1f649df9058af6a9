"""The outputs of ``stickslip catalog``: the catalogue's tables, figures, JSON and its page.

:func:`write_catalog` writes, into one folder, what :func:`stickslip.analysis.stats.catalog.catalog_analysis`
found: ``catalog.parquet``/``.csv`` (one row per slip), ``moment_rate.parquet``/``.csv`` (where
the run kept profiles), ``catalog.json`` (every number), the figures of
:mod:`stickslip.plotting.catalog` as PNG and PDF, and ``index.html`` from the package's template
``catalog.html.j2``; :func:`catalog_statements` says in sentences what the numbers mean.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from stickslip import io
from stickslip.analysis.stats.catalog import CATALOG_DOCS, Catalog
from stickslip.pages import image_src, write_page
from stickslip.plotting.catalog import catalog_figures
from stickslip.plotting.style import FIGURE_FORMATS, save_figure
from stickslip.run.ownership import CATALOG_FIGURES, CATALOG_FILES

__all__ = ["write_catalog", "catalog_statements", "CATALOG_FILES", "FIGURE_STEMS"]

#: The figures, and every file ``stickslip catalog`` may write into its folder (named with the run
#: directory's files, :mod:`stickslip.run.ownership`, so that a chain run knows them).
FIGURE_STEMS = CATALOG_FIGURES


def _g(x: Any, digits: int = 3) -> str:
    return "n/a" if x is None or (isinstance(x, float) and not math.isfinite(x)) else f"{x:.{digits}g}"


#: What the paper states of the slip sizes of its chain (section 3, Figs. 7, 8), by beta: cited
#: only on the catalogue of a run of the paper's chain at that beta.
PAPER_SIZES = {
    1.0: {"whole_range": "; the paper: 1.5 at beta = 1"},
    0.2: {"below_spanning": " (the paper: about 1.6 and an excess at beta = 0.2)"},
}


def _paper_says(summary: dict[str, Any], reading: str) -> str:
    """The paper's statement on ``reading`` for this run, or "" for a run the paper did not make."""
    return PAPER_SIZES.get(summary.get("paper_beta"), {}).get(reading, "")


def catalog_statements(summary: dict[str, Any]) -> list[str]:
    """What the catalogue's numbers say, one sentence each (the page's list, the command's text)."""
    out = []
    sizes = summary["sizes"]
    w = sizes.get("whole_range", {})
    if "tau" in w:
        out.append(
            f"Size exponent tau = {_g(w['tau'])} ± {_g(w['tau_err'], 2)} (truncated power law on S in "
            f"[{_g(w['s_min'])}, {_g(w['s_max'])}], {w['n']} slips{_paper_says(summary, 'whole_range')})."
        )
    b = sizes.get("below_spanning", {})
    if "tau" in b:
        out.append(
            f"Below the smallest system-spanning slip (S < {_g(b['s_max'])}): tau = {_g(b['tau'])} ± "
            f"{_g(b['tau_err'], 2)}; spanning slips are {_g(b['excess'])} times as many as that power law "
            f"predicts{_paper_says(summary, 'below_spanning')}."
        )
    fm = summary["frequency_magnitude"]
    bv = fm.get("b_value")
    if bv:
        c = fm["completeness"]
        out.append(
            f"b-value {_g(bv['b'])} ± {_g(bv['b_err_shi_bolt'], 2)} (Shi-Bolt; bootstrap ± "
            f"{_g(bv['b_err_bootstrap'], 2)}) from {bv['n']} slips with M >= Mc = {_g(c['mc'])} ({c['method']})."
        )
    elif fm.get("reason"):
        out.append(fm["reason"])
    if fm.get("truncated_gr"):
        gr = fm["truncated_gr"]
        out.append(
            f"Doubly truncated Gutenberg-Richter on the tau fit's range: b = {_g(gr['b'])} ± {_g(gr['b_err'], 2)}, "
            f"the same law as tau: (3/2)(tau - 1) = {_g(fm['b_from_tau'])}."
        )
    dist = summary["distributions"]
    for c in dist.get("comparisons", []):
        if c.get("verdict") is None:
            out.append(f"power law against {c['alternative']}: {c['reason']}")
            continue
        out.append(
            f"power law against {c['alternative']}: normalised log-likelihood ratio {_g(c['normalized_ratio'])}, "
            f"p = {_g(c['p'], 2)}{' (nested)' if c['nested'] else ''}: "
            + ("undecided" if c["verdict"] == "undecided" else f"favours {c['verdict']}")
        )
    gof = summary["goodness_of_fit"]
    if "p" in gof:
        out.append(
            f"Goodness of fit of the power law: KS distance {_g(gof['D'])}, p = {_g(gof['p'], 2)} from {gof['sims']} "
            f"synthetic catalogues ({'plausible: p > 0.1' if gof['p'] > 0.1 else 'rejected: p <= 0.1'})."
        )
    for key, rec in summary["recurrence"].items():
        if rec.get("best"):
            out.append(
                f"Recurrence of {key} slips: {rec['n']} intervals, mean {_g(rec['mean'])}, CV {_g(rec['cv'])}; "
                f"least AIC: {rec['best']}."
            )
        else:
            out.append(f"Recurrence of {key} slips: {rec.get('reason', 'no fit')}.")
    return out


def _records(summary: dict[str, Any]) -> dict[str, Any]:
    """The tables of the page."""
    size_rows = []
    for key, v in summary["sizes"].items():
        row = {
            "reading": key.replace("_", " "),
            **{k: v.get(k) for k in ("tau", "tau_err", "s_min", "s_max", "n", "ks_distance")},
        }
        row["note"] = v.get("reason", "")
        size_rows.append(row)
    dist = summary["distributions"]
    candidates = []
    for name, f in dist.get("fits", {}).items():
        if isinstance(f, str):
            candidates.append({"candidate": name, "parameters": f})
        else:
            shown = ", ".join(f"{k} = {v:.4g}" for k, v in f["params"].items())
            candidates.append({"candidate": name, "parameters": shown, "log L": f["loglikelihood"], "AIC": f["aic"]})
    renewal_rows = []
    for key, rec in summary["recurrence"].items():
        for f in rec.get("fits", []):
            shown = ", ".join(f"{k} = {v:.4g} ± {f['errors'][k]:.2g}" for k, v in f.get("params", {}).items())
            renewal_rows.append(
                {
                    "slips": key,
                    "model": f["model"],
                    "parameters": shown or f.get("reason", ""),
                    "AIC": f.get("aic"),
                    "delta AIC": f.get("delta_aic"),
                    "weight": f.get("weight"),
                }
            )
        if not rec.get("fits"):
            renewal_rows.append({"slips": key, "model": "", "parameters": rec.get("reason", "")})
    return {
        "size_rows": size_rows,
        "size_cols": ["reading", "tau", "tau_err", "s_min", "s_max", "n", "ks_distance", "note"],
        "comparisons": dist.get("comparisons", []),
        "comparison_cols": ["alternative", "R", "normalized_ratio", "p", "nested", "verdict"],
        "candidates": candidates,
        "candidate_cols": ["candidate", "parameters", "log L", "AIC"],
        "renewal_rows": renewal_rows,
        "renewal_cols": ["slips", "model", "parameters", "AIC", "delta AIC", "weight"],
        "moment_rows": summary["moment_rate"]["events"],
        "moment_cols": ["event", "S", "magnitude", "duration", "windows", "covered_fraction", "peak_rate", "t_peak"],
    }


def write_catalog(
    cat: Catalog,
    out: str | Path,
    *,
    run_dir: str | Path,
    command: str,
    formats: tuple[str, ...] = FIGURE_FORMATS,
) -> dict[str, Any]:
    """Write every output of a catalogue into ``out`` (module docstring); returns ``outputs`` (file
    names, relative to ``out``) and ``figures`` (one record per figure, drawn or with the reason)."""
    out = Path(out)
    meta = {"run_dir": str(run_dir), "command": command}
    outputs = [p.name for p in io.write_table_files(out / "catalog", cat.table, CATALOG_DOCS, metadata=meta)]
    if cat.moment_rate is not None and not cat.moment_rate.empty:
        outputs += [p.name for p in io.write_table_files(out / "moment_rate", cat.moment_rate, metadata=meta)]
    figures = []
    for stem, title, fig, why in catalog_figures(cat):
        if fig is None:
            figures.append({"figure": stem, "title": title, "skipped": why or "nothing to draw"})
            continue
        files = [p.name for p in save_figure(fig, out / stem, formats=formats)]
        outputs += files
        figures.append({"figure": stem, "title": title, "files": files})
    outputs += ["catalog.json", "index.html"]
    summary = {**cat.summary, "statements": catalog_statements(cat.summary)}
    io.write_json(out / "catalog.json", {**meta, **summary, "outputs": outputs, "figures": figures})
    page_figures = [
        {
            "title": f["title"],
            "skipped": f.get("skipped", ""),
            "src": image_src(f"{f['figure']}.png", out) if "files" in f and "png" in formats else "",
        }
        for f in figures
    ]
    write_page(
        out / "index.html",
        "catalog.html.j2",
        s=cat.summary,
        command=command,
        run_dir=str(run_dir),
        outputs=outputs,
        statements=summary["statements"],
        figures=page_figures,
        **_records(cat.summary),
    )
    return {"outputs": outputs, "figures": figures, "statements": summary["statements"]}
