"""The defaults of the matching rule of :mod:`stickslip.analysis.stats.periodicity`, in a module of their
own so that the command line states them without loading the engine."""

from __future__ import annotations

__all__ = ["RTOL", "MAX_PERIOD", "REPEATS"]

#: Default relative tolerance on the slip size S: a settled orbit of the chain repeats its sizes
#: to about 1e-12, the single block's (whose slips start at a different fraction of a step each
#: time) to about 4e-7; successive slips of the loading pulse differ by 1e-6 to 1e-5.
RTOL = 1e-6
#: Default longest period searched, in slips.
MAX_PERIOD = 500
#: Default number of periods the periodic stretch must hold.
REPEATS = 3
