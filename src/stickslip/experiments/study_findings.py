"""What each study's table says (statements for its page and ``--json``) and its figures.

The numbers come from :mod:`stickslip.analysis.order` (transition brackets, power-law fits of
m); the figures from :mod:`stickslip.plotting.studies`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from stickslip.analysis.order import transition_bracket
from stickslip.experiments.studies import Study, study_command
from stickslip.models.presets import PRESETS, is_paper

__all__ = ["conclusions", "draw"]


def _finite(x) -> bool:
    return x is not None and math.isfinite(float(x))


def _g(x: float, digits: int = 3) -> str:
    return "n/a" if x is None or not math.isfinite(float(x)) else f"{float(x):.{digits}g}"


def conclusions(spec: Study, table: pd.DataFrame) -> dict[str, Any]:
    """Findings of a study from the rows of its finished points."""
    if not len(table):
        return {"statements": ["no finished points"]}
    return {"phase-diagram": _phase, "exponents": _exponents, "chaos": _chaos}[spec.name](table)


def _phase(table: pd.DataFrame) -> dict[str, Any]:
    out: dict[str, Any] = {"statements": [], "disagree": []}
    say = out["statements"].append
    cells = table.groupby(["alpha", "D", "beta"])
    n_cells = n_dis = 0
    agree_lin = n_lin = 0
    for (a, d, b), g in cells:
        states = dict(zip(g["start"], g["final_state"], strict=False))
        n_cells += 1
        if len(set(states.values())) > 1:
            n_dis += 1
            out["disagree"].append({"alpha": a, "D": d, "beta": b, **states})
        if states.get("paper") in ("steady", "stick-slip"):
            n_lin += 1
            agree_lin += (states["paper"] == "steady") == (b > a)
    say(
        f"{n_cells} cells; the two starts end differently in {n_dis} of them"
        + (
            ": "
            + "; ".join(
                f"alpha = {c['alpha']:g}, D = {c['D']:g}, beta = {c['beta']:g} (paper: {c.get('paper')}, "
                f"steady: {c.get('steady')})"
                for c in out["disagree"]
            )
            if n_dis
            else ""
        )
        + "."
    )
    say(
        f"From the paper's start, {agree_lin} of {n_lin} settled cells are on the side of beta_c = alpha that "
        f"linear stability predicts (steady for beta > alpha, stick-slip below)."
    )
    for a, g in table[(table["D"] == 5.0) & (table["start"] == "paper")].groupby("alpha"):
        br = transition_bracket(g["beta"], g["final_state"])
        say(
            f"alpha = {a:g} (D = 5, paper's start): last stick-slip beta = {_g(br['lo'])}, first steady above it "
            f"= {_g(br['hi'])} (beta_c = alpha = {a:g})."
        )
    for d, g in table[(table["alpha"] == 1.0) & (table["start"] == "paper")].groupby("D"):
        br = transition_bracket(g["beta"], g["final_state"])
        say(
            f"D = {d:g} (alpha = 1, paper's start): last stick-slip beta = {_g(br['lo'])}, first steady above it "
            f"= {_g(br['hi'])}."
        )
    return out


def _exponents(table: pd.DataFrame) -> dict[str, Any]:
    out: dict[str, Any] = {"statements": []}
    say = out["statements"].append
    for r in table.sort_values(["model", "beta"]).itertuples():
        label = PRESETS[r.model].point_label(r.beta, r.N, with_N=False)
        say(
            f"{label}: tau = {_g(r.tau)} +- {_g(getattr(r, 'tau_err', math.nan), 2)} on S in "
            f"[{_g(getattr(r, 's_min', math.nan))}, {_g(getattr(r, 's_max', math.nan))}] "
            f"({_g(getattr(r, 'n_fit', math.nan))} of {r.n_events} events), great-event excess "
            f"{_g(getattr(r, 'excess', math.nan))} ({getattr(r, 'observed', 'n/a')} observed / "
            f"{_g(getattr(r, 'expected', math.nan))} expected)."
        )
    chain = table[table["model"].map(is_paper)].sort_values("beta")
    ok = chain[np.isfinite(chain["tau"].astype(float))]
    if len(ok) > 1:
        slope = np.polyfit(ok["beta"].astype(float), ok["tau"].astype(float), 1)[0]
        say(
            f"eq. (4): tau changes by {slope:+.2f} per unit beta between beta = {ok['beta'].min():g} and "
            f"{ok['beta'].max():g} (least squares)."
        )
    return out


def _chaos(table: pd.DataFrame) -> dict[str, Any]:
    """The chaos study's findings (:func:`stickslip.experiments.chaos_findings.conclusions`)."""
    from stickslip.experiments.chaos_findings import conclusions as chaos_conclusions

    return chaos_conclusions(table)


def draw(spec: Study, table: pd.DataFrame, page_dir: Path) -> list[dict[str, Any]]:
    """Draw the study's figures into ``page_dir`` (PNG and PDF); returns their descriptions."""
    from stickslip.plotting import studies as pl
    from stickslip.plotting.style import save_figure

    cmd = study_command(spec.name, spec.mode)
    figs: list[tuple[str, Any, str]] = []
    if not len(table):
        return []
    if spec.name == "phase-diagram":
        figs.append(
            (
                "phase_alpha_beta",
                pl.phase_map_figure(table[table["D"] == 5.0], "alpha", "D = 5"),
                "Final state and m over (alpha, beta) at D = 5; dashed: beta_c = alpha.",
            )
        )
        figs.append(
            (
                "phase_D_beta",
                pl.phase_map_figure(table[table["alpha"] == 1.0], "D", "alpha = 1"),
                "Final state and m over (D, beta) at alpha = 1; dashed: beta_c = alpha = 1.",
            )
        )
    elif spec.name == "chaos":
        from stickslip.experiments.chaos_findings import figures as chaos_figures

        figs += chaos_figures(table, Path(page_dir).parent / "runs" / spec.dirname / "points", page_dir)
    else:
        figs.append(
            (
                "tau_beta",
                pl.exponents_figure(table),
                "Slip-size exponent tau (truncated power law below the smallest spanning event, "
                "bootstrap errors) and great-event excess against beta; Carlson-Langer as a band.",
            )
        )
    out = []
    for name, fig, caption in figs:
        save_figure(fig, page_dir / name)
        out.append({"name": name, "image": f"{name}.png", "pdf": f"{name}.pdf", "caption": caption, "command": cmd})
    return out
