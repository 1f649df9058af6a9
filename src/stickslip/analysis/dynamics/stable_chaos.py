"""Two further tests of stable chaos (Politi and Torcini, arXiv 0902.2545, sections 3 and 5).

In stable chaos the largest Lyapunov exponent is negative or zero, yet the motion is irregular.
Two signatures besides the decorrelation of :mod:`stickslip.analysis.dynamics.decorrelation`:

* **Finite perturbations propagate faster than infinitesimal ones.** A perturbation put on one
  block spreads along the chain; its front is the farthest block whose difference from the
  reference exceeds ``rel`` times the initial size delta. In the linear (infinitesimal) regime
  the profile scales with delta, so the front does not depend on it, and with all exponents
  non-positive it moves at the linear velocity V_L = 0 or stalls; in stable chaos a finite
  perturbation (one that changes which blocks start and stop) moves at a finite V_F > V_L.
  :func:`perturbation_front` measures the front of each delta on the located integrator
  (:mod:`stickslip.run.located`): the equations with switches, eq. (4) or a relative.
* **An irregular transient whose lifetime grows exponentially with the system size.** Where the
  irregular motion ends (here: in steady sliding, above the inverse transition of eq. (4)), its
  lifetime T(N) is measured at several N; ln T linear in N is the stable-chaos signature,
  T growing as the loading time (N^2) is not. :func:`steady_lifetime` runs the engine from the
  paper's start until every block slides steadily (:func:`stickslip.run.driver.run_chain`,
  ``until_steady``).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from stickslip.models.params import ChainParams, ParameterError, check_number

__all__ = ["FrontResult", "perturbation_front", "block_differences", "front_position", "steady_lifetime"]


def block_differences(ref, twin) -> np.ndarray:
    """Per block, the size of twin - ref: the absolute difference of positions (u = x - V t) plus
    that of velocities, blocks 1..N.

    Parameters
    ----------
    ref, twin : LocatedState
        The two states.

    Returns
    -------
    numpy.ndarray
        N differences.
    """
    return np.abs(twin.u[1:-1] - ref.u[1:-1]) + np.abs(twin.v[1:-1] - ref.v[1:-1])


def front_position(diff: np.ndarray, block: int, threshold: float) -> int:
    """How far a perturbation has spread: blocks from ``block`` out to the farthest block whose
    difference exceeds ``threshold``, counting ``block`` itself.

    Parameters
    ----------
    diff : numpy.ndarray
        Per-block differences (:func:`block_differences`).
    block : int
        The block perturbed, 0-based.
    threshold : float
        The difference that counts.

    Returns
    -------
    int
        The front's reach in blocks; 0 when no block exceeds the threshold.

    Examples
    --------
    >>> import numpy as np
    >>> from stickslip.analysis.dynamics.stable_chaos import front_position
    >>> front_position(np.array([1.0, 0.5, 0.2, 0.0]), 0, 0.3)
    2
    """
    hot = np.flatnonzero(np.asarray(diff) > threshold)
    if not hot.size:
        return 0
    return int(np.max(np.abs(hot - block))) + 1


@dataclass(frozen=True)
class FrontResult:
    """The front of each perturbation size delta (:func:`perturbation_front`), its threshold ``rel``
    times delta.

    Attributes
    ----------
    rows : list of dict
        One per delta: ``delta``, ``reach`` (blocks reached at the end), ``t_reach`` (when it
        first got there), ``speed`` ((reach - 1) / t_reach, blocks per unit time; 0 if it never
        left the block), ``log_growth`` (ln of the largest block difference over delta at the end).
    times : numpy.ndarray
        When the fronts were read.
    fronts : dict
        delta -> the front against ``times``.
    block : int
        The block perturbed (0-based).
    rel : float
        The threshold's factor.
    t_max : float
        The run length.
    wall_seconds : float
        Time taken.
    """

    rows: list[dict[str, Any]]
    times: np.ndarray
    fronts: dict[float, np.ndarray]
    block: int
    rel: float
    t_max: float
    wall_seconds: float

    def to_dict(self) -> dict[str, Any]:
        """Rows and settings for JSON."""
        return {
            "fronts": self.rows,
            "front_block": self.block,
            "front_rel": self.rel,
            "front_t": self.t_max,
            "front_wall_seconds": self.wall_seconds,
            "front_method": (
                "farthest block whose |du| + |dv| from the reference exceeds rel * delta, after the "
                "position of one block is moved by delta (located switches)"
            ),
        }


def perturbation_front(
    params: ChainParams,
    start,
    deltas,
    *,
    t_max: float,
    block: int = 0,
    rel: float = 1e-2,
    check: float = 1.0,
) -> FrontResult:
    """Fronts of perturbations of size delta on one block (module docstring; Politi and Torcini,
    arXiv 0902.2545, "propagation of finite perturbations").

    For each delta the twin is ``start`` with the position of ``block`` moved by delta (signed:
    u = x - V t, so a negative delta on block 0 stretches the spring to the drive); reference and
    twin run with located switches for ``t_max``.

    Parameters
    ----------
    params : ChainParams
        The chain.
    start : LocatedState
        The start (:class:`~stickslip.run.located.LocatedState`, or what
        :func:`~stickslip.run.located.start_state` takes).
    deltas : sequence of float
        Perturbation sizes.
    t_max : float
        How long each pair runs.
    block : int
        The block moved, 0-based (0 is the block next to the drive of eq. (4)).
    rel : float
        A block is in the front when its difference exceeds ``rel`` * delta.
    check : float
        Time between readings of the front.

    Returns
    -------
    FrontResult
        Reach, speed and growth per delta, and each front against time.
    """
    from stickslip.run.located import LocatedStepper, start_state

    t_max = float(check_number("t_max", t_max, low=0.0, low_open=True))
    rel = float(check_number("rel", rel, low=0.0, low_open=True))
    check = float(check_number("check", check, low=params.dt))
    block = int(check_number("block", block, low=0, high=params.N - 1, integer=True))
    deltas = [float(check_number("delta", d)) for d in deltas]
    if not deltas or any(d == 0.0 for d in deltas):
        raise ParameterError("give at least one delta, none of them 0")
    wall0 = time.perf_counter()
    ref0 = start_state(params, start)
    n0 = ref0.step
    m = max(1, int(round(check / params.dt)))
    n_checks = max(1, int(round(t_max / (m * params.dt))))
    times = np.arange(1, n_checks + 1) * m * params.dt
    stepper = LocatedStepper(params)
    ref = ref0.copy()
    twins = []
    for delta in deltas:
        twin = ref0.copy()
        twin.u[1 + block] += delta
        twins.append(twin)
    front = np.zeros((len(deltas), n_checks), dtype=np.int64)
    last = np.zeros(len(deltas))
    for k in range(n_checks):
        n = n0 + (k + 1) * m
        ref, _ = stepper.advance(ref, n)
        for j, delta in enumerate(deltas):
            twins[j], _ = stepper.advance(twins[j], n)
            diff = block_differences(ref, twins[j])
            front[j, k] = front_position(diff, block, rel * abs(delta))
            last[j] = float(np.max(diff))
    rows, fronts = [], {}
    for j, delta in enumerate(deltas):
        reach = int(front[j, -1])
        t_reach = float(times[int(np.argmax(front[j] >= reach))]) if reach > 0 else math.nan
        rows.append(
            {
                "delta": delta,
                "reach": reach,
                "t_reach": t_reach,
                "speed": (reach - 1) / t_reach if reach > 1 else 0.0,
                "log_growth": math.log(last[j] / abs(delta)) if last[j] > 0 else -math.inf,
            }
        )
        fronts[delta] = front[j]
    return FrontResult(rows, times, fronts, block, rel, t_max, time.perf_counter() - wall0)


def steady_lifetime(params: ChainParams, t_max: float, *, tol: float = 1e-6, sample_interval: float | None = None):
    """Lifetime of the stick-slip motion of eq. (4) from the paper's start: the time at which every
    block first slides within ``tol`` of steady sliding.

    Parameters
    ----------
    params : ChainParams
        The chain.
    t_max : float
        Longest run.
    tol : float
        Largest deviation from steady sliding (:func:`stickslip.run.state.steady_deviation`).
    sample_interval : float, optional
        Time between readings (default t_max / 2000).

    Returns
    -------
    dict
        ``N``, ``beta``, ``t_steady`` (None if not by ``t_max``), ``t_max``, ``events`` (slip
        events before it) and ``wall_seconds``.
    """
    from stickslip.run.driver import run_chain
    from stickslip.run.errors import short_runs_expected

    t_max = float(check_number("t_max", t_max, low=0.0, low_open=True))
    si = float(sample_interval) if sample_interval else max(t_max / 2000.0, params.dt)
    with short_runs_expected():
        run = run_chain(params, t_max, start="paper", sample_interval=si, until_steady=tol)
    s = run.summary
    reached = bool(s.get("stopped_early"))
    return {
        "N": params.N,
        "beta": params.beta,
        "t_steady": float(s["t_steady"]) if reached else None,
        "t_max": t_max,
        "events": int(s["n_events"]),
        "wall_seconds": float(s["wall_seconds"]),
    }
