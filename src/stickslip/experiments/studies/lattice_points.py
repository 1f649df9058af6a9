"""The points of ``stickslip study lattice`` (docs/studies/lattice.md), tasks of
:func:`stickslip.experiments.sweep.run_sweep`.

``part`` says which task runs a point:

* ``ladder``: eq. (4) on the L x L square pulled at its left edge (docs/lattice.md), continued in
  beta rung after rung (:func:`ladder_task`): ``up`` from rest (x = -A u, u uniform) at the lowest
  beta, ``down`` from steady sliding perturbed by ``down_perturbation`` at the highest (A =
  ``perturbation``: without it every row of the square moves as the chain does, the rows'
  springs never stretched); per rung the order parameter
  m = 1 - <d>/d_ss of the mean slip deficit d (:func:`rung_order`) and the final state;
* ``sizes``: eq. (4) on the square at one beta from the paper's start (:func:`sizes_task`): the
  moments of the events after the transient and whether each reached the far (right) edge;
* ``chain``: the paper's chain of N = L blocks at the same beta (its own fast path): the slips S
  and whether each reached block N;
* ``cl``: Carlson-Langer on the periodic square from rest (the active-set exact path): the
  moments and whether each event moved every block.

The lattice runs are cut into segments, each ending with a checkpoint in the point's folder
(:func:`run_segments`), so an interrupted point goes on from its last segment (a ladder from its
last finished rung); the chain runs checkpoint in the chain driver.
"""

from __future__ import annotations

import io as _io
import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    import pandas as pd

__all__ = [
    "lattice_task",
    "lattice_check",
    "lattice_params",
    "loading_time",
    "run_segments",
    "rung_order",
    "steady_deficit",
    "at_steady",
    "ladder_task",
    "sizes_task",
    "chain_sizes_task",
    "cl_task",
    "CHECKPOINT",
]

#: The checkpoint of a lattice point (state, events and samples so far), in its folder.
CHECKPOINT = "lattice-checkpoint.npz"
#: The rungs of a ladder finished so far, in its folder.
RUNGS = "rungs.json"
#: The samples' columns (:attr:`stickslip.run.lattice.LatticeRun.samples`), none yet.
_NO_SAMPLES = {"t": [], "mean_slip_deficit": [], "mean_v": [], "moving": []}


def loading_time(L: int, K: float = 10.0, V: float = 0.001) -> float:
    """L_ss / V at c = 1 of a chain of L blocks, ``L (L - 1) / (2 K V)`` (docs/model.md): each row of
    the square pulled at its left edge has the chain's steady profile (docs/lattice.md), so it loads
    in the same time."""
    return L * (L - 1) / (2.0 * K * V)


def lattice_params(point: dict[str, Any], beta: float | None = None):
    """The point's model on the L x L square (:func:`stickslip.chain_params` with ``lattice``):
    eq. (4) at the point's (or the given) beta with the paper's other parameters, or
    Carlson-Langer at its standard ones (periodic, plate drive)."""
    from stickslip import chain_params

    model = point.get("model", "sakaguchi")
    L = int(point["L"])
    if model == "carlson-langer":
        return chain_params("carlson-langer", lattice="square", shape=(L, L))
    b = float(point["beta"] if beta is None else beta)
    return chain_params(model, lattice="square", shape=(L, L), beta=b)


def lattice_check(cfg: dict[str, Any]) -> None:
    """Raise ParameterError (one line) unless a point's merged settings make valid runs."""
    from stickslip.models.params import ParameterError

    part = cfg.get("part")
    if part not in ("ladder", "sizes", "chain", "cl"):
        raise ParameterError(f"part must be ladder, sizes, chain or cl (got {part!r})")
    if part == "chain":
        from stickslip import chain_params

        chain_params("sakaguchi", N=int(cfg["L"]), beta=float(cfg["beta"]))
        return
    for beta in cfg.get("betas", [cfg.get("beta", 1.0)]):
        lattice_params(cfg, float(beta))


def lattice_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """One point of the study, by its ``part`` (module docstring); a task of ``run_sweep``."""
    tasks = {"ladder": ladder_task, "sizes": sizes_task, "chain": chain_sizes_task, "cl": cl_task}
    return tasks[point["part"]](point, Path(point_dir))


# ---------------------------------------------------------------------------------------------
# Segmented lattice runs with a checkpoint after each segment


def _save(path: Path, state, events: pd.DataFrame, samples: pd.DataFrame, extra: dict[str, Any]) -> None:
    from stickslip import io

    arrays = {f"state_{k}": getattr(state, k) for k in state.__dataclass_fields__}
    arrays.update({f"ev_{c}": events[c].to_numpy() for c in events.columns})
    arrays.update({f"sm_{c}": samples[c].to_numpy() for c in samples.columns})
    arrays["extra"] = np.frombuffer(json.dumps(extra).encode(), dtype=np.uint8)
    buf = _io.BytesIO()
    np.savez(buf, **arrays)
    io.write_bytes(path, buf.getvalue())


def _load(path: Path):
    import pandas as pd

    from stickslip.run.lattice import LatticeState

    with np.load(path) as z:
        state = LatticeState(**{k[6:]: z[k].copy() for k in z.files if k.startswith("state_")})
        events = pd.DataFrame({k[3:]: z[k] for k in z.files if k.startswith("ev_")})
        samples = pd.DataFrame({k[3:]: z[k] for k in z.files if k.startswith("sm_")})
        extra = json.loads(bytes(z["extra"]).decode())
    return state, events, samples, extra


def run_segments(
    p,
    t_end: float,
    point_dir: Path,
    *,
    start: Any = "paper",
    perturbation: float = 0.0,
    seed: int = 0,
    sample_every: float,
    segments: int = 8,
    key: Any = None,
    stop=None,
    integrator: str = "exact",
):
    """:func:`stickslip.run.lattice.run_lattice` to ``t_end`` (an absolute time) in ``segments``
    equal parts, each continued from the state the last one ended with (the same steps, events
    and samples as one run), with a checkpoint in ``point_dir`` after each; a checkpoint of the
    same ``key`` is continued. ``stop()`` true between segments raises
    :class:`~stickslip.run.errors.Interrupted` (the sweep was interrupted). ``integrator``:
    :func:`~stickslip.run.lattice.run_lattice`'s (both give the same bits).

    Returns
    -------
    tuple
        The final :class:`~stickslip.run.lattice.LatticeState`, the events and the samples
        (t, mean_slip_deficit, mean_v, moving), each sample once.
    """
    import pandas as pd  # here, not above: the study's registry is read by `stickslip --help`

    from stickslip.run.errors import Interrupted
    from stickslip.run.lattice import run_lattice

    path = Path(point_dir) / CHECKPOINT
    state, events, samples, t0 = start, None, None, None
    if path.exists():
        state, events, samples, extra = _load(path)
        if extra.get("key") != key:  # another run's checkpoint: start afresh
            state, events, samples = start, None, None
        else:
            t0 = extra["t0"]
    if t0 is None:
        t0 = 0.0 if isinstance(start, str) else start.step * p.dt
    done = 0 if isinstance(state, str) else int(round((state.step * p.dt - t0) / ((t_end - t0) / segments)))
    for k in range(done, segments):
        if stop is not None and stop():
            raise Interrupted(path if path.exists() else None, t0 if isinstance(state, str) else state.step * p.dt)
        target = t0 + (t_end - t0) * (k + 1) / segments
        run = run_lattice(
            p,
            target,
            start=state,
            perturbation=perturbation,
            seed=seed,
            sample_every=sample_every,
            integrator=integrator,
        )
        state = run.state
        events = run.events if events is None else pd.concat([events, run.events], ignore_index=True)
        new = run.samples  # None where no sample falls in the segment (an interval longer than it)
        if new is None:
            new = samples if samples is not None else pd.DataFrame(_NO_SAMPLES).astype({"moving": np.int64})
        elif samples is not None and len(samples):
            new = new[new["t"] > samples["t"].iloc[-1]]
            new = pd.concat([samples, new], ignore_index=True)
        samples = new
        _save(path, state, events, samples, {"key": key, "t0": t0})
    return state, events, samples


# ---------------------------------------------------------------------------------------------
# Ladders: the order parameter per rung


def rung_order(
    samples: pd.DataFrame,
    d_ss: float,
    n_blocks: int,
    t0: float,
    t_end: float,
    steady: bool,
    average_from: float | None = None,
):
    """The order parameter of one rung, the lattice's analogue of the chain's m = 1 - <L>/L_ss
    (:mod:`stickslip.analysis.stats.order`): m = 1 - <d>/d_ss, d the mean slip deficit (the load
    point V t less x, over the blocks) and d_ss its value in steady sliding, averaged over the
    rung's second half (or from ``average_from``) with its batch-means error; the fraction of samples with a block stuck
    there; and the final state (:func:`~stickslip.analysis.stats.order.classify_final_state` on
    the rung's last two quarters, ``steady`` where every block slides at V at the end).

    Parameters
    ----------
    samples : pandas.DataFrame
        The rung's samples (t, mean_slip_deficit, moving).
    d_ss : float
        d in steady sliding at the rung's beta.
    n_blocks : int
        Blocks of the lattice.
    t0, t_end : float
        The rung's start and end.
    steady : bool
        Whether the rung ended in steady sliding.
    average_from : float, optional
        The start of the average (default the middle of the rung), an absolute time.

    Returns
    -------
    dict
        ``order_parameter``, ``order_parameter_err``, ``err_reliable``, ``stuck_fraction``,
        ``final_state``, ``final_reason``.
    """
    from stickslip.analysis.stats.order import classify_final_state, mean_with_error, quarter_stats

    s = samples[(samples["t"] >= t0) & (samples["t"] <= t_end + 1e-9)]
    t = s["t"].to_numpy(dtype=float) - t0
    m = 1.0 - s["mean_slip_deficit"].to_numpy(dtype=float) / d_ss
    stuck = (s["moving"].to_numpy() < n_blocks).astype(float)
    late = t >= (0.5 * (t_end - t0) if average_from is None else average_from - t0) - 1e-9
    est = mean_with_error(m[late])
    q = quarter_stats(t, m, stuck, t_end - t0)
    state, reason = classify_final_state(reached_steady=steady, **q)
    return {
        "order_parameter": est.mean,
        "order_parameter_err": est.err,
        "err_reliable": est.reliable,
        "stuck_fraction": float(stuck[late].mean()) if late.any() else math.nan,
        "final_state": state,
        "final_reason": reason,
    }


def steady_deficit(p) -> float:
    """d_ss: the mean of V t - x over the blocks in steady sliding (:func:`steady_fields` at t = 0),
    the lattice's L_ss of the order parameter (:func:`rung_order`).

    Raises
    ------
    ParameterError
        Where the model has no steady sliding on its lattice (:func:`steady_fields`).
    """
    from stickslip.run.lattice import steady_fields

    return float(-np.mean(steady_fields(p)["x"]))


def at_steady(p, state) -> bool:
    """Whether every block of ``state`` slides at V (within 1e-6): the run ended in steady sliding."""
    f = state.fields(p.lattice)
    return bool(not f["stopped"].any() and np.max(np.abs(f["v"] - p.V)) < 1e-6)


def ladder_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """One ladder of eq. (4) on the square (module docstring): each rung runs ``rung_loads``
    loading times (:func:`loading_time`) at its beta from the state the rung before ended with,
    and gives :func:`rung_order`; finished rungs are kept in the point's folder, so an
    interrupted ladder goes on at its running rung. Returns the rungs as JSON text."""
    from stickslip import io
    from stickslip.experiments.sweep import stop_requested

    L, betas = int(point["L"]), [float(b) for b in point["betas"]]
    rung_t = float(point["rung_loads"]) * loading_time(L)
    n_samples = int(point.get("n_samples", 400))
    rungs_file = point_dir / RUNGS
    rungs = io.read_json(rungs_file)["rungs"] if rungs_file.exists() else []
    rungs = rungs if [r["beta"] for r in rungs] == betas[: len(rungs)] else []
    up = point["direction"] == "up"
    state = None
    if rungs:
        state = _load(point_dir / f"rung-{len(rungs) - 1}.npz")[0]
    for i in range(len(rungs), len(betas)):
        p = lattice_params(point, betas[i])
        if state is None:
            start = "rest" if up else "steady"
            amp = float(point.get("perturbation", 1e-3) if up else point.get("down_perturbation", 1e-5))
        else:
            start, amp = state, 0.0
        t0 = 0.0 if state is None else state.step * p.dt
        key = {"rung": i, "beta": betas[i], "t0": t0}
        state, events, samples = run_segments(
            p,
            t0 + rung_t,
            point_dir,
            start=start,
            perturbation=amp,
            seed=int(point.get("seed", 0)),
            sample_every=rung_t / n_samples,
            segments=int(point.get("segments", 4)),
            key=key,
            stop=stop_requested(point_dir),
        )
        order = rung_order(samples, steady_deficit(p), p.lattice.n_blocks, t0, t0 + rung_t, at_steady(p, state))
        late = events[events["t_start"] >= t0 + 0.5 * rung_t]
        all_rows = int(np.count_nonzero((late["row_min"] <= 1) & (late["row_max"] >= L)))
        rungs.append(
            {"beta": betas[i], **order, "n_events": int(len(late)), "n_all_rows": all_rows, "t_end": t0 + rung_t}
        )
        _save(point_dir / f"rung-{i}.npz", state, events.iloc[:0], samples.iloc[:0], key)
        io.write_json(rungs_file, {"rungs": rungs})
        (point_dir / CHECKPOINT).unlink(missing_ok=True)
    return {"L": L, "N": L * L, "rungs": json.dumps(rungs), "n_rungs": len(rungs)}


# ---------------------------------------------------------------------------------------------
# Event sizes


def _sizes_result(S: np.ndarray, spans: np.ndarray, **extra: Any) -> dict[str, Any]:
    return {
        "n_events": int(S.size),
        "n_spanning": int(np.count_nonzero(spans)),
        "S_max": float(S.max()) if S.size else math.nan,
        "sizes": json.dumps([float(f"{s:.6g}") for s in S]),
        "spans": json.dumps([bool(x) for x in spans]),
        **extra,
    }


def _lattice_sizes(point: dict[str, Any], point_dir: Path, p, start: str, amp: float, far) -> dict[str, Any]:
    import time

    from stickslip.experiments.sweep import stop_requested

    t_end = float(point["t_end"])
    t0 = time.perf_counter()
    state, events, samples = run_segments(
        p,
        t_end,
        point_dir,
        start=start,
        perturbation=amp,
        sample_every=t_end / int(point.get("n_samples", 400)),
        segments=int(point.get("segments", 8)),
        key={"t_end": t_end},
        stop=stop_requested(point_dir),
    )
    late = events[events["t_start"] >= float(point.get("transient", 0.5)) * t_end]
    rows = p.lattice.shape[0]
    return _sizes_result(
        late["moment"].to_numpy(dtype=float),
        far(late).to_numpy(dtype=bool),
        n_all_rows=int(np.count_nonzero((late["row_min"] <= 1) & (late["row_max"] >= rows))),
        L=int(point["L"]),
        N=p.lattice.n_blocks,
        t_end=t_end,
        n_events_total=int(len(events)),
        mean_v_late=float(samples.loc[samples["t"] >= 0.5 * t_end, "mean_v"].mean()),
        run_wall_seconds=time.perf_counter() - t0,
        block_updates=int(state.ist[_block_updates_index()]),
    )


def _block_updates_index() -> int:
    from stickslip.kernels import layout

    return layout.BLOCK_UPDATES


def sizes_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """Eq. (4) on the L x L square from steady sliding perturbed by ``perturbation`` (seed 0; loaded
    from the start, so no loading transient of L_ss / V) to ``t_end``: the moments of the events
    that start after ``transient`` t_end and whether each reached the far edge (column L), as the
    chain's spanning events reach block N."""
    p = lattice_params(point)
    L = int(point["L"])
    amp = float(point.get("perturbation", 1e-3))
    return _lattice_sizes(point, point_dir, p, "steady", amp, lambda ev: ev["col_max"] >= L)


def cl_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """Carlson-Langer on the periodic L x L square from rest (x = -0.01 u, u uniform; seed 0) to
    ``t_end``: the moments of the events after ``transient`` t_end and whether each moved every
    block."""
    p = lattice_params(point)
    n = p.lattice.n_blocks
    return _lattice_sizes(point, point_dir, p, "rest", 0.01, lambda ev: ev["area"] >= n)


def chain_sizes_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """The paper's chain of N = L blocks at the point's beta from steady sliding perturbed by
    ``perturbation`` (seed 0), as the square's :func:`sizes_task`, to ``t_end`` (the chain
    driver's fast path, checkpointed): the slips S after ``transient`` t_end and whether each
    reached block N."""
    from stickslip import chain_params
    from stickslip.experiments.sweep import run_chain_point

    L, t_end = int(point["L"]), float(point["t_end"])
    params = chain_params("sakaguchi", N=L, beta=float(point["beta"]))
    amp = float(point.get("perturbation", 1e-3))
    run = run_chain_point(params, t_end, point_dir, start="steady", perturbation=amp, seed=0)
    late = run.events[run.events["t_start"] >= float(point.get("transient", 0.5)) * t_end]
    return _sizes_result(
        late["S"].to_numpy(dtype=float),
        (late["max_block"] >= L).to_numpy(),
        L=L,
        N=L,
        t_end=t_end,
        n_events_total=int(run.summary["n_events"]),
        run_wall_seconds=float(run.summary["wall_seconds"]),
        block_updates=int(run.summary["block_updates"]),
    )
