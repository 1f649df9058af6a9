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

from stickslip.analysis.order import power_law_fit, transition_bracket
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
    return {"transition": _transition, "phase-diagram": _phase, "exponents": _exponents, "chaos": _chaos}[spec.name](
        table
    )


def _transition(table: pd.DataFrame) -> dict[str, Any]:
    out: dict[str, Any] = {"per_N": {}, "statements": []}
    say = out["statements"].append
    undecided = table[table["final_state"] == "undecided"]
    if len(undecided):
        say(
            "Undecided points (still changing at the end, not averaged as settled): "
            + ", ".join(f"N = {r.N}, beta = {r.beta:g}" for r in undecided.itertuples())
            + "."
        )
    for N, g in sorted(table.groupby("N"), key=lambda x: x[0]):
        g = g.sort_values("beta")
        br = transition_bracket(g["beta"], g["final_state"])
        below = g[(g["beta"] < 1.0) & (g["final_state"] == "stick-slip")]
        fit = power_law_fit(
            1.0 - below["beta"].to_numpy(float),
            below["order_parameter"].to_numpy(float),
            below["order_parameter_err"].to_numpy(float),
        )
        above = g[g["beta"] > 1.0]
        not_steady = above[above["final_state"] != "steady"]
        jump = math.nan
        if math.isfinite(br["lo"]) and math.isfinite(br["hi"]):
            m_lo = float(g.loc[g["beta"] == br["lo"], "order_parameter"].iloc[0])
            m_hi = float(g.loc[g["beta"] == br["hi"], "order_parameter"].iloc[0])
            jump = m_lo - m_hi
        m_max = float(g["order_parameter"].max())
        stuck_above = float(above["stuck_fraction"].mean()) if len(above) else math.nan
        out["per_N"][int(N)] = {
            **br,
            "fit": fit,
            "jump": jump,
            "m_max": m_max,
            "betas_above_1_not_steady": not_steady["beta"].tolist(),
            "mean_stuck_fraction_above_1": stuck_above,
        }
        if math.isfinite(br["estimate"]):
            where = (
                f"between beta = {br['lo']:g} (last stick-slip) and {br['hi']:g} (first steady): "
                f"beta_t = {br['estimate']:.3g} +- {br['uncertainty']:.2g}"
            )
        elif math.isfinite(br["lo"]):
            where = f"above beta = {br['lo']:g}: every point up to the largest beta still stick-slips or is undecided"
        else:
            where = "not bracketed: no point ends in stick-slip"
        if br["undecided"]:
            where += f" (undecided inside the bracket: {br['undecided']})"
        say(f"N = {N}: transition {where}.")
        if math.isfinite(jump):
            kind = (
                "small against the range of m, consistent with a continuous transition at this resolution"
                if abs(jump) < 0.25 * max(m_max, 1e-12)
                else "a visible jump"
            )
            say(f"N = {N}: m falls by {_g(jump)} across the bracket (max m = {_g(m_max)}): {kind}.")
        if math.isfinite(fit["b"]):
            say(
                f"N = {N}: m ~ (1 - beta)^b for beta < 1 with b = {fit['b']:.2f} +- {fit['b_err']:.2f} "
                f"({fit['n']} points)."
            )
    pn = out["per_N"]
    Ns = sorted(pn)
    if len(Ns) > 1:
        counts = ", ".join(
            f"N = {N}: {len(pn[N]['betas_above_1_not_steady'])} of "
            f"{int((table[(table['N'] == N)]['beta'] > 1).sum())} "
            f"(stuck fraction {_g(pn[N]['mean_stuck_fraction_above_1'])})"
            for N in Ns
        )
        n_not = [len(pn[N]["betas_above_1_not_steady"]) for N in Ns]
        trend = "shrinks" if n_not[-1] < n_not[0] else "grows" if n_not[-1] > n_not[0] else "does not change"
        say(
            f"Points above beta = 1 not in steady sliding at the end ({counts}): with N the stick-slip region "
            f"above beta = 1 {trend} at these run lengths (runs of the same number of loading times)."
        )
        bs = [pn[N]["fit"]["b"] for N in Ns if math.isfinite(pn[N]["fit"]["b"])]
        if len(bs) > 1:
            errs = [pn[N]["fit"]["b_err"] for N in Ns if math.isfinite(pn[N]["fit"]["b"])]
            agree = max(bs) - min(bs) <= 2 * math.hypot(max(errs), max(errs))
            say(
                f"Collapse: exponents b = {', '.join(f'{b:.2f}' for b in bs)} "
                + (
                    "agree within errors: m(1 - beta) needs no N-dependent rescaling."
                    if agree
                    else "differ: no simple collapse of m against 1 - beta."
                )
            )
    return out


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
    if spec.name == "transition":
        fits = {int(N): conclusions(spec, table)["per_N"][int(N)]["fit"] for N in table["N"].unique()}
        figs.append(
            (
                "order_parameter",
                pl.order_parameter_figure(table),
                "Order parameter m = 1 - <L>/L_ss against beta for each N (second half of each run; "
                "batch-means error bars; large open circles: undecided).",
            )
        )
        if table["t_steady"].notna().any():
            figs.append(
                (
                    "steady_time",
                    pl.steady_time_figure(table),
                    "Time to reach steady sliding (every block within 1e-6 of it), in loading times, "
                    "where it was reached.",
                )
            )
        figs.append(
            (
                "collapse",
                pl.collapse_figure(table, fits),
                "m against 1 - beta (log-log) for the stick-slip points below beta = 1, with power-law fits.",
            )
        )
    elif spec.name == "phase-diagram":
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
