"""The revised verdict on irregular slip motion: periodic, chaotic or stable chaos (issue 51).

One point (a model at one N and beta) is judged from three measurements:

* **settling**: how many starts settled on a periodic orbit or in steady sliding within their
  window, and the periods (:mod:`stickslip.analysis.stats.periodicity`, the lifetimes study);
* **the flow's largest exponent** and its error (:func:`stickslip.analysis.dynamics.lyapunov_flow.flow_lyapunov`);
* **the decorrelation threshold** of slip sequences: the bracket (below, low] of the smallest
  perturbation of the state that changed the sequence within the window
  (:func:`stickslip.analysis.dynamics.threshold.delta_star`);

and, per model and beta, **how the lifetimes grow with N**: the slope b of ln <T> on N with its
error (:func:`stickslip.analysis.stats.survival.size_fits`).

The verdicts, in the order they are tested (:func:`chaos_verdict`):

- ``periodic``: every start settled within its window, at least one on a periodic orbit (its
  period given); ``steady``: every start ended in steady sliding;
- ``chaotic``: the exponent above two of its errors (a positive largest exponent);
- ``stable chaos``: some start irregular to the end of its window, no positive exponent, a
  finite decorrelation threshold (no window decorrelated at the smallest delta tested, some did
  at a larger one) *and* lifetimes that grow with N (b above two of its errors): the irregular
  motion is a transient whose lifetime grows with the size, as in Politi, Livi, Oppo and Kapral,
  Europhys. Lett. 22, 571 (1993) and Politi and Torcini, arXiv:0902.2545;
- ``undetermined``: irregular, no positive exponent, and one of the other two tests failed or
  was not measured (the text says which).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

from stickslip.models.params import ParameterError

__all__ = ["ChaosVerdict", "chaos_verdict", "VERDICTS"]

VERDICTS = ("periodic", "steady", "chaotic", "stable chaos", "undetermined")


@dataclass(frozen=True)
class ChaosVerdict:
    """The verdict of one point (:func:`chaos_verdict`).

    Attributes
    ----------
    verdict : str
        One of :data:`VERDICTS`.
    text : str
        The verdict with the numbers it rests on, one sentence.
    reasons : tuple of str
        What each test said (settling, exponent, threshold, growth), in the order tested; a test
        not reached is not listed.
    """

    verdict: str
    text: str
    reasons: tuple[str, ...]

    def to_dict(self) -> dict[str, Any]:
        """``verdict``, ``verdict_text`` and ``reasons`` for JSON."""
        d = asdict(self)
        d["verdict_text"] = d.pop("text")
        d["reasons"] = list(self.reasons)
        return d


def _finite(x) -> bool:
    try:
        return x is not None and math.isfinite(float(x))
    except (TypeError, ValueError):
        return False


def chaos_verdict(
    *,
    starts: int = 0,
    periodic: int = 0,
    steady: int = 0,
    periods=(),
    lyapunov: float | None = None,
    lyapunov_err: float | None = None,
    threshold: tuple[float | None, float | None] | None = None,
    growth: tuple[float, float] | None = None,
    sigmas: float = 2.0,
) -> ChaosVerdict:
    """The revised verdict of one point (module docstring; issue 51, item 5).

    Parameters
    ----------
    starts, periodic, steady : int
        Starts run, and how many of them settled on a periodic orbit or in steady sliding within
        their window; the others were irregular to its end (censored). ``starts = 0``: the
        lifetimes were not measured.
    periods : sequence of int
        The periods (slips) of the orbits reached.
    lyapunov, lyapunov_err : float or None
        The flow's largest exponent and its error; None (or NaN): not measured.
    threshold : (below, low) or None
        The bracket of the decorrelation threshold: ``below`` the largest delta at which no window
        decorrelated under the smallest that did, ``low`` the smallest that did (either None: none
        did, or every delta did); None: not measured.
    growth : (slope, slope_err) or None
        The slope b of ln <T> on N (per block) for this model and beta, with its error; None: not
        measured (fewer than two N with ended lifetimes).
    sigmas : float
        How many errors make a positive exponent, or a growth.

    Returns
    -------
    ChaosVerdict

    Raises
    ------
    ParameterError
        Counts that do not add up.

    Examples
    --------
    >>> from stickslip.analysis.dynamics.chaos_verdict import chaos_verdict
    >>> chaos_verdict(starts=8, periodic=8, periods=[10, 16]).verdict
    'periodic'
    >>> chaos_verdict(starts=8, lyapunov=0.025, lyapunov_err=0.001).verdict
    'chaotic'
    >>> chaos_verdict(starts=8, lyapunov=-1e-4, lyapunov_err=3e-5, threshold=(1e-4, 1e-2), growth=(1.9, 0.25)).verdict
    'stable chaos'
    """
    starts, periodic, steady = int(starts), int(periodic), int(steady)
    if min(starts, periodic, steady) < 0 or periodic + steady > starts:
        raise ParameterError(
            f"periodic + steady must lie in [0, starts] (got {periodic} + {steady} of {starts} starts)"
        )
    censored = starts - periodic - steady
    reasons: list[str] = []
    orbits = ", ".join(str(int(p)) for p in sorted(set(periods))[:6])
    if starts and not censored:
        if periodic:
            text = (
                f"periodic: all {starts} starts settled within their window ({periodic} on periodic orbits"
                + (f" of {orbits} slips" if orbits else "")
                + (f", {steady} in steady sliding" if steady else "")
                + ")"
            )
            return ChaosVerdict("periodic", text, (text,))
        text = f"steady: all {starts} starts ended in steady sliding within their window"
        return ChaosVerdict("steady", text, (text,))
    if starts:
        reasons.append(f"{censored} of {starts} starts irregular to the end of their window")
    else:
        reasons.append("lifetimes not measured")
    # the exponent
    if not (_finite(lyapunov) and _finite(lyapunov_err)):
        reasons.append("no exponent measured")
        return _undetermined(reasons)
    lam, err = float(lyapunov), float(lyapunov_err)
    if lam > sigmas * err:
        reasons.append(f"the flow's exponent {lam:.3g} +- {err:.2g} is above {sigmas:g} errors")
        return ChaosVerdict("chaotic", "chaotic: " + "; ".join(reasons), tuple(reasons))
    reasons.append(f"no positive exponent ({lam:.3g} +- {err:.2g})")
    # the threshold
    if threshold is None:
        reasons.append("no decorrelation threshold measured")
        return _undetermined(reasons)
    below, low = threshold
    if low is None:
        reasons.append("no finite decorrelation threshold: no window decorrelated at any delta tested")
        return _undetermined(reasons)
    if below is None:
        reasons.append(f"the decorrelation threshold lies below the deltas tested (delta = {low:g} decorrelated)")
        return _undetermined(reasons)
    reasons.append(f"a finite decorrelation threshold in ({below:g}, {low:g}]")
    # the growth of the lifetimes with N
    if growth is None or not (_finite(growth[0]) and _finite(growth[1])):
        reasons.append("the growth of the lifetimes with N not measured")
        return _undetermined(reasons)
    b, b_err = float(growth[0]), float(growth[1])
    if not b > sigmas * b_err:
        reasons.append(f"lifetimes do not grow with N beyond {sigmas:g} errors (b = {b:.3g} +- {b_err:.2g})")
        return _undetermined(reasons)
    reasons.append(f"lifetimes that grow with N (ln <T> on N: b = {b:.3g} +- {b_err:.2g} per block)")
    return ChaosVerdict("stable chaos", "stable chaos: " + "; ".join(reasons), tuple(reasons))


def _undetermined(reasons: list[str]) -> ChaosVerdict:
    return ChaosVerdict("undetermined", "undetermined: " + "; ".join(reasons), tuple(reasons))
