"""The cost of a slip event on the active-set exact path against the event's size and the
lattice's (docs/lattice.md, "Speed"; issue: the cost per event grows with its size, not with L^2).

A run's event lasts while any block of the lattice moves, so under a plate moving fast enough two
ruptures far apart run into one event, more often the larger the lattice. The workload here keeps
them apart: the plate's velocity falls with the lattice as V_L = V_64 (64 / L)^2, so the lattice
as a whole is loaded at the same rate per unit time at every L and its events overlap no more
often at 256 than at 64; V_64 = 1e-6 leaves a block moving in 1.5 % of the steps at L = 64 and
0.3 % at 256 (``busy_fraction``: the steps inside events over the steps of the window, the
chance that a rupture starting at random falls inside another). Each lattice is prepared by the
exact path from rest (A = 0.01) over ``loading_times`` 1 / V_L, then the window of
``timed_loading_times`` 1 / V_L is timed, as is a run of one step from the same state: a run's
fixed cost (the first step computes every block, builds the neighbour table and the heap of
triggers; the final state is hashed) grows with L^2 but once per run, so it is subtracted:

    seconds per event = (seconds of the window - seconds of the one-step run) / events

and likewise per block update and per block of event area (the sum of the events' areas). The
same window run again with the kernel returning after each event gives each event's work
(block updates from the end of the one before it to its own end: its steps, then the triggers of
its last movers' neighbourhood), which is set against its area event by event.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
import pandas as pd

from stickslip.kernels import layout
from stickslip.models.lattice.params import LatticeParams, on_lattice
from stickslip.models.params import ParameterError, check_number
from stickslip.run.errors import NonFiniteState
from stickslip.run.lattice import run_lattice, sparse_path

#: The workload of `stickslip bench --lattice square --workload events`: the sizes L of the
#: L x L lattices, the plate's V at L = 64 (scaled as (64 / L)^2), the preparation and the timed
#: window in loading times 1 / V_L, and the timings of each (the fastest kept).
EVENTS = {"sizes": (64, 128, 256), "V64": 1e-6, "loading_times": 1.5, "timed_loading_times": 0.5, "repeat": 2}

#: Bins of event area (blocks) for the work per event: [1, 2), [2, 4), [4, 8), ...
AREA_BINS = tuple(2**k for k in range(0, 25))


def sized(p: LatticeParams, L: int, v64: float) -> LatticeParams:
    """The model ``p`` on the L x L square with its edges, the plate at V_L = v64 (64 / L)^2."""
    if p.lattice.name != "square":
        raise ParameterError("the events workload runs on the square lattice (--lattice square)")
    L = int(check_number("size", L, low=4, integer=True))
    edges = dict(zip(("top", "bottom", "left", "right"), p.lattice.edges, strict=True))
    return on_lattice(p.chain.replace(V=v64 * (64.0 / L) ** 2), "square", (L, L), edges)


def _timed(p: LatticeParams, t_end: float, state) -> tuple[float, Any]:
    c0 = time.process_time()
    run = run_lattice(p, t_end, start=state, integrator="exact")
    return time.process_time() - c0, run


def event_work(p: LatticeParams, state, t_end: float) -> pd.DataFrame:
    """The events of the exact path's run of ``p`` from ``state`` to ``t_end`` with each one's
    work: ``block_updates`` from the end of the event before it (or the run's start) to its own
    end, and ``steps_computed`` likewise. The kernel returns after every event (an event buffer
    of one row), which changes no bit of the run."""
    from stickslip.run import lattice as rl

    if not sparse_path(p):
        raise ParameterError(f"the events workload needs the active-set exact path (got {p.model})")
    n_end = int(round(t_end / p.dt))
    s = state.copy()
    scratch = [np.zeros(p.lattice.size) for _ in range(6)]
    ev_int, ev_moment = np.zeros((1, 9), dtype=np.int64), np.zeros(1)
    sparse = rl._sparse_args(p)
    call = rl._kernel(p, rl._args(p, s, scratch, ev_int, ev_moment, n_end), sparse)
    rows, moments, work = [], [], []
    bu, sc = int(s.ist[layout.BLOCK_UPDATES]), int(s.ist[layout.STEPS_COMPUTED])
    while s.step < n_end:
        status = call(rl._args(p, s, scratch, ev_int, ev_moment, n_end))
        if int(s.ist[layout.EV_COUNT]):
            rows.append(ev_int[0].copy())
            moments.append(float(ev_moment[0]))
            b, c = int(s.ist[layout.BLOCK_UPDATES]), int(s.ist[layout.STEPS_COMPUTED])
            work.append((b - bu, c - sc))
            bu, sc = b, c
        s.ist[layout.EV_COUNT] = 0
        if status == layout.NONFINITE:
            raise NonFiniteState(f"the run became non-finite at step {s.step}")
    table = rl._event_table(p, np.array(rows, dtype=np.int64).reshape(-1, 9), np.array(moments, dtype=float))
    w = np.array(work, dtype=np.int64).reshape(-1, 2)
    table["block_updates"] = w[:, 0]
    table["steps_computed"] = w[:, 1]
    return table


def _slope(x, y) -> float | None:
    """The exponent of y on x: the slope of a straight line through (log x, log y), least squares."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    ok = (x > 0) & (y > 0)
    if ok.sum() < 2 or np.ptp(np.log(x[ok])) == 0:
        return None
    return float(np.polyfit(np.log(x[ok]), np.log(y[ok]), 1)[0])


def area_bins(events: pd.DataFrame) -> pd.DataFrame:
    """The events' work against their area in bins of doubling area: per bin the events, their
    mean area and mean block updates, and block updates per block of area."""
    edges = np.asarray(AREA_BINS)
    k = np.searchsorted(edges, events["area"].to_numpy(), side="right") - 1
    g = events.assign(bin=edges[k]).groupby("bin")
    out = pd.DataFrame(
        {"events": g.size(), "area_mean": g["area"].mean(), "block_updates_mean": g["block_updates"].mean()}
    )
    out["block_updates_per_area"] = out["block_updates_mean"] / out["area_mean"]
    return out.reset_index().rename(columns={"bin": "area_from"})


def one_size(
    p: LatticeParams, *, loading_times: float, timed_loading_times: float, repeat: int
) -> tuple[dict[str, Any], pd.DataFrame]:
    """One lattice of :func:`event_cost`: prepare, time the window and a one-step run (alternated,
    ``repeat`` times, the fastest processor time of each kept), count the window's events and
    their work (module docstring). Returns the row and the events with their work (the first
    event of the window left out: it carries the run's first step over every block)."""
    V = p.V
    prep = run_lattice(p, loading_times / V, start="rest", perturbation=0.01, integrator="exact")
    t0 = prep.summary["t_end"]
    t1 = t0 + timed_loading_times / V
    best, fixed = np.inf, np.inf
    run = one = None
    for _ in range(repeat):
        seconds, run = _timed(p, t1, prep.state)
        best = min(best, seconds)
        seconds, one = _timed(p, t0 + p.dt, prep.state)
        fixed = min(fixed, seconds)
    ev = run.events
    work = event_work(p, prep.state, t1)
    if not (work.drop(columns=["block_updates", "steps_computed"]).equals(ev)):
        raise RuntimeError("the run that returns after every event gave other events")
    n = len(ev)
    steps = run.summary["steps"] - prep.summary["steps"]
    updates = run.summary["block_updates"] - one.summary["block_updates"]
    area = int(ev["area"].sum())
    net = max(best - fixed, 0.0)
    # the window's first event carries the one-step run's work (the fresh first step): left out
    w = work.iloc[1:] if len(work) > 1 else work
    row = {
        "L": p.lattice.shape[0],
        "blocks": p.lattice.n_blocks,
        "V": V,
        "t_prepare": t0,
        "t_timed": t1 - t0,
        "steps": steps,
        "events": n,
        "area_total": area,
        "area_mean": area / n if n else 0.0,
        "area_max": int(ev["area"].max()) if n else 0,
        "busy_fraction": float((ev["step_end"] - ev["step_start"] + 1).sum() / steps) if steps else 0.0,
        "block_updates": int(updates),
        "seconds": best,
        "fixed_seconds": fixed,
        "seconds_per_event": net / n if n else None,
        "ns_per_block_update": 1e9 * net / updates if updates > 0 else None,
        "ns_per_area": 1e9 * net / area if area else None,
        "block_updates_per_event": updates / n if n else None,
        "triggers_per_event": (run.summary["triggers"] - one.summary["triggers"]) / n if n else None,
        "block_updates_per_area": float(w["block_updates"].sum() / w["area"].sum()) if len(w) else None,
        "work_exponent_on_area": _slope(w["area"], w["block_updates"]),
        "area_bins": area_bins(w).to_dict(orient="records"),
        "prepare_events": len(prep.events),
        "state_sha256": run.summary["state_sha256"],
    }
    return row, w


def event_cost(
    p: LatticeParams,
    sizes=EVENTS["sizes"],
    *,
    v64: float = EVENTS["V64"],
    loading_times: float = EVENTS["loading_times"],
    timed_loading_times: float = EVENTS["timed_loading_times"],
    repeat: int = EVENTS["repeat"],
    say=None,
) -> dict[str, Any]:
    """The exact path's cost per slip event against the event's area and the lattice's size, on
    the model ``p`` (its pieces and parameters; a plate-driven model such as Carlson-Langer's) on
    L x L squares of each of ``sizes`` (module docstring; docs/lattice.md, "Speed").

    Returns one row per L (events, their mean area, the busy fraction, seconds per event, ns per
    block update and per block of area, block updates per event and per block of area, the
    exponent of an event's work on its area over the window's events, the work in bins of area)
    and the exponents fitted by least squares on logs: of an event's block updates on its area,
    event by event over every L; over the sizes, of the seconds per event, the ns per block of
    area and per block update, and the block updates per block of area on L."""
    if not isinstance(p, LatticeParams):
        raise ParameterError("the events workload needs a model on the square (lattice='square')")
    if not sparse_path(p) or not p.drive_piece.leaf_spring:
        raise ParameterError(
            f"the events workload needs a plate-driven model on the active-set exact path (got {p.model}; "
            "e.g. carlson-langer)"
        )
    if p.per_block():
        raise ParameterError("the events workload takes one value per parameter (no per-block values)")
    v64 = check_number("V", v64, low=0.0, low_open=True)
    check_number("loading_times", loading_times, low=0.0, low_open=True)
    check_number("timed_loading_times", timed_loading_times, low=0.0, low_open=True)
    repeat = int(check_number("repeat", repeat, low=1, integer=True))
    sizes = sorted({int(check_number("size", L, low=4, high=4096, integer=True)) for L in sizes})
    # compile (or load) the exact path once, outside the timings
    run_lattice(sized(p, sizes[0], v64), 2 * p.dt, start="rest", perturbation=0.01, integrator="exact")
    rows, works = [], []
    for L in sizes:
        if say is not None:
            say(f"{L} x {L}: preparing over {loading_times:g} loading times, then timing")
        q = sized(p, L, v64)
        row, work = one_size(q, loading_times=loading_times, timed_loading_times=timed_loading_times, repeat=repeat)
        rows.append(row)
        works.append(work)
    pooled = pd.concat(works) if works else pd.DataFrame({"area": [], "block_updates": []})
    col = lambda name: [r[name] for r in rows]  # noqa: E731
    return {
        "model": p.model,
        "V64": v64,
        "loading_times": loading_times,
        "timed_loading_times": timed_loading_times,
        "repeat": repeat,
        "sizes": rows,
        "exponents": {
            "block_updates_per_event_on_area": _slope(pooled["area"], pooled["block_updates"]),
            "seconds_per_event_on_L": _slope(col("L"), col("seconds_per_event")),
            "ns_per_area_on_L": _slope(col("L"), col("ns_per_area")),
            "ns_per_block_update_on_L": _slope(col("L"), col("ns_per_block_update")),
            "block_updates_per_area_on_L": _slope(col("L"), col("block_updates_per_area")),
        },
    }


def format_event_cost(r: dict[str, Any]) -> str:
    """Human-readable lines of :func:`event_cost`'s result."""
    lines = [
        f"{r['model']} on L x L, V = {r['V64']:g} (64 / L)^2, prepared over {r['loading_times']:g} loading times, "
        f"timed over {r['timed_loading_times']:g} (processor time, best of {r['repeat']}, less a one-step run's)",
        f"{'L':>5} {'events':>7} {'mean area':>9} {'max':>6} {'busy':>7} {'us/event':>9} {'ns/update':>9} "
        f"{'ns/area':>8} {'updates/area':>12} {'work~area^':>10} {'fixed s':>8}",
    ]
    f = lambda v, spec: "-" if v is None else format(v, spec)  # noqa: E731
    for s in r["sizes"]:
        lines.append(
            f"{s['L']:>5} {s['events']:>7} {s['area_mean']:>9.3g} {s['area_max']:>6} {s['busy_fraction']:>7.2%} "
            f"{f(None if s['seconds_per_event'] is None else 1e6 * s['seconds_per_event'], '>9.3g')} "
            f"{f(s['ns_per_block_update'], '>9.3g')} {f(s['ns_per_area'], '>8.3g')} "
            f"{f(s['block_updates_per_area'], '>12.3g')} {f(s['work_exponent_on_area'], '>10.2f')} "
            f"{s['fixed_seconds']:>8.3f}"
        )
    bins = sorted({b["area_from"] for s in r["sizes"] for b in s["area_bins"]})
    lines.append("block updates per event / per block of area, by the event's area (blocks):")
    lines.append(f"{'area':>12} " + " ".join(f"{'L = ' + str(s['L']):>24}" for s in r["sizes"]))
    for a in bins:
        cells = []
        for s in r["sizes"]:
            b = next((b for b in s["area_bins"] if b["area_from"] == a), None)
            cells.append(
                f"{'':>24}"
                if b is None
                else f"{b['events']:>7} x {b['block_updates_mean']:>8.3g} / {b['block_updates_per_area']:>4.0f}"
            )
        lines.append(f"{f'{a}-{2 * a - 1}':>12} " + " ".join(cells))
    e = r["exponents"]
    lines.append(
        "fitted exponents (least squares on logs): an event's block updates on its area "
        f"{f(e['block_updates_per_event_on_area'], '.2f')} (event by event); on L: seconds per event "
        f"{f(e['seconds_per_event_on_L'], '.2f')}, ns per block of area {f(e['ns_per_area_on_L'], '.2f')}, "
        f"ns per block update {f(e['ns_per_block_update_on_L'], '.2f')}, block updates per block of area "
        f"{f(e['block_updates_per_area_on_L'], '.2f')}"
    )
    return "\n".join(lines)
