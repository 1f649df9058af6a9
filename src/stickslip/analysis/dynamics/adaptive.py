"""When a run of the chain (eq. 4) has measured its order parameter: transient, error, stop.

A point of the transition study runs in segments; after each one :func:`assess` looks at the
samples so far and says whether the point may stop. Three pieces:

* the transient after a start or a hand-over is found and dropped by the marginal standard
  error rule (MSER, White 1997; MSER-5: on means of 5 samples): the cut d minimises
  var(x[d:]) / (n - d)^2 over the first half of the series, so a drift at the start is cut
  exactly as long as it raises the error of the mean more than the lost samples do;
* the order parameter m = 1 - <L>/L_ss (:mod:`stickslip.analysis.stats.order`) and the second order
  parameter, the time-averaged fraction of stuck blocks ``phi = 1 - <n_moving>/N``, which is zero
  in steady sliding by construction (every block moves) and positive in stick-slip;
* the stop rule: the batch-means error of m below a target with at least :data:`STOP_BATCHES`
  batches of :data:`~stickslip.analysis.stats.order.BATCH_TAUS` tau_int each. Sixteen, not the eight
  that make an estimate ``reliable``: in stick-slip the largest events come about once per loading
  time, and a window of about one loading time underestimates both tau_int and the spread of the
  batch means. At N = 99, beta = 0.8 a stop at 8 batches gave m = 0.122 +- 0.006 after 1.8
  loading times, where 12 loading times give 0.096 +- 0.004 (docs/studies/transition.md); with 16
  the same series stops at 5 loading times with 0.097 +- 0.005.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from stickslip.analysis.stats.order import MeanEstimate, mean_with_error

__all__ = ["mser_cut", "Assessment", "assess", "run_rung", "STUCK_SLIDING", "STOP_BATCHES"]

#: A kept window whose time-averaged stuck fraction is below this is sliding (no block sticks).
STUCK_SLIDING = 1e-3
#: Fewest batches of 10 tau_int from which the stop rule accepts the error of m.
STOP_BATCHES = 16
#: Samples per block of the MSER rule (MSER-5).
MSER_BLOCK = 5


def mser_cut(x: np.ndarray, block: int = MSER_BLOCK) -> int:
    """Number of leading samples of ``x`` to drop as transient (MSER-``block``, White 1997).

    The series is cut into means of ``block`` samples y_j; the cut d (in blocks) minimises
    sum_{j>=d} (y_j - mean(y[d:]))^2 / (n - d)^2 over d <= n / 2.

    Parameters
    ----------
    x : numpy.ndarray
        The series, in time order (the order parameter m of a rung, say).
    block : int
        Samples per batch mean (MSER-5 by default).

    Returns
    -------
    int
        d * block, the samples to drop; 0 for a constant series.

    Examples
    --------
    >>> import numpy as np
    >>> from stickslip.analysis.dynamics.adaptive import mser_cut
    >>> mser_cut(np.concatenate([np.linspace(10.0, 0.0, 50), np.zeros(450)]))
    50
    """
    x = np.asarray(x, dtype=float)
    n = x.size // block
    if n < 4:
        return 0
    y = x[: n * block].reshape(n, block).mean(axis=1)
    # suffix sums give every tail's mean and sum of squares at once
    s1 = np.cumsum(y[::-1])[::-1]
    s2 = np.cumsum((y * y)[::-1])[::-1]
    k = np.arange(n, 0, -1, dtype=float)
    ss = s2 - s1 * s1 / k
    half = n // 2 + 1
    crit = ss[:half] / (k[:half] * k[:half])
    return int(np.argmin(crit)) * block


@dataclass(frozen=True)
class Assessment:
    """What the samples of one point say after the transient is dropped (:func:`assess`).

    Attributes
    ----------
    m : MeanEstimate
        The order parameter m over the kept window with its batch-means error
        (:func:`stickslip.analysis.stats.order.mean_with_error`).
    phi : MeanEstimate
        The stuck fraction phi over the kept window, likewise.
    t_cut : float
        Start of the kept window (model time).
    decided : bool
        Whether the stop rule holds (error of m below the target from enough batches).
    sliding : bool
        Whether no block was stuck in the kept window.
    reason : str
        One line saying why the point is decided or not.
    """

    m: MeanEstimate
    phi: MeanEstimate
    t_cut: float
    decided: bool
    sliding: bool
    reason: str

    def to_dict(self) -> dict[str, Any]:
        out = {f"m_{k}": v for k, v in asdict(self.m).items()}
        out.update({f"phi_{k}": v for k, v in asdict(self.phi).items()})
        out.update(t_cut=self.t_cut, decided=self.decided, sliding=self.sliding, reason=self.reason)
        return out


def assess(t: np.ndarray, m: np.ndarray, phi: np.ndarray, target: float, min_batches: int = STOP_BATCHES) -> Assessment:
    """Drop the transient of the order parameter ``m`` sampled at times ``t`` and test the stop rule
    of the transition study (docs/studies/transition.md).

    The transient is cut by MSER (:func:`mser_cut`) on m and on the stuck fraction ``phi``, the
    later cut winning; the rule holds when the batch-means error of m is below ``target`` from at
    least ``min_batches`` (:data:`STOP_BATCHES`) batches of 10 tau_int.

    Parameters
    ----------
    t : numpy.ndarray
        Sampling times (model time), increasing.
    m : numpy.ndarray
        m = 1 - L / L_ss at those times.
    phi : numpy.ndarray
        Stuck fraction 1 - n_moving / N at those times.
    target : float
        Largest error of m at which the point is decided.
    min_batches : int
        Fewest batches of 10 tau_int the error must come from.

    Returns
    -------
    Assessment
        m and phi over the kept window, where it starts, and whether the rule holds, with why.
    """
    t, m, phi = (np.asarray(a, dtype=float) for a in (t, m, phi))
    if t.size < 4 * MSER_BLOCK:
        empty = mean_with_error(m)
        return Assessment(empty, mean_with_error(phi), float(t[0]) if t.size else 0.0, False, False, "too few samples")
    cut = max(mser_cut(m), mser_cut(phi))
    m_est, phi_est = mean_with_error(m[cut:]), mean_with_error(phi[cut:])
    sliding = bool(phi_est.mean < STUCK_SLIDING)
    enough = m_est.reliable and m_est.n_batches >= min_batches
    decided = bool(enough and math.isfinite(m_est.err) and m_est.err < target)
    if decided:
        reason = (
            f"error of m {m_est.err:.2g} < {target:g} from {m_est.n_batches} batches of "
            f"{m_est.batch} samples (tau_int {m_est.tau_int:.3g} samples)"
        )
    elif not enough:
        reason = f"fewer than {min_batches} batches of 10 tau_int (tau_int {m_est.tau_int:.3g} samples, {m_est.n} kept)"
    else:
        reason = f"error of m {m_est.err:.2g} above the target {target:g}"
    return Assessment(m_est, phi_est, float(t[cut]), decided, sliding, reason)


def run_rung(
    params, state, cfg: dict[str, Any], *, leave_stops: bool = False, stop_requested=None, resume=None, save=None
) -> dict[str, Any]:
    """One rung of the transition study: the chain of eq. (4) at ``params`` from ``state`` in
    segments until its answer is known.

    The first segment lasts ``first_segment_loads`` loading times, each next one twice the last,
    up to ``segment_loads``. The rung stops when :func:`assess` decides with a stuck fraction of
    at least :data:`STUCK_SLIDING` over a window of half a loading time or more (stick-slip); when
    steady sliding is reached (every block within ``UNTIL_STEADY`` of it) or every block slides
    with the deviation from it falling; with ``leave_stops`` (the down ladder), when a block
    sticks; or at the cap of ``cap_loads`` loading times (then ``undecided``, with the reason).
    Each segment is a run continued from the state before, so a rung resumed from its progress
    ends as the rung without a stop does.

    Parameters
    ----------
    params : ChainParams
        The chain of the rung (its beta).
    state : ChainState
        The state it starts from (the loaded start, or the final state of the rung before).
    cfg : dict
        The rung's settings: ``target`` (error of m), ``cap_loads``, ``first_segment_loads``,
        ``segment_loads``, ``samples_per_load`` and optionally ``stop_batches``.
    leave_stops : bool
        Stop as soon as a block sticks (the down ladder leaving steady sliding).
    stop_requested : callable, optional
        Passed to :func:`stickslip.run.driver.run_chain`: a stop raises
        :class:`stickslip.run.errors.Interrupted` within the segment.
    resume : dict, optional
        The progress ``save`` was given after a segment: the rung goes on from there.
    save : callable, optional
        Called after each segment that does not end the rung with its progress: ``state``, the
        next segment's length ``seg``, ``t_start``, ``devs`` (deviations from steady sliding),
        the samples ``t``, ``L``, ``n_moving`` and ``wall_seconds``.

    Returns
    -------
    dict
        ``row`` (m and its error, the stuck fraction phi and its error, the final state and its
        reason, times in model time and in loading times), ``state`` (the final
        :class:`~stickslip.run.state.ChainState`) and ``samples`` (arrays t, L, n_moving).
    """
    from stickslip.models.physics import UNTIL_STEADY, chain_steady_length, loading_time
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
    if resume is not None:
        state, seg, t_start, devs = resume["state"], resume["seg"], resume["t_start"], list(resume["devs"])
        t_s, L_s, n_s = ([resume[k]] if resume["t"].size else [] for k in ("t", "L", "n_moving"))
        wall0 -= resume["wall_seconds"]
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
        if save is not None:
            progress = {"state": state, "seg": seg, "t_start": t_start, "devs": devs, "t": t_all, "L": L_all}
            save(progress | {"n_moving": n_all, "wall_seconds": time.perf_counter() - wall0})
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
