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

__all__ = ["verdict_point", "check_verdict", "delta_column", "flow_lengths", "verdict_once"]

FLOW_KEYS = ("flow_t", "decorrelation_t")


def flow_lengths(flow_t: float, decorrelation_t: float) -> dict[str, float]:
    """A point's lengths of the located runs behind its verdict."""
    return {"flow_t": flow_t, "decorrelation_t": decorrelation_t}


def verdict_once(point: dict[str, Any], d0: float) -> dict[str, Any]:
    """``point`` without the verdict's lengths unless d0 = 1e-10: one verdict per relative, the
    other values of d0 only show the spread of the gridded exponent."""
    return {k: v for k, v in point.items() if d0 == 1e-10 or k not in FLOW_KEYS}


def delta_column(delta: float) -> str:
    """Table column of n(delta): ``n_decorr_1e-12`` etc."""
    return f"n_decorr_{delta:g}"


def check_verdict(cfg: dict[str, Any], params, options: dict[str, Any]) -> None:
    """Raise ParameterError (one line) unless the verdict's run lengths of a point are valid."""
    from stickslip.analysis.lyapunov import _check_run
    from stickslip.models.params import ParameterError, check_number

    if not any(k in cfg for k in FLOW_KEYS):
        return
    if not all(k in cfg for k in FLOW_KEYS):
        raise ParameterError(f"a chaos point with a verdict needs both {' and '.join(FLOW_KEYS)}")
    check_number("decorrelation_t", cfg["decorrelation_t"], low=0.0, low_open=True)
    if params.ends_piece.wall and float(options.get("transient", 0.0)) > 0.0:
        raise ParameterError("the verdict's located runs restart the clock: fixed ends (which read t) are refused")
    interval = float(options.get("interval", 10.0))
    _check_run(params, float(cfg["flow_t"]), interval, float(options.get("d0", 1e-10)), 0.0, None, 10)


def _located_start(cfg: dict[str, Any], params, options: dict[str, Any]):
    """The located state at the end of the transient (the engine's run up to there)."""
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
    from stickslip.analysis.lyapunov_flow import flow_ladder

    check_verdict(cfg, params, options)
    start = _located_start(cfg, params, options)
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
    }
    for r in rows:
        out[delta_column(r["delta"])] = float(r["events"]) if r["decorrelated"] else math.nan
    return out
