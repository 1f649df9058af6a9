"""What ``stickslip study chaos`` reports of ``stickslip study lifetimes`` run into the same
output folder (docs/studies/chaos.md, "The standard test"): the lifetimes study's revised
verdicts (:func:`stickslip.analysis.dynamics.chaos_verdict.chaos_verdict`), the paper chain's lower bound
of <T> at N = 399, the revised verdicts of the chaos study's own points, and the lifetimes'
figures drawn again on the chaos study's page.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from stickslip.experiments.studies import Study, finite
from stickslip.models.presets import PRESETS, is_paper

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["LIFETIMES", "load", "revised_verdicts", "lifetime_findings", "lifetime_figures"]


def _value(x) -> float | None:
    """A number of the table, None where it is missing or not finite."""
    return float(x) if finite(x) and math.isfinite(float(x)) else None


#: Where the lifetimes study's page lies beside this study's (the same output folder).
LIFETIMES = "lifetimes"


def load(spec: Study, table: pd.DataFrame, points_dir: Path) -> pd.DataFrame:
    """The table of finished points, with the findings of ``stickslip study lifetimes`` run into
    the same output folder (its ``study.json``, issue 51) in ``table.attrs['lifetimes']``:
    ``mode``, ``page``, ``table`` (its table.parquet) and ``findings``; nothing where it was not
    run there."""
    from stickslip import io

    out = Path(points_dir).parent.parent.parent  # OUT/runs/<name>-<key>/points
    page = out / LIFETIMES
    table = table.copy()
    if (page / "study.json").is_file() and (page / "table.parquet").is_file():
        record = io.read_json(page / "study.json")
        table.attrs["lifetimes"] = {
            "mode": record["meta"]["mode"],
            "page": str(page / "index.html"),
            "table": str(page / "table.parquet"),
            "findings": record["findings"],
        }
    return table


def revised_verdicts(table: pd.DataFrame, fits: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The revised verdict (:func:`stickslip.analysis.dynamics.chaos_verdict.chaos_verdict`) of each of this
    study's points: its flow exponent at dt -> 0 and the bracket of its threshold, with the growth
    of lifetimes with N that the lifetimes study measured for the same model and beta at small N
    (``fits``: the slope b of ln <T> on N); no lifetimes of its own at these N."""
    from stickslip.analysis.dynamics.chaos_verdict import chaos_verdict

    growth = {(f["model"], f["beta"]): f["exponential"] for f in fits if "exponential" in f}
    out = []
    for _, r in table.iterrows():
        beta = _value(r.get("beta"))
        g = growth.get((r["model"], beta))
        v = chaos_verdict(
            lyapunov=_value(r.get("lyapunov_dt0")),
            lyapunov_err=_value(r.get("lyapunov_dt0_err")),
            threshold=(_value(r.get("threshold_below")), _value(r.get("threshold_low"))),
            growth=(g["slope"], g["slope_err"]) if g else None,
        )
        out.append({"model": r["model"], "N": int(r["N"]), "beta": beta, **v.to_dict()})
    return out


def lifetime_findings(
    lives: dict[str, Any] | None, table: pd.DataFrame | None = None
) -> tuple[dict[str, Any], list[str]]:
    """What the chaos study reports of the lifetimes study (:func:`load`): its revised verdicts
    (:func:`stickslip.analysis.dynamics.chaos_verdict.chaos_verdict`) by model, the paper chain's lower
    bound of <T> at N = 399 per beta, the revised verdicts of this study's own points
    (:func:`revised_verdicts`, where ``table`` is given) and statements; or, where it was not run
    into the same folder, how to run it."""
    if not lives:
        how = (
            "The lifetimes of the irregular motion against N, the small-N exponents and the revised verdicts "
            "(periodic, chaotic, stable chaos) are those of `stickslip study lifetimes` "
            "(docs/studies/lifetimes.md); run it with the same --out DIR and this study again to report them here."
        )
        return {"found": False, "how": how}, [how]
    found = lives["findings"]
    by: dict[str, list[str]] = {}
    for v in found.get("verdicts", []):
        name = PRESETS[v["model"]].label or v["model"]
        where = f"{name}, N = {v['N']}" + (f", beta = {v['beta']:g}" if v.get("beta") is not None else "")
        by.setdefault(v["verdict"], []).append(where)
    bounds = [
        {"beta": f["beta"], "T_399_low95": f["T_399_low95"], "Ns": f["Ns"]}
        for f in found.get("fits", [])
        if is_paper(f["model"]) and "T_399_low95" in f
    ]
    lines = [
        f"Lifetimes (stickslip study lifetimes --{lives['mode']}, {lives['page']}): "
        + "; ".join(f"{k} at {', '.join(names)}" for k, names in by.items())
        + "."
    ]
    if bounds:
        lines.append(
            "Extrapolated from the chain's lifetimes at small N to the paper's N = 399, if ln <T> grows as N or as "
            "ln N: "
            + "; ".join(f"beta = {b['beta']:g}: <T> > {b['T_399_low95']:.3g}" for b in bounds)
            + " time units, with 95 % confidence (the lesser of the two laws' bounds)."
        )
    mine = revised_verdicts(table, found.get("fits", [])) if table is not None and len(table) else []
    if mine:
        own: dict[str, list[str]] = {}
        for v in mine:
            own.setdefault(v["verdict"], []).append(PRESETS[v["model"]].point_label(v["beta"], v["N"]))
        lines.append(
            "Revised verdicts of this study's points (their exponent and threshold, with the growth of lifetimes "
            "with N measured at small N for the same beta): "
            + "; ".join(f"{k} at {', '.join(names)}" for k, names in own.items())
            + "."
        )
    summary = {"found": True, "mode": lives["mode"], "page": lives["page"], "verdicts": by, "bounds_399": bounds}
    return {**summary, "revised_verdicts": mine}, lines


def lifetime_figures(lives: dict[str, Any] | None, page_dir: Path) -> list[tuple[str, Any, str]]:
    """The lifetimes study's figures (survival curves, <T> against N, the exponent against N),
    drawn again from its table (:func:`load`) as ``lifetimes_*``; none where it was not run."""
    import pandas as pd

    from stickslip.experiments.studies import lifetimes

    if not lives:
        return []
    table = pd.read_parquet(lives["table"])
    note = f" (from stickslip study lifetimes --{lives['mode']}, {lives['page']})"
    return [
        (f"lifetimes_{name}", fig, caption + note) for name, fig, caption in lifetimes.figures(None, table, page_dir)
    ]
