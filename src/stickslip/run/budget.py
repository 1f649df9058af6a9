"""What an option asks of the machine, estimated before anything runs: the memory of a chain
run's outputs (eq. 4: L sampled, snapshots, displacement profiles), of a catalogue's magnitude
bins, and the work of counts (resamples, synthetic catalogues, slips of a decorrelation window).
What cannot finish is refused at once with a :class:`~stickslip.models.params.ParameterError`
naming the option, the estimate and the limit (docs/limits.md)."""

from __future__ import annotations

import math
import os

from stickslip.models.params import ParameterError

__all__ = [
    "physical_memory",
    "check_memory",
    "check_count",
    "check_run_outputs",
    "MAX_SLIPS",
]

#: Slips simulated by one decorrelation measurement (every sequence of every window together): at
#: the fastest of this package's chains (some 1e5 slips a second on one core) 1e9 take three hours.
MAX_SLIPS = 1_000_000_000


def physical_memory() -> int:
    """Bytes of memory of this machine (``os.sysconf``; 2**40 where it does not say)."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return 2**40


def _size(n_bytes: float) -> str:
    return f"{n_bytes / 2**30:.3g} GiB" if n_bytes >= 2**28 else f"{n_bytes / 2**20:.3g} MiB"


def check_memory(option: str, n_bytes: float, what: str, advice: str) -> None:
    """Refuse ``option`` when ``n_bytes`` (what it implies, said in ``what``) exceeds this machine's memory.

    Parameters
    ----------
    option : str
        The option named in the message (``sample_interval``, ``--dm``).
    n_bytes : float
        The estimate.
    what : str
        What the estimate counts, in words.
    advice : str
        What to change.

    Raises
    ------
    ParameterError
        One line: the option, the estimate, the limit and the advice.
    """
    have = physical_memory()
    if not n_bytes <= have:
        raise ParameterError(
            f"{option}: {what} would need about {_size(n_bytes)} of memory, more than this machine's "
            f"{_size(have)}; {advice}"
        )


def check_count(option: str, value: int, limit: int, why: str) -> int:
    """Refuse a count above ``limit`` (the message says why that is enough); returns the count.

    Parameters
    ----------
    option : str
        The option.
    value : int
        The count given.
    limit : int
        The most that is done.
    why : str
        Why the limit is enough (what more would not change).

    Returns
    -------
    int
        ``value``.
    """
    if value > limit:
        raise ParameterError(f"{option} must be <= {limit} (got {value}): {why}")
    return int(value)


def check_run_outputs(N: int, dt: float, options) -> None:
    """Refuse a chain run (eq. 4) whose outputs no machine of this size can hold: L sampled every
    ``sample_interval`` (t, L and, with ``sample_moving``, the moving count: 16 or 32 bytes a
    sample, twice over while the run's parts are joined), N positions per snapshot, and at most
    N displacements per ``profile_window`` of the run (an upper bound: profiles are kept only
    during slips).

    Parameters
    ----------
    N : int
        Blocks of the chain.
    dt : float
        The time step.
    options : RunOptions
        The run's options (validated: ``t_end`` given).
    """
    t_end = float(options.t_end)
    samples = math.floor(t_end / options.sample_interval) + 1
    per_sample = 2 * (32 if options.sample_moving else 16)
    check_memory(
        "sample_interval",
        samples * per_sample,
        f"L sampled every {options.sample_interval:g} to t = {t_end:g} ({samples:.3g} samples)",
        "sample less often",
    )
    snaps = len(options.snapshot_times)
    check_memory(
        "snapshot_times",
        2 * snaps * (N + 1) * 8,
        f"{snaps} snapshots of {N} blocks",
        "ask for fewer snapshots",
    )
    if options.profile_window is not None:
        windows = math.floor(t_end / options.profile_window) + 1
        check_memory(
            "profile_window",
            2 * windows * (N + 4) * 8,
            f"profiles of {N} blocks every {options.profile_window:g} to t = {t_end:g} (up to {windows:.3g} windows)",
            "take longer windows or a shorter run",
        )
