"""The lattice points of a parameter sweep (docs/sweeps.md, "On a lattice"): a model on the square
(docs/lattice.md) at each point, a task of :func:`stickslip.experiments.sweep.run_sweep`.

A point holds :class:`~stickslip.models.params.ChainParams` fields (``model``: a preset, default
the paper's chain; not ``N``: the square's size is its ``shape``), the lattice (``lattice``,
``shape`` and optionally ``edges``, as :func:`stickslip.chain_params` takes them) and the run
options of :data:`LATTICE_RUN_OPTIONS`; ``t_end`` is needed. The run is cut into
:data:`SEGMENTS` parts with a checkpoint after each
(:func:`~stickslip.experiments.studies.lattice_points.run_segments`), so an interrupted point
goes on from its last one, to the bits of one run.

What a point measures, from the run's samples and events (as the chain's point measures <L>
from ``average_from``, by default t_end / 2, the lattice catalogue's window too):

* the mean slip deficit d (the load point V t less x, over the blocks) averaged over the
  samples at t >= ``average_from``, and where the model has steady sliding its value d_ss
  there and the order parameter m = 1 - <d>/d_ss with its batch-means error, the fraction of
  samples with a block stuck and the final state
  (:func:`~stickslip.experiments.studies.lattice_points.rung_order`, the lattice study's);
* the number of events, and of the events that start at t >= ``average_from`` their mean and
  largest moment (total slip) and area (blocks).
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
from pathlib import Path
from typing import Any

import numpy as np

from stickslip.experiments.studies.lattice_points import CHECKPOINT, at_steady, run_segments, rung_order, steady_deficit
from stickslip.models.params import MAX_PERTURBATION, ChainParams, ParameterError, check_number, steps_for

__all__ = ["LATTICE_KEYS", "LATTICE_RUN_OPTIONS", "NOT_ON_LATTICE", "SEGMENTS", "lattice_run_args", "lattice_run_task"]

#: The lattice of a point, as :func:`stickslip.chain_params` takes it.
LATTICE_KEYS = ("lattice", "shape", "edges")
#: A lattice point's run options (:func:`stickslip.run.lattice.run_lattice`'s, with the chain
#: sweep's names: ``sample_interval`` is its ``sample_every``).
LATTICE_RUN_OPTIONS = ("t_end", "integrator", "start", "perturbation", "seed", "sample_interval", "average_from")
#: What a chain point may hold and a lattice point may not, and why.
NOT_ON_LATTICE = {
    "N": "the square's size is its shape",
    "profile_window": "a lattice run keeps no profiles",
    "profile_min_blocks": "a lattice run keeps no profiles",
}
#: Parts of a point's run, each ending with a checkpoint in its folder.
SEGMENTS = 8
#: The time between samples where a point gives none: the chain's (RunOptions.sample_interval).
SAMPLE_INTERVAL = 10.0


def lattice_run_args(point: dict[str, Any]):
    """The model, run length and run options of a lattice point, every value checked.

    Parameters
    ----------
    point : dict
        ChainParams fields, :data:`LATTICE_KEYS` and :data:`LATTICE_RUN_OPTIONS` (module docstring).

    Returns
    -------
    tuple
        (:class:`~stickslip.models.lattice.params.LatticeParams`, t_end, options): ``integrator``
        (default ``exact``), ``start`` and ``perturbation`` (default
        :func:`~stickslip.run.lattice.start_defaults`, the `stickslip chain --lattice` command's),
        ``seed`` (0), ``sample_interval`` (10) and ``average_from`` (default t_end / 2).

    Raises
    ------
    ParameterError
        One line naming the value: an unknown key, one of :data:`NOT_ON_LATTICE`, no lattice or
        shape, an integrator or start a lattice run has not, a value out of its range.
    """
    from stickslip import chain_params
    from stickslip.run.lattice import STARTS, start_defaults, steady_fields

    fields = {f.name for f in dataclasses.fields(ChainParams)}
    for key, why in NOT_ON_LATTICE.items():
        if key in point:
            raise ParameterError(f"{key} does not go with a lattice ({why})")
    unknown = sorted(set(point) - fields - set(LATTICE_KEYS) - set(LATTICE_RUN_OPTIONS))
    if unknown:
        raise ParameterError(f"unknown keys of a lattice point: {', '.join(unknown)}")
    if point.get("lattice") in (None, "chain") or "shape" not in point:
        raise ParameterError("a lattice point needs lattice (square) and shape (rows x cols, e.g. 8x8)")
    values = {k: v for k, v in point.items() if k in fields}
    lattice = {k: point[k] for k in LATTICE_KEYS if k in point}
    p = chain_params(values.pop("model", "sakaguchi"), **lattice, **values)
    if "t_end" not in point:
        raise ParameterError("a sweep point needs t_end")
    t_end = check_number("t_end", point["t_end"], low=0.0, low_open=True)
    steps_for(t_end, p.dt, "t_end")
    integrator = point.get("integrator", "exact")
    if integrator not in ("exact", "dense"):
        raise ParameterError(f"integrator must be exact or dense on a lattice (got {integrator!r})")
    if point.get("start", "paper") not in STARTS:
        raise ParameterError(f"start must be one of {', '.join(STARTS)} on a lattice (got {point['start']!r})")
    given = point.get("perturbation")
    if given is not None:
        given = check_number("perturbation", given, low=0.0, high=MAX_PERTURBATION)
    start, amplitude = start_defaults(p, point.get("start"), given)
    if start == "paper" and (given is not None or "seed" in point):
        raise ParameterError("perturbation and seed go with start steady or rest")
    if start == "steady":
        steady_fields(p)  # one line where there is no steady sliding
    options = {
        "integrator": integrator,
        "start": start,
        "perturbation": amplitude,
        "seed": check_number("seed", point.get("seed", 0), low=0, integer=True),
        "sample_interval": check_number(
            "sample_interval", point.get("sample_interval", SAMPLE_INTERVAL), low=0.0, low_open=True, high=t_end
        ),
        "average_from": check_number(
            "average_from", point.get("average_from", 0.5 * t_end), low=0.0, high=t_end, high_open=True
        ),
    }
    return p, t_end, options


def lattice_run_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """Run a model on the square at one sweep point (module docstring) and return what it measures.

    Parameters
    ----------
    point : dict
        ChainParams fields, the lattice and the run options (:func:`lattice_run_args`).
    point_dir : Path
        Where the run writes run.json, events.csv, samples.csv and state.nc (those of
        `stickslip chain --lattice square --out`), and its checkpoint while it runs.

    Returns
    -------
    dict
        ``n_events``; over t >= ``average_from``: ``mean_slip_deficit``, ``steady_slip_deficit``,
        ``order_parameter`` (and ``order_parameter_err``, ``stuck_fraction``, ``final_state``; NaN
        or None without steady sliding), ``n_events_window``, ``moment_mean``, ``moment_max``,
        ``area_mean``, ``area_max``; the run's ``state_sha256``, steps and block updates.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> s = lattice_run_task({"lattice": "square", "shape": "3x3", "t_end": 20.0}, Path(tempfile.mkdtemp()))
    >>> s["lattice"], s["steps"]
    ('square 3x3 (top free, bottom free, left driven, right free)', 4000)
    """
    from stickslip.experiments.sweep import stop_requested
    from stickslip.run.lattice import LatticeRun, sparse_path

    p, t_end, opt = lattice_run_args(point)
    point_dir = Path(point_dir)
    wall = time.perf_counter()
    key = json.loads(json.dumps({k: point[k] for k in sorted(point)}, default=float))
    state, events, samples = run_segments(
        p,
        t_end,
        point_dir,
        start=opt["start"],
        perturbation=opt["perturbation"],
        seed=opt["seed"],
        sample_every=opt["sample_interval"],
        segments=SEGMENTS,
        key=key,
        stop=stop_requested(point_dir),
        integrator=opt["integrator"],
    )
    from stickslip.kernels import layout

    t_reached = state.step * p.dt
    summary = {
        "model": p.model,
        **p.pieces,
        "lattice": p.lattice.describe(),
        "n_events": int(len(events)),
        "event_in_progress": bool(state.ist[layout.EV_ACTIVE]),
        **_measures(p, state, events, samples, t_reached, opt["average_from"]),
        "t_end": t_reached,
        "steps": state.step,
        "steps_computed": int(state.ist[layout.STEPS_COMPUTED]),
        "block_updates": int(state.ist[layout.BLOCK_UPDATES]),
        "moving_at_end": int(state.ist[layout.N_MOVING]),
        "integrator": "exact" if opt["integrator"] == "exact" and sparse_path(p) else "dense",
        "start": opt["start"],
        "wall_seconds": time.perf_counter() - wall,
        "state_sha256": state.sha256(p.lattice),
    }
    LatticeRun(p, events, state, None, summary, samples).write(point_dir)
    (point_dir / CHECKPOINT).unlink(missing_ok=True)  # a finished point keeps no checkpoint
    return summary


def _measures(p, state, events, samples, t_end: float, average_from: float) -> dict[str, Any]:
    """The slip deficit, the order parameter and the events' sizes over t >= ``average_from``."""
    late = samples[samples["t"] >= average_from - 0.5 * p.dt]
    d = late["mean_slip_deficit"].to_numpy(dtype=float)
    try:
        d_ss = steady_deficit(p)
    except ParameterError:  # no steady sliding: a fixed side, per-block values, a law without one
        d_ss = math.nan
    out: dict[str, Any] = {
        "mean_slip_deficit": float(d.mean()) if d.size else math.nan,
        "mean_slip_deficit_from": average_from,
        "steady_slip_deficit": d_ss,
    }
    if math.isfinite(d_ss) and d_ss != 0.0 and d.size:
        order = rung_order(samples, d_ss, p.lattice.n_blocks, 0.0, t_end, at_steady(p, state), average_from)
        out.update({k: order[k] for k in ("order_parameter", "order_parameter_err", "stuck_fraction", "final_state")})
    else:
        out.update(order_parameter=math.nan, order_parameter_err=math.nan, stuck_fraction=math.nan, final_state=None)
    ev = events[events["t_start"] >= average_from]
    moment, area = ev["moment"].to_numpy(dtype=float), ev["area"].to_numpy(dtype=np.int64)
    out.update(
        n_events_window=int(len(ev)),
        moment_mean=float(moment.mean()) if moment.size else math.nan,
        moment_max=float(moment.max()) if moment.size else math.nan,
        area_mean=float(area.mean()) if area.size else math.nan,
        area_max=int(area.max()) if area.size else 0,
    )
    return out
