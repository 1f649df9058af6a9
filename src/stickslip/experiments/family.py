"""Experiments across the model family (docs/model.md, "The family the paper stands in").

:func:`cl_statistics`: what the paper says of Carlson-Langer ("all sizes of events, a power law
at small sizes, and great events more frequent than that power law predicts"), measured, beside
the paper's own chain at beta = 0.2 (Fig. 8).
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import pandas as pd

from stickslip import io
from stickslip.analysis.chain_runs import size_statistics
from stickslip.models.presets import chain_params
from stickslip.run.driver import ChainState, run_chain

__all__ = ["cl_statistics"]


def _measure(p, t_end: float, start, transient: float, spanning: str, seed: int, bootstrap: int):
    wall = time.perf_counter()
    run = run_chain(p, t_end, start=start, sample_interval=max(10.0, t_end / 1000.0))
    wall = time.perf_counter() - wall
    t_from = transient * t_end
    events = run.events[run.events["t_start"] >= t_from]
    stats = size_statistics(events, p.N, small_only=True, seed=seed, spanning=spanning, bootstrap=bootstrap)
    fit = stats["fit"]
    summary = {
        "model": p.model,
        "N": p.N,
        "t_end": float(t_end),
        "t_from": t_from,
        "wall_seconds": wall,
        "n_events_run": int(len(run.events)),
        "n_events": stats["n_events"],
        "spanning": spanning,
        "n_spanning": stats["n_spanning"],
        "s_span": stats["s_span"],
        "S_max": stats["S_max"],
        "tau": fit.tau,
        "tau_err": fit.tau_err,
        "tau_err_fisher": fit.tau_err_fisher,
        "s_min": fit.s_min,
        "s_max": fit.s_max,
        "n_fit": fit.n,
        "ks_distance": fit.ks_distance,
        "excess": stats["excess"],
        "observed": stats["observed"],
        "expected": stats["expected"],
    }
    return events, stats, summary


def cl_statistics(
    t_end: float = 1e5,
    out: str | Path | None = None,
    *,
    transient: float = 0.2,
    fig8_N: int = 399,
    fig8_t_end: float = 1e7,
    fig8_transient: float = 0.5,
    seed: int = 0,
    bootstrap: int = 200,
) -> dict[str, Any]:
    """Slip-size statistics of Carlson-Langer (standard parameters, periodic) and of Fig. 8's chain.

    CL: ``chain_params("carlson-langer")`` from rest (A = 0.01, ``seed``) to ``t_end``, events
    after ``transient * t_end``; system-spanning events are those in which all N blocks moved.
    Fig. 8: ``chain_params("sakaguchi", beta=0.2, N=fig8_N)`` from the paper's start to
    ``fig8_t_end`` (the paper: N = 399 to 2e7), events after ``fig8_transient * fig8_t_end``;
    spanning events reach block N. Both: truncated power law below the smallest spanning event,
    s_min by least KS distance, bootstrap error, and the excess of events at or above it over the
    power law's count (:func:`stickslip.analysis.chain_runs.size_statistics`).

    With ``out``, writes the figure ``family_sizes.png`` and ``.pdf``, the sizes drawn in it
    (``family_sizes.parquet`` and ``.csv``: model, event, t_start, S) and the summaries
    (``family_sizes.json``) there. Returns
    {"carlson_langer": summary, "fig8": summary, "files": [...]}; a model without a spanning
    event has NaN excess.
    """
    from stickslip.plotting.family import family_sizes
    from stickslip.plotting.style import save_figure

    p_cl = chain_params("carlson-langer")
    ev_cl, st_cl, cl = _measure(p_cl, t_end, ChainState.rest(p_cl, 0.01, seed), transient, "n_blocks", seed, bootstrap)
    p_8 = chain_params("sakaguchi", beta=0.2, N=int(fig8_N))
    ev_8, st_8, f8 = _measure(p_8, fig8_t_end, "paper", fig8_transient, "max_block", seed, bootstrap)
    result: dict[str, Any] = {"carlson_langer": cl, "fig8": f8, "files": []}
    if out is not None:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        fig = family_sizes(
            [
                (f"Carlson-Langer, N = {p_cl.N} periodic, t = {t_end:g} (from {cl['t_from']:g})", ev_cl, st_cl),
                (f"eq. (4), beta = 0.2 (Fig. 8), N = {p_8.N}, t = {fig8_t_end:g} (from {f8['t_from']:g})", ev_8, st_8),
            ]
        )
        files = [str(f) for f in save_figure(fig, out / "family_sizes")]
        drawn = pd.concat(
            [
                ev[["event", "t_start", "S"]].assign(model=name)
                for name, ev in (("carlson-langer", ev_cl), ("fig8", ev_8))
            ]
        )[["model", "event", "t_start", "S"]]
        files += [str(f) for f in io.write_table_files(out / "family_sizes", drawn)]
        files.append(str(io.write_json(out / "family_sizes.json", {k: v for k, v in result.items() if k != "files"})))
        result["files"] = files
    return result
