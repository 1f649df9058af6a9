"""``stickslip study lifetimes``: how long the irregular motion of the chain of eq. (4) and its
relatives lasts against N, the standard test of stable chaos (Politi, Livi, Oppo and Kapral,
Europhys. Lett. 22, 571 (1993); Politi and Torcini, arXiv:0902.2545): a transient whose lifetime
grows exponentially with the system size (docs/studies/lifetimes.md).

Models are a dimension of the study: the paper's chain (eq. 4) at N from 3 up and beta = 0.5,
0.9, 1, 1.1; the train model (eq. 4 with F0 + beta v) at the same N; two blocks (N = 2, fixed);
Carlson-Langer (periodic ends) at N = 8 and up. Two kinds of point
(:mod:`stickslip.experiments.studies.lifetimes_points`):

- a **lifetime**: one start (a perturbed paper start, a seeded rest start, or a loaded start),
  run until its slip sequence is periodic (:class:`stickslip.analysis.stats.periodicity.PeriodicStop`),
  it slides steadily (``until_steady``) or its budget of time is spent (censored);
- an **exponent**: from the model's own start run to a transient, the flow's largest exponent at
  dt (located switches), whether the engine's slips repeat over the same time, and the
  decorrelation threshold of perturbations of the state.

The findings (:func:`conclusions`), per model, beta and N: the lifetimes ended and censored,
<T> by the maximum-likelihood exponential law of censored data
(:func:`stickslip.analysis.stats.survival.exponential_fit`; a lower bound where none ended), the
Weibull test of the exponential law, the periods reached, the exponent and the threshold, and
the revised verdict (:func:`stickslip.analysis.dynamics.chaos_verdict.chaos_verdict`); per model and beta
the fits of ln <T> on N and on ln N (:func:`stickslip.analysis.stats.survival.size_fits`) over the N
with at least two ended lifetimes, and for the paper's chain the extrapolation to N = 399 with
its one-sided 95 % lower bound. The figures: Kaplan-Meier survival curves, <T> against N and the
exponent against N (:mod:`stickslip.plotting.lifetimes`).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from stickslip.experiments.studies import Design, Study, finite, short
from stickslip.experiments.studies.lifetimes_points import (  # noqa: F401 (the study's points, re-exported)
    STARTS,
    check_point,
    exponent_point,
    lifetime_point,
    start_state,
    task,
)
from stickslip.models.presets import PRESETS, is_paper

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["DESIGN", "lifetime_point", "exponent_point", "conclusions", "start_state", "PAPER_N", "RELATIVES"]

#: The paper's chain: the size the lifetimes are extrapolated to.
PAPER_N = 399
BETAS = (0.5, 0.9, 1.0, 1.1)
#: The relatives beside the paper's chain (docs/model.md, "Preset defaults").
RELATIVES = ("train", "two-blocks", "carlson-langer")
#: One-sided 95 % point of the normal law: the lower bound of an extrapolated <T>.
Z95 = 1.6449
#: The flow's interval (time units) per drive: the plate's slips are some ten times more frequent.
INTERVAL = {"end": 10.0, "plate": 1.0}


def _grid(mode: str) -> dict[str, Any]:
    """The numbers of each mode (see :func:`build`)."""
    if mode == "tiny":
        return {
            "chain": ((3, 5), (1.0,), 2, 1, 2e5),
            "train": ((), (), 0, 0, 0.0),
            "two-blocks": (1, 0, 2e3),
            "carlson-langer": ((), 0, 0, 0.0),
            "exponents": {"sakaguchi": ((3,), (1.0,), 2e3, 1e3), "two-blocks": (200.0,), "carlson-langer": ((), 0.0)},
            "events": 30,
            "windows": 1,
            "deltas": (1e-8, 1e-2),
        }
    quick = mode == "quick"
    if quick:
        chain = ((3, 5, 7, 9, 11, 13), BETAS, 6, 2, 1e6)
        train = ((3, 5, 9, 13), (0.5, 1.0), 4, 1, 1e6)
        two, cl = (6, 2, 2e5), ((8, 16, 32), 4, 1, 2e4)
        exps = {
            "sakaguchi": ((5, 9, 13), BETAS, 2e5, 5e4),
            "train": ((5, 9, 13), (0.5, 1.0), 2e5, 5e4),
            "two-blocks": (1.2e4,),
            "carlson-langer": ((8, 16, 32), 1e3),
        }
    else:
        chain = ((3, 5, 7, 9, 11, 13, 15, 17, 19, 21), BETAS, 12, 4, 4e6)
        train = ((3, 5, 9, 13, 17, 21), BETAS, 8, 2, 4e6)
        two, cl = (12, 4, 1e6), ((8, 16, 32, 64), 8, 2, 1e5)
        exps = {
            "sakaguchi": ((5, 9, 13, 17, 21, 25), BETAS, 2e5, 1e5),
            "train": ((5, 9, 13, 17, 21), BETAS, 2e5, 1e5),
            "two-blocks": (1.2e4,),
            "carlson-langer": ((8, 16, 32, 64), 1e3),
        }
    return {
        "chain": chain,
        "train": train,
        "two-blocks": two,
        "carlson-langer": cl,
        "exponents": exps,
        "events": 1000,
        "windows": 2 if quick else 3,
        "deltas": (1e-10, 1e-8, 1e-6, 1e-4, 1e-3, 1e-2, 1e-1),
    }


def build(mode: str) -> Study:
    """The study of ``mode``: the paper's chain at N from 3 up and beta = 0.5, 0.9, 1, 1.1, several
    perturbed paper starts and loaded starts per point, each with the same budget of time; the
    train model at the same kind of points; two blocks and Carlson-Langer from seeded rest starts
    and loaded starts, with budgets of some thousands of their slips; the exponent points of each
    model. The chain's lifetime points are those of the study before the relatives came."""
    g = _grid(mode)
    Ns, betas, seeds, loaded, budget = g["chain"]
    points: list[dict[str, Any]] = [
        {"model": "sakaguchi", "N": N, "beta": b, "start": start, "seed": s}
        for N in Ns
        for b in betas
        for start, n in (("paper", seeds), ("loaded", loaded))
        for s in range(n)
    ]
    tNs, tbetas, tseeds, tloaded, tbudget = g["train"]
    points += [
        {"model": "train", "N": N, "beta": b, "start": start, "seed": s, "budget": tbudget}
        for N in tNs
        for b in tbetas
        for start, n in (("paper", tseeds), ("loaded", tloaded))
        for s in range(n)
    ]
    # the relatives at rest: the preset's draw (A = 0.01) with the seed; loaded after 2e3 (20 loading
    # times of the plate, Fs / (Kp V) = 100)
    rel = {"perturbation": 0.01, "load_t": 2e3}
    seeds2, loaded2, budget2 = g["two-blocks"]
    points += [
        {"model": "two-blocks", "N": 2, "start": start, "seed": s, "budget": budget2, **rel}
        for start, n in (("rest", seeds2), ("loaded", loaded2))
        for s in range(n)
    ]
    clNs, clseeds, clloaded, clbudget = g["carlson-langer"]
    points += [
        {"model": "carlson-langer", "N": N, "start": start, "seed": s, "budget": clbudget, **rel}
        for N in clNs
        for start, n in (("rest", clseeds), ("loaded", clloaded))
        for s in range(n)
    ]
    exps = g["exponents"]
    for model in ("sakaguchi", "train"):
        if model in exps:
            eNs, ebetas, transient, flow_t = exps[model]
            # beta = 0.5 of the paper's chain, where the motion outlasts the budget: every N of the
            # lifetimes from 5 up, so that each irregular point has its exponent
            dense = {(N, 0.5) for N in Ns if N >= 5} if model == "sakaguchi" and 0.5 in ebetas else set()
            pairs = sorted({(N, b) for N in eNs for b in ebetas} | dense)
            points += [
                {"measure": "exponent", "model": model, "N": N, "beta": b, "transient": transient, "flow_t": flow_t}
                for N, b in pairs
            ]
    plate = {"measure": "exponent", "transient": 2e3, "interval": INTERVAL["plate"]}
    points.append({**plate, "model": "two-blocks", "N": 2, "flow_t": exps["two-blocks"][0]})
    clNs_e, cl_flow = exps["carlson-langer"]
    points += [{**plate, "model": "carlson-langer", "N": N, "flow_t": cl_flow} for N in clNs_e]

    def cost(p: dict[str, Any]) -> float:  # dearest first: a flow step costs some 20 engine steps
        return p["N"] * (20 * p["flow_t"] if p.get("measure") == "exponent" else p.get("budget", budget))

    points.sort(key=lambda p: (-cost(p), p["model"], p.get("beta", 0.0), p.get("start", ""), p.get("seed", 0)))
    common = {
        "analysis": "lifetimes",
        "budget": budget,
        # 5 % of the steady length L_ss = 1 at N = 5: starts that differ from the first slips on
        "perturbation": 0.05,
        "until_steady": 1e-6,
        "rtol": 1e-6,
        # no cap below a third of a run's slips: small chains settle on orbits of thousands of slips
        # (N = 7, beta = 0.5: 2474 slips, 8e5 time units), which a cap of 500 counted as censored
        "max_period": 100_000,
        "repeats": 3,
        # the exponent points: d0 above the rounding floor (docs/studies/chaos.md), n(delta) of the state
        "d0": 1e-8,
        "events": g["events"],
        "windows": g["windows"],
        "deltas": list(g["deltas"]),
    }
    note = (
        f"{mode}: eq. (4) at N = {', '.join(map(str, Ns))}, beta = {', '.join(f'{b:g}' for b in betas)}; "
        f"{seeds} perturbed paper starts and {loaded} loaded starts per point (x_i moved by up to 0.05), "
        f"each run until periodic, steady or t = {budget:g} after its start"
    )
    if tNs:
        note += f"; the train model at N = {', '.join(map(str, tNs))}, beta = {', '.join(f'{b:g}' for b in tbetas)}"
    note += f"; two blocks ({seeds2} rest starts, {loaded2} loaded, budget {budget2:g})"
    if clNs:
        note += f"; Carlson-Langer at N = {', '.join(map(str, clNs))} (budget {clbudget:g})"
    note += "; the flow's exponent and the decorrelation threshold of each model at some of these N"
    return Study("lifetimes", mode, common, tuple(points), note=note)


# ---------------------------------------------------------------------------------------------
# Findings and figures


def label(model: str, beta: float | None) -> str:
    """The name the study gives a model at a beta, in its tables, figures and page.

    For example ``eq. (4), beta = 1``, ``train model, beta = 0.5``, or ``two blocks`` alone (the
    relatives whose friction reads no beta)."""
    name = PRESETS[model].label or model
    return f"{name}, beta = {beta:g}" if beta is not None else name


def _value(x) -> float | None:
    return float(x) if finite(x) else None


def _split(table: pd.DataFrame) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The ok rows of the table: lifetimes, exponents."""
    rows = table[table["status"] == "ok"] if "status" in table else table
    if "model" not in rows:
        rows = rows.assign(model="sakaguchi")
    measure = rows["measure"].fillna("lifetime") if "measure" in rows else None
    if measure is None:
        return rows, rows.iloc[0:0]
    return rows[measure == "lifetime"], rows[measure == "exponent"]


def _groups(rows: pd.DataFrame):
    rows = rows.assign(_beta=rows["beta"].fillna(-1.0) if "beta" in rows else -1.0)
    for (model, beta, N), g in rows.groupby(["model", "_beta", "N"], sort=True):
        yield str(model), (None if beta < 0 else float(beta)), int(N), g


def per_point(table: pd.DataFrame) -> list[dict[str, Any]]:
    """Per model, beta and N: the starts, ended and censored lifetimes, <T> of the exponential law
    (the sample mean where none was censored) with its error (the sample's where none was
    censored) or its lower bound, the median of the Kaplan-Meier curve, the Weibull test and the
    periods reached."""
    import pandas

    from stickslip.analysis.stats.survival import exponential_fit, kaplan_meier

    out = []
    for model, beta, N, g in _groups(_split(table)[0]):
        T, ended = g["lifetime"].to_numpy(float), g["ended"].to_numpy(bool)
        fit = exponential_fit(T, ended)
        km = kaplan_meier(T, ended)
        below = km[km["survival"] <= 0.5]
        periods = pandas.Series(g.loc[g["end"] == "periodic", "period_slips"]).dropna().astype(int)
        out.append(
            {
                "model": model,
                "beta": beta,
                "N": N,
                "starts": int(len(g)),
                "ended": int(ended.sum()),
                "censored": int((~ended).sum()),
                "periodic": int((g["end"] == "periodic").sum()),
                "steady": int((g["end"] == "steady").sum()),
                "budget": float(g["budget"].max()),
                "mean_T": fit.mean if fit.ended else None,
                # every lifetime seen: the sample's standard error (the lifetimes need not be
                # exponential); else the exponential law's, tau / sqrt(ended)
                "mean_T_err": (float(np.std(T, ddof=1) / np.sqrt(T.size)) if T.size > 1 else None)
                if ended.all()
                else (fit.mean_err if fit.ended else None),
                "mean_T_err_exponential": fit.mean_err if fit.ended else None,
                "mean_T_low95": fit.tau_low,
                "median_T": float(below["t"].iloc[0]) if len(below) else None,
                "weibull_shape": fit.weibull_shape,
                "exponential_p": fit.exponential_p,
                "periods": sorted(set(periods.tolist())),
                "max_slips": int(g["slips"].max()),
                # time per slip over every start (for lifetimes in slips)
                "t_per_slip": float(g["t_reached"].sum() / g["slips"].sum()) if g["slips"].sum() else None,
            }
        )
    return out


def fits(points: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per model and beta, :func:`~stickslip.analysis.stats.survival.size_fits` of <T> against N over the
    N with at least two ended lifetimes (and an error above 0), extrapolated to N = 399; for the
    paper's chain also the one-sided 95 % lower bound of <T>(399) by each law and the smaller of
    the two (``T_399_low95``: the law is not known, so the lesser bound)."""
    from stickslip.analysis.stats.survival import size_fits

    out = []
    for model, beta in sorted({(p["model"], p["beta"]) for p in points}, key=lambda k: (k[0], k[1] or 0.0)):
        use = [
            p
            for p in points
            if p["model"] == model and p["beta"] == beta and p["ended"] >= 2 and (p["mean_T_err"] or 0.0) > 0
        ]
        entry: dict[str, Any] = {"model": model, "beta": beta, "Ns": [p["N"] for p in use]}
        if len(use) >= 2:
            entry.update(
                size_fits(
                    [p["N"] for p in use],
                    [p["mean_T"] for p in use],
                    [p["mean_T_err"] for p in use],
                    extrapolate_to=PAPER_N,
                )
            )
            if is_paper(model):
                low = {k: entry[k]["log10_T_at"] - Z95 * entry[k]["log10_T_at_err"] for k in ("exponential", "power")}
                entry["log10_T_399_low95"] = low
                entry["T_399_low95"] = 10.0 ** min(low.values())
        out.append(entry)
    return out


def exponents(table: pd.DataFrame) -> list[dict[str, Any]]:
    """Per model, beta and N: the flow's exponent with its error, the slips it counted, whether the
    engine's slips over the same time were periodic, and the bracket of the decorrelation
    threshold (:func:`~stickslip.experiments.studies.lifetimes_points.exponent_point`)."""
    out = []
    for model, beta, N, g in _groups(_split(table)[1]):
        r = g.iloc[0]
        out.append(
            {
                "model": model,
                "beta": beta,
                "N": N,
                "lyapunov": float(r["lyapunov"]),
                "lyapunov_err": float(r["lyapunov_err"]),
                "flow_dt": float(r["flow_dt"]),
                "flow_slips": int(r["flow_slips"]),
                "flow_t": float(r["flow_t"]),
                "orbit_period": int(r["orbit_period"]) if finite(r.get("orbit_period")) else None,
                "orbit_from_t": float(r["orbit_from_t"]) if finite(r.get("orbit_from_t")) else None,
                "threshold_below": _value(r.get("threshold_below")),
                "threshold_low": _value(r.get("threshold_low")),
                "windows_decorrelated": int(r["windows_decorrelated"]),
            }
        )
    return out


def verdicts(points, fitted, exps) -> list[dict[str, Any]]:
    """The revised verdict (:func:`~stickslip.analysis.dynamics.chaos_verdict.chaos_verdict`) of every model,
    beta and N measured: settling from the lifetimes, the exponent and the threshold from the
    exponent point, the growth from the fit of ln <T> on N of that model and beta."""
    from stickslip.analysis.dynamics.chaos_verdict import chaos_verdict

    lives = {(p["model"], p["beta"], p["N"]): p for p in points}
    flows = {(e["model"], e["beta"], e["N"]): e for e in exps}
    growth = {(f["model"], f["beta"]): f["exponential"] for f in fitted if "exponential" in f}
    out = []
    for key in sorted(set(lives) | set(flows), key=lambda k: (not is_paper(k[0]), k[0], k[1] or 0.0, k[2])):
        life, flow, g = lives.get(key), flows.get(key), growth.get(key[:2])
        v = chaos_verdict(
            starts=life["starts"] if life else 0,
            periodic=life["periodic"] if life else 0,
            steady=life["steady"] if life else 0,
            periods=life["periods"] if life else (),
            lyapunov=flow["lyapunov"] if flow else None,
            lyapunov_err=flow["lyapunov_err"] if flow else None,
            threshold=(flow["threshold_below"], flow["threshold_low"]) if flow else None,
            growth=(g["slope"], g["slope_err"]) if g else None,
        )
        out.append({"model": key[0], "beta": key[1], "N": key[2], **v.to_dict()})
    return out


def conclusions(spec: Study | None, table: pd.DataFrame) -> dict[str, Any]:
    """Statements, per-point lifetimes, the fits of <T> against N, the exponents and the verdicts
    (module docstring)."""
    points = per_point(table)
    exps = exponents(table)
    fitted = fits(points)
    out: dict[str, Any] = {"statements": [], "points": points, "fits": fitted, "exponents": exps}
    out["verdicts"] = verdicts(points, fitted, exps)
    say = out["statements"].append
    for p in points:
        if p["ended"]:
            mean = f"<T> = {short(p['mean_T'])} +- {short(p['mean_T_err'], 2)}"
        else:
            mean = f"<T> > {short(p['mean_T_low95'])} (95 %, none ended)"
        test = (
            f"; Weibull shape {p['weibull_shape']:.2f}, exponential p = {p['exponential_p']:.2g}"
            if p["weibull_shape"] is not None
            else ""
        )
        orbits = f"; periods {', '.join(map(str, p['periods'][:6]))}" if p["periods"] else ""
        say(
            f"{label(p['model'], p['beta'])}, N = {p['N']}: {p['ended']} of {p['starts']} starts ended "
            f"({p['steady']} in steady sliding), {p['censored']} outlasted t = {p['budget']:g}; {mean}{test}{orbits}."
        )
    for f in fitted:
        name = label(f["model"], f["beta"])
        if "exponential" not in f:
            say(f"{name}: fewer than two N with two ended lifetimes; no fit of <T> against N.")
            continue
        e, pw = f["exponential"], f["power"]
        chi = f"chi2 {e['chi2']:.3g} against {pw['chi2']:.3g} for {e['dof']} degrees of freedom"
        if f["better"] is None:
            better = ""
        elif abs(e["chi2"] - pw["chi2"]) < 4.0:  # a likelihood ratio below e^2: no clear choice
            better = f" (neither fits clearly better: {chi})"
        else:
            better = f" ({f['better']} fits better: {chi})"
        line = (
            f"{name}, N = {', '.join(map(str, f['Ns']))}: ln <T> = a + b N with "
            f"b = {e['slope']:.3g} +- {e['slope_err']:.2g}; ln <T> = a + c ln N with c = {pw['slope']:.3g} +- "
            f"{pw['slope_err']:.2g}{better}."
        )
        if is_paper(f["model"]):
            line += (
                f" Extrapolated to N = {PAPER_N}: exponential <T> ~ 10^({e['log10_T_at']:.1f} +- "
                f"{e['log10_T_at_err']:.1f}), power law 10^({pw['log10_T_at']:.2f} +- {pw['log10_T_at_err']:.2f}) "
                f"= {pw['T_at']:.3g} (1 sigma {pw['T_at_low']:.3g} .. {pw['T_at_high']:.3g}); if either law holds "
                f"to N = {PAPER_N}, <T> > {f['T_399_low95']:.3g} with 95 % confidence (the lesser of the two bounds)."
            )
        say(line)
    for e in exps:
        orbit = f", on a periodic orbit of {e['orbit_period']} slips" if e["orbit_period"] else ""
        bracket = (
            f"threshold in ({short(e['threshold_below'])}, {short(e['threshold_low'])}]"
            if e["threshold_low"] is not None
            else "no window decorrelated"
        )
        say(
            f"{label(e['model'], e['beta'])}, N = {e['N']}: flow exponent {e['lyapunov']:.3g} +- "
            f"{e['lyapunov_err']:.2g} at dt = {e['flow_dt']:g} ({e['flow_slips']} slips{orbit}); {bracket}."
        )
    counts: dict[str, list[str]] = {}
    for v in out["verdicts"]:
        counts.setdefault(v["verdict"], []).append(f"{label(v['model'], v['beta'])}, N = {v['N']}")
    say("Verdicts: " + "; ".join(f"{k} at {', '.join(names)}" for k, names in counts.items()) + ".")
    return out


def figures(spec: Study | None, table: pd.DataFrame, page_dir: Path) -> list[tuple[str, Any, str]]:
    """Kaplan-Meier survival curves (one panel per model and beta, one curve per N), <T> against N
    with the fits, and the flow's exponent against N (one panel per model)."""
    from stickslip.analysis.stats.survival import kaplan_meier
    from stickslip.plotting import lifetimes as pl

    def first(p: dict[str, Any]) -> bool:  # the paper's chain first, then the relatives
        return not is_paper(p["model"])

    curves = []
    for model, beta, N, g in sorted(_groups(_split(table)[0]), key=lambda k: not is_paper(k[0])):
        km = kaplan_meier(g["lifetime"].to_numpy(float), g["ended"].to_numpy(bool))
        curves.append({"panel": label(model, beta), "N": N, "km": km})
    found = conclusions(spec, table)
    out = []
    if curves:
        series = [{**p, "series": label(p["model"], p["beta"])} for p in sorted(found["points"], key=first)]
        lines = [{**f, "series": label(f["model"], f["beta"])} for f in found["fits"]]
        out += [
            (
                "survival",
                pl.survival_figure(curves),
                "Kaplan-Meier survival S(t) = P(T > t) of the irregular motion, one panel per model and "
                "beta, one curve per N, from every start; a curve that ends above 0 has lifetimes "
                "censored at the budget.",
            ),
            (
                "lifetime_vs_N",
                pl.lifetime_figure(series, lines),
                "<T> against N (maximum-likelihood exponential law of censored lifetimes, with its standard "
                "error; triangles: 95 % lower bounds where no lifetime ended), with the fit of ln <T> on N "
                "(solid) and on ln N (dashed) for each model and beta.",
            ),
        ]
    if found["exponents"]:
        rows = [{**e, "panel": PRESETS[e["model"]].label or e["model"]} for e in sorted(found["exponents"], key=first)]
        out.append(
            (
                "exponent_vs_N",
                pl.exponent_figure(rows),
                "The flow's largest exponent (located switches, one step dt, the time shift removed) against "
                "N, one panel per model, one colour per beta; open markers: the engine's slips were periodic "
                "over the same stretch (the exponent is the orbit's). Dotted: zero.",
            )
        )
    return out


def tables(findings: dict[str, Any]) -> list[tuple[str, list[str], list[dict[str, Any]]]]:
    """The page's tables: lifetimes per model, beta and N; exponents; verdicts."""
    cols = ["model", "beta", "N", "starts", "ended", "censored", "steady", "budget", "mean_T", "mean_T_err"]
    cols += ["mean_T_low95", "median_T", "weibull_shape", "exponential_p", "periods"]
    rows = [{**p, "periods": ", ".join(map(str, p["periods"]))} for p in findings.get("points", [])]
    ecols = ["model", "beta", "N", "lyapunov", "lyapunov_err", "flow_dt", "flow_slips", "orbit_period"]
    ecols += ["threshold_below", "threshold_low"]
    vcols = ["model", "beta", "N", "verdict", "verdict_text"]
    return [
        ("Lifetimes per model, beta and N", cols, rows),
        ("The flow's exponent and the decorrelation threshold", ecols, findings.get("exponents", [])),
        ("Verdicts", vcols, findings.get("verdicts", [])),
    ]


COST = {
    "quick": "about 5 minutes on two free cores (measured: 294 s)",
    "full": "about 40 minutes on two free cores (measured: 4317 s of CPU over its points; 61 minutes of wall "
    "time beside a test run on the same two cores)",
}


def describe() -> str:
    """The text of ``stickslip study lifetimes --help``."""
    quick, full = build("quick"), build("full")
    return (
        "How long does the irregular motion of the chain of eq. (4) and of its relatives last against N "
        "(the standard test of stable chaos: a transient whose lifetime grows exponentially with N), "
        "and is it chaos proper? Each lifetime point is one start (a perturbed paper start, a seeded "
        "rest start or a loaded start) at one N and beta, run until its slip sequence is periodic "
        "(stickslip period's rule), it slides steadily or its budget is spent (censored); each exponent "
        "point measures the flow's largest exponent and the decorrelation threshold. Per model, N and "
        "beta: Kaplan-Meier survival, <T> of the exponential law of censored lifetimes, the Weibull test, "
        "the periods reached, the exponent, and the verdict (periodic, steady, chaotic, stable chaos or "
        "undetermined); per model and beta the fits of ln <T> on N and on ln N, and for the paper's chain "
        f"the extrapolation to N = {PAPER_N}. Grid: --quick {quick.note.split(': ', 1)[1]} "
        f"({len(quick.points)} points, {COST['quick']}); --full {full.note.split(': ', 1)[1]} "
        f"({len(full.points)} points, {COST['full']}). Outputs in DIR/lifetimes/: table.parquet and "
        "table.csv (one row per point), survival, lifetime_vs_N and exponent_vs_N (PNG, PDF), study.json, "
        "index.html."
    )


DESIGN = Design(
    cost=COST,
    name="lifetimes",
    summary="how long the irregular motion lasts against N (stable chaos), with censored lifetimes; the verdicts",
    describe=describe,
    build=build,
    task=task,
    check=check_point,
    findings=conclusions,
    figures=figures,
    tables=tables,
    columns=(
        *"measure model N beta start seed lifetime ended end period_slips period_t settled_from_slip slips".split(),
        "t_start",
        "t_reached",
        "budget",
        *"lyapunov lyapunov_err flow_slips orbit_period threshold_below threshold_low".split(),
    ),
)
