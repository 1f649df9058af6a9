"""Decorrelation of event sequences, and the verdict chaotic / stable chaos / regular.

Two runs of the equations with switches (located integrator, :mod:`stickslip.run.located`) start
from one state and from that state moved by delta along one fixed direction (y coordinates of
:mod:`stickslip.analysis.lyapunov_flow`, on the reference's branch). Their slip events are
compared in order; the number of events that agree before the first pair whose sizes differ by
more than ``rtol`` (relative) is n(delta). A chaotic flow (largest exponent lambda > 0) gives
n ~ ln(1/delta) / (lambda T) with T the mean time between events; a regular one never
decorrelates, or only after a number of events that grows as a power of 1/delta (a separation
growing linearly in time); "stable chaos" (Politi and Torcini, arXiv 0902.2545) is a flow
exponent of zero together with finite perturbations that decorrelate the sequence after a number
of events growing as ln(1/delta) or slower, the discrete start and stop decisions amplifying
them.

:func:`verdict` turns lambda of the flow with its error and n(delta) into one of
:data:`VERDICTS`; it reads the growth of n with 1/delta through the exponent of a power law,
d ln(n + 1) / d ln(1/delta): about 1 / ln(1/delta), 0.03 to 0.07 over 1e-12 .. 1e-6, for
logarithmic growth, 0.5 to 1 for a separation growing as a power of time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from stickslip.models.params import ChainParams, ParameterError, check_number

VERDICTS = ("chaotic", "stable chaos", "regular", "undetermined")
#: The deltas of the study's decorrelation tables.
DELTAS = (1e-12, 1e-10, 1e-8, 1e-6)
#: Largest power-law exponent of n(delta) still counted as growth like ln(1/delta) or slower.
MAX_POWER = 0.25


def first_disagreement(sizes_a, sizes_b, rtol: float = 1e-3) -> int | None:
    """Index of the first event whose sizes differ by more than ``rtol`` times the larger of the
    two, over the events both sequences have; None if all of those agree."""
    a = np.asarray(sizes_a, dtype=float)
    b = np.asarray(sizes_b, dtype=float)
    n = min(a.size, b.size)
    a, b = a[:n], b[:n]
    bad = np.abs(a - b) > rtol * np.maximum(np.abs(a), np.abs(b))
    idx = np.flatnonzero(bad)
    return int(idx[0]) if idx.size else None


@dataclass(frozen=True)
class Decorrelation:
    """n(delta) for each delta: ``rows`` of ``delta``, ``events`` (events that agree before the
    first disagreement, or events compared when none), ``decorrelated``, ``t_decorrelated``."""

    rows: list[dict[str, Any]]
    t_max: float
    rtol: float
    reference_events: int

    def to_dict(self) -> dict[str, Any]:
        """The rows, the settings and the power-law exponent of n(delta), for JSON."""
        return {
            "decorrelation": self.rows,
            "decorrelation_t": self.t_max,
            "decorrelation_rtol": self.rtol,
            "decorrelation_reference_events": self.reference_events,
            "decorrelation_power": growth_power(
                [r["delta"] for r in self.rows],
                [r["events"] for r in self.rows],
                [r["decorrelated"] for r in self.rows],
            ),
        }


def event_decorrelation(
    params: ChainParams,
    start,
    deltas=DELTAS,
    *,
    t_max: float,
    rtol: float = 1e-3,
    direction_seed: int = 0,
    chunk: float | None = None,
) -> Decorrelation:
    """n(delta) of :mod:`this module <stickslip.analysis.decorrelation>` for a model of the family.

    ``start`` is a :class:`~stickslip.run.located.LocatedState` (or anything
    :func:`~stickslip.run.located.start_state` takes); the reference runs from it to ``t_max``
    (time after the start), each twin from it moved by delta (0 gives an identical copy) along
    one direction drawn by ``default_rng(direction_seed)``, in chunks of ``chunk`` (default a
    twentieth of t_max), stopping at its first disagreement.
    """
    from stickslip.analysis.lyapunov_flow import twin_state
    from stickslip.run.located import LocatedStepper, start_state

    t_max = float(check_number("t_max", t_max, low=0.0, low_open=True))
    rtol = float(check_number("rtol", rtol, low=0.0, low_open=True))
    deltas = [float(check_number("delta", d, low=0.0)) for d in deltas]
    if not deltas:
        raise ParameterError("give at least one delta")
    dt = params.dt
    ref0 = start_state(params, start)
    n0 = ref0.step
    n_end = n0 + max(1, int(round(t_max / dt)))
    m = max(1, int(round((chunk if chunk else t_max / 20) / dt)))
    stepper = LocatedStepper(params)
    _, ev = stepper.advance(ref0.copy(), n_end)
    ref_sizes = ev[:, 2] if len(ev) else np.zeros(0)
    ref_t = ev[:, 0] if len(ev) else np.zeros(0)
    direction = np.random.default_rng(direction_seed).standard_normal(3 * params.N)
    rows = []
    for delta in deltas:
        twin = ref0.copy() if delta == 0.0 else twin_state(ref0, direction, delta, params)
        sizes: list[np.ndarray] = []
        n = n0
        first = None
        while n < n_end and first is None:
            n = min(n + m, n_end)
            twin, ev = stepper.advance(twin, n)
            if len(ev):
                sizes.append(ev[:, 2])
            got = np.concatenate(sizes) if sizes else np.zeros(0)
            first = first_disagreement(ref_sizes, got, rtol)
        compared = min(ref_sizes.size, sum(s.size for s in sizes))
        rows.append(
            {
                "delta": delta,
                "events": int(first if first is not None else compared),
                "decorrelated": first is not None,
                "t_decorrelated": float(ref_t[first] - n0 * dt) if first is not None else None,
            }
        )
    return Decorrelation(rows, t_max, rtol, int(ref_sizes.size))


def growth_power(deltas, events, decorrelated) -> float:
    """d ln(n + 1) / d ln(1/delta) by least squares over the decorrelated deltas > 0 (NaN with
    fewer than two)."""
    d = np.asarray(deltas, dtype=float)
    n = np.asarray(events, dtype=float)
    ok = np.asarray(decorrelated, dtype=bool) & (d > 0) & np.isfinite(n)
    if np.count_nonzero(ok) < 2 or np.unique(d[ok]).size < 2:
        return math.nan
    return float(np.polyfit(np.log(1.0 / d[ok]), np.log(n[ok] + 1.0), 1)[0])


def verdict(
    lyapunov: float | None,
    lyapunov_err: float | None,
    deltas,
    events,
    decorrelated,
    *,
    sigmas: float = 2.0,
    max_power: float = MAX_POWER,
) -> str:
    """One of :data:`VERDICTS` (issue 26, item 4; Politi and Torcini, arXiv 0902.2545).

    ``chaotic``: the exponent of the flow above ``sigmas`` errors. ``stable chaos``: within
    ``sigmas`` errors of zero, and every delta > 0 decorrelated with n(delta) growing no faster
    than a power ``max_power`` of 1/delta (:func:`growth_power`; ln(1/delta) growth gives about
    0.05). ``regular``: otherwise (below zero beyond its errors, a delta that never decorrelated,
    or n growing as a larger power). ``undetermined``: no finite exponent or error.
    """
    if lyapunov is None or lyapunov_err is None:
        return "undetermined"
    lam, err = float(lyapunov), float(lyapunov_err)
    if not (math.isfinite(lam) and math.isfinite(err)):
        return "undetermined"
    if lam > sigmas * err:
        return "chaotic"
    if lam < -sigmas * err:
        return "regular"
    d = np.asarray(deltas, dtype=float)
    dec = np.asarray(decorrelated, dtype=bool)
    pos = d > 0
    if np.count_nonzero(pos) < 2 or not dec[pos].all():
        return "regular"
    power = growth_power(d[pos], np.asarray(events, dtype=float)[pos], dec[pos])
    return "stable chaos" if math.isfinite(power) and power <= max_power else "regular"
