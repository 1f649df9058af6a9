"""One point of a study that is one chain run and its analysis (the phase diagram, the exponents).

Each point is one chain run of eq. (4) (or of a relative of it, :mod:`stickslip.models.presets`)
plus the analysis of that run, carried out on a Dask worker through
:func:`stickslip.experiments.sweep.run_sweep`: finished points are reused, failed ones are
recorded and retried by the next call, interrupted runs continue from their checkpoints.
:func:`order_task` gives the order parameter and the final state, :func:`sizes_task` the
slip-size exponent.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["order_task", "sizes_task", "check_point", "point_params", "loading_time", "t_end_of"]


def loading_time(N: int, K: float = 10.0, V: float = 0.001) -> float:
    """L_ss / V at c = 1: the time the pulling point takes to stretch the chain to its steady
    length, ``N (N - 1) / (2 K V)`` (docs/model.md, "Steady sliding")."""
    return N * (N - 1) / (2.0 * K * V)


def t_end_of(N: int, loads: float) -> float:
    """Run length: ``loads`` loading times of a chain of ``N`` blocks (the paper's K and V),
    rounded up to 3 significant digits."""
    t = loads * loading_time(N)
    scale = 10.0 ** (math.floor(math.log10(t)) - 2)
    return math.ceil(t / scale) * scale


# ---------------------------------------------------------------------------------------------
# One point: a chain run and its analysis, on a worker

_PARAM_FIELDS = ("N", "K", "D", "V", "beta", "alpha", "Fs", "dt", "l", "nu")


def point_params(cfg: dict[str, Any]):
    """The :class:`~stickslip.models.params.ChainParams` of a point's merged settings."""
    from stickslip.models.presets import chain_params

    return chain_params(cfg.get("model", "sakaguchi"), **{k: cfg[k] for k in _PARAM_FIELDS if k in cfg})


def point_run_options(cfg: dict[str, Any], params) -> tuple[float, dict[str, Any]]:
    """Run length and :func:`~stickslip.run.driver.run_chain` options of a point."""
    from stickslip.models.presets import PRESETS

    t_end = float(cfg["t_end"])
    preset = PRESETS[params.model]
    start = cfg.get("start", preset.start)
    options: dict[str, Any] = {
        "start": start,
        "perturbation": float(cfg.get("perturbation", preset.start_options.get("amplitude", 0.0))),
        "seed": int(cfg.get("seed", preset.start_options.get("seed", 0))),
        "sample_interval": max(t_end / float(cfg.get("n_samples", 2000)), params.dt),
        "average_from": float(cfg.get("average_fraction", 0.5)) * t_end,
        "sample_moving": cfg.get("analysis") == "order",
    }
    if start == "paper":
        options["perturbation"] = 0.0
    if cfg.get("until_steady"):
        options["until_steady"] = float(cfg["until_steady"])
    return t_end, options


def check_point(cfg: dict[str, Any]) -> None:
    """Raise ParameterError (one line) unless a point's merged settings make a valid run."""
    point_run_options(cfg, point_params(cfg))


def _run(point: dict[str, Any], point_dir: Path):
    """The point's chain run (continued from its checkpoint), its parameters, options and the
    summary fields every point stores."""
    from stickslip.experiments.sweep import run_chain_point

    params = point_params(point)
    t_end, options = point_run_options(point, params)
    run = run_chain_point(params, t_end, Path(point_dir), **options)
    base = {
        "model": params.model,
        "t_end": t_end,
        "t_reached": float(run.summary["t_reached"]),
        "n_events_total": int(run.summary["n_events"]),
        "run_wall_seconds": float(run.summary["wall_seconds"]),
        "block_updates": int(run.summary["block_updates"]),
    }
    return run, params, options, base


def order_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """One chain run and its order parameter and final state (:func:`order_summary`), a task of
    ``run_sweep``; returns the summary stored in the point's ``done.json``."""
    run, params, options, base = _run(point, point_dir)
    return {**base, **order_summary(run, params, options["average_from"])}


def sizes_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """One chain run and its slip-size exponent (:func:`sizes_summary`), a task of ``run_sweep``;
    returns the summary stored in the point's ``done.json``."""
    run, _, _, base = _run(point, point_dir)
    return {**base, **sizes_summary(run, point)}


def order_summary(run, params, t_from: float) -> dict[str, Any]:
    """The order parameter m = 1 - <L>/L_ss over t >= ``t_from`` with its batch-means error, the
    fraction of samples with some block stuck, the event rate and largest event over the same
    window, the time steady sliding was reached, and the final state
    (:func:`stickslip.analysis.order.classify_final_state`)."""
    from stickslip.analysis.order import classify_final_state, order_parameter, quarter_stats
    from stickslip.models.physics import chain_steady_length

    L_ss = chain_steady_length(params)
    s = run.summary
    t_end = float(run.options.t_end)
    dt_s = float(run.options.sample_interval)
    t = run.samples["t"].values
    L = run.samples["L"].values
    tm = run.samples["t_moving"].values
    stuck = (run.samples["n_moving"].values < params.N).astype(float)
    reached = bool(s.get("stopped_early", False))
    if reached:
        # steady sliding from t_steady on: L = L_ss and nothing stuck at the remaining sample times
        t_rest = (
            np.arange(math.floor(float(s["t_steady"]) / dt_s + 1e-9) + 1, math.floor(t_end / dt_s + 1e-9) + 1) * dt_s
        )
        t = np.concatenate([t[t < t_rest[0]] if t_rest.size else t, t_rest])
        L = np.concatenate([run.samples["L"].values[: t.size - t_rest.size], np.full(t_rest.size, L_ss)])
        tm_keep = tm < t_rest[0] if t_rest.size else np.ones(tm.size, bool)
        tm = np.concatenate([tm[tm_keep], t_rest])
        stuck = np.concatenate([stuck[tm_keep], np.zeros(t_rest.size)])
    m = 1.0 - L / L_ss
    late = t >= t_from - 1e-9
    est = order_parameter(L[late], L_ss)
    late_m = tm >= t_from - 1e-9
    stuck_fraction = float(stuck[late_m].mean()) if late_m.any() else math.nan
    q = quarter_stats(t, m, None, t_end)
    q.update({k: v for k, v in quarter_stats(tm, np.zeros(tm.size), stuck, t_end).items() if k.startswith("stuck")})
    state, reason = classify_final_state(
        reached_steady=reached,
        stuck_q3=q["stuck_q3"],
        stuck_q4=q["stuck_q4"],
        m_q3=q["m_q3"],
        m_err_q3=q["m_err_q3"],
        m_q4=q["m_q4"],
        m_err_q4=q["m_err_q4"],
    )
    ev = run.events[run.events["t_start"] >= t_from]
    window = t_end - t_from
    return {
        "order_parameter": est.mean,
        "order_parameter_err": est.err,
        "order_parameter_err_tau": est.err_tau,
        "tau_int": est.tau_int * dt_s,
        "batch_time": est.batch * dt_s,
        "n_batches": est.n_batches,
        "err_reliable": est.reliable,
        "L_mean": float(np.mean(L[late])) if late.any() else math.nan,
        "L_steady": L_ss,
        "stuck_fraction": stuck_fraction,
        "event_rate": len(ev) / window if window > 0 else math.nan,
        "n_events": int(len(ev)),
        "S_max": float(ev["S"].max()) if len(ev) else 0.0,
        "max_blocks": int(ev["n_blocks"].max()) if len(ev) else 0,
        "t_steady": float(s["t_steady"]) if reached else None,
        "final_state": state,
        "final_reason": reason,
        **q,
    }


def sizes_summary(run, cfg: dict[str, Any]) -> dict[str, Any]:
    """Slip-size exponent tau (truncated power law below the smallest spanning event, s_min by
    least KS distance, bootstrap error), the fitted range and the excess of great events
    (:func:`stickslip.analysis.chain_runs.size_statistics`) over the events after the transient."""
    from stickslip.analysis.chain_runs import size_statistics

    t_end = float(run.options.t_end)
    t_from = float(cfg.get("transient", cfg.get("average_fraction", 0.5))) * t_end
    events = run.events[run.events["t_start"] >= t_from]
    spanning = cfg.get("spanning", "max_block")
    out: dict[str, Any] = {"t_from": t_from, "n_events": int(len(events)), "spanning": spanning}
    if len(events) < 20:
        out.update(tau=math.nan, tau_err=math.nan, error_note=f"only {len(events)} events after t = {t_from:g}")
        return out
    st = size_statistics(
        events,
        run.params.N,
        small_only=True,
        seed=int(cfg.get("seed", 0)),
        spanning=spanning,
        bootstrap=int(cfg.get("bootstrap", 200)),
    )
    fit = st["fit"]
    out.update(
        tau=fit.tau,
        tau_err=fit.tau_err,
        tau_err_fisher=fit.tau_err_fisher,
        s_min=fit.s_min,
        s_max=fit.s_max,
        n_fit=fit.n,
        ks_distance=fit.ks_distance,
        n_spanning=st["n_spanning"],
        s_span=st["s_span"],
        S_max=st["S_max"],
        excess=st["excess"],
        observed=st["observed"],
        expected=st["expected"],
    )
    return out
