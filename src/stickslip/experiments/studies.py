"""The studies the paper leaves open (``stickslip study NAME``), as specs, and the task of one point.

A :class:`Study` is data: a name, a mode, the settings every point shares and the list of points.
Its key hashes the name, the shared settings and the package version (not the point list, so a
point added to a study keeps the directory and runs only the new point). Each point is one chain
run of eq. (4) (or of a relative of it, :mod:`stickslip.models.presets`) plus the analysis of
that run, carried out on a Dask worker by :func:`study_point_task` through
:func:`stickslip.experiments.sweep.run_sweep`: finished points are reused, failed ones are
recorded and retried by the next call, interrupted runs continue from their checkpoints.

* ``transition``: run by continuation in beta (:mod:`stickslip.experiments.transition_study`),
  not by points of this module.
* ``phase-diagram``: final state and m over (alpha, beta) and over (D, beta) at N = 99, each
  point started from the paper's start and from perturbed steady sliding (hysteresis).
* ``exponents``: the slip-size exponent tau (Figs. 7, 8) against beta, and for Carlson-Langer.
* ``chaos``: is the paper's chain chaotic at the onset (section 3, "chaotic motion")? At several N
  and beta = 0.5, 0.9, 1 from a loaded state: the flow's largest exponent over some 300 slips,
  the decorrelation of the slip sequence over 1000 slips against the size of a perturbation
  (state, Fs, V), its threshold delta* and the verdict
  (:mod:`stickslip.experiments.chaos_verdict`); two blocks and Carlson-Langer as known answers.

The runners that turn the points' results into tables, figures and pages are in
:mod:`stickslip.experiments.study_run`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from stickslip import __version__
from stickslip.analysis.chain_runs import UNTIL_STEADY
from stickslip.experiments.cache import canonical, spec_key
from stickslip.experiments.chaos_verdict import chaos_points
from stickslip.models.presets import PRESETS, is_paper, paper_parameters

__all__ = [
    "Study",
    "STUDIES",
    "MODES",
    "study",
    "study_point_task",
    "study_command",
    "check_point",
    "point_params",
    "loading_time",
]

STUDIES = ("transition", "phase-diagram", "exponents", "chaos")
#: ``tiny`` runs every study on chains of a few blocks in seconds (tests); its numbers mean nothing.
MODES = ("quick", "full", "tiny")
_PAPER = paper_parameters("N", "beta")


@dataclass(frozen=True)
class Study:
    """One study as data: ``name`` (one of :data:`STUDIES`), ``mode``, ``common`` (settings
    every point shares: model parameters, run options, analysis), ``points`` (the varying
    settings of each point) and a ``note`` for the page. The result depends on ``name``,
    ``common``, the points and the package version only."""

    name: str
    mode: str
    common: dict[str, Any] = field(default_factory=dict)
    points: tuple[dict[str, Any], ...] = ()
    note: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "common", canonical(dict(self.common)))
        object.__setattr__(self, "points", tuple(canonical(dict(p)) for p in self.points))

    def spec(self) -> dict[str, Any]:
        """What the results depend on: name, shared settings, points, package version."""
        return canonical(
            {"study": self.name, "common": self.common, "points": list(self.points), "version": __version__}
        )

    def key(self) -> str:
        """First 12 hex digits of the SHA-256 of the spec without its points."""
        spec = self.spec()
        spec.pop("points")
        return spec_key(spec)

    @property
    def dirname(self) -> str:
        return f"{self.name}-{self.key()}"


def loading_time(N: int, K: float = 10.0, V: float = 0.001) -> float:
    """L_ss / V at c = 1: the time the pulling point takes to stretch the chain to its steady
    length, ``N (N - 1) / (2 K V)`` (docs/model.md, "Steady sliding")."""
    return N * (N - 1) / (2.0 * K * V)


def _t_end(N: int, loads: float) -> float:
    """Run length: ``loads`` loading times, rounded up to 3 significant digits."""
    t = loads * loading_time(N)
    scale = 10.0 ** (math.floor(math.log10(t)) - 2)
    return math.ceil(t / scale) * scale


# ---------------------------------------------------------------------------------------------
# The spec sets


def _phase_diagram(mode: str) -> Study:
    if mode == "tiny":
        N, alphas, Ds, betas = 9, (1.0,), (5.0,), (0.8, 1.2)
        D_betas = betas
    elif mode == "quick":
        N, alphas, Ds = 99, (0.5, 1.0, 1.5), (0.5, 5.0, 50.0)
        betas = (0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75)
        D_betas = (0.7, 0.9, 1.0, 1.1, 1.3)
    else:
        N, alphas, Ds = 99, (0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0), (0.1, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0)
        betas = tuple(round(0.125 * k, 3) for k in range(1, 19))
        D_betas = (0.6, 0.7, 0.8, 0.85, 0.9, 0.95, 1.0, 1.05, 1.1, 1.15, 1.2, 1.3, 1.4)
    loads = 2.5
    t_end = _t_end(N, loads)
    cells = [{"alpha": a, "D": 5.0, "beta": b} for a in alphas for b in betas]
    cells += [{"alpha": 1.0, "D": d, "beta": b} for d in Ds for b in D_betas]
    unique: list[dict[str, Any]] = []
    for c in cells:
        if c not in unique:
            unique.append(c)
    # Longest first: deep on the sliding side (beta - alpha large) the paper's start slides
    # longest before it settles.
    unique.sort(key=lambda c: -(c["beta"] - c["alpha"]))
    points = [{**c, "N": N, "t_end": t_end, "start": s} for c in unique for s in ("paper", "steady")]
    common = {
        **{k: v for k, v in _PAPER.items() if k not in ("alpha", "D")},
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
    return Study(
        "phase-diagram",
        mode,
        common,
        tuple(points),
        note=(
            f"{mode}: N = {N}, {len(unique)} cells of (alpha, beta) and (D, beta), each from the "
            f"paper's start and from steady sliding perturbed by 0.01"
        ),
    )


def _exponents(mode: str) -> Study:
    if mode == "tiny":
        N, betas, loads, cl = 19, (0.2, 1.0), 5.0, {"N": 16, "t_end": 2000.0}
    elif mode == "quick":
        N, betas, loads, cl = 199, (0.2, 0.4, 0.6, 0.8, 1.0), 5.0, {"N": 100, "t_end": 1e5}
    else:
        N, betas, loads, cl = 399, (0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0), 5.0, {"N": 100, "t_end": 1e6}
    t_end = _t_end(N, loads)
    points = [{"model": "sakaguchi", "N": N, "beta": b, "t_end": t_end} for b in betas]
    points.append(
        {
            "model": "carlson-langer",
            **cl,
            "start": "rest",
            "perturbation": 0.01,
            "seed": 0,
            "spanning": "n_blocks",
            "transient": 0.2,
        }
    )
    common = {
        "start": "paper",
        "average_fraction": 0.5,
        "n_samples": 2000,
        "analysis": "sizes",
        "spanning": "max_block",
        "bootstrap": 200,
    }
    return Study(
        "exponents",
        mode,
        common,
        tuple(points),
        note=(
            f"{mode}: eq. (4) at N = {N} to t = {t_end:g} ({loads:g} loading times), events of the "
            f"second half; Carlson-Langer (standard parameters, N = {cl['N']}, periodic) to "
            f"t = {cl['t_end']:g}, events after the first fifth"
        ),
    )


def _chaos(mode: str) -> Study:
    points, shared = chaos_points(mode)
    chain = [{**shared, **p} for p in points if is_paper(p["model"])]
    Ns = sorted({p["N"] for p in chain})
    betas = sorted({p["beta"] for p in chain})
    first = chain[0]
    transients = ", ".join(f"{p['transient']:g}" for p in sorted(chain, key=lambda p: p["N"]) if p["beta"] == betas[0])
    family = " and ".join(PRESETS[p["model"]].label or p["model"] for p in points if not is_paper(p["model"]))
    common = {"analysis": "chaos", "segments": 10, "direction_seed": 0, **shared}
    return Study(
        "chaos",
        mode,
        common,
        tuple(points),
        note=(
            f"{mode}: eq. (4) at N = {', '.join(map(str, Ns))}, beta = {', '.join(f'{b:g}' for b in betas)}, "
            f"from loaded states (transients {transients}); "
            f"flow ladders of {first['flow_t']:g} time units; n(delta) for {len(first['deltas'])} deltas "
            f"({first['deltas'][0]:g} .. {first['deltas'][-1]:g}), perturbations of the state, Fs and V, "
            f"{first['seeds']} windows of {first['events']} slips; {family} at standard parameters"
        ),
    )


_BUILDERS = {"phase-diagram": _phase_diagram, "exponents": _exponents, "chaos": _chaos}


def study(name: str, mode: str = "quick") -> Study:
    """The spec of study ``name`` (:data:`STUDIES`) in ``mode`` (:data:`MODES`)."""
    if name not in _BUILDERS:
        raise ValueError(f"study must be one of {', '.join(STUDIES)} (got {name!r})")
    if mode not in MODES:
        raise ValueError(f"mode must be one of {', '.join(MODES)} (got {mode!r})")
    return _BUILDERS[name](mode)


def study_command(name: str, mode: str) -> str:
    """The command line that computes study ``name`` in ``mode`` (shown beside each figure)."""
    return f"stickslip study {name} --{mode} --out DIR"


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
    params = point_params(cfg)
    if cfg.get("analysis") == "chaos":
        from stickslip.experiments.chaos_verdict import check_point as check_chaos

        check_chaos(cfg, params)
    else:
        point_run_options(cfg, params)


def study_point_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """One point of a study: the chain run and its analysis (a task of ``run_sweep``).

    ``analysis = "order"``: :func:`order_summary`; ``"sizes"``: :func:`sizes_summary`;
    ``"chaos"``: :func:`stickslip.experiments.chaos_verdict.chaos_point` (no chain run record).
    Returns the summary stored in the point's ``done.json``.
    """
    from stickslip.experiments.sweep import run_chain_point

    if point.get("analysis") == "chaos":
        from stickslip.experiments.chaos_verdict import chaos_point

        return chaos_point(point, point_params(point), Path(point_dir))
    params = point_params(point)
    t_end, options = point_run_options(point, params)
    point_dir = Path(point_dir)
    run = run_chain_point(params, t_end, point_dir, **options)
    base = {
        "model": params.model,
        "t_end": t_end,
        "t_reached": float(run.summary["t_reached"]),
        "n_events_total": int(run.summary["n_events"]),
        "run_wall_seconds": float(run.summary["wall_seconds"]),
        "block_updates": int(run.summary["block_updates"]),
    }
    if point.get("analysis") == "sizes":
        return {**base, **sizes_summary(run, point)}
    return {**base, **order_summary(run, params, options["average_from"])}


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
