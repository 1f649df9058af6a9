"""What ``stickslip study chaos`` finds: the statements of its page, delta* against N, its figures.

From the table (one row per point, :func:`stickslip.experiments.chaos_verdict.chaos_point`):
each point's verdict with the window it holds for, the flow's exponent and the slips its rungs
counted, the loading check; delta* of each kind per point (geometric mean over the windows, its
error in decades, the range) and, for each beta and kind, the least-squares slope of log10 delta*
(one point per window) on log10 N (:func:`stickslip.analysis.threshold.threshold_fit`). The
figures (:mod:`stickslip.plotting.chaos`) read each point's ``flow.json``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pandas as pd

from stickslip.experiments.chaos_verdict import threshold_columns
from stickslip.models.presets import PRESETS, is_paper

__all__ = ["conclusions", "curves", "figures", "decorrelation_table"]

KINDS = ("state", "Fs", "V")


def _finite(x) -> bool:
    try:
        return x is not None and math.isfinite(float(x))
    except (TypeError, ValueError):
        return False


def _g(x, digits: int = 3) -> str:
    return f"{float(x):.{digits}g}" if _finite(x) else "n/a"


def _per_seed(row: pd.Series, kind: str) -> list[float | None]:
    """The per-window delta* of ``kind`` in a row (``delta_star_<kind>_seed<k>``; None: censored)."""
    base = f"{threshold_columns(kind)[0]}_seed"
    cols = [f"{base}{k}" for k in range(int(row["seeds"]))]
    return [float(row[c]) if c in row.index and _finite(row[c]) else None for c in cols]


def thresholds(table: pd.DataFrame) -> list[dict[str, Any]]:
    """delta* of every chain point and kind: ``N``, ``beta``, ``kind``, ``per_seed``,
    ``geometric_mean``, ``log10_err``, ``low``, ``high``, ``censored``."""
    out = []
    chain = table[table["model"].map(is_paper)].sort_values(["N", "beta"])
    for _, row in chain.iterrows():
        for kind in KINDS:
            mean, err, low, high, censored = threshold_columns(kind)
            if mean not in row.index or not _finite(row.get(censored)):
                continue
            out.append(
                {
                    "N": int(row["N"]),
                    "beta": float(row["beta"]),
                    "kind": kind,
                    "per_seed": _per_seed(row, kind),
                    "geometric_mean": float(row[mean]) if _finite(row[mean]) else None,
                    "log10_err": float(row[err]) if _finite(row[err]) else math.nan,
                    "low": float(row[low]) if _finite(row[low]) else None,
                    "high": float(row[high]) if _finite(row[high]) else None,
                    "censored": int(row[censored]),
                }
            )
    return out


def fits(points: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """For each beta and kind, :func:`~stickslip.analysis.threshold.threshold_fit` of its points."""
    from stickslip.analysis.threshold import threshold_fit

    out = []
    keys = sorted({(p["beta"], p["kind"]) for p in points}, key=lambda k: (KINDS.index(k[1]), k[0]))
    for beta, kind in keys:
        mine = sorted((p for p in points if p["beta"] == beta and p["kind"] == kind), key=lambda p: p["N"])
        fit = threshold_fit([p["N"] for p in mine], [p["per_seed"] for p in mine])
        out.append({"beta": beta, "kind": kind, **fit})
    return out


def conclusions(table: pd.DataFrame) -> dict[str, Any]:
    """Statements, verdicts, delta* and its fits of a chaos study's rows (module docstring)."""
    out: dict[str, Any] = {"statements": [], "verdicts": {}, "points": []}
    say = out["statements"].append
    rows = table.copy()
    rows["_chain"] = rows["model"].map(is_paper)
    rows = rows.sort_values(["_chain", "N", "beta"], ascending=[False, True, True])
    for _, r in rows.iterrows():
        name = PRESETS[r["model"]].point_label(r["beta"], r["N"])
        lam, err = r.get("lyapunov_dt0"), r.get("lyapunov_dt0_err")
        slips = int(r["flow_slips"]) if _finite(r.get("flow_slips")) else None
        loaded = bool(r.get("loaded")) if r.get("loaded") is not None else None
        out["points"].append(
            {
                "point": name,
                "model": r["model"],
                "N": int(r["N"]),
                "beta": float(r["beta"]) if _finite(r.get("beta")) else None,
                "verdict": r.get("verdict"),
                "verdict_text": r.get("verdict_text"),
                "lyapunov_dt0": float(lam) if _finite(lam) else None,
                "lyapunov_dt0_err": float(err) if _finite(err) else None,
                "flow_slips": slips,
                "loaded": loaded,
            }
        )
        out["verdicts"].setdefault(r.get("verdict"), []).append(name)
        say(
            f"{name}: flow exponent {_g(lam)} +- {_g(err, 2)} (each rung counting at least {slips} slips); "
            f"{r.get('verdict_text')}."
        )
    say("Verdicts: " + "; ".join(f"{label} at {', '.join(names)}" for label, names in out["verdicts"].items()) + ".")
    chain = rows[rows["_chain"]]
    if "loaded" in chain.columns and len(chain):
        not_loaded = [PRESETS[r.model].point_label(r.beta, r.N) for r in chain.itertuples() if not bool(r.loaded)]
        say(
            "Loading: every chain point started from a loaded state (transient at least twice the start of the "
            "first slip that moved block N)."
            if not not_loaded
            else f"Loading: NOT loaded by that rule: {', '.join(not_loaded)}."
        )
    points = thresholds(table)
    out["thresholds"] = points
    out["fits"] = fits(points)
    for kind in KINDS:
        mine = [f for f in out["fits"] if f["kind"] == kind and math.isfinite(f["slope"])]
        if not mine:
            continue
        parts = [
            f"beta = {f['beta']:g}: {f['slope']:+.2f} +- {f['slope_err']:.2f} "
            + ("(no trend)" if f["trend"] == "none" else f"({f['trend']} with N)")
            for f in mine
        ]
        Ns = sorted({n for f in mine for n in f["Ns"]})
        say(
            f"delta* ({kind}) against N = {', '.join(map(str, Ns))}, slope of log10 delta* on log10 N "
            f"with its standard error: {'; '.join(parts)}."
        )
    return out


def curves(table: pd.DataFrame, points_dir: Path) -> list[dict[str, Any]]:
    """The ``flow.json`` of every point that has one, with ``label``, ``N`` and ``beta`` (None
    for the relatives); chain points by N then beta, the relatives last."""
    from stickslip import io

    found = []
    if "point_dir" not in table.columns:
        return found
    for r in table.itertuples():
        path = Path(points_dir) / str(r.point_dir) / "flow.json"
        if not path.is_file():
            continue
        chain = is_paper(r.model)
        label = f"eq. (4), N = {int(r.N)}, beta = {r.beta:g}" if chain else f"{r.model}, N = {int(r.N)}"
        key = (0, int(r.N), float(r.beta)) if chain else (1, 0, 0.0)
        data = io.read_json(path)
        found.append((key, {**data, "label": label, "N": int(r.N), "beta": float(r.beta) if chain else None}))
    return [c for _, c in sorted(found, key=lambda x: x[0])]


def decorrelation_table(found: list[dict[str, Any]]) -> pd.DataFrame:
    """Every n(delta) row of the points: model label, N, beta, kind, delta, seed, events,
    decorrelated, t_decorrelated."""
    rows = []
    for c in found:
        for kind, d in (c.get("decorrelation") or {}).items():
            for r in d.get("decorrelation", []):
                rows.append(
                    {
                        "point": c["label"],
                        "N": c["N"],
                        "beta": c["beta"],
                        "kind": kind,
                        **{k: r.get(k) for k in ("delta", "seed", "events", "decorrelated", "t_decorrelated")},
                    }
                )
    return pd.DataFrame(rows)


def figures(table: pd.DataFrame, points_dir: Path, page_dir: Path) -> list[tuple[str, Any, str]]:
    """The study's figures (name, Figure, caption) and ``decorrelation.csv``/``.parquet`` in
    ``page_dir`` (every n(delta) row)."""
    from stickslip import io
    from stickslip.plotting import chaos as pc

    found = curves(table, points_dir)
    if not found:
        return []
    io.write_table_files(Path(page_dir) / "decorrelation", decorrelation_table(found))
    out = [
        (
            "decorrelation",
            pc.decorrelation_figure(found),
            "n(delta): slips that agree between a reference and a twin started delta apart (rows: "
            "the state moved, Fs or V changed by delta relative), one colour per beta, one marker per "
            "window of slips; open markers: the window never disagreed (n = the slips compared).",
        ),
        (
            "flow_ladder",
            pc.flow_ladder_figure(found),
            "Largest exponent of the flow (located switches, the time shift removed) at dt, dt/2, "
            "dt/4, with the fit lambda_0 + c dt^2 and lambda_0 (square) at dt = 0.",
        ),
    ]
    points = thresholds(table)
    if points:
        out.append(
            (
                "threshold",
                pc.threshold_figure(points, fits(points)),
                "delta*, the smallest delta that decorrelated within the window, against N: each "
                "window (dots), the geometric mean with its standard error, and the least-squares "
                "line of log10 delta* on log10 N for each beta (dashed, slope in the legend).",
            )
        )
    return out
