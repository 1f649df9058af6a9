"""The page of a laboratory protocol (``stickslip lab step|shs|fit|invert --out DIR``): ``index.html``.

One page per protocol run, beside its NetCDF, JSON and figures: the command, what the run found
(the lines the command prints), the figures embedded, the model's parameters and the protocol's
own table (the steps of a velocity-step test, the holds of a slide-hold-slide test, the fitted
parameters with their standard errors and correlations). Written from the package's template
``lab.html.j2`` through :func:`stickslip.pages.write_page`, every value escaped.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from stickslip.pages import image_src, write_page

__all__ = ["PAGE", "lab_tables", "write_lab_page"]

#: The page's file name in ``--out``.
PAGE = "index.html"

#: The title of each protocol's page.
TITLES = {
    "step": "Velocity-step test",
    "shs": "Slide-hold-slide test",
    "fit": "Fit of rate-and-state friction",
    "invert": "Inversion of a stick-slip record",
}


def _parameter_rows(data: dict[str, Any]) -> list[dict[str, Any]]:
    """The fitted parameters with their standard errors (and the posterior's where there is one)."""
    post = data.get("posterior", {}).get("parameters", {})
    rows = []
    for name, p in data.get("parameters", {}).items():
        row = {"parameter": name, "value": p["value"], "standard error": p["stderr"]}
        if name in post:
            lo, hi = post[name]["interval_95"]
            row |= {"posterior mean": post[name]["mean"], "posterior std": post[name]["std"]}
            row |= {"95% low": lo, "95% high": hi}
        rows.append(row)
    return rows


def lab_tables(protocol: str, data: dict[str, Any]) -> list[dict[str, Any]]:
    """The tables of a protocol's page, each ``{"title", "rows", "cols"}``, from the protocol's
    summary ``data`` (the command's ``--json``): the steps of a velocity-step test, the holds of a
    slide-hold-slide test (and its healing rate, Delta mu per decade of hold time), the fitted
    parameters of a fit or an inversion with their correlation matrix, the observables of an
    inversion, and the model's parameters."""
    tables = []
    if protocol == "step":
        cols = ["t", "V_before", "V_after", "mu_before", "mu_peak", "mu_end", "mu_ss_closed_form", "a_minus_b_from_run"]
        tables.append({"title": "Steps", "rows": data["steps"], "cols": cols})
    elif protocol == "shs":
        cols = ["t_hold", "mu_peak", "delta_mu", "relaxation"]
        tables.append({"title": "Holds", "rows": data["holds"], "cols": cols})
    else:
        rows = _parameter_rows(data)
        cols = ["parameter", "value", "standard error"]
        if rows and "posterior mean" in rows[0]:
            cols += ["posterior mean", "posterior std", "95% low", "95% high"]
        tables.append({"title": "Parameters", "rows": rows, "cols": cols})
        corr = data.get("correlation", {})
        if corr:
            names = list(corr)
            corr_rows = [{"": a, **{b: corr[a][b] for b in names}} for a in names]
            tables.append({"title": "Correlations", "rows": corr_rows, "cols": ["", *names]})
        obs = data.get("observables", {})
        if obs:
            obs_rows = [{"observable": k, **v} for k, v in obs.items()]
            cols = ["observable", "observed", "stderr", "model"]
            tables.append({"title": "Observables of the cycles", "rows": obs_rows, "cols": cols})
    model = data.get("model", {})
    if model:
        rows = [{"name": k, "value": v if isinstance(v, (int, float)) else str(v)} for k, v in model.items()]
        tables.append({"title": "Model", "rows": rows, "cols": ["name", "value"]})
    return tables


def write_lab_page(
    out: str | Path,
    protocol: str,
    data: dict[str, Any],
    *,
    command: str,
    statements: list[str],
    figures: list[str],
    outputs: list[str],
) -> Path:
    """Write ``out/index.html``: the page of one laboratory protocol run (the module's docstring).

    Parameters
    ----------
    out : path
        The command's ``--out`` directory (the figures' PNG files are read from there and embedded).
    protocol : {"step", "shs", "fit", "invert"}
        The protocol (``stickslip lab step``: velocity steps; ``shs``: slide-hold-slide; ``fit``:
        least squares of rate-and-state friction; ``invert``: the inversion of stick-slip cycles).
    data : dict
        The protocol's summary, as ``--json`` prints it.
    command : str
        The command line that made the run.
    statements : list of str
        What the run found, one line each.
    figures : list of str
        The stems of the figures saved in ``out`` (``step``, ``fit``, ...).
    outputs : list of str
        The files written, linked from the page.

    Returns
    -------
    pathlib.Path
        The page.
    """
    out = Path(out)
    page_figures = [{"title": stem, "src": image_src(f"{stem}.png", out)} for stem in figures]
    return write_page(
        out / PAGE,
        "lab.html.j2",
        title=TITLES[protocol],
        command=command,
        statements=statements,
        figures=page_figures,
        tables=lab_tables(protocol, data),
        outputs=[Path(p).name for p in outputs],
    )
