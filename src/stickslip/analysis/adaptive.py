"""When a run of the chain (eq. 4) has measured its order parameter: transient, error, stop.

A point of the transition study runs in segments; after each one :func:`assess` looks at the
samples so far and says whether the point may stop. Three pieces:

* the transient after a start or a hand-over is found and dropped by the marginal standard
  error rule (MSER, White 1997; MSER-5: on means of 5 samples): the cut d minimises
  var(x[d:]) / (n - d)^2 over the first half of the series, so a drift at the start is cut
  exactly as long as it raises the error of the mean more than the lost samples do;
* the order parameter m = 1 - <L>/L_ss (:mod:`stickslip.analysis.order`) and the second order
  parameter, the time-averaged fraction of stuck blocks ``phi = 1 - <n_moving>/N``, which is zero
  in steady sliding by construction (every block moves) and positive in stick-slip;
* the stop rule: the batch-means error of m below a target with at least :data:`STOP_BATCHES`
  batches of :data:`~stickslip.analysis.order.BATCH_TAUS` tau_int each. Sixteen, not the eight
  that make an estimate ``reliable``: in stick-slip the largest events come about once per loading
  time, and a window of about one loading time underestimates both tau_int and the spread of the
  batch means. At N = 99, beta = 0.8 a stop at 8 batches gave m = 0.122 +- 0.006 after 1.8
  loading times, where 12 loading times give 0.096 +- 0.004 (docs/studies/transition.md); with 16
  the same series stops at 5 loading times with 0.097 +- 0.005.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from stickslip.analysis.order import MeanEstimate, mean_with_error

__all__ = ["mser_cut", "Assessment", "assess", "STUCK_SLIDING", "STOP_BATCHES"]

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
    >>> from stickslip.analysis.adaptive import mser_cut
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
        (:func:`stickslip.analysis.order.mean_with_error`).
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
