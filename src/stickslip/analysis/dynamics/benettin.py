"""The two-trajectory method of Benettin, Galgani, Giorgilli and Strelcyn (Meccanica 15, 9, 1980).

One loop serves every integrator of the family (docs/lyapunov.md): a reference and a twin d0
away advance side by side; every ``interval`` the distance d of the twin from the reference is
measured, ln(d / d0) recorded, and the twin put back d0 away along the current separation. The
exponent is the sum of ln(d / d0) over the renormalisations that end after transient + align,
divided by their total time; its error bar the standard error of the exponents of ``segments``
consecutive groups of them.

What the loop needs of an integrator is :class:`TwoTrajectoryEngine`: advance both to a grid step,
the separation in the coordinates of the norm, a twin built along a direction, the projection
onto the reference's branch (no velocity on a stuck block), whether both have the same blocks
stuck, and, optionally, a neutral direction whose component is removed before measuring (the
flow's shift in time). :class:`stickslip.analysis.dynamics.lyapunov.GridEngine` is the engine's map
(starts and stops on the time grid); :class:`stickslip.analysis.dynamics.lyapunov_flow.LocatedEngine` the
equations with located switches. Both give a :class:`LyapunovResult`.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from stickslip.models.params import ChainParams, ParameterError, check_number, steps_for

#: Largest allowed initial separation: beyond it the twin is not a small perturbation.
D0_MAX = 1e-3
#: Smallest allowed initial separation: below it the twin differs from the reference by less than
#: the rounding of the state's numbers (2.2e-16 of them), and the separation is lost.
D0_MIN = 1e-15

METHOD = "Benettin et al. (1980) two-trajectory method with renormalisation"
#: Renormalisations between two questions to ``stop_requested`` (a file's existence).
STOP_CHECK = 64


class TwoTrajectoryEngine(Protocol):
    """An integrator as the two-trajectory method sees it (states are the engine's own objects).

    ``params``, ``method`` and ``norm`` (words for the output); ``max_wait``: grid steps a
    renormalisation may be delayed until :meth:`same_branch` holds (0: never delayed).
    """

    params: ChainParams
    method: str
    norm: str
    max_wait: int

    def advance(self, ref: Any, twin: Any, step: int) -> tuple[Any, Any, int]:
        """Both to grid ``step``; returns them and the slip events the reference completed."""

    def step(self, ref: Any) -> int:
        """The reference's grid step."""

    def separation(self, ref: Any, twin: Any) -> np.ndarray:
        """twin - ref in the coordinates of the norm (length 3N)."""

    def twin(self, ref: Any, direction: np.ndarray, d0: float) -> Any:
        """ref + d0 * direction (on the reference's branch, normalised)."""

    def on_branch(self, dy: np.ndarray, ref: Any) -> np.ndarray:
        """dy less what the reference's branch does not allow (velocity of its stuck blocks)."""

    def same_branch(self, ref: Any, twin: Any) -> bool:
        """Whether both have the same blocks stuck."""

    def neutral(self, ref: Any) -> np.ndarray | None:
        """A direction along which separations neither grow nor decay (removed before measuring), or None."""

    def fingerprint(self, ref: Any) -> str:
        """SHA-256 of the reference's state (to compare with an uninterrupted run)."""


@dataclass(frozen=True)
class LyapunovResult:
    """The largest Lyapunov exponent of one run (Benettin et al. 1980, two trajectories).

    lyapunov: sum of ln(d_k / d0_k) over the counted renormalisations divided by their total
    time; lyapunov_err: standard error of the means of ``segments`` consecutive groups of them;
    times, log_growth, durations: end time, ln(d / d0) and length of every renormalisation
    interval (counted or not); counted: which enter the exponent (those ending after
    transient + align); waits: renormalisations delayed until both had the same blocks stuck;
    extra: what only one engine reports (the flow's ``neutral``, the grid's ``frame``).
    """

    lyapunov: float
    lyapunov_err: float
    dt: float
    t_end: float
    transient: float
    align: float
    interval: float
    d0: float
    renormalisations: int
    segments: int
    segment_means: tuple[float, ...]
    events: int
    waits: int
    max_log_growth: float
    reference_sha256: str
    wall_seconds: float
    params: ChainParams
    start: str
    method: str
    norm: str
    extra: dict[str, Any]
    times: np.ndarray = field(repr=False)
    log_growth: np.ndarray = field(repr=False)
    durations: np.ndarray = field(repr=False)
    counted: np.ndarray = field(repr=False)

    @property
    def merges(self) -> int:
        """Counted renormalisations after which the twin had fallen onto the reference (d = 0):
        d0 at the rounding floor of the state, or a sticking phase that contracts to one point.
        Any makes the exponent -inf; a larger d0 tells the two apart."""
        return int(np.count_nonzero(np.isneginf(self.log_growth[self.counted])))

    @property
    def neutral(self) -> str | None:
        """'remove' or 'keep' for the flow (the time-shift direction), None for the grid."""
        return self.extra.get("neutral")

    def to_dict(self) -> dict[str, Any]:
        """The scalars of the result, its parameters and the method, as a plain dict for JSON."""
        return {
            "lyapunov": self.lyapunov,
            "lyapunov_err": self.lyapunov_err,
            "dt": self.dt,
            "t_end": self.t_end,
            "transient": self.transient,
            "align": self.align,
            "interval": self.interval,
            "d0": self.d0,
            "renormalisations": self.renormalisations,
            "merges": self.merges,
            "segments": self.segments,
            "segment_means": list(self.segment_means),
            "events": self.events,
            "waits": self.waits,
            "max_log_growth": self.max_log_growth,
            **self.extra,
            "reference_sha256": self.reference_sha256,
            "wall_seconds": self.wall_seconds,
            "params": self.params.to_dict(),
            "start": self.start,
            "method": self.method,
            "norm": self.norm,
        }

    def truncated(self, t_end: float) -> LyapunovResult:
        """The estimate a run to ``t_end`` (a renormalisation time of this run) would have given.

        The twin's history does not depend on the run's end, so this equals the shorter run
        apart from the reference's final state (its hash is left empty), its events (-1) and its
        waits (counted only to ``t_end``).
        """
        keep = self.times <= t_end + 0.5 * self.dt
        lam, err, means = estimate(self.log_growth[keep], self.durations[keep], self.counted[keep], self.segments)
        return LyapunovResult(
            lyapunov=lam,
            lyapunov_err=err,
            dt=self.dt,
            t_end=float(t_end),
            transient=self.transient,
            align=self.align,
            interval=self.interval,
            d0=self.d0,
            renormalisations=int(np.count_nonzero(self.counted[keep])),
            segments=self.segments,
            segment_means=means,
            events=-1,
            waits=-1,
            max_log_growth=float(np.max(self.log_growth[keep], initial=-np.inf)),
            reference_sha256="",
            wall_seconds=float("nan"),
            params=self.params,
            start=self.start,
            method=self.method,
            norm=self.norm,
            extra=dict(self.extra),
            times=self.times[keep],
            log_growth=self.log_growth[keep],
            durations=self.durations[keep],
            counted=self.counted[keep],
        )


def estimate(log_growth, durations, counted, segments) -> tuple[float, float, tuple[float, ...]]:
    """Exponent, standard error of the segment means, and the segment means (NaN with fewer
    counted renormalisations than segments)."""
    g = log_growth[counted]
    tau = durations[counted]
    if len(g) < segments:
        return float("nan"), float("nan"), ()
    lam = float(np.sum(g) / np.sum(tau))
    parts = np.array_split(np.arange(len(g)), segments)
    means = tuple(float(np.sum(g[p]) / np.sum(tau[p])) for p in parts)
    err = float(np.std(means, ddof=1) / math.sqrt(segments))
    return lam, err, means


def check_run(params: ChainParams, t_end, interval, d0, transient, align, segments):
    """Validate the options; returns (t_end, interval, d0, transient, align, segments) as numbers."""
    t_end = float(check_number("t_end", t_end, low=0.0, low_open=True))
    interval = float(check_number("interval", interval, low=params.dt))
    d0 = float(check_number("d0", d0, low=D0_MIN, high=D0_MAX))
    transient = float(check_number("transient", transient, low=0.0, high=t_end, high_open=True))
    if align is None:
        align = 0.1 * (t_end - transient)
    align = float(check_number("align", align, low=0.0, high=t_end - transient, high_open=True))
    segments = int(check_number("segments", segments, low=2, integer=True))
    m = int(round(interval / params.dt))
    n_lo = steps_for(transient + align, params.dt, "transient + align")
    n_end = steps_for(t_end, params.dt, "t_end")
    counted = -(-(n_end - n_lo) // m) if n_end > n_lo else 0
    if counted < segments:
        need = transient + align + segments * m * params.dt
        raise ParameterError(
            f"t_end must be >= {need:g} for {segments} segments of one renormalisation each "
            f"after transient + align (got {t_end:g})"
        )
    return t_end, interval, d0, transient, align, segments


def remove_flow(dy: np.ndarray, flow: np.ndarray | None, floor: float = 0.0) -> np.ndarray:
    """dy less its component along ``flow`` (left as it is where ``flow`` is None or its norm is
    not above ``floor``)."""
    if flow is None:
        return dy
    norm = float(np.linalg.norm(flow))
    if not norm > floor:
        return dy
    f = flow / norm
    return dy - float(np.dot(dy, f)) * f


def two_trajectory_exponent(
    engine: TwoTrajectoryEngine,
    ref: Any,
    t_end: float,
    *,
    interval: float,
    d0: float,
    transient: float,
    align: float,
    segments: int,
    direction_seed: int = 0,
    start: str = "state",
    extra: dict[str, Any] | None = None,
    progress: bool = False,
    wall0: float | None = None,
    stop_requested: Callable[[], bool] | None = None,
) -> LyapunovResult:
    """The largest Lyapunov exponent by Benettin et al. (1980) over ``engine`` (module docstring).

    ``ref`` is the reference at the transient's end; the options are those of :func:`check_run`
    (already checked). A twin is placed d0 away in a random direction (numpy
    ``default_rng(direction_seed)``); both advance by ``interval`` (then step by step until
    :meth:`~TwoTrajectoryEngine.same_branch`, at most ``engine.max_wait`` steps); the separation,
    less its component along the engine's neutral direction, gives ln(d / d0) and the twin is
    put back d0 away along it on the reference's branch (a fresh random direction if nothing is
    left there: the twin fell onto the reference). d0 is the realised distance after the twin's
    rounding, so ln(d / d0) carries no bias from it. ``stop_requested``, if given, is asked every
    :data:`STOP_CHECK` renormalisations whether to stop (:class:`stickslip.run.errors.Interrupted`).
    """
    wall0 = time.perf_counter() if wall0 is None else wall0
    params = engine.params
    dt = params.dt
    m = int(round(interval / dt))
    n_end = steps_for(t_end, dt, "t_end")
    n_count = steps_for(transient + align, dt, "transient + align")
    rng = np.random.default_rng(direction_seed)
    dim = 3 * params.N

    def measured(ref, twin):
        return remove_flow(engine.separation(ref, twin), engine.neutral(ref))

    twin = engine.twin(ref, rng.standard_normal(dim), d0)
    d_start = float(np.linalg.norm(measured(ref, twin)))
    times, logs, taus = [], [], []
    events = waits = 0
    n = engine.step(ref)
    bar = _bar(progress, t_end - n * dt)
    try:
        while n < n_end:
            n_next = min(n + m, n_end)
            ref, twin, n_ev = engine.advance(ref, twin, n_next)
            extra_steps = 0
            while extra_steps < engine.max_wait and not engine.same_branch(ref, twin):
                ref, twin, more = engine.advance(ref, twin, engine.step(ref) + 1)
                n_ev += more
                extra_steps += 1
            waits += extra_steps > 0
            n_next = engine.step(ref)
            if n_next > n_count:
                events += n_ev
            dy = measured(ref, twin)
            d = float(np.linalg.norm(dy))
            times.append(n_next * dt)
            taus.append((n_next - n) * dt)
            logs.append(math.log(d / d_start) if d > 0.0 and d_start > 0.0 else -math.inf)
            if d > 0.0 and np.any(engine.on_branch(dy, ref) != 0.0):
                twin = engine.twin(ref, dy, d0)
            else:
                # The twin fell onto the reference (sticking can merge them): start a fresh one.
                twin = engine.twin(ref, rng.standard_normal(dim), d0)
            d_start = float(np.linalg.norm(measured(ref, twin)))
            if bar is not None:
                bar.update(taus[-1])
            n = n_next
            if stop_requested is not None and len(times) % STOP_CHECK == 0 and stop_requested():
                from stickslip.run.errors import Interrupted

                raise Interrupted(None, n * dt)
    finally:
        if bar is not None:
            bar.close()
    times_a, logs_a, taus_a = np.array(times), np.array(logs), np.array(taus)
    counted = times_a > n_count * dt + 0.5 * dt
    lam, err, means = estimate(logs_a, taus_a, counted, segments)
    return LyapunovResult(
        lyapunov=lam,
        lyapunov_err=err,
        dt=dt,
        t_end=t_end,
        transient=transient,
        align=align,
        interval=interval,
        d0=d0,
        renormalisations=int(np.count_nonzero(counted)),
        segments=segments,
        segment_means=means,
        events=events,
        waits=waits,
        max_log_growth=float(np.max(logs_a[counted], initial=-np.inf)),
        reference_sha256=engine.fingerprint(ref),
        wall_seconds=time.perf_counter() - wall0,
        params=params,
        start=start,
        method=engine.method,
        norm=engine.norm,
        extra=dict(extra or {}),
        times=times_a,
        log_growth=logs_a,
        durations=taus_a,
        counted=counted,
    )


def _bar(progress: bool, total: float):
    """A tqdm bar on stderr, only when asked and stderr is a terminal."""
    if not (progress and sys.stderr.isatty()):
        return None
    from tqdm import tqdm

    # rate in model time units per wall-clock second
    return tqdm(
        total=total,
        unit=" time units",
        unit_scale=False,
        dynamic_ncols=True,
        desc="lyapunov",
        file=sys.stderr,
        bar_format="{l_bar}{bar}| t = {n:.4g}/{total:.4g} [{elapsed}<{remaining}, {rate_fmt}]",
    )
