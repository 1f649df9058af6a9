"""Finite-size Lyapunov exponents (Aurell, Boffetta, Crisanti, Paladin and Vulpiani, J. Phys. A 30,
1, 1997): the rate at which a separation of size delta grows to r delta.

Thresholds delta_k = delta_0 r^k. A twin is placed delta_0 from the reference; both advance and
the time at which the separation first exceeds each threshold is recorded (interpolated in
ln d between checks); when it exceeds the largest threshold the twin is put back delta_0 from
the reference along the current separation, and a new cycle starts. With tau_k the time from
delta_k to delta_{k+1} in one cycle,

    lambda(delta_k) = ln r / <tau_k>,

averaged over the counted cycles; its error is the standard error of <tau_k> carried through
(ln r sigma_tau / (sqrt(n) <tau>^2)). For delta -> 0 lambda(delta) tends to the largest
Lyapunov exponent; at finite delta it measures how fast finite perturbations grow, which for a
stick-slip system can differ from the infinitesimal rate (finite perturbations change which
blocks start and stop).

The method only needs a pair of trajectories (:class:`Pair`): :class:`LocatedPair` for the
family's models on the located integrator, or any other system (the tests run the Lorenz system
through the same :func:`finite_size_exponents`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from stickslip.analysis.dynamics.benettin import remove_flow
from stickslip.models.params import ChainParams, ParameterError, check_number


class Pair(Protocol):
    """Two trajectories of one system, advanced side by side."""

    dt: float

    def advance(self, steps: int) -> None:
        """Advance both by ``steps`` steps of dt."""

    def distance(self) -> float:
        """The separation's norm now."""

    def reset(self, delta: float) -> None:
        """Put the twin ``delta`` from the reference along the current separation."""


FSLE_COLUMNS = ["delta", "rate", "rate_err", "cycles"]


@dataclass(frozen=True)
class FSLEResult:
    """lambda(delta) at each threshold but the last; ``rows`` as dicts of :data:`FSLE_COLUMNS`."""

    rows: list[dict[str, float]]
    ratio: float
    cycles: int
    discarded: int
    unfinished: int
    check: float
    extra: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """``fsle`` rows and the settings, for JSON."""
        return {
            "fsle": self.rows,
            "ratio": self.ratio,
            "cycles": self.cycles,
            "discarded": self.discarded,
            "unfinished": self.unfinished,
            "check": self.check,
            "method": "finite-size Lyapunov exponent, Aurell et al. (1997): ln r / <time from delta to r delta>",
            **self.extra,
        }


#: Most thresholds of one finite-size measurement (delta_min to delta_max by factors of ratio).
MAX_THRESHOLDS = 200


def thresholds(delta_min: float, delta_max: float, ratio: float = 2.0) -> np.ndarray:
    """delta_min r^k up to the last one not above delta_max (at least two)."""
    delta_min = float(check_number("delta_min", delta_min, low=0.0, low_open=True))
    delta_max = float(check_number("delta_max", delta_max, low=delta_min, low_open=True))
    ratio = float(check_number("ratio", ratio, low=1.0, low_open=True))
    # Logarithms apart: delta_max / delta_min may overflow (1e300 / 1e-300).
    k = (math.log(delta_max) - math.log(delta_min)) / math.log(ratio)
    if k > MAX_THRESHOLDS - 1:
        raise ParameterError(
            f"delta_max / delta_min must be <= ratio^{MAX_THRESHOLDS - 1} = {ratio:g}^{MAX_THRESHOLDS - 1} "
            f"(at most {MAX_THRESHOLDS} thresholds; got {delta_max:g} / {delta_min:g})"
        )
    n = int(math.floor(k + 1e-9)) + 1
    if n < 2:
        raise ParameterError(f"delta_max must be >= ratio * delta_min = {ratio * delta_min:g} (got {delta_max:g})")
    return delta_min * ratio ** np.arange(n)


def finite_size_exponents(
    pair: Pair,
    deltas: np.ndarray,
    *,
    cycles: int,
    check_steps: int = 1,
    discard: int = 1,
    max_cycle_time: float = math.inf,
    pooled_below: float | None = None,
) -> FSLEResult:
    """lambda(delta) of :mod:`this module <stickslip.analysis.dynamics.fsle>` from ``cycles`` cycles of ``pair``.

    The distance is read every ``check_steps`` steps and the crossing times interpolated in
    ln d; the first ``discard`` cycles (the separation turning into the growing direction) are
    not counted; a cycle longer than ``max_cycle_time`` is abandoned (counted in ``unfinished``:
    a separation that does not grow, e.g. on a stable orbit). With ``pooled_below`` the result's
    ``extra`` also holds ``pooled_rate`` and ``pooled_rate_err``: ln(delta_j / delta_0) over the
    mean time to grow from delta_0 to delta_j, the largest threshold not above it (one number for
    the range where growth is still linear).
    """
    deltas = np.asarray(deltas, dtype=float)
    ratio = float(deltas[1] / deltas[0])
    K = len(deltas)
    taus: list[list[float]] = [[] for _ in range(K - 1)]
    unfinished = 0
    totals: list[float] = []
    j_pool = int(np.searchsorted(deltas, pooled_below, side="right")) - 1 if pooled_below else 0
    h = check_steps * pair.dt
    for c in range(cycles + discard):
        pair.reset(deltas[0])
        cross = np.full(K, np.nan)
        cross[0] = 0.0
        t = 0.0
        d_prev = pair.distance()
        k = 1
        while k < K:
            pair.advance(check_steps)
            t += h
            d = pair.distance()
            while k < K and d >= deltas[k]:
                # ln d linear between the checks
                if d_prev > 0 and d > d_prev:
                    frac = math.log(deltas[k] / d_prev) / math.log(d / d_prev)
                    cross[k] = t - h + h * min(max(frac, 0.0), 1.0)
                else:
                    cross[k] = t
                k += 1
            d_prev = d
            if t > max_cycle_time:
                break
        if k < K:
            unfinished += 1
        if c < discard:
            continue
        if j_pool > 0:
            totals.append(cross[j_pool])
        for j in range(K - 1):
            if np.isfinite(cross[j]) and np.isfinite(cross[j + 1]):
                taus[j].append(cross[j + 1] - cross[j])
    rows = []
    for j in range(K - 1):
        tau = np.array(taus[j])
        n = len(tau)
        mean = float(np.mean(tau)) if n else math.nan
        rate = math.log(ratio) / mean if n and mean > 0 else math.nan
        err = math.nan
        if n > 1 and mean > 0:
            err = math.log(ratio) * float(np.std(tau, ddof=1)) / (math.sqrt(n) * mean**2)
        rows.append({"delta": float(deltas[j]), "rate": rate, "rate_err": err, "cycles": n})
    extra: dict[str, Any] = {}
    if j_pool > 0:
        rate, err = pooled_rate(deltas[: j_pool + 1], np.array(totals))
        extra = {"pooled_below": float(deltas[j_pool]), "pooled_rate": rate, "pooled_rate_err": err}
    return FSLEResult(rows, ratio, cycles, discard, unfinished, h, extra)


def pooled_rate(deltas: np.ndarray, cross_totals: np.ndarray) -> tuple[float, float]:
    """ln(delta_last / delta_first) / <time from the first to the last>, and its error."""
    t = np.asarray(cross_totals, dtype=float)
    t = t[np.isfinite(t)]
    if len(t) < 2:
        return math.nan, math.nan
    growth = math.log(deltas[-1] / deltas[0])
    mean = float(np.mean(t))
    return growth / mean, growth * float(np.std(t, ddof=1)) / (math.sqrt(len(t)) * mean**2)


class LocatedPair:
    """Reference and twin of a model of the family on the located integrator (a :class:`Pair`).

    Distances as in :mod:`stickslip.analysis.dynamics.lyapunov_flow` (y coordinates, the component along
    the flow removed with ``neutral='remove'``); the twin is rebuilt on the reference's branch.
    """

    def __init__(self, params: ChainParams, ref, *, neutral: str = "remove", direction_seed: int = 0):
        from stickslip.analysis.dynamics.lyapunov_flow import LocatedEngine

        self.params = params
        self.dt = params.dt
        self.engine = LocatedEngine(params, neutral=neutral)
        self.ref = ref.copy()
        self.twin = None
        self.neutral = neutral
        self.rng = np.random.default_rng(direction_seed)

    def _dy(self) -> np.ndarray:
        return remove_flow(self.engine.separation(self.ref, self.twin), self.engine.neutral(self.ref))

    def advance(self, steps: int) -> None:
        """Both by ``steps`` grid steps."""
        self.ref, self.twin, _ = self.engine.advance(self.ref, self.twin, self.ref.step + steps)

    def distance(self) -> float:
        """The norm of y_twin - y_ref (less the part along the flow with neutral 'remove')."""
        return float(np.linalg.norm(self._dy()))

    def reset(self, delta: float) -> None:
        """The twin ``delta`` away along the current separation (a random direction at first)."""
        direction = None
        if self.twin is not None:
            dy = self._dy()
            if np.any(self.engine.on_branch(dy, self.ref) != 0.0):
                direction = dy
        if direction is None:
            direction = self.rng.standard_normal(3 * self.params.N)
        # delta is the measured distance: rescale once for the removed part
        self.twin = self.engine.twin(self.ref, direction, delta)
        d = self.distance()
        if d > 0:
            self.twin = self.engine.twin(self.ref, direction, delta * delta / d)
