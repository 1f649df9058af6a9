"""One point of ``stickslip study chaos``: a loaded state, the flow's exponent, n(delta), delta*
and the verdict (docs/studies/chaos.md).

A point is one model at one N and beta. From the engine's state at the end of its transient
(:func:`stickslip.run.loaded.loaded_state`, kept in the point's folder with its loading check):

- the flow's largest exponent by two trajectories with located switches
  (:func:`stickslip.analysis.lyapunov_flow.flow_lyapunov`) at dt, dt/2, dt/4 over ``flow_t``, each
  rung counting some 300 slips or more in the chain's points, extrapolated to dt -> 0
  (:func:`stickslip.analysis.lyapunov_flow.extrapolate`);
- n(delta) on the engine's map over windows of ``events`` slips, for each kind of perturbation
  (state, Fs, V), each delta and ``seeds`` consecutive windows
  (:func:`stickslip.analysis.decorrelation.sequence_decorrelation`, the measurement of
  ``stickslip lyapunov --decorrelation``), and delta* per kind
  (:func:`stickslip.analysis.threshold.delta_star`);
- the verdict (:func:`stickslip.analysis.decorrelation.verdict`) from the exponent and the
  state's n(delta).

Every part (each rung, each kind) is written to ``parts/`` in the point's folder as it finishes
and read back, not run again, when the point runs again with the same settings, and the transient
keeps its finished chunks: an interrupted point loses at most the part it was in. A study that is
interrupted asks its points to stop (:func:`stickslip.experiments.sweep.stop_requested`); a point
stops within a chunk of the transient, 64 renormalisations of a rung or one twin.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any

__all__ = [
    "chaos_point",
    "check_point",
    "DELTAS_FULL",
    "DELTAS_QUICK",
    "TRANSIENTS",
    "MIN_FLOW_SLIPS",
    "threshold_columns",
    "kinds_of",
]

#: The deltas of ``--full`` (and of docs/studies/decorrelation-grid.json): 1e-12, 1e-11, ..., 1e-1.
DELTAS_FULL = tuple(float(f"1e{k}") for k in range(-12, 0))
DELTAS_QUICK = (1e-10, 1e-8, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1)
#: Transients of the paper's chain from its start: at least twice the start of the first slip that
#: moves block N at beta = 0.5, 0.9, 1 (measured, docs/studies/chaos.md, "Loaded before comparing");
#: 2.5 loading times N (N - 1) / (2 K V) at N = 399 and 799.
TRANSIENTS = {49: 5e5, 99: 1.5e6, 199: 5e6, 399: 2e7, 799: 8e7}
#: Slips each rung of a chain point's ladder should count (the page reports what they did).
MIN_FLOW_SLIPS = 300
_KEYS = ("transient", "kinds", "deltas", "seeds", "events", "flow_t")


def kinds_of(cfg: dict[str, Any]) -> list[str]:
    """A point's kinds of perturbation: a list, or one text with commas."""
    kinds = cfg["kinds"]
    return [k.strip() for k in kinds.split(",")] if isinstance(kinds, str) else [str(k) for k in kinds]


def threshold_columns(kind: str) -> tuple[str, ...]:
    """Table columns of delta* of one kind: geometric mean, its error in decades, range, censored."""
    base = f"delta_star_{kind}"
    return (base, f"{base}_err_log10", f"{base}_low", f"{base}_high", f"{base}_censored")


def check_point(cfg: dict[str, Any], params) -> None:
    """Raise ParameterError (one line) unless a chaos point's settings make a valid measurement."""
    from stickslip.analysis.benettin import check_run
    from stickslip.analysis.decorrelation import PERTURBATIONS
    from stickslip.models.params import ParameterError, check_number

    missing = [k for k in _KEYS if k not in cfg]
    if missing:
        raise ParameterError(f"a chaos point needs {', '.join(missing)}")
    check_number("transient", cfg["transient"], low=0.0, low_open=True)
    check_number("events", cfg["events"], low=1, integer=True)
    check_number("seeds", cfg["seeds"], low=1, integer=True)
    for kind in kinds_of(cfg):
        if kind not in PERTURBATIONS:
            raise ParameterError(f"kinds must be among {', '.join(PERTURBATIONS)} (got {kind!r})")
    if "state" not in kinds_of(cfg):
        raise ParameterError("a chaos point's verdict needs the kind 'state'")
    for d in cfg["deltas"]:
        check_number("delta", d, low=0.0, low_open=True, high=1.0)
    if params.ends_piece.wall:
        raise ParameterError("the chaos study restarts the clock: fixed ends (which read t) are refused")
    check_run(
        params, float(cfg["flow_t"]), float(cfg.get("interval", 10.0)), float(cfg.get("d0", 1e-10)), 0.0, None, 10
    )


class _Parts:
    """The finished parts of a point (``parts/NAME.json``), each with the settings it was made with
    and its own checksum (:func:`stickslip.experiments.cache.sealed`): an edited or foreign part is
    computed again."""

    def __init__(self, folder: Path, spec: dict[str, Any]):
        self.folder = folder
        self.spec = spec

    def get(self, name: str, compute) -> dict[str, Any]:
        from stickslip import io
        from stickslip.experiments.cache import canonical, read_done, sealed

        path = self.folder / f"{name}.json"
        want = canonical({**self.spec, "part": name})
        kept, _ = read_done(path, want, "result")
        if kept is not None:
            return kept["result"]
        io.write_json(path, {"spec": want, "result": compute(), "files": {}})
        record = io.read_json(path)  # as a reused part reads it (NaN as null), then sealed
        io.write_json(path, sealed(record))
        return record["result"]


def chaos_point(cfg: dict[str, Any], params, point_dir: Path) -> dict[str, Any]:
    """One point (module docstring) of the model ``params``
    (:func:`stickslip.experiments.sweep_points.point_params` of ``cfg``): writes
    ``flow.json`` (loading check, ladder, n(delta) of every kind, delta*, verdict) into
    ``point_dir`` and returns the table's columns."""
    from stickslip import __version__, io
    from stickslip.analysis.decorrelation import GridSequences, sequence_decorrelation, verdict
    from stickslip.analysis.lyapunov_flow import extrapolate, flow_lyapunov
    from stickslip.analysis.threshold import delta_star
    from stickslip.experiments.sweep import stop_requested
    from stickslip.experiments.sweep_points import preset_start
    from stickslip.run.loaded import loaded_state

    wall0 = time.perf_counter()
    check_point(cfg, params)
    point_dir = Path(point_dir)
    stop = stop_requested(point_dir)
    start = preset_start(params, cfg)
    loaded = loaded_state(params, float(cfg["transient"]), **start, cache=point_dir / "state", stop_requested=stop)
    spec = {k: v for k, v in cfg.items()} | {"version": __version__}
    parts = _Parts(point_dir / "parts", spec)
    direction_seed = int(cfg.get("direction_seed", 0))
    interval, d0 = float(cfg.get("interval", 10.0)), float(cfg.get("d0", 1e-10))
    flow_t, levels = float(cfg["flow_t"]), int(cfg.get("levels", 3))
    located = loaded.located(params)

    def rung(k: int):
        p = params.replace(dt=params.dt / 2**k)
        res = flow_lyapunov(
            p,
            flow_t,
            start=located,
            interval=interval,
            d0=d0,
            direction_seed=direction_seed,
            segments=int(cfg.get("segments", 10)),
            stop_requested=stop,
        )
        return res.to_dict()

    rungs = [parts.get(f"flow-rung-{k}", lambda k=k: rung(k)) for k in range(levels)]
    lam0, err0, slope = extrapolate(
        [r["dt"] for r in rungs], [_num(r["lyapunov"]) for r in rungs], [_num(r["lyapunov_err"]) for r in rungs]
    )
    decorrelation, thresholds = {}, {}
    for kind in kinds_of(cfg):

        def measure(kind=kind):
            res = sequence_decorrelation(
                GridSequences(params),
                loaded.state,
                [float(d) for d in cfg["deltas"]],
                perturbation=kind,
                events=int(cfg["events"]),
                seeds=int(cfg["seeds"]),
                direction_seed=direction_seed,
                progress=lambda _line: _stop_now(stop),
            )
            return res.to_dict()

        decorrelation[kind] = parts.get(f"decorrelation-{kind}", measure)
        thresholds[kind] = delta_star(decorrelation[kind]["decorrelation"])
    windows = decorrelation["state"]["decorrelation_windows"]
    window = min(int(w["reference_events"]) for w in windows)
    v = verdict(lam0, err0, decorrelation["state"]["decorrelation"], window=window)
    ladder = [
        {k: r[k] for k in ("dt", "lyapunov", "lyapunov_err", "renormalisations", "events", "waits", "wall_seconds")}
        for r in rungs
    ]
    flow_slips = min(int(r["events"]) for r in rungs)
    info = {
        "loading": loaded.info,
        "ladder": ladder,
        "lyapunov_dt0": lam0,
        "lyapunov_dt0_err": err0,
        "dt2_slope": slope,
        "flow_t": flow_t,
        "flow_slips": flow_slips,
        "interval": interval,
        "d0": d0,
        "decorrelation": decorrelation,
        "thresholds": thresholds,
        **v.to_dict(),
    }
    point_dir.mkdir(parents=True, exist_ok=True)
    io.write_json(point_dir / "flow.json", info)
    out: dict[str, Any] = {
        "loaded": bool(loaded.info["loaded"]),
        "first_slip_reaching_block_N": loaded.info["first_slip_reaching_block_N"],
        "lyapunov_dt0": lam0,
        "lyapunov_dt0_err": err0,
        "flow_slips": flow_slips,
        "window": window,
        "n_deltas": len(cfg["deltas"]),
        **v.to_dict(),
        "point_wall_seconds": time.perf_counter() - wall0,
    }
    for kind, th in thresholds.items():
        mean, err, low, high, censored = threshold_columns(kind)
        out.update(
            {
                mean: _num(th["geometric_mean"]),
                err: _num(th["log10_err"]),
                low: _num(th["low"]),
                high: _num(th["high"]),
                censored: int(th["censored"]),
            }
        )
        for s, value in zip(th["seeds"], th["per_seed"], strict=True):
            out[f"{mean}_seed{s}"] = _num(value)
    return out


def _stop_now(stop) -> None:
    """Raise :class:`stickslip.run.errors.Interrupted` if the study asked its points to stop."""
    if stop():
        from stickslip.run.errors import Interrupted

        raise Interrupted(None, math.nan)


def _num(x) -> float:
    return math.nan if x is None else float(x)
