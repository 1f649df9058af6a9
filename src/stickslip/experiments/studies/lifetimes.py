"""``stickslip study lifetimes``: how long the irregular motion of the chain of eq. (4) lasts
against N, the standard test of stable chaos (Politi, Livi, Oppo and Kapral, Europhys. Lett. 22,
571 (1993); Politi and Torcini, arXiv:0902.2545): a transient whose lifetime grows exponentially
with the system size (docs/studies/lifetimes.md).

A point is one start of the paper's chain at one N and beta, run until its slip sequence is
periodic (:class:`stickslip.analysis.stats.periodicity.PeriodicStop`), it slides steadily
(``until_steady``) or its budget of time is spent:

- ``paper``: the paper's start (x = 0, v = 0.1, theta = 0.1), every x_i moved by a uniform draw
  in [-A, A] (``perturbation`` A, ``seed``); the lifetime counts from t = 0;
- ``loaded``: the paper's start run to twice its loading time L_ss / V
  (:func:`stickslip.models.physics.loading_time`), then every x_i moved so; the lifetime counts
  from there.

The lifetime T is the time of the first slip of the periodic orbit (``settled_from_t``), or of
the steady stop, less the start's time; a start still irregular at the end of its budget is
censored there. A lifetime that ends within the last stretch the detector needs (a few periods)
is seen as censored: the budget is that much shorter in effect.

The findings (:func:`conclusions`), per beta and N: the lifetimes ended and censored, <T> by
the maximum-likelihood exponential law of censored data (:func:`stickslip.analysis.stats.survival.exponential_fit`;
a lower bound where none ended), the Weibull test of the exponential law (stable chaos predicts
it), the periods reached; per beta the fits of ln <T> on N and on ln N
(:func:`stickslip.analysis.stats.survival.size_fits`) over the N with at least two ended lifetimes,
which fits better, and the extrapolation to the paper's N = 399. The figures: Kaplan-Meier
survival curves and <T> against N (:mod:`stickslip.plotting.lifetimes`).
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from stickslip.experiments.studies import Design, Study, short
from stickslip.experiments.sweep_points import point_params

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["DESIGN", "lifetime_point", "conclusions", "start_state", "PAPER_N"]

#: The paper's chain: the size the lifetimes are extrapolated to.
PAPER_N = 399
STARTS = ("paper", "loaded")
BETAS = (0.5, 0.9, 1.0, 1.1)


def build(mode: str) -> Study:
    """The study of ``mode``: the paper's chain at N from 3 up and beta = 0.5, 0.9, 1, 1.1, several
    perturbed paper starts and loaded starts per point, each with the same budget of time."""
    if mode == "tiny":
        Ns, betas, seeds, loaded, budget = (3, 5), (1.0,), 2, 1, 2e5
    elif mode == "quick":
        Ns, betas, seeds, loaded, budget = (3, 5, 7, 9, 11, 13), BETAS, 6, 2, 1e6
    else:
        Ns, betas, seeds, loaded, budget = (3, 5, 7, 9, 11, 13, 15, 17, 19, 21), BETAS, 12, 4, 4e6
    points = [
        {"model": "sakaguchi", "N": N, "beta": b, "start": start, "seed": s}
        for N in Ns
        for b in betas
        for start, n in (("paper", seeds), ("loaded", loaded))
        for s in range(n)
    ]
    # dearest first: long chains and weak strengthening outlast the budget
    points.sort(key=lambda p: (-p["N"], p["beta"], p["start"], p["seed"]))
    common = {
        "analysis": "lifetimes",
        "budget": budget,
        # 5 % of the steady length L_ss = 1 at N = 5: starts that differ from the first slips on
        "perturbation": 0.05,
        "until_steady": 1e-6,
        "rtol": 1e-6,
        "max_period": 500,
        "repeats": 3,
    }
    note = (
        f"{mode}: eq. (4) at N = {', '.join(map(str, Ns))}, beta = {', '.join(f'{b:g}' for b in betas)}; "
        f"{seeds} perturbed paper starts and {loaded} loaded starts per point (x_i moved by up to 0.05), "
        f"each run until periodic, steady or t = {budget:g} after its start"
    )
    return Study("lifetimes", mode, common, tuple(points), note=note)


def check_point(cfg: dict[str, Any], params=None) -> None:
    """Raise ParameterError (one line) unless a lifetime point's merged settings are valid."""
    from stickslip.models.params import ParameterError, check_number

    params = point_params("chain", cfg) if params is None else params
    if cfg.get("start") not in STARTS:
        raise ParameterError(f"start must be one of {', '.join(STARTS)} (got {cfg.get('start')!r})")
    check_number("budget", cfg.get("budget"), low=0.0, low_open=True)
    check_number("perturbation", cfg.get("perturbation", 0.0), low=0.0, high=1.0)
    check_number("seed", cfg.get("seed", 0), low=0, integer=True)
    if params.ends_piece.wall or params.drive_piece.leaf_spring:
        raise ParameterError("the lifetimes study runs chains pulled at one end (the paper's start)")


def start_state(params, start: str, amplitude: float, seed: int, stop_requested=None):
    """The state a point starts from (module docstring): the paper's start, or the state at twice
    its loading time, every x_i moved by a uniform draw in [-amplitude, amplitude] (numpy's
    Generator seeded with ``seed``)."""
    from stickslip.models import physics
    from stickslip.run.driver import run_chain
    from stickslip.run.errors import short_runs_expected
    from stickslip.run.state import ChainState

    state = ChainState.paper(params)
    if start == "loaded":
        t_load = 2.0 * physics.loading_time(params)
        with short_runs_expected():
            state = run_chain(
                params, t_load, sample_interval=t_load, progress=False, stop_requested=stop_requested
            ).state
    state = state.copy()
    rng = np.random.default_rng(seed)
    state.x[:] += rng.uniform(-amplitude, amplitude, params.N)
    return state


def lifetime_point(cfg: dict[str, Any], params, point_dir: Path | None = None) -> dict[str, Any]:
    """One start (module docstring): its lifetime, whether it ended (on a periodic orbit or in
    steady sliding) or was censored, and the orbit's period."""
    from stickslip.analysis.stats.periodicity import PeriodicStop
    from stickslip.experiments.sweep import stop_requested
    from stickslip.run.driver import run_chain

    wall0 = time.perf_counter()
    check_point(cfg, params)
    stop = stop_requested(point_dir) if point_dir is not None else None
    state = start_state(params, cfg["start"], float(cfg["perturbation"]), int(cfg["seed"]), stop)
    t0 = state.step * params.dt
    hook = PeriodicStop(rtol=float(cfg["rtol"]), max_period=int(cfg["max_period"]), repeats=int(cfg["repeats"]))
    budget = float(cfg["budget"])
    run = run_chain(
        params,
        t0 + budget,
        start=state,
        hooks=[hook],
        until_steady=float(cfg["until_steady"]),
        sample_interval=max(params.dt, budget / 1000),
        progress=False,
        stop_requested=stop,
    )
    found = hook.result
    if found is not None:
        end, t_end = "periodic", found.settled_from_t
    elif run.summary.get("stopped_early"):
        end, t_end = "steady", run.summary["t_steady"]
    else:
        end, t_end = "censored", run.summary["t_reached"]
    return {
        "lifetime": float(t_end) - t0,
        "ended": end != "censored",
        "end": end,
        "period_slips": found.period_slips if found else None,
        "period_t": found.period_t if found else None,
        "settled_from_slip": found.settled_from_slip if found else None,
        "slips": int(len(run.events)),
        "t_start": t0,
        "t_reached": float(run.summary["t_reached"]) - t0,
        "budget": budget,
        "point_wall_seconds": time.perf_counter() - wall0,
    }


def task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """One point on a worker (:func:`lifetime_point`)."""
    return lifetime_point(point, point_params("chain", point), Path(point_dir))


# ---------------------------------------------------------------------------------------------
# Findings and figures


def _groups(table: pd.DataFrame):
    rows = table[table["status"] == "ok"] if "status" in table else table
    for (beta, N), g in rows.groupby(["beta", "N"], sort=True):
        yield float(beta), int(N), g


def per_point(table: pd.DataFrame) -> list[dict[str, Any]]:
    """Per beta and N: the starts, ended and censored lifetimes, <T> of the exponential law (the
    sample mean where none was censored) with its error (the sample's where none was censored)
    or its lower bound, the median of the Kaplan-Meier curve, the Weibull test and the
    periods reached."""
    import pandas

    from stickslip.analysis.stats.survival import exponential_fit, kaplan_meier

    out = []
    for beta, N, g in _groups(table):
        T, ended = g["lifetime"].to_numpy(float), g["ended"].to_numpy(bool)
        fit = exponential_fit(T, ended)
        km = kaplan_meier(T, ended)
        below = km[km["survival"] <= 0.5]
        periods = pandas.Series(g.loc[g["end"] == "periodic", "period_slips"]).dropna().astype(int)
        out.append(
            {
                "beta": beta,
                "N": N,
                "starts": int(len(g)),
                "ended": int(ended.sum()),
                "censored": int((~ended).sum()),
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
            }
        )
    return out


def fits(points: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per beta, :func:`~stickslip.analysis.stats.survival.size_fits` of <T> against N over the N with at
    least two ended lifetimes, extrapolated to N = 399."""
    from stickslip.analysis.stats.survival import size_fits

    out = []
    for beta in sorted({p["beta"] for p in points}):
        use = [p for p in points if p["beta"] == beta and p["ended"] >= 2]
        entry: dict[str, Any] = {"beta": beta, "Ns": [p["N"] for p in use]}
        if len(use) >= 2:
            f = size_fits(
                [p["N"] for p in use],
                [p["mean_T"] for p in use],
                [p["mean_T_err"] for p in use],
                extrapolate_to=PAPER_N,
            )
            entry.update(f)
        out.append(entry)
    return out


def conclusions(spec: Study | None, table: pd.DataFrame) -> dict[str, Any]:
    """Statements, per-point lifetimes and the fits of <T> against N (module docstring)."""
    points = per_point(table)
    out: dict[str, Any] = {"statements": [], "points": points, "fits": fits(points)}
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
            f"beta = {p['beta']:g}, N = {p['N']}: {p['ended']} of {p['starts']} starts ended "
            f"({p['steady']} in steady sliding), {p['censored']} outlasted t = {p['budget']:g}; {mean}{test}{orbits}."
        )
    for f in out["fits"]:
        if "exponential" not in f:
            say(f"beta = {f['beta']:g}: fewer than two N with two ended lifetimes; no fit of <T> against N.")
            continue
        e, pw = f["exponential"], f["power"]
        chi = f"chi2 {e['chi2']:.3g} against {pw['chi2']:.3g} for {e['dof']} degrees of freedom"
        if f["better"] is None:
            better = ""
        elif abs(e["chi2"] - pw["chi2"]) < 4.0:  # a likelihood ratio below e^2: no clear choice
            better = f" (neither fits clearly better: {chi})"
        else:
            better = f" ({f['better']} fits better: {chi})"
        say(
            f"beta = {f['beta']:g}, N = {', '.join(map(str, f['Ns']))}: ln <T> = a + b N with "
            f"b = {e['slope']:.3g} +- {e['slope_err']:.2g}; ln <T> = a + c ln N with c = {pw['slope']:.3g} +- "
            f"{pw['slope_err']:.2g}{better}. Extrapolated to N = {PAPER_N}: exponential "
            f"<T> ~ 10^({e['log10_T_at']:.1f} +- {e['log10_T_at_err']:.1f}), power law "
            f"10^({pw['log10_T_at']:.2f} +- {pw['log10_T_at_err']:.2f}) = {pw['T_at']:.3g} "
            f"(1 sigma {pw['T_at_low']:.3g} .. {pw['T_at_high']:.3g})."
        )
    return out


def figures(spec: Study, table: pd.DataFrame, page_dir: Path) -> list[tuple[str, Any, str]]:
    """Kaplan-Meier survival curves (one panel per beta, one curve per N) and <T> against N with
    the fits."""
    from stickslip.analysis.stats.survival import kaplan_meier
    from stickslip.plotting import lifetimes as pl

    curves = []
    for beta, N, g in _groups(table):
        km = kaplan_meier(g["lifetime"].to_numpy(float), g["ended"].to_numpy(bool))
        curves.append({"beta": beta, "N": N, "km": km})
    if not curves:
        return []
    found = conclusions(spec, table)
    return [
        (
            "survival",
            pl.survival_figure(curves),
            "Kaplan-Meier survival S(t) = P(T > t) of the irregular motion, one panel per beta, one "
            "curve per N, from every start (perturbed paper starts and loaded starts); a curve that "
            "ends above 0 has lifetimes censored at the budget.",
        ),
        (
            "lifetime_vs_N",
            pl.lifetime_figure(found["points"], found["fits"]),
            "<T> against N (maximum-likelihood exponential law of censored lifetimes, with its standard "
            "error; triangles: 95 % lower bounds where no lifetime ended), with the fit of ln <T> on N "
            "(solid) and on ln N (dashed) for each beta.",
        ),
    ]


def tables(findings: dict[str, Any]) -> list[tuple[str, list[str], list[dict[str, Any]]]]:
    """The page's table of lifetimes per beta and N."""
    cols = ["beta", "N", "starts", "ended", "censored", "steady", "budget", "mean_T", "mean_T_err", "mean_T_low95"]
    cols += ["median_T", "weibull_shape", "exponential_p", "periods"]
    rows = [{**p, "periods": ", ".join(map(str, p["periods"]))} for p in findings.get("points", [])]
    return [("Lifetimes per beta and N", cols, rows)]


COST = {"quick": "about 11 minutes on two cores", "full": "about an hour and a half on two cores"}


def describe() -> str:
    """The text of ``stickslip study lifetimes --help``."""
    quick, full = build("quick"), build("full")
    return (
        "How long does the irregular motion of the chain of eq. (4) last against N (the standard test "
        "of stable chaos: a transient whose lifetime grows exponentially with N)? Each point is one "
        "start (a perturbed paper start or a loaded start) at one N and beta, run until its slip "
        "sequence is periodic (stickslip period's rule), it slides steadily or its budget is spent "
        "(censored). Per N and beta: Kaplan-Meier survival, <T> of the exponential law of censored "
        "lifetimes, the Weibull test, the periods reached; per beta the fits of ln <T> on N and on "
        f"ln N and the extrapolation to N = {PAPER_N}. Grid: --quick {quick.note.split(': ', 1)[1]} "
        f"({len(quick.points)} points, {COST['quick']}, measured with other work on them); --full "
        f"{full.note.split(': ', 1)[1]} ({len(full.points)} points, {COST['full']}, estimated). "
        "Outputs in DIR/lifetimes/: table.parquet and table.csv (one row per start: lifetime, "
        "ended, period), survival and lifetime_vs_N (PNG, PDF), study.json, index.html."
    )


DESIGN = Design(
    cost=COST,
    name="lifetimes",
    summary="how long the irregular motion lasts against N (stable chaos), with censored lifetimes",
    describe=describe,
    build=build,
    task=task,
    check=check_point,
    findings=conclusions,
    figures=figures,
    tables=tables,
    columns=(
        *"model N beta start seed lifetime ended end period_slips period_t settled_from_slip slips".split(),
        "t_start",
        "t_reached",
        "budget",
    ),
)
