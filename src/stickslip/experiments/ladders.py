"""Continuation in beta for the transition study: ladders of chain runs (eq. 4) handing states on.

A *ladder* is one Dask task of ``stickslip study transition``: for one N and one direction it
runs points ("rungs") one after the other, each starting from the final state of the one before.

* ``up``: starts in stick-slip (the loaded start below, at beta well below 1) and hands each
  rung's final state to the next larger beta, until a rung leaves stick-slip; then bisects
  between the last stick-slip beta and the first sliding one, each time from the last
  stick-slip state. beta_t(N) is the last beta where the up ladder still stick-slips.
* ``down``: starts from exact discrete steady sliding (the docs page ``docs/model.md``) plus a
  seeded perturbation above beta_t and hands each rung's final state, perturbed again by the
  same amount, to the next smaller beta, until a rung leaves steady sliding (some block sticks);
  then bisects. Linear stability puts that lower edge at beta = 1.

A rung runs in segments and stops when its answer is known (:func:`stickslip.analysis.adaptive.assess`):
the error of m below the target from at least 16 batches of 10 tau_int; steady sliding reached
(every block within :data:`UNTIL_STEADY` of it) or every block sliding with the deviation falling;
on the down ladder, a block stuck (it left steady sliding); or the cap, then ``undecided`` with the
reason. Each finished rung is written to ``<ladder>/rungs/<k>-beta<b>/`` (``rung.json``, the final
state ``state.npz``, the samples ``samples.npz``); a ladder started again replays its finished
rungs and continues with the first unfinished one.
"""

from __future__ import annotations

import math
import re
import time
from io import BytesIO
from pathlib import Path
from typing import Any

import numpy as np

from stickslip import io
from stickslip.experiments.cache import canonical
from stickslip.jsonable import to_jsonable
from stickslip.models.physics import UNTIL_STEADY
from stickslip.models.presets import paper_parameters

__all__ = ["ladder_task", "run_rung", "perturbed", "ladder_entry"]

_PAPER = paper_parameters("N", "beta")


def params_at(cfg: dict[str, Any], beta: float):
    """The chain of eq. (4) with the ladder's settings at ``beta``."""
    from stickslip.experiments.sweep_points import point_params

    return point_params("chain", {**cfg, "N": int(cfg["N"]), "beta": float(beta)})


def perturbed(state, amplitude: float, seed: int):
    """A copy of ``state`` with x_i and v_i of every moving block shifted by independent uniform
    numbers in [-amplitude, amplitude] (numpy's default generator with ``seed``), as
    :meth:`~stickslip.run.state.ChainState.steady` perturbs steady sliding."""
    s = state.copy()
    if amplitude > 0:
        rng = np.random.default_rng(seed)
        n = s.N
        moving = s.mov[1:-1] != 0.0
        s.x[1:-1] += np.where(moving, rng.uniform(-amplitude, amplitude, n), 0.0)
        s.v[1:-1] += np.where(moving, rng.uniform(-amplitude, amplitude, n), 0.0)
    return s


def _save_npz(path: Path, arrays: dict) -> None:
    """Arrays to ``path``, built in memory and written atomically (a full disk leaves no half file)."""
    buf = BytesIO()
    np.savez(buf, **arrays)
    io.write_bytes(path, buf.getvalue())


def run_rung(params, state, cfg: dict[str, Any], *, leave_stops: bool = False, stop_requested=None) -> dict[str, Any]:
    """One rung: the chain of eq. (4) at ``params`` from ``state`` in segments until its answer is
    known (module docstring). Returns the row (m, its error, the stuck fraction phi and its error,
    final state and reason, times in model time and loading times) with ``state`` (the final
    :class:`~stickslip.run.state.ChainState`) and ``samples`` (arrays t, L, n_moving)."""
    from stickslip.analysis.adaptive import STOP_BATCHES, STUCK_SLIDING, assess
    from stickslip.models.physics import chain_steady_length, loading_time
    from stickslip.run.driver import run_chain
    from stickslip.run.state import steady_deviation

    L_ss, t_load, dt = chain_steady_length(params), loading_time(params), params.dt
    every = max(int(round(t_load / float(cfg["samples_per_load"]) / dt)), 1)
    sample_interval = every * dt
    target, cap = float(cfg["target"]), float(cfg["cap_loads"]) * t_load
    seg, seg_max = float(cfg["first_segment_loads"]) * t_load, float(cfg["segment_loads"]) * t_load
    t_start = state.step * dt
    devs = [steady_deviation(state, params)]
    t_s: list[np.ndarray] = []
    L_s: list[np.ndarray] = []
    n_s: list[np.ndarray] = []
    wall0 = time.perf_counter()
    final, reason, reached, a = "undecided", "", False, None
    while True:
        t_now = state.step * dt
        # segment ends on the sample grid, so no two segments sample the same step twice
        t_target = (math.floor((t_now + seg) / sample_interval + 1e-9) + 1) * sample_interval
        run = run_chain(
            params,
            t_target,
            start=state,
            sample_interval=sample_interval,
            until_steady=UNTIL_STEADY,
            sample_moving=True,
            stop_requested=stop_requested,
        )
        state = run.state
        t, L = run.samples["t"].values, run.samples["L"].values
        nm = run.samples["n_moving"].values
        k = min(t.size, nm.size)
        keep = t[:k] > (t_s[-1][-1] if t_s else -1.0)
        t_s.append(t[:k][keep])
        L_s.append(L[:k][keep])
        n_s.append(nm[:k][keep])
        devs.append(steady_deviation(state, params))
        seg_stuck = bool(n_s[-1].size and n_s[-1].min() < params.N)
        elapsed = state.step * dt - t_start
        if run.summary.get("stopped_early"):
            final, reached = "steady", True
            reason = (
                f"steady sliding reached at t = {float(run.summary['t_steady']):.6g} (deviation <= {UNTIL_STEADY:g})"
            )
            break
        t_all, L_all, n_all = (np.concatenate(x) for x in (t_s, L_s, n_s))
        m = 1.0 - L_all / L_ss
        phi = 1.0 - n_all / params.N
        a = assess(t_all, m, phi, target, int(cfg.get("stop_batches", STOP_BATCHES)))
        # Leaving stick-slip (up), a falling deviation says sliding; near beta = 1 from below (down)
        # fast modes decay while the slow one grows, so there only reaching steady sliding counts.
        falling = len(devs) >= 2 and math.isfinite(devs[-2]) and devs[-1] < 0.5 * devs[-2]
        if not leave_stops and not seg_stuck and falling:
            final = "steady"
            reason = f"every block slides, deviation from steady sliding falling ({devs[-2]:.2g} -> {devs[-1]:.2g})"
            break
        if leave_stops and seg_stuck:
            final = "stick-slip"
            reason = f"left steady sliding: {params.N - int(n_s[-1].min())} blocks stuck at once"
            break
        # a window shorter than half a loading time may hold no event at all (m constant, error 0)
        long_enough = t_all[-1] - a.t_cut >= 0.5 * t_load
        if a.decided and a.phi.mean >= STUCK_SLIDING and long_enough:
            final, reason = "stick-slip", a.reason
            break
        if elapsed >= cap - 1e-9:
            why = a.reason if not a.decided or long_enough else "kept window shorter than half a loading time"
            reason = f"cap of {cfg['cap_loads']:g} loading times: {why}"
            break
        seg = min(2.0 * seg, seg_max, cap - elapsed) if cap - elapsed > 0 else seg
    t_all = np.concatenate(t_s) if t_s else np.zeros(0)
    L_all = np.concatenate(L_s) if L_s else np.zeros(0)
    n_all = np.concatenate(n_s) if n_s else np.zeros(0)
    row: dict[str, Any] = {
        "N": params.N,
        "beta": params.beta,
        "final_state": final,
        "final_reason": reason,
        "t_start": t_start,
        "t_end": state.step * dt,
        "loads": (state.step * dt - t_start) / t_load,
        "loading_time": t_load,
        "deviation_end": devs[-1],
        "wall_seconds": time.perf_counter() - wall0,
    }
    if reached or a is None or (final == "steady" and a.phi.mean < STUCK_SLIDING):
        # steady sliding: L = L_ss and every block moves, so m = phi = 0 exactly
        est = {"order_parameter": 0.0, "order_parameter_err": 0.0, "stuck_fraction": 0.0, "stuck_fraction_err": 0.0}
        row.update(est, sliding=True, tau_int=math.nan, tau_int_loads=math.nan, n_batches=0, t_cut_loads=math.nan)
        row["err_reliable"] = True
    else:
        row.update(
            order_parameter=a.m.mean,
            order_parameter_err=a.m.err,
            stuck_fraction=a.phi.mean,
            stuck_fraction_err=a.phi.err,
            sliding=a.sliding,
            tau_int=a.m.tau_int * sample_interval,
            tau_int_loads=a.m.tau_int * sample_interval / t_load,
            n_batches=a.m.n_batches,
            err_reliable=a.m.reliable,
            t_cut_loads=(a.t_cut - t_start) / t_load,
        )
    row["branch_state"] = "sliding" if row["sliding"] else "stick-slip"
    return {"row": row, "state": state, "samples": {"t": t_all, "L": L_all, "n_moving": n_all}}


def _rung_settings(cfg: dict[str, Any]) -> dict[str, Any]:
    from stickslip.analysis.adaptive import STOP_BATCHES

    keys = ("target", "cap_loads", "segment_loads", "first_segment_loads", "samples_per_load")
    keys += ("perturbation", "down_perturbation", "seed")
    # a rung of another stop rule is not this rung: it is run again, not replayed
    return (
        {k: cfg[k] for k in keys}
        | {k: cfg.get(k, v) for k, v in _PAPER.items()}
        | {"stop_batches": int(cfg.get("stop_batches", STOP_BATCHES))}
    )


#: The files of a rung's folder, each recorded with its SHA-256 in rung.json.
RUNG_FILES = ("state.npz", "samples.npz")


def ladder_entry(path: Path, rel: str = ""):
    """Whether an entry of a ladder's folder is the ladder's: the sweep's bookkeeping, and its
    ``rungs`` folder, holding only rungs (``<k>-beta<b>``) of ``rung.json`` and
    :data:`RUNG_FILES`. True or False, or for a folder the test of its entries (the walk of
    :func:`stickslip.experiments.study_run.foreign_files`)."""
    from stickslip.experiments.cache import BOOKKEEPING

    def rung(p: Path, r: str) -> bool:
        return p.is_file() and p.name in ("rung.json", *RUNG_FILES)

    def rungs(p: Path, r: str):
        return rung if p.is_dir() and re.fullmatch(r"\d{2,}-beta[^/]+", p.name) else False

    if path.name == "rungs" and path.is_dir():
        return rungs
    return path.is_file() and path.name in BOOKKEEPING


def _replay(rdir: Path, spec: dict[str, Any], params) -> tuple[dict[str, Any] | None, str | None]:
    """The row and final state of the rung stored in ``rdir`` if it was run from ``spec`` and is
    whole: its record as written (its SHA-256), every file present with the checksum recorded
    when it was written, the state the one its row names and one a run can go on from. Else
    None, and why a stored rung of this spec is not reused (None when there is none)."""
    from stickslip.experiments.cache import read_done
    from stickslip.models.params import ParameterError
    from stickslip.run.rundir import read_state_file
    from stickslip.run.validate import check_start_state

    # another rung's record (another start or settings) is not this rung's: (None, None)
    rec, why = read_done(rdir / "rung.json", spec, "row")
    if rec is None:
        return None, why
    row = rec["row"]
    if set(rec["files"]) != set(RUNG_FILES):
        return None, "rung.json records no checksums of its files"
    try:
        state = read_state_file(rdir / "state.npz")
        if state.sha256() != row.get("final_sha256"):
            return None, "state.npz is not the final state its row records"
        check_start_state(state, params, where="state.npz")
    except (ValueError, ParameterError) as exc:
        return None, str(exc)
    return {"row": row, "state": state}, None


def _rung(
    ladder_dir: Path, index: int, beta: float, state, start: str, cfg: dict[str, Any], role: str = "grid", **kw
) -> dict[str, Any]:
    """Rung ``index`` at ``beta`` from ``state``: reused from its directory when it was run from the
    same state with the same settings and its files are whole (:func:`_replay`), else run and
    written; a rung run again because its stored files were damaged says so in its row's ``note``."""
    from stickslip.experiments.cache import file_sha256, sealed
    from stickslip.run.rundir import write_state_file

    rdir = ladder_dir / "rungs" / f"{index:02d}-beta{beta:.6g}"
    sha = state.sha256()
    settings = _rung_settings(cfg)
    # The rung's spec: the state it starts from and its settings (the study cache's record format).
    spec = canonical({"start_sha256": sha, "settings": settings})
    params = params_at(cfg, beta)
    stored, why = _replay(rdir, spec, params)
    if stored is not None:
        return stored
    res = run_rung(params, state, cfg, **kw)
    row = {**res["row"], "branch": cfg["direction"], "replica": int(cfg.get("replica", 0)), "seed": int(cfg["seed"])}
    row.update(rung=index, role=role, start=start, start_sha256=sha)
    row["final_sha256"] = res["state"].sha256()
    row = to_jsonable(row)  # as a replay reads it back (NaN and inf become None)
    rdir.mkdir(parents=True, exist_ok=True)
    (rdir / "rung.json").unlink(missing_ok=True)  # no record while its files are rewritten
    write_state_file(rdir / "state.npz", res["state"])
    _save_npz(rdir / "samples.npz", res["samples"])
    files = {name: file_sha256(rdir / name) for name in RUNG_FILES}
    io.write_json(rdir / "rung.json", sealed({"spec": spec, "row": row, "files": files}))
    if why is not None:  # this run's row says why the stored rung was not reused
        row = {**row, "note": f"cached rung damaged ({why}): run again"}
    return {"row": row, "state": res["state"]}


def ladder_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """One ladder of the transition study (a task of ``run_sweep``): ``point`` holds ``N``,
    ``direction`` (``up``/``down``), the coarse grid ``betas``, ``bisections``, the rung settings
    (``target``, ``cap_loads``, segments, ``samples_per_load``) and the start's ``perturbation``
    and ``seed``. Returns the rungs as rows (``rows``) and the bracket found."""
    from stickslip.experiments.sweep import stop_requested
    from stickslip.run.state import ChainState

    cfg, d = dict(point), Path(point_dir)
    up = cfg["direction"] == "up"
    betas = sorted((float(b) for b in cfg["betas"]), reverse=not up)
    # The down ladder's perturbation stays well below V: a kick of v by V stops blocks at once.
    amp = float(cfg["perturbation"] if up else cfg["down_perturbation"])
    seed = int(cfg["seed"])
    kw = {"leave_stops": not up, "stop_requested": stop_requested(d)}
    state = ChainState.steady(params_at(cfg, betas[0]), amp, seed)
    start = f"steady sliding + uniform perturbation {amp:g} (seed {seed})"
    rows: list[dict[str, Any]] = []
    inside = outside = None  # (beta, state) on the ladder's own branch / the first beta off it
    for b in betas:
        r = _rung(d, len(rows), b, state, start, cfg, **kw)
        rows.append(r["row"])
        own = r["row"]["branch_state"] == ("stick-slip" if up else "sliding")
        if not own:
            outside = b
            break
        inside = (b, r["state"])
        state = r["state"] if up else perturbed(r["state"], amp, seed + len(rows))
        start = f"final state of beta = {b:g}" + (
            "" if up else f" + uniform perturbation {amp:g} (seed {seed + len(rows)})"
        )
    for _ in range(int(cfg["bisections"]) if inside is not None and outside is not None else 0):
        b_in, s_in = inside
        mid = round(0.5 * (b_in + outside), 6)
        s0 = s_in if up else perturbed(s_in, amp, seed + len(rows) + 1)
        start = f"final state of beta = {b_in:g}" + ("" if up else " + perturbation")
        r = _rung(d, len(rows), mid, s0, start, cfg, role="bisection", **kw)
        rows.append(r["row"])
        if r["row"]["branch_state"] == ("stick-slip" if up else "sliding"):
            inside = (mid, r["state"])
        else:
            outside = mid
    return {
        "N": int(cfg["N"]),
        "direction": cfg["direction"],
        "inside": inside[0] if inside else None,
        "outside": outside,
        "rows": rows,
    }
