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
    """Statements on the largest Lyapunov exponents: is each distinguishable from zero, and how
    the chain of eq. (4) compares with its plate-driven relatives."""
    out: dict[str, Any] = {"statements": [], "chain": {}, "family": {}}
    say = out["statements"].append
    chain = table[table["model"].map(is_paper)].sort_values("beta")
    lam = chain["lyapunov"].to_numpy(float)
    err = chain["lyapunov_err"].to_numpy(float)
    ok = np.isfinite(lam) & np.isfinite(err) & (err > 0)
    if ok.any():
        z = lam[ok] / err[ok]
        pos, neg = chain["beta"][ok][z > 3].tolist(), chain["beta"][ok][z < -3].tolist()
        bound = float(np.max(np.abs(lam[ok]) + 2 * err[ok]))
        out["chain"] = {"n": int(ok.sum()), "positive_3sigma": pos, "negative_3sigma": neg, "bound_2sigma": bound}
        Ns = sorted(int(n) for n in chain["N"].unique())
        say(
            f"eq. (4), N = {', '.join(map(str, Ns))}: lambda within 3 error bars of zero at "
            f"{int(np.count_nonzero(np.abs(z) <= 3))} of {int(ok.sum())} values of beta "
            f"(|lambda| + 2 errors <= {_g(bound, 2)} per unit time everywhere)"
            + (f"; positive beyond 3 errors at beta = {', '.join(f'{b:g}' for b in pos)}" if pos else "")
            + (f"; negative beyond 3 errors at beta = {', '.join(f'{b:g}' for b in neg)}" if neg else "")
            + "."
        )
        per_event = chain["lyapunov_per_event"].to_numpy(float)[ok]
        if np.isfinite(per_event).any():
            say(
                f"eq. (4): per slip event, lambda ranges over [{_g(np.nanmin(per_event), 2)}, "
                f"{_g(np.nanmax(per_event), 2)}]."
            )
    for model, g in table[~table["model"].map(is_paper)].groupby("model"):
        rows = g.sort_values("d0")
        vals = ", ".join(f"{_g(r.lyapunov)} +- {_g(r.lyapunov_err, 2)} (d0 = {r.d0:g})" for r in rows.itertuples())
        lam_m = rows["lyapunov"].to_numpy(float)
        err_m = rows["lyapunov_err"].to_numpy(float)
        # A twin that falls onto the reference makes the exponent -inf (no number): judge the
        # values of d0 that gave one, and name the others.
        fin = np.isfinite(lam_m) & np.isfinite(err_m)
        positive = bool(fin.any() and np.all(lam_m[fin] > 3 * err_m[fin]))
        out["family"][model] = {
            "lyapunov": lam_m.tolist(),
            "lyapunov_err": err_m.tolist(),
            "d0": rows["d0"].tolist(),
            "positive_3sigma": positive,
        }
        verdict = "chaotic (positive beyond 3 errors)" if positive else "not positive beyond 3 errors"
        if not fin.any():
            verdict = "no finite exponent"
        elif not fin.all():
            verdict += f" at d0 = {', '.join(f'{d:g}' for d in rows['d0'][fin])}"
        if fin.sum() > 1:
            verdict += f"; spread over d0 {_g(np.ptp(lam_m[fin]), 2)} against errors of {_g(np.max(err_m[fin]), 2)}"
        lost = [
            f"d0 = {r.d0:g} (the twin fell onto the reference {int(r.merges)} times: d0 at the rounding floor)"
            if "merges" in rows and np.isfinite(r.merges) and r.merges > 0
            else f"d0 = {r.d0:g}"
            for r, f in zip(rows.itertuples(), fin, strict=True)
            if not f
        ]
        if lost:
            verdict += "; no exponent at " + ", ".join(lost)
        say(f"{model} (N = {int(rows['N'].iloc[0])}): lambda = {vals}: {verdict}.")
    _verdicts(table, out)
    return out


def _verdicts(table: pd.DataFrame, out: dict[str, Any]) -> None:
    """One statement: which points the flow exponent and the decorrelation of the event sequence
    call chaotic, stable chaos or regular (:func:`stickslip.analysis.decorrelation.verdict`)."""
    if "verdict" not in table.columns or not table["verdict"].notna().any():
        return
    rows = table[table["verdict"].notna()]
    out["verdicts"] = {}
    parts = []
    for label, g in rows.groupby("verdict", sort=False):
        names = [PRESETS[r.model].point_label(r.beta, r.N) for r in g.itertuples()]
        out["verdicts"][label] = names
        parts.append(f"{label} at {', '.join(names)}")
    if "fsle_unfinished" in rows.columns and rows["fsle_unfinished"].notna().any():
        parts_f = []
        for r in rows[rows["fsle_unfinished"].notna()].itertuples():
            # the relatives have no beta (their friction has none)
            name = f"beta = {r.beta:g} (N = {int(r.N)})" if _finite(r.beta) else r.model
            pooled = f"{_g(r.fsle_pooled, 2)}" if _finite(r.fsle_pooled) else "no doubling below 1e-6"
            peak = (
                f"largest {_g(r.fsle_peak, 2)} at delta = {r.fsle_peak_delta:.2g}" if _finite(r.fsle_peak) else "none"
            )
            parts_f.append(
                f"{name}: {pooled}, {peak}"
                + (
                    f", {int(r.fsle_unfinished)} cycles unfinished"
                    if _finite(r.fsle_unfinished) and r.fsle_unfinished
                    else ""
                )
            )
        out["statements"].append("Finite-size exponent (pooled below 1e-6; largest row): " + "; ".join(parts_f) + ".")
    out["statements"].append(
        "Verdict (flow exponent at dt -> 0, decorrelation of the event sequence against delta): "
        + "; ".join(parts)
        + "."
    )


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
        figs.append(
            (
                "lyapunov_beta",
                pl.chaos_figure(table),
                "Largest Lyapunov exponent (Benettin et al. two-trajectory method, d0 = 1e-10 unless "
                "marked) against beta for eq. (4), error bars from 10 segments; right: two blocks and "
                "Carlson-Langer at standard parameters as marked points.",
            )
        )
        figs += _flow_figures(spec, table, page_dir)
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


def chaos_curves(table: pd.DataFrame, points_dir: Path) -> list[dict[str, Any]]:
    """The ``flow.json`` of every chaos point that has one (ladder, finite-size exponents,
    decorrelation: :func:`stickslip.experiments.chaos_verdict.verdict_point`), labelled by model,
    N and beta; chain points by N then beta, the relatives last."""
    from stickslip import io

    curves = []
    if "point_dir" not in table.columns:
        return curves
    for r in table.itertuples():
        path = Path(points_dir) / str(r.point_dir) / "flow.json"
        if not path.is_file():
            continue
        chain = _finite(r.beta)  # the relatives have no beta
        label = f"eq. (4), N = {int(r.N)}, beta = {r.beta:g}" if chain else f"{r.model}, N = {int(r.N)}"
        key = (0, int(r.N), float(r.beta)) if chain else (1, 0, 0.0)
        curves.append((key, {"label": label, **io.read_json(path)}))
    return [c for _, c in sorted(curves, key=lambda x: x[0])]


def _flow_figures(spec: Study, table: pd.DataFrame, page_dir: Path) -> list[tuple[str, Any, str]]:
    """lambda of the flow against dt, the FSLE against delta and n(delta) against delta, from the
    points' ``flow.json`` (:mod:`stickslip.plotting.chaos`)."""
    from stickslip.plotting import chaos as pc

    curves = chaos_curves(table, Path(page_dir).parent / "runs" / spec.dirname / "points")
    if not curves:
        return []
    out = [
        (
            "flow_ladder",
            pc.flow_ladder_figure(curves),
            "Largest exponent of the flow (located switches, the time shift removed) at dt, dt/2, "
            "dt/4, with the fit lambda_0 + c dt^2 and lambda_0 (square) at dt = 0.",
        )
    ]
    if any(c.get("finite_size") for c in curves):
        out.append(
            (
                "fsle",
                pc.fsle_figure(curves),
                "Finite-size Lyapunov exponent ln 2 / <time from delta to 2 delta> against delta "
                "(located switches); rows with no finished doubling are left out.",
            )
        )
    out.append(
        (
            "decorrelation",
            pc.decorrelation_figure(curves),
            "Slip events whose sizes agree (to 1e-3) between runs started delta apart; open "
            "triangles: still agreeing after all the events compared.",
        )
    )
    return out
