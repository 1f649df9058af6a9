"""The verdict of one point of ``stickslip study chaos``: chaotic, stable chaos or regular.

A point that names ``flow_t`` and ``decorrelation_t`` continues its model from the engine's
state at the end of the transient with located switches (:mod:`stickslip.run.located`): the
exponent of the flow over ``flow_t`` at dt, dt/2, dt/4 extrapolated to dt -> 0
(:func:`stickslip.analysis.lyapunov_flow.flow_ladder`), and the decorrelation of the event
sequence over ``decorrelation_t`` for delta in :data:`stickslip.analysis.decorrelation.DELTAS`
(:func:`stickslip.analysis.decorrelation.event_decorrelation`); the two give the verdict
(:func:`stickslip.analysis.decorrelation.verdict`).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

__all__ = [
    "verdict_point",
    "check_verdict",
    "delta_column",
    "flow_lengths",
    "verdict_once",
    "chaos_points",
    "fsle_summary",
    "located_start",
]

FLOW_KEYS = ("flow_t", "decorrelation_t")
VERDICT_KEYS = (*FLOW_KEYS, "fsle_cycles", "fsle_t")
#: Finite-size exponents of a point: thresholds from FSLE_MIN to FSLE_MAX (ratio 2), distance
#: read every FSLE_CHECK time units; rows below FSLE_POOLED are pooled into one rate.
FSLE_MIN, FSLE_MAX, FSLE_CHECK, FSLE_POOLED = 1e-8, 0.1, 0.5, 1e-6


def flow_lengths(flow_t: float, decorrelation_t: float, fsle_cycles: int = 0, fsle_t: float = 0.0) -> dict[str, Any]:
    """A point's lengths of the located runs behind its verdict: the flow ladder, the
    decorrelation run and (with ``fsle_cycles``) finite-size cycles of at most ``fsle_t`` each."""
    out: dict[str, Any] = {"flow_t": flow_t, "decorrelation_t": decorrelation_t}
    if fsle_cycles:
        out.update({"fsle_cycles": int(fsle_cycles), "fsle_t": float(fsle_t)})
    return out


def verdict_once(point: dict[str, Any], d0: float) -> dict[str, Any]:
    """``point`` without the verdict's lengths unless d0 = 1e-10: one verdict per relative, the
    other values of d0 only show the spread of the gridded exponent."""
    return {k: v for k, v in point.items() if d0 == 1e-10 or k not in VERDICT_KEYS}


def delta_column(delta: float) -> str:
    """Table column of n(delta): ``n_decorr_1e-12`` etc."""
    return f"n_decorr_{delta:g}"


def check_verdict(cfg: dict[str, Any], params, options: dict[str, Any]) -> None:
    """Raise ParameterError (one line) unless the verdict's run lengths of a point are valid."""
    from stickslip.analysis.benettin import check_run
    from stickslip.models.params import ParameterError, check_number

    if not any(k in cfg for k in FLOW_KEYS):
        return
    if not all(k in cfg for k in FLOW_KEYS):
        raise ParameterError(f"a chaos point with a verdict needs both {' and '.join(FLOW_KEYS)}")
    check_number("decorrelation_t", cfg["decorrelation_t"], low=0.0, low_open=True)
    if "fsle_cycles" in cfg:
        check_number("fsle_cycles", cfg["fsle_cycles"], low=1, integer=True)
        check_number("fsle_t", cfg.get("fsle_t"), low=0.0, low_open=True)
    if params.ends_piece.wall and float(options.get("transient", 0.0)) > 0.0:
        raise ParameterError("the verdict's located runs restart the clock: fixed ends (which read t) are refused")
    interval = float(options.get("interval", 10.0))
    check_run(params, float(cfg["flow_t"]), interval, float(options.get("d0", 1e-10)), 0.0, None, 10)


def located_start(params, options: dict[str, Any]):
    """The located state at the end of ``options["transient"]`` (the engine's run of eq. (4) or a
    relative up to there from ``options["start"]``, clock restarted; docs/lyapunov.md)."""
    from stickslip.run.driver import run_chain
    from stickslip.run.errors import short_runs_expected
    from stickslip.run.located import LocatedState, start_state

    transient = float(options.get("transient", 0.0))
    kw = {"perturbation": options["perturbation"], "seed": options["seed"]}
    if transient <= 0.0:
        return start_state(params, options["start"], **kw)
    with short_runs_expected():
        run = run_chain(params, transient, start=options["start"], sample_interval=transient, **kw)
    # the drive's frame does not read t: every rung of the ladder can start at t = 0 (fixed
    # ends read it, and are refused here)
    return LocatedState.from_chain_state(run.state, params, restart_clock=True)


def verdict_point(cfg: dict[str, Any], params, options: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """``lyapunov_dt0``, ``lyapunov_dt0_err``, n(delta) (NaN where the sequences still agreed at
    the end), its power-law exponent and ``verdict`` of a chaos point; the ladder and the
    decorrelation table also go to ``flow.json`` in ``point_dir``."""
    from stickslip import io
    from stickslip.analysis.decorrelation import DELTAS, event_decorrelation, verdict
    from stickslip.analysis.fsle import LocatedPair, finite_size_exponents, thresholds
    from stickslip.analysis.lyapunov_flow import flow_ladder

    check_verdict(cfg, params, options)
    start = located_start(params, options)
    flow_t = float(cfg["flow_t"])
    ladder = flow_ladder(
        params,
        flow_t,
        levels=int(cfg.get("levels", 3)),
        start=start,
        interval=float(options.get("interval", 10.0)),
        d0=float(options.get("d0", 1e-10)),
        direction_seed=int(options.get("direction_seed", 0)),
        segments=int(options.get("segments", 10)),
    )
    dec = event_decorrelation(
        params, start, DELTAS, t_max=float(cfg["decorrelation_t"]), direction_seed=int(options.get("direction_seed", 0))
    )
    d = dec.to_dict()
    rows = dec.rows
    label = verdict(
        ladder.lyapunov_dt0,
        ladder.lyapunov_dt0_err,
        [r["delta"] for r in rows],
        [r["events"] for r in rows],
        [r["decorrelated"] for r in rows],
    )
    info = {**ladder.to_dict(), **d, "verdict": label}
    fsle_cols: dict[str, Any] = {}
    if int(cfg.get("fsle_cycles", 0)) > 0:
        pair = LocatedPair(params, start, direction_seed=int(options.get("direction_seed", 0)))
        res = finite_size_exponents(
            pair,
            thresholds(FSLE_MIN, FSLE_MAX),
            cycles=int(cfg["fsle_cycles"]),
            check_steps=max(1, int(round(FSLE_CHECK / params.dt))),
            max_cycle_time=float(cfg["fsle_t"]),
            pooled_below=FSLE_POOLED,
        )
        fsle = res.to_dict()
        info["finite_size"] = fsle
        fsle_cols = fsle_summary(fsle)
    point_dir = Path(point_dir)
    point_dir.mkdir(parents=True, exist_ok=True)
    io.write_json(point_dir / "flow.json", info)
    out: dict[str, Any] = {
        "lyapunov_dt0": ladder.lyapunov_dt0,
        "lyapunov_dt0_err": ladder.lyapunov_dt0_err,
        "flow_t": flow_t,
        "decorrelation_t": dec.t_max,
        "decorrelation_compared": dec.reference_events,
        "decorrelation_power": d["decorrelation_power"],
        "verdict": label,
        **fsle_cols,
    }
    for r in rows:
        out[delta_column(r["delta"])] = float(r["events"]) if r["decorrelated"] else math.nan
    return out


def fsle_summary(fsle: dict[str, Any]) -> dict[str, Any]:
    """Table columns of a point's finite-size exponents (Aurell et al. 1997,
    :func:`stickslip.analysis.fsle.finite_size_exponents`): the pooled rate below 1e-6 with its
    error, the largest row rate and its delta, and the cycles that never reached the top."""
    rows = [r for r in fsle["fsle"] if r["cycles"] > 0 and math.isfinite(r["rate"])]
    peak = max(rows, key=lambda r: r["rate"]) if rows else None
    return {
        "fsle_pooled": fsle.get("pooled_rate", math.nan),
        "fsle_pooled_err": fsle.get("pooled_rate_err", math.nan),
        "fsle_peak": peak["rate"] if peak else math.nan,
        "fsle_peak_delta": peak["delta"] if peak else math.nan,
        "fsle_unfinished": int(fsle["unfinished"]),
    }


_CHAOS_BETAS_QUICK = tuple(round(0.2 + 0.1 * k, 3) for k in range(11))
_CHAOS_BETAS_FULL = (0.2, 0.6, 1.0, 1.2)


def chaos_points(mode: str) -> tuple[list[dict[str, Any]], tuple[float, ...]]:
    """The points of ``stickslip study chaos`` in ``mode`` and the relatives' values of d0: the
    paper's chain (eq. 4) over beta, two blocks and Carlson-Langer at their standard parameters,
    each with the lengths of its verdict's located runs (:func:`flow_lengths`)."""
    _flow = flow_lengths
    # Transients: the chain needs about one loading time (4.85e5 at N = 99, 1.97e6 at N = 199)
    # before its length fluctuates about its mean (docs/lyapunov.md); the plate-driven relatives
    # forget their start within 2e3.
    if mode == "tiny":
        chain = [
            {"N": 9, "beta": b, "t_end": 6000.0, "transient": 3000.0, "interval": 10.0, **_flow(200.0, 300.0, 2, 100.0)}
            for b in (0.6, 1.2)
        ]
        # steady sliding well above the inverse transition: the exponent is the least stable
        # eigenvalue of eq. (5), negative (docs/lyapunov.md, checks with known answers)
        chain.append(
            {
                "N": 4,
                "beta": 1.5,
                "V": 0.5,
                "start": "steady",
                "perturbation": 1e-3,
                "t_end": 400.0,
                "transient": 0.0,
                "interval": 5.0,
                **_flow(100.0, 100.0),
            }
        )
        family = [
            {"model": "two-blocks", "t_end": 600.0, "transient": 100.0, **_flow(200.0, 600.0, 2, 200.0)},
            {"model": "carlson-langer", "N": 16, "t_end": 300.0, "transient": 100.0, **_flow(100.0, 200.0, 2, 50.0)},
        ]
        d0s: tuple[float, ...] = (1e-10,)
    elif mode == "quick":
        chain = [
            {"N": 99, "beta": b, "t_end": 6e5, "transient": 5e5, "interval": 10.0, **_flow(500.0, 5e3, 3, 1e3)}
            for b in _CHAOS_BETAS_QUICK
        ]
        family = [
            {"model": "two-blocks", "t_end": 4.2e4, "transient": 2e3, **_flow(2e3, 4e3, 3, 1e3)},
            {"model": "carlson-langer", "t_end": 2.2e4, "transient": 2e3, **_flow(500.0, 2e3, 3, 200.0)},
        ]
        d0s = (1e-10,)
    else:
        chain = [
            {"N": 99, "beta": b, "t_end": 1.1e6, "transient": 1e6, "interval": 10.0, **_flow(1e3, 5e3, 3, 1e3)}
            for b in _CHAOS_BETAS_FULL
        ]
        chain += [
            {"N": 199, "beta": b, "t_end": 2.05e6, "transient": 2e6, "interval": 10.0, **_flow(500.0, 3e3, 2, 1e3)}
            for b in (1.0,)
        ]
        family = [
            {"model": "two-blocks", "t_end": 1.02e5, "transient": 2e3, **_flow(1e4, 1e4, 10, 1e3)},
            {"model": "carlson-langer", "t_end": 2.2e4, "transient": 2e3, **_flow(1e3, 2e3, 5, 200.0)},
        ]
        d0s = (1e-10,)
    points = [{"model": "sakaguchi", "start": "paper", **c, "d0": 1e-10} for c in chain]
    points += [
        {**verdict_once(f, d0), "interval": 1.0, "start": "rest", "perturbation": 0.01, "seed": 0, "d0": d0}
        for f in family
        for d0 in d0s
    ]
    # Longest first: a shorter tail on a few workers.
    points.sort(
        key=lambda p: -(p["t_end"] - p["transient"] + p.get("decorrelation_t", 0.0)) * p.get("N", 100) / p["interval"]
    )
    return points, d0s
