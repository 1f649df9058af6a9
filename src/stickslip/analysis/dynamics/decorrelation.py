"""Decorrelation of slip sequences, and the verdict chaotic / stable chaos / regular.

A reference and a twin start from one state: the twin moved by delta along a fixed direction
(y coordinates of :mod:`stickslip.analysis.dynamics.lyapunov`, on the reference's branch), or run with
Fs or V changed by delta (relative). Their slips are compared in order, with the engine's map
(:class:`GridSequences`, :func:`stickslip.run.driver.run_chain`) or the equations with located
switches (:class:`LocatedSequences`). The k-th slips disagree when they start at different
blocks, move different numbers of blocks, or their sizes differ by more than ``rtol`` (relative):
the start block and the blocks moved say which slip it is, and a slip that stays the same slip
changes its size continuously with delta, by a factor that grows with the slip (a 34-block slip
of the chain at N = 99 by 64 delta under a relative change delta of Fs); :data:`SIZE_RTOL` = 0.1
leaves that to the slip's identity (docs/lyapunov.md). n(delta), the slips that agree before the
first disagreement, is what :func:`sequence_decorrelation` measures. A chaotic flow (largest
exponent lambda > 0) gives n ~ ln(1/delta) / (lambda T) with T the mean time between slips,
whatever delta; a finite-amplitude instability decorrelates the sequence only above a threshold
delta* (:mod:`stickslip.analysis.dynamics.threshold`), below which the slips stay the same.

:func:`verdict` turns the flow's exponent with its error and the state's n(delta) over windows of
slips into one of :data:`VERDICTS`: ``chaotic`` (a positive exponent), ``stable chaos`` (no
positive exponent, yet decorrelation within the window above a finite threshold while smaller
deltas never decorrelate: Politi, Livi, Oppo and Kapral, Europhys. Lett. 22, 571 (1993); Politi
and Torcini, arXiv 0902.2545), ``regular`` (no positive exponent and no decorrelation: regular
over the window's slips for the deltas tested, and only so) or ``undetermined``.
:func:`growth_power` is the slope of ln(n + 1) against ln(1/delta), reported with the rows.
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


#: What a twin differs from the reference in (``--perturb``): its state, or Fs or V (relative).
PERTURBATIONS = ("state", "Fs", "V")
#: Reference slips compared by default (``--events``).
EVENTS = 1000
#: Relative size difference beyond which two slips with the same start block and number of
#: blocks still count as different (:data:`RULE`).
SIZE_RTOL = 0.1


def first_disagreement(sizes_a, sizes_b, rtol: float = 1e-3, blocks_a=None, blocks_b=None) -> int | None:
    """Index of the first slip at which two sequences disagree, over the slips both have; None
    if all of those agree.

    Slips disagree when their sizes differ by more than ``rtol`` times the larger of the two, or,
    given ``blocks_a`` and ``blocks_b`` (rows of start block and number of blocks moved), when
    they start at different blocks or move different numbers of blocks.
    """
    a = np.asarray(sizes_a, dtype=float)
    b = np.asarray(sizes_b, dtype=float)
    n = min(a.size, b.size)
    a, b = a[:n], b[:n]
    bad = np.abs(a - b) > rtol * np.maximum(np.abs(a), np.abs(b))
    if blocks_a is not None and blocks_b is not None:
        ia = np.asarray(blocks_a).reshape(-1, 2)[:n]
        ib = np.asarray(blocks_b).reshape(-1, 2)[:n]
        bad |= np.any(ia != ib, axis=1)
    idx = np.flatnonzero(bad)
    return int(idx[0]) if idx.size else None


@dataclass(frozen=True)
class Decorrelation:
    """n(delta) for each delta (and seed): ``rows`` of ``delta``, ``seed``, ``events`` (slips that
    agree before the first disagreement, or slips compared when none), ``decorrelated``,
    ``t_decorrelated`` (the reference's start of the first disagreeing slip, after the start)."""

    rows: list[dict[str, Any]]
    t_max: float | None
    rtol: float
    reference_events: int
    perturbation: str = "state"
    events: int | None = None
    windows: tuple[dict[str, Any], ...] = ()
    switches: str = "located"

    def to_dict(self) -> dict[str, Any]:
        """The rows, the settings and the power-law exponent of n(delta), for JSON."""
        return {
            "decorrelation": self.rows,
            "decorrelation_t": self.t_max,
            "decorrelation_rtol": self.rtol,
            "decorrelation_reference_events": self.reference_events,
            "decorrelation_perturbation": self.perturbation,
            "decorrelation_events": self.events,
            "decorrelation_windows": list(self.windows),
            "decorrelation_switches": self.switches,
            "decorrelation_rule": RULE,
            "decorrelation_power": growth_power(
                [r["delta"] for r in self.rows],
                [r["events"] for r in self.rows],
                [r["decorrelated"] for r in self.rows],
            ),
        }


RULE = (
    "the k-th slips of reference and twin disagree when they start at different blocks, move "
    "different numbers of blocks, or their sizes differ by more than rtol of the larger; a twin "
    "with fewer slips than the reference when it has run twice the reference's window of slips "
    "disagrees at its first missing slip"
)


class GridSequences:
    """Slip sequences of the engine's map (:func:`stickslip.run.driver.run_chain`, in chunks)."""

    switches = "grid"

    def __init__(self, params: ChainParams):
        self.params = params

    def prepare(self, state):
        """The start state with the clock restarted (positions relative to the drive kept), so
        that a twin with another V starts from the same forces; fixed ends read t and keep it."""
        from stickslip.analysis.dynamics.lyapunov import moved_back

        if self.params.ends_piece.wall or state.step == 0:
            return state.copy()
        return moved_back(state, state.step, self.params)

    def twin(self, params: ChainParams, state, direction: np.ndarray, delta: float):
        """``state`` moved by delta along ``direction`` (y, :func:`stickslip.analysis.dynamics.lyapunov.twin_state`)."""
        from stickslip.analysis.dynamics.lyapunov import twin_state

        out = twin_state(state, direction, delta, params)
        out.model = state.model
        bounds = params.friction_piece.theta_range
        if bounds is not None:  # a stuck block's theta at the end of its range stays in it
            np.clip(out.theta, bounds[0], bounds[1], out=out.theta)
        return out

    def run(self, params: ChainParams, state, step: int):
        """``state`` run to grid ``step``; its slips completed on the way as rows of t_start,
        size S, start block and blocks moved."""
        from stickslip.run.driver import run_chain

        t_end = step * params.dt
        run = run_chain(params, t_end, start=state, sample_interval=max(t_end - state.step * params.dt, params.dt))
        ev = run.events
        rows = np.column_stack((ev["t_start"], ev["S"], ev["start_block"], ev["n_blocks"])) if len(ev) else _NO_ROWS
        return run.state, rows


class LocatedSequences:
    """Slip sequences of the equations with located switches (:class:`stickslip.run.located.LocatedStepper`)."""

    switches = "located"

    def __init__(self, params: ChainParams):
        self.params = params
        self._steppers: dict[ChainParams, Any] = {}

    def prepare(self, state):
        """The start state as it is (positions are held relative to the drive)."""
        return state.copy()

    def twin(self, params: ChainParams, state, direction: np.ndarray, delta: float):
        """``state`` moved by delta along ``direction``
        (:func:`stickslip.analysis.dynamics.lyapunov_flow.twin_state`)."""
        from stickslip.analysis.dynamics.lyapunov_flow import twin_state

        return twin_state(state, direction, delta, params)

    def run(self, params: ChainParams, state, step: int):
        """``state`` run to grid ``step``; its slips as rows of t_start, size, start block, blocks moved."""
        from stickslip.run.located import LocatedStepper

        if params not in self._steppers:
            self._steppers[params] = LocatedStepper(params)
        state, ev = self._steppers[params].advance(state, step)
        return state, (ev[:, [0, 2, 3, 4]] if len(ev) else _NO_ROWS)


_NO_ROWS = np.zeros((0, 4))


def check_slips(events: int | None, seeds: int, n_deltas: int) -> None:
    """Refuse a measurement of :func:`sequence_decorrelation` that simulates more than
    :data:`~stickslip.run.budget.MAX_SLIPS` slips: ``events`` in each of ``seeds`` windows, for
    the reference and each of the ``n_deltas`` perturbed sequences (ParameterError, one line)."""
    from stickslip.run.budget import MAX_SLIPS

    if events is None:
        return
    slips = events * seeds * (1 + n_deltas)
    if slips > MAX_SLIPS:
        raise ParameterError(
            f"events = {events} and seeds = {seeds} with {n_deltas} deltas ask for {slips:.3g} slips "
            f"simulated; at most {MAX_SLIPS:.0e} (at some 1e5 slips a second, three hours): "
            "ask for fewer events or seeds"
        )


def sequence_decorrelation(
    source,
    start,
    deltas,
    *,
    perturbation: str = "state",
    events: int | None = EVENTS,
    t_max: float | None = None,
    rtol: float = SIZE_RTOL,
    direction_seed: int = 0,
    seeds: int = 1,
    chunk: float | None = None,
    progress=None,
) -> Decorrelation:
    """n(delta): a reference and one twin per delta from one state, their slips compared in order.

    ``source`` runs slip sequences (:class:`GridSequences` or :class:`LocatedSequences`); ``start``
    is its state. The twin is ``start`` moved by delta along a direction drawn by
    ``default_rng(direction_seed + seed)`` (``perturbation`` 'state', y coordinates, 0 an
    identical copy), or the model with Fs or V times 1 + delta ('Fs', 'V'). The reference's
    window holds its first ``events`` slips, or ends ``t_max`` after the start, whichever comes
    first. Each twin runs in chunks (``chunk`` time units; default the time of about 50 of the
    reference's slips) until it disagrees with the reference (:data:`RULE`), has as many slips as
    the window, or has run for twice the window (``t_max`` exactly when given). ``seeds`` repeats
    it all from the state where the previous window ended, with the next direction: consecutive
    windows of one run. ``progress``, if given, is called with a line of text after each twin.
    """
    params = source.params
    if perturbation not in PERTURBATIONS:
        raise ParameterError(f"perturbation must be one of {', '.join(PERTURBATIONS)} (got {perturbation!r})")
    if events is None and t_max is None:
        raise ParameterError("give events or t_max (the window)")
    if events is not None:
        events = int(check_number("events", events, low=1, integer=True))
    if t_max is not None:
        t_max = float(check_number("t_max", t_max, low=0.0, low_open=True))
    rtol = float(check_number("rtol", rtol, low=0.0, low_open=True))
    seeds = int(check_number("seeds", seeds, low=1, integer=True))
    deltas = [float(check_number("delta", d, low=0.0)) for d in deltas]
    if not deltas:
        raise ParameterError("give at least one delta")
    if perturbation != "state":
        _check_parameter_perturbation(params, perturbation, deltas)
    check_slips(events, seeds, len(deltas))
    dt = params.dt
    ref = start
    rows: list[dict[str, Any]] = []
    windows = []
    for seed in range(seeds):
        ref = source.prepare(ref)
        ref0 = ref.copy()
        n0 = ref0.step
        ref, ref_rows = _reference_window(source, ref, events, t_max, chunk)
        n_window = ref.step - n0
        windows.append({"seed": seed, "reference_events": int(len(ref_rows)), "t_window": n_window * dt})
        direction = np.random.default_rng(direction_seed + seed).standard_normal(3 * params.N)
        m = _twin_chunk(chunk, ref_rows, n_window, dt)
        # A window of time (the reference stopped at t_max): both run exactly as long. A window
        # of slips: the twin may take up to twice as long, and a slip it lacks then disagrees.
        by_time = events is None or len(ref_rows) < events
        cap = n0 + (n_window if by_time else 2 * n_window)
        for delta in deltas:
            row = _compare(source, ref0, ref_rows, perturbation, delta, direction, rtol, m, cap, not by_time)
            rows.append({"delta": delta, "seed": seed, **row})
            if progress is not None:
                state = "decorrelated" if row["decorrelated"] else "agree"
                progress(f"seed {seed} delta {delta:g}: {row['events']} slips, {state}")
    return Decorrelation(
        rows,
        t_max,
        rtol,
        windows[0]["reference_events"],
        perturbation=perturbation,
        events=events,
        windows=tuple(windows),
        switches=source.switches,
    )


def _check_parameter_perturbation(params: ChainParams, name: str, deltas) -> None:
    """Refuse a change of a parameter the model does not read, or of V where the ends read t."""
    if name not in params.used():
        reads = ", ".join(params.used())
        raise ParameterError(f"perturbation {name} needs a model that reads {name} (this one reads {reads})")
    if name == "V" and params.ends_piece.wall:
        raise ParameterError("perturbation V needs ends that do not read t (fixed ends do)")
    for d in deltas:
        params.replace(**{name: getattr(params, name) * (1.0 + d)})  # in range, one line if not


#: A window of slips also ends when the reference has had no slip for this many steps and for
#: QUIET_INTERVALS times the mean time between its slips so far (steady sliding, say).
QUIET_STEPS = 2_000_000
QUIET_INTERVALS = 100


def _reference_window(source, ref, events, t_max, chunk):
    """The reference from its state to the end of its ``events``-th slip (or ``t_max`` later, or
    once it has gone quiet: :data:`QUIET_STEPS`)."""
    dt = source.params.dt
    n0 = ref.step
    n_cap = n0 + int(round(t_max / dt)) if t_max is not None else None
    m = max(1, int(round((chunk if chunk else (t_max / 20 if t_max else 1000.0)) / dt)))
    parts = []
    have = 0
    n = n0
    last = n0  # step of the latest slip's start
    while (events is None or have < events) and (n_cap is None or n < n_cap):
        target = n + m if n_cap is None else min(n + m, n_cap)
        ref, rows = source.run(source.params, ref, target)
        n = target
        if len(rows):
            parts.append(rows)
            have += len(rows)
            last = int(round(rows[-1, 0] / dt))
        mean = (last - n0) / have if have > 1 else 0.0
        if n_cap is None and n - last > max(QUIET_STEPS, QUIET_INTERVALS * mean):
            break
        if chunk is None and t_max is None and len(rows) < 50:
            m *= 2  # about 50 slips a chunk
    rows = np.concatenate(parts) if parts else _NO_ROWS
    rows = rows.copy()
    rows[:, 0] -= n0 * dt
    if events is not None and len(rows) > events:
        rows = rows[:events]
    return ref, rows


def _twin_chunk(chunk, ref_rows, n_window, dt) -> int:
    """Steps of a twin's chunk: ``chunk``, or the time of about 50 of the reference's slips."""
    if chunk:
        return max(1, int(round(chunk / dt)))
    per = n_window / max(len(ref_rows), 1)
    return max(1, int(min(n_window, 50 * per)))


def _compare(source, ref0, ref_rows, perturbation, delta, direction, rtol, m, cap, missing) -> dict[str, Any]:
    """One twin against the reference's slips (:func:`sequence_decorrelation`): run in chunks of
    ``m`` steps up to step ``cap``; with ``missing``, a slip the twin lacks there disagrees."""
    params = source.params
    if perturbation == "state":
        twin = ref0.copy() if delta == 0.0 else source.twin(params, ref0, direction, delta)
    else:
        params = params.replace(**{perturbation: getattr(params, perturbation) * (1.0 + delta)})
        twin = ref0.copy()
    parts = []
    have = 0
    n = ref0.step
    first = None
    while n < cap and first is None and have < len(ref_rows):
        n = min(n + m, cap)
        twin, rows = source.run(params, twin, n)
        if len(rows):
            parts.append(rows)
            have += len(rows)
            got = np.concatenate(parts)
            first = first_disagreement(ref_rows[:, 1], got[:, 1], rtol, ref_rows[:, 2:4], got[:, 2:4])
    compared = min(len(ref_rows), have)
    if first is None and missing and have < len(ref_rows):
        first = have
    return {
        "events": int(first if first is not None else compared),
        "decorrelated": first is not None,
        "t_decorrelated": float(ref_rows[first, 0]) if first is not None else None,
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
    """n(delta) of :mod:`this module <stickslip.analysis.dynamics.decorrelation>` over a window of time,
    with located switches: :func:`sequence_decorrelation` with :class:`LocatedSequences`.

    ``start`` is a :class:`~stickslip.run.located.LocatedState` (or anything
    :func:`~stickslip.run.located.start_state` takes); the reference runs from it for ``t_max``,
    each twin from it moved by delta (0 gives an identical copy) along one direction drawn by
    ``default_rng(direction_seed)``, in chunks of ``chunk`` (default a twentieth of t_max),
    stopping at its first disagreement.
    """
    from stickslip.run.located import start_state

    t_max = float(check_number("t_max", t_max, low=0.0, low_open=True))
    source = LocatedSequences(params)
    return sequence_decorrelation(
        source,
        start_state(params, start),
        deltas,
        events=None,
        t_max=t_max,
        rtol=rtol,
        direction_seed=direction_seed,
        chunk=chunk if chunk else t_max / 20,
    )


def growth_power(deltas, events, decorrelated) -> float:
    """d ln(n + 1) / d ln(1/delta) by least squares over the decorrelated deltas > 0 (NaN with
    fewer than two)."""
    d = np.asarray(deltas, dtype=float)
    n = np.asarray(events, dtype=float)
    ok = np.asarray(decorrelated, dtype=bool) & (d > 0) & np.isfinite(n)
    if np.count_nonzero(ok) < 2 or np.unique(d[ok]).size < 2:
        return math.nan
    return float(np.polyfit(np.log(1.0 / d[ok]), np.log(n[ok] + 1.0), 1)[0])


@dataclass(frozen=True)
class Verdict:
    """What the flow's exponent and the decorrelation of the slip sequence say (:func:`verdict`).

    ``label``: one of :data:`VERDICTS`; ``text``: the label with what it holds for (the window of
    slips, the deltas); ``window``: slips compared per window (the smallest over the windows);
    ``delta_min``, ``delta_max``: the smallest and largest delta tested; ``threshold``: the bracket
    (``below``, ``low``] of :func:`stickslip.analysis.dynamics.threshold.delta_star` where some window
    decorrelated; ``windows_decorrelated``, ``windows``: how many windows decorrelated at some delta.
    """

    label: str
    text: str
    window: int | None
    delta_min: float | None
    delta_max: float | None
    threshold: tuple[float | None, float] | None
    windows_decorrelated: int
    windows: int

    def to_dict(self) -> dict[str, Any]:
        """The fields, for JSON and the study's table."""
        return {
            "verdict": self.label,
            "verdict_text": self.text,
            "verdict_window": self.window,
            "verdict_delta_min": self.delta_min,
            "verdict_delta_max": self.delta_max,
            "threshold_below": None if self.threshold is None else self.threshold[0],
            "threshold_low": None if self.threshold is None else self.threshold[1],
            "windows_decorrelated": self.windows_decorrelated,
            "windows": self.windows,
        }


def verdict(lyapunov, lyapunov_err, rows, *, window: int | None, sigmas: float = 2.0) -> Verdict:
    """The verdict of one point (docs/lyapunov.md, "The verdict"): one of :data:`VERDICTS`.

    ``lyapunov``, ``lyapunov_err``: the flow's exponent at dt -> 0 and its error; ``rows``: the
    decorrelation rows of the state's perturbation (``delta``, ``seed``, ``decorrelated``) over
    windows of ``window`` slips.

    - ``undetermined``: no finite exponent or error; or no finite threshold although the exponent
      is not positive: the smallest delta tested already decorrelated in some window;
    - ``chaotic``: the exponent above ``sigmas`` errors (a positive largest exponent);
    - ``stable chaos``: the exponent not above ``sigmas`` errors, yet some window decorrelated
      within its slips at a delta of the list, while at the smallest delta tested (and every delta
      up to the bracket's ``below``) no window did: a finite-amplitude instability without a
      positive exponent (Politi, Livi, Oppo and Kapral, Europhys. Lett. 22, 571, 1993; Politi
      and Torcini, arXiv 0902.2545);
    - ``regular``: the exponent not above ``sigmas`` errors and no window decorrelated at any
      delta: regular over ``window`` slips for delta up to the largest tested, and only so.
    """
    from stickslip.analysis.dynamics.threshold import delta_star

    rows = [r for r in rows if float(r["delta"]) > 0.0]
    if not rows:
        raise ParameterError("the verdict needs decorrelation rows with deltas above 0")
    ds = delta_star(rows)
    d_min, d_max = ds["deltas"][0], ds["deltas"][-1]
    k = len(ds["seeds"]) - ds["censored"]
    base = {
        "window": None if window is None else int(window),
        "delta_min": d_min,
        "delta_max": d_max,
        "windows_decorrelated": k,
        "windows": len(ds["seeds"]),
    }
    span = f"{window} slips" if window is not None else "the window"
    finite = lyapunov is not None and lyapunov_err is not None
    lam = float(lyapunov) if finite else math.nan
    err = float(lyapunov_err) if finite else math.nan
    if not (math.isfinite(lam) and math.isfinite(err)):
        return Verdict("undetermined", "undetermined: no finite exponent of the flow", threshold=None, **base)
    if lam > sigmas * err:
        text = f"chaotic: the flow's exponent {lam:.3g} +- {err:.2g} is above {sigmas:g} errors"
        return Verdict("chaotic", text, threshold=None, **base)
    if k == 0:
        text = f"regular over {span} for delta <= {d_max:g} (no window of {len(ds['seeds'])} decorrelated)"
        return Verdict("regular", text, threshold=None, **base)
    if ds["below"] is None:
        text = (
            f"undetermined: no positive exponent, but delta = {d_min:g}, the smallest tested, "
            f"decorrelated within {span}: the threshold lies below the deltas tested"
        )
        return Verdict("undetermined", text, threshold=(None, ds["low"]), **base)
    text = (
        f"stable chaos: no positive exponent; decorrelated within {span} in {k} of "
        f"{len(ds['seeds'])} windows, at delta >= {ds['low']:g} (delta* {ds['low']:g} .. {ds['high']:g}), "
        f"never at delta <= {ds['below']:g}"
    )
    return Verdict("stable chaos", text, threshold=(ds["below"], ds["low"]), **base)
