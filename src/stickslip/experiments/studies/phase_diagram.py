"""``stickslip study phase-diagram``: the final state and m = 1 - <L>/L_ss of eq. (4) over
(alpha, beta) at D = 5 and over (D, beta) at alpha = 1, at N = 99, each cell from the paper's
start and from steady sliding perturbed by 0.01 (hysteresis), against the linear-stability
line beta_c = alpha (docs/studies/phase-diagram.md). Each point is one chain run and its order
parameter (:func:`stickslip.experiments.studies.chain_point.order_task`).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from stickslip.experiments.studies import Design, Study, short
from stickslip.experiments.studies.chain_point import check_point, order_task, t_end_of
from stickslip.models.physics import UNTIL_STEADY
from stickslip.models.presets import paper_parameters

if TYPE_CHECKING:  # loaded where used, so that listing the studies loads no heavy module
    import pandas as pd

__all__ = ["DESIGN"]

#: The two slices of the diagram: the parameter that varies beside beta, the one held and its value.
_SLICES = (("alpha", "D", 5.0, "D = 5"), ("D", "alpha", 1.0, "alpha = 1"))


def build(mode: str) -> Study:
    """The cells of ``mode``, deep on the sliding side first (there the paper's start slides
    longest before it settles), each from two starts."""
    if mode == "tiny":
        N, alphas, Ds, betas, D_betas = 9, (1.0,), (5.0,), (0.8, 1.2), (0.8, 1.2)
    elif mode == "quick":
        N, alphas, Ds = 99, (0.5, 1.0, 1.5), (0.5, 5.0, 50.0)
        betas, D_betas = (0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75), (0.7, 0.9, 1.0, 1.1, 1.3)
    else:
        N, alphas, Ds = 99, (0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0), (0.1, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0)
        betas = tuple(round(0.125 * k, 3) for k in range(1, 19))
        D_betas = (0.6, 0.7, 0.8, 0.85, 0.9, 0.95, 1.0, 1.05, 1.1, 1.15, 1.2, 1.3, 1.4)
    loads = 2.5
    cells = [(a, 5.0, b) for a in alphas for b in betas] + [(1.0, d, b) for d in Ds for b in D_betas]
    unique = sorted(dict.fromkeys(cells), key=lambda c: -(c[2] - c[0]))  # (alpha, D, beta), each once
    points = [
        {"alpha": a, "D": d, "beta": b, "N": N, "t_end": t_end_of(N, loads), "start": s}
        for a, d, b in unique
        for s in ("paper", "steady")
    ]
    common = {
        **paper_parameters("N", "beta", "alpha", "D"),
        "model": "sakaguchi",
        "loads": loads,
        "average_fraction": 0.5,
        "n_samples": 20000 if mode != "tiny" else 2000,
        "until_steady": UNTIL_STEADY,
        "perturbation": 0.01,
        "seed": 0,
        "analysis": "order",
        "alphas": list(alphas),
        "Ds": list(Ds),
    }
    note = (
        f"{mode}: N = {N}, {len(unique)} cells of (alpha, beta) and (D, beta), each from the "
        f"paper's start and from steady sliding perturbed by 0.01"
    )
    return Study("phase-diagram", mode, common, tuple(points), note=note)


def findings(spec: Study, table: pd.DataFrame) -> dict[str, Any]:
    """Cells where the two starts disagree, the settled cells on the side of beta_c = alpha that
    linear stability predicts, and the bracket of the transition for each alpha and each D."""
    from stickslip.analysis.stats.order import transition_bracket

    out: dict[str, Any] = {"statements": [], "disagree": []}
    say = out["statements"].append
    n_cells = agree_lin = n_lin = 0
    for (a, d, b), g in table.groupby(["alpha", "D", "beta"]):
        states = dict(zip(g["start"], g["final_state"], strict=False))
        n_cells += 1
        if len(set(states.values())) > 1:
            out["disagree"].append({"alpha": a, "D": d, "beta": b, **states})
        if states.get("paper") in ("steady", "stick-slip"):
            n_lin += 1
            agree_lin += (states["paper"] == "steady") == (b > a)
    cells = "; ".join(
        f"alpha = {c['alpha']:g}, D = {c['D']:g}, beta = {c['beta']:g} (paper: {c.get('paper')}, "
        f"steady: {c.get('steady')})"
        for c in out["disagree"]
    )
    n_dis = len(out["disagree"])
    say(f"{n_cells} cells; the two starts end differently in {n_dis} of them" + (f": {cells}." if cells else "."))
    say(
        f"From the paper's start, {agree_lin} of {n_lin} settled cells are on the side of beta_c = alpha that "
        f"linear stability predicts (steady for beta > alpha, stick-slip below)."
    )
    for name, fixed, value, where in _SLICES:
        for x, g in table[(table[fixed] == value) & (table["start"] == "paper")].groupby(name):
            br = transition_bracket(g["beta"], g["final_state"])
            line = (
                f"{name} = {x:g} ({where}, paper's start): last stick-slip beta = {short(br['lo'])}, "
                f"first steady above it = {short(br['hi'])}"
            )
            say(line + (f" (beta_c = alpha = {x:g})." if name == "alpha" else "."))
    return out


def figures(spec: Study, table: pd.DataFrame, page_dir: Path) -> list[tuple[str, Any, str]]:
    """The two maps of final state and m (:func:`stickslip.plotting.studies.phase_map_figure`)."""
    from stickslip.plotting.studies import phase_map_figure

    return [
        (
            f"phase_{name}_beta",
            phase_map_figure(table[table[fixed] == value], name, where),
            f"Final state and m over ({name}, beta) at {where}; dashed: beta_c = alpha{' = 1' if name == 'D' else ''}.",
        )
        for name, fixed, value, where in _SLICES
    ]


#: The wall time of each mode (``stickslip study --help``, the README).
COST = {"quick": "7 to 8 minutes on two cores", "full": "about 80 minutes on two cores"}


def describe() -> str:
    """The text of ``stickslip study phase-diagram --help``."""
    quick, full = build("quick"), build("full")
    return (
        "Where does the chain of eq. (4) stick-slip and where does it slide steadily, over (alpha, "
        "beta) at D = 5 and (D, beta) at alpha = 1? Each cell is run from the paper's start and from "
        "steady sliding perturbed by 0.01 (two starts that end differently mark hysteresis), 2.5 "
        "loading times, and compared with beta_c = alpha of linear stability. "
        f"Grid: --quick {quick.note.split(': ', 1)[1]} ({len(quick.points)} runs, {COST['quick']}"
        f"); --full {full.note.split(': ', 1)[1]} ({len(full.points)} runs, {COST['full']}). "
        "Outputs in DIR/phase-diagram/: table.parquet and table.csv (one row per run: final state, m "
        "and its error, stuck fraction), phase_alpha_beta and phase_D_beta (PNG, PDF), study.json, "
        "index.html."
    )


DESIGN = Design(
    cost=COST,
    name="phase-diagram",
    summary="final state over (alpha, beta) and (D, beta), from two starts",
    describe=describe,
    build=build,
    task=order_task,
    check=check_point,
    findings=findings,
    figures=figures,
    columns=tuple(
        "N alpha D beta start final_state order_parameter order_parameter_err stuck_fraction t_steady t_end".split()
    ),
)
