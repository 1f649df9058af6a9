"""Periodicity of a slip sequence: the smallest period in slips, and the slip from which it repeats.

A run of the chain of eq. (4) (or of any model of its family, or the single block of eq. 1 read
as one block) records one row per slip (docs/model.md, "Slip events"). Where the motion has
settled on a periodic orbit, the slips repeat: the same block starts them, as many blocks move,
and their sizes agree. The rule, stated in every result (:attr:`Periodicity.rule`):

* slip i **matches** slip j when ``start_block`` and ``n_blocks`` are equal and
  ``|S_i - S_j| <= rtol max(|S_i|, |S_j|)``;
* the sequence of n slips is **periodic with period p from slip s** when every slip i >= s
  matches slip i + p (for i + p < n) and the periodic stretch n - s holds at least
  ``max(repeats p, p + P)`` slips, P the longest period searched,
  ``min(max_period, n // repeats)``;
* the result is the **smallest** such p and, for it, the **earliest** s.

The second term of the stretch, p + P, makes the smallest p the true one: a stretch of length at
least p + q with periods p and q has the period gcd(p, q) (Fine and Wilf's theorem), so a
shorter period found on it is a period of the orbit too, not a coincidence of a few slips.

The cost is linear in the number of slips: each p is tried on the last stretch it needs only
(first on its last few slips, which rejects a wrong p at once), so the search over p costs
O(P^2) comparisons whatever n is, and for the p found the stretch is followed backwards in
chunks of doubling length until a slip fails to match: O(n). :attr:`Periodicity.comparisons`
counts the slip pairs compared.

:class:`PeriodicStop` is the same test as a hook of the run loop
(:class:`~stickslip.run.loop.Hook`): it reads the slips as the kernels record them and ends the
run once the sequence is periodic (``stickslip chain --until-periodic``).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from stickslip.analysis.stats.period_rule import MAX_PERIOD, REPEATS, RTOL
from stickslip.kernels import layout
from stickslip.models.params import ParameterError, check_number
from stickslip.run.loop import Hook, Loop

__all__ = [
    "Periodicity",
    "find_period",
    "lattice_periodicity",
    "periodicity",
    "PeriodicStop",
    "RTOL",
    "MAX_PERIOD",
    "REPEATS",
    "rule_text",
]

#: Slips compared first on each p: a wrong period fails on them at once.
_PROBE = 8


#: The names of a slip's three columns in the rule's words: the chain's event table's.
CHAIN_COLUMNS = ("start_block", "n_blocks", "S")
#: A lattice's slip (:func:`lattice_periodicity`): its epicentre, area and moment.
LATTICE_COLUMNS = ("epicentre", "area", "moment")


def rule_text(rtol: float, max_period: int, repeats: int, columns: tuple[str, str, str] = CHAIN_COLUMNS) -> str:
    """The matching rule in words (module docstring), for a result's ``rule``.

    Parameters
    ----------
    rtol, max_period, repeats
        The rule's tolerance on S, longest period searched and periods in the stretch.
    columns
        The names of the slip's block, count and size (:data:`CHAIN_COLUMNS`, :data:`LATTICE_COLUMNS`).

    Returns
    -------
    str
        One sentence.
    """
    block, count, S = columns
    return (
        f"slip i matches slip i + p when {block} and {count} are equal and |{S}_i - {S}_(i+p)| <= "
        f"{rtol:g} max(|{S}_i|, |{S}_(i+p)|); periodic with period p from slip s when every slip from s on "
        f"matches the one p later over a stretch of at least max({repeats} p, p + P) slips to the end, "
        f"P = min({max_period}, slips // {repeats}) the longest period searched; the smallest such p, "
        "the earliest such s"
    )


@dataclass(frozen=True)
class Periodicity:
    """Whether a slip sequence settles on a periodic orbit (module docstring for the rule).

    Attributes
    ----------
    period_slips : int or None
        The smallest period in slips; None where the sequence does not repeat within the run.
    period_t : float or None
        Its duration in time: the mean over the periodic stretch of t_start(i + p) - t_start(i).
    settled_from_slip : int or None
        The first slip (0-based) of the periodic stretch; 0 when the sequence repeats from its
        first slip.
    settled_from_t : float or None
        That slip's start time: the lifetime of the irregular motion before the orbit.
    periods_seen : float or None
        How many periods the periodic stretch holds.
    n_slips : int
        Slips in the sequence.
    t_last : float or None
        Start time of the last slip.
    rtol : float
        The rule's relative tolerance on S.
    max_period : int
        The longest period asked for.
    repeats : int
        The periods the stretch must hold.
    longest_period_searched : int
        P = min(max_period, n_slips // repeats).
    rule : str
        The rule in words (:func:`rule_text`).
    comparisons : int
        Slip pairs compared (the work done: linear in n_slips).
    """

    period_slips: int | None
    period_t: float | None
    settled_from_slip: int | None
    settled_from_t: float | None
    periods_seen: float | None
    n_slips: int
    t_last: float | None
    rtol: float
    max_period: int
    repeats: int
    longest_period_searched: int
    rule: str
    comparisons: int

    @property
    def periodic(self) -> bool:
        """Whether a period was found."""
        return self.period_slips is not None

    def to_dict(self) -> dict[str, Any]:
        """The fields as a JSON-ready dict (``stickslip period --json``)."""
        return asdict(self)

    def text(self) -> str:
        """A few lines for the command line."""
        if not self.periodic:
            head = (
                f"not periodic: no period up to {self.longest_period_searched} slips repeats over the "
                f"last stretch of the {self.n_slips} slips"
            )
        else:
            head = (
                f"periodic: period {self.period_slips} slips ({self.period_t:.6g} time units), settled from "
                f"slip {self.settled_from_slip} (t = {self.settled_from_t:.6g}); {self.periods_seen:.1f} "
                f"periods seen of {self.n_slips} slips"
            )
        return f"{head}\nrule: {self.rule}"


def _check(rtol: float, max_period: int, repeats: int) -> None:
    check_number("rtol", rtol, low=0.0, high=1.0)
    check_number("max_period", max_period, low=1, integer=True)
    check_number("repeats", repeats, low=2, integer=True)


def find_period(
    start_block: Any,
    n_blocks: Any,
    S: Any,
    t_start: Any = None,
    *,
    rtol: float = RTOL,
    max_period: int = MAX_PERIOD,
    repeats: int = REPEATS,
    columns: tuple[str, str, str] = CHAIN_COLUMNS,
) -> Periodicity:
    """The smallest period of a slip sequence and the slip from which it repeats (module docstring).

    Parameters
    ----------
    start_block, n_blocks, S : array_like
        Per slip, in order: the block that moved first, the number of blocks that moved and the
        slip size (the event table's columns, docs/model.md "Slip events").
    t_start : array_like, optional
        Start times of the slips (for ``period_t`` and ``settled_from_t``).
    rtol : float
        Relative tolerance on S (default :data:`RTOL`).
    max_period : int
        Longest period searched (default :data:`MAX_PERIOD`; no more than n // repeats is searched).
    repeats : int
        Periods the periodic stretch must hold, >= 2 (default :data:`REPEATS`).
    columns : tuple of str
        What the three columns are called in the rule's words (:func:`rule_text`).

    Returns
    -------
    Periodicity
        The period, where it settled, the rule and the comparisons made.

    Raises
    ------
    ParameterError
        A bad rule, or columns of different lengths.

    Examples
    --------
    >>> from stickslip.analysis.stats.periodicity import find_period
    >>> sizes = [5.0, 3.0, 1.0, 2.0, 1.0, 2.0, 1.0, 2.0, 1.0, 2.0, 1.0, 2.0]
    >>> r = find_period([1] * 12, [1] * 12, sizes, range(12))
    >>> r.period_slips, r.settled_from_slip, r.settled_from_t, r.period_t
    (2, 2, 2.0, 2.0)
    >>> find_period([1, 1, 1, 1], [1, 1, 1, 1], [1.0, 2.0, 3.0, 4.0]).period_slips is None
    True
    """
    _check(rtol, max_period, repeats)
    sb = np.asarray(start_block, dtype=np.int64).ravel()
    nb = np.asarray(n_blocks, dtype=np.int64).ravel()
    size = np.asarray(S, dtype=np.float64).ravel()
    t = None if t_start is None else np.asarray(t_start, dtype=np.float64).ravel()
    n = sb.size
    if nb.size != n or size.size != n or (t is not None and t.size != n):
        raise ParameterError("start_block, n_blocks, S and t_start must have one entry per slip")
    longest = int(min(max_period, n // repeats))
    count = [0]

    def matches(lo: int, hi: int, p: int) -> np.ndarray:
        """match(i, i + p) for i in [lo, hi)."""
        count[0] += hi - lo
        a, b = slice(lo, hi), slice(lo + p, hi + p)
        near = np.abs(size[a] - size[b]) <= rtol * np.maximum(np.abs(size[a]), np.abs(size[b]))
        return (sb[a] == sb[b]) & (nb[a] == nb[b]) & near

    # every p's probe at once (one numpy pass over P x _PROBE pairs), then the full stretch of the
    # candidates in order: the same p, and the same comparisons counted, as trying p = 1, 2, ... in turn
    ps = np.arange(1, longest + 1)
    need = np.maximum(repeats * ps, ps + longest)
    fits = int(np.searchsorted(need, n, side="right"))  # need grows with p: the p that fit are a prefix
    ps, need = ps[:fits], need[:fits]
    lo = n - need
    probe = np.maximum(lo, n - ps - _PROBE)
    i = n - ps[:, None] - np.arange(1, _PROBE + 1)[None, :]  # slip i against slip i + p, the last ones
    inside = i >= probe[:, None]
    i = np.where(inside, i, 0)
    j = i + ps[:, None]
    near = np.abs(size[i] - size[j]) <= rtol * np.maximum(np.abs(size[i]), np.abs(size[j]))
    probe_ok = ((sb[i] == sb[j]) & (nb[i] == nb[j]) & near | ~inside).all(axis=1)
    probed = (n - ps) - probe  # pairs each p's probe compares
    period = None
    for k in np.flatnonzero(probe_ok):
        p = int(ps[k])
        if probe[k] == lo[k] or matches(int(lo[k]), int(probe[k]), p).all():
            period = p
            break
    count[0] += int(probed[: (ps.size if period is None else period)].sum())
    rule = rule_text(rtol, max_period, repeats, columns)
    common = dict(n_slips=n, t_last=None if t is None or n == 0 else float(t[-1]), rtol=float(rtol))
    common.update(max_period=int(max_period), repeats=int(repeats), longest_period_searched=longest, rule=rule)
    if period is None:
        return Periodicity(None, None, None, None, None, comparisons=count[0], **common)
    start, chunk = n - max(repeats * period, period + longest), max(repeats * period, period + longest)
    while start > 0:
        lo = max(0, start - chunk)
        bad = np.flatnonzero(~matches(lo, start, period))
        if bad.size:
            start = lo + int(bad[-1]) + 1
            break
        start, chunk = lo, 2 * chunk
    k = (n - 1 - start) // period  # whole periods between the stretch's first and last slips
    period_t = settled_t = None
    if t is not None:
        period_t = float(t[n - 1] - t[n - 1 - k * period]) / k
        settled_t = float(t[start])
    return Periodicity(period, period_t, int(start), settled_t, (n - start) / period, comparisons=count[0], **common)


def periodicity(events: Any, **rule: Any) -> Periodicity:
    """:func:`find_period` of an event table (a :class:`~stickslip.run.outputs.ChainRun`'s
    ``events``, or a run directory's events.parquet read back).

    Parameters
    ----------
    events : pandas.DataFrame
        With columns ``start_block``, ``n_blocks``, ``S`` and ``t_start``, one row per slip in order.
    **rule
        ``rtol``, ``max_period``, ``repeats`` (:func:`find_period`).

    Returns
    -------
    Periodicity

    Examples
    --------
    >>> import stickslip
    >>> from stickslip.analysis.stats.periodicity import periodicity
    >>> run = stickslip.run_chain(stickslip.chain_params(N=5), 1e6, progress=False)
    >>> r = periodicity(run.events)
    >>> r.period_slips, r.settled_from_slip
    (16, 156)
    """
    return find_period(events["start_block"], events["n_blocks"], events["S"], events["t_start"], **rule)


def lattice_periodicity(events: Any, lattice: Any, **rule: Any) -> Periodicity:
    """:func:`find_period` of a lattice run's events (docs/lattice.md): a slip is its epicentre
    (the row-major index of its first block, :func:`stickslip.run.lattice.epicentre_index`), its
    area and its moment, in the places of the chain's start block, number of blocks and size S.

    Parameters
    ----------
    events : pandas.DataFrame
        A :class:`~stickslip.run.lattice.LatticeRun`'s ``events`` (or a run directory's
        events.csv read back): ``epicentre_row``, ``epicentre_col``, ``area``, ``moment``,
        ``t_start``, one row per slip in order.
    lattice : Chain or Square
        The run's lattice (``run.params.lattice``).
    **rule
        ``rtol`` (on the moment), ``max_period``, ``repeats`` (:func:`find_period`).

    Returns
    -------
    Periodicity
        Its rule names the epicentre, the area and the moment.
    """
    from stickslip.run.lattice import epicentre_index

    return find_period(
        epicentre_index(events, lattice), events["area"], events["moment"], events["t_start"], **rule,
        columns=LATTICE_COLUMNS,
    )  # fmt: skip


class PeriodicStop(Hook):
    """End a chain run (eq. 4, or a relative) once its slip sequence is periodic
    (:func:`find_period`): a hook of the run loop (:class:`~stickslip.run.loop.Hook`).

    At each stop of the kernel (some four a second) it takes the slips recorded since its last
    look (those already moved out of the kernel's buffer and those still in it, told apart by
    their number) and, where new slips came, tests the whole sequence. When a period is found
    the run ends there, and :attr:`result` holds it; else :attr:`result` stays None and
    :meth:`finish` gives the test of the whole run. A resumed run reads the slips of its
    checkpoint as well.

    Parameters
    ----------
    rtol, max_period, repeats
        The rule (:func:`find_period`).

    Examples
    --------
    >>> import stickslip
    >>> from stickslip.analysis.stats.periodicity import PeriodicStop
    >>> hook = PeriodicStop()
    >>> run = stickslip.run_chain(stickslip.chain_params(N=5), 1e7, hooks=[hook], progress=False)
    >>> hook.result.period_slips, hook.result.settled_from_slip, run.summary["t_reached"] < 1e7
    (16, 156, True)
    """

    def __init__(self, *, rtol: float = RTOL, max_period: int = MAX_PERIOD, repeats: int = REPEATS):
        _check(rtol, max_period, repeats)
        self.rule = {"rtol": float(rtol), "max_period": int(max_period), "repeats": int(repeats)}
        self.cols = np.zeros((4, 1024))  # start_block, n_blocks, S, t_start
        self.n = 0
        self.parts_seen = 0
        self.tested_at = 0
        self.result: Periodicity | None = None

    def _add(self, ev_int: np.ndarray, ev_S: np.ndarray, dt: float) -> None:
        new = ev_int[:, layout.E_ID] >= self.n
        if not new.any():
            return
        rows, sizes = ev_int[new], ev_S[new]
        m = len(rows)
        while self.n + m > self.cols.shape[1]:
            self.cols = np.concatenate([self.cols, np.zeros_like(self.cols)], axis=1)
        block = np.vstack([rows[:, layout.E_START_BLOCK], rows[:, layout.E_N_BLOCKS], sizes])
        self.cols[:3, self.n : self.n + m] = block
        self.cols[3, self.n : self.n + m] = rows[:, layout.E_START_STEP] * dt
        self.n += m

    def _collect(self, loop: Loop) -> None:
        parts, dt = loop.outputs.parts, loop.params.dt
        for k in range(self.parts_seen, len(parts["ev_int"])):
            self._add(parts["ev_int"][k], parts["ev_S"][k], dt)
        self.parts_seen = len(parts["ev_int"])
        pending = int(loop.state.ist[layout.EV_COUNT])
        if pending:
            self._add(loop.outputs.ev_int[:pending], loop.outputs.ev_S[:pending], dt)

    def finish(self) -> Periodicity:
        """:func:`find_period` of every slip the hook has seen."""
        c = self.cols[:, : self.n]
        return find_period(c[0], c[1], c[2], c[3], **self.rule)

    def at(self, loop: Loop, n: int) -> bool:
        """Take the new slips; True (end the run) once the sequence is periodic."""
        self._collect(loop)
        if self.n == self.tested_at:
            return False
        self.tested_at = self.n
        found = self.finish()
        if found.periodic:
            self.result = found
            return True
        return False
