"""The loaded chain: the engine's state at the end of a transient, with the check that it is loaded.

Started from the paper's state (x = 0) the chain of eq. (4) is stretched from the pulling end:
slips reach the far block N only after about a loading time L_ss / V (docs/studies/chaos.md,
"Loaded before comparing"), and until then its statistics are not stationary.
:func:`loaded_state` runs :func:`stickslip.run.driver.run_chain` to the transient T0 and
returns its final state with :func:`loading_summary` of the slips on the way: the time of the
first slip that moved block N, and T0 counted as loaded when it is at least twice that time
(:data:`LOADED_FACTOR`).

With ``cache`` (a folder), the state is kept there as a checksummed npz file (the format of the
run checkpoints, :mod:`stickslip.run.checkpoint`) named by the SHA-256 of everything it depends
on (parameters, start, T0, package version), and later calls with the same settings read it
instead of running again: several measurements from one loaded state share one transient. A long
transient is run in chunks and its progress kept in a second file, so an interrupted one
continues where it stopped. The chunks continue one run exactly (the state at T0 is that of one
uninterrupted run; only the time of the next L sample, which a continued run sets anew, differs).
A damaged or foreign file is not used: the state is computed again and the file rewritten.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from stickslip import __version__
from stickslip.models.params import ChainParams, check_number, steps_for
from stickslip.run.state import ChainState

__all__ = [
    "LoadedState",
    "loaded_state",
    "located_start",
    "loading_summary",
    "loaded_spec",
    "LOADED_FACTOR",
    "STRETCHES",
]

#: T0 counts as loaded when it is at least this many times the first slip that moved block N.
LOADED_FACTOR = 2.0
#: The transient's slips are summarised in this many equal stretches (:func:`loading_summary`).
STRETCHES = 5
#: A cached transient runs in this many chunks, its progress kept after each.
CHUNKS = 16
_FORMAT = 1


@dataclass(frozen=True)
class LoadedState:
    """The engine's state at the end of the transient and what the transient's slips say.

    ``info``: ``transient``, ``first_slip_reaching_block_N`` (None if no slip moved block N),
    ``loaded`` (T0 at least :data:`LOADED_FACTOR` times that), ``stretches`` (rows of
    :func:`loading_summary`), ``slips``, ``state_sha256``, ``wall_seconds`` (of the run, or of the
    run that filled the cache), ``cached`` (read from the cache) and ``cache_file``.
    """

    state: ChainState = field(repr=False)
    info: dict[str, Any]

    def located(self, params: ChainParams):
        """The state as the located integrator's start, clock restarted (docs/lyapunov.md): the
        drive's frame does not read t, so every measurement from it can start at t = 0."""
        from stickslip.run.located import LocatedState

        return LocatedState.from_chain_state(self.state, params, restart_clock=True)


def loaded_spec(params: ChainParams, transient: float, start: str, perturbation: float, seed: int) -> dict[str, Any]:
    """What the loaded state depends on (the cache's key): parameters, start, T0, version."""
    return {
        "params": params.to_dict(),
        "transient": float(transient),
        "start": str(start),
        "perturbation": float(perturbation),
        "seed": int(seed),
        "version": __version__,
        "format": _FORMAT,
    }


def _key(spec: dict[str, Any]) -> str:
    return hashlib.sha256(json.dumps(spec, sort_keys=True).encode()).hexdigest()[:16]


class _Tally:
    """The transient's slips, summed chunk by chunk (:func:`loading_summary` at the end)."""

    def __init__(self, transient: float, N: int, data: dict[str, Any] | None = None):
        self.transient = transient
        self.N = N
        d = data or {}
        self.first = d.get("first")
        self.slips = list(d.get("slips", [0] * STRETCHES))
        self.sum_S = list(d.get("sum_S", [0.0] * STRETCHES))
        self.max_block = list(d.get("max_block", [0] * STRETCHES))
        self.reach = list(d.get("reach", [0] * STRETCHES))

    def add(self, events) -> None:
        if not len(events):
            return
        t = np.asarray(events["t_start"], dtype=float)
        S = np.asarray(events["S"], dtype=float)
        mb = np.asarray(events["max_block"], dtype=np.int64)
        at_N = np.flatnonzero(mb >= self.N)
        if self.first is None and at_N.size:
            self.first = float(t[at_N[0]])
        k = np.minimum((t / self.transient * STRETCHES).astype(np.int64), STRETCHES - 1)
        for j in range(STRETCHES):
            m = k == j
            if m.any():
                self.slips[j] += int(np.count_nonzero(m))
                self.sum_S[j] += float(S[m].sum())
                self.max_block[j] = max(self.max_block[j], int(mb[m].max()))
                self.reach[j] += int(np.count_nonzero(mb[m] >= self.N))

    def data(self) -> dict[str, Any]:
        return {
            "first": self.first,
            "slips": self.slips,
            "sum_S": self.sum_S,
            "max_block": self.max_block,
            "reach": self.reach,
        }

    def summary(self) -> dict[str, Any]:
        return loading_summary(self.transient, self.first, self.slips, self.sum_S, self.max_block, self.reach)


def loading_summary(transient: float, first_reach, slips, sum_S, max_block, reach) -> dict[str, Any]:
    """The loading check of a transient of length ``transient``: ``first_slip_reaching_block_N``,
    ``loaded`` (transient >= :data:`LOADED_FACTOR` times it) and ``stretches``, one row per equal
    stretch of the transient with its ``slips``, ``mean_S``, ``max_block`` (the farthest block any
    slip moved) and ``slips_reaching_block_N``."""
    n = len(slips)
    rows = []
    for j in range(n):
        rows.append(
            {
                "t_from": transient * j / n,
                "t_to": transient * (j + 1) / n,
                "slips": int(slips[j]),
                "mean_S": float(sum_S[j] / slips[j]) if slips[j] else None,
                "max_block": int(max_block[j]),
                "slips_reaching_block_N": int(reach[j]),
            }
        )
    loaded = first_reach is not None and transient >= LOADED_FACTOR * float(first_reach)
    return {
        "transient": float(transient),
        "first_slip_reaching_block_N": None if first_reach is None else float(first_reach),
        "loaded": bool(loaded),
        "loaded_rule": f"T0 >= {LOADED_FACTOR:g} x the start of the first slip that moved block N",
        "slips": int(sum(slips)),
        "stretches": rows,
    }


def loaded_state(
    params: ChainParams,
    transient: float,
    *,
    start: str = "paper",
    perturbation: float = 0.0,
    seed: int = 0,
    cache: str | Path | None = None,
    stop_requested=None,
) -> LoadedState:
    """The engine's state at ``transient`` from ``start`` (:func:`stickslip.run.driver.run_chain`)
    and its loading check (module docstring); read from, or written to, the folder ``cache``.
    ``stop_requested`` goes to the engine (:class:`stickslip.run.errors.Interrupted` when it says
    stop; a cached transient keeps its finished chunks)."""
    from stickslip.run.driver import run_chain
    from stickslip.run.errors import short_runs_expected

    transient = float(check_number("transient", transient, low=0.0, low_open=True))
    steps_for(transient, params.dt, "transient")  # refused as what the caller gave, not as run_chain's t_end
    if cache is not None:
        check_cache_folder(cache)  # before the transient's first chunk
    spec = loaded_spec(params, transient, start, perturbation, seed)
    wall0 = time.perf_counter()
    if cache is None:
        with short_runs_expected():  # only the state at the transient's end is used
            run = run_chain(
                params,
                transient,
                start=start,
                perturbation=perturbation,
                seed=seed,
                sample_interval=transient,
                stop_requested=stop_requested,
            )
        tally = _Tally(transient, params.N)
        tally.add(run.events)
        return LoadedState(run.state, _info(tally, run.state, time.perf_counter() - wall0, False, None))
    folder = Path(cache)
    key = _key(spec)
    path = folder / f"loaded-{key}.npz"
    partial = folder / f"loaded-{key}.partial.npz"
    found = _read(path, spec, params)
    if found is not None:
        state, header = found
        tally = _Tally(transient, params.N, header["tally"])
        return LoadedState(state, _info(tally, state, header["wall_seconds"], True, path))
    state: ChainState | str = start
    tally = _Tally(transient, params.N)
    done, wall_before = 0, 0.0
    resumed = _read(partial, spec, params)
    if resumed is not None:
        state, header = resumed
        tally = _Tally(transient, params.N, header["tally"])
        done, wall_before = int(header["chunk"]), float(header["wall_seconds"])
    for j in range(done, CHUNKS):
        t_j = transient if j == CHUNKS - 1 else transient * (j + 1) / CHUNKS
        with short_runs_expected():
            run = run_chain(
                params,
                t_j,
                start=state,
                perturbation=perturbation,
                seed=seed,
                sample_interval=t_j,
                stop_requested=stop_requested,
            )
        state = run.state
        tally.add(run.events)
        wall = wall_before + time.perf_counter() - wall0
        header = {"spec": spec, "tally": tally.data(), "chunk": j + 1, "wall_seconds": wall}
        _write(path if j == CHUNKS - 1 else partial, state, header)
    partial.unlink(missing_ok=True)
    assert isinstance(state, ChainState)
    return LoadedState(state, _info(tally, state, wall_before + time.perf_counter() - wall0, False, path))


def check_cache_folder(folder: str | Path, name: str = "cache") -> Path:
    """Refuse a cache folder that cannot be read from and written to, before any work: a file, a
    path under a file, a folder (or the folder it would be made in) that is not writable, as on a
    read-only file system. Nothing is created.

    Parameters
    ----------
    folder : str or Path
        The cache folder of :func:`loaded_state`.
    name : str
        The option named in the message (``--state-cache`` on the command line).

    Returns
    -------
    Path
        The folder.

    Raises
    ------
    ParameterError
        One line naming ``name``, the folder and what is wrong.
    """
    import os

    from stickslip.models.params import ParameterError

    folder = Path(folder)
    if str(folder).strip() == "":
        raise ParameterError(f"{name} must name a folder (got '')")
    if folder.exists() and not folder.is_dir():
        raise ParameterError(f"{name} {folder} is a file, not a folder")
    probe = folder
    while not probe.exists() and probe.parent != probe:
        probe = probe.parent
    if not probe.is_dir():
        raise ParameterError(f"{name} {folder}: cannot make a folder there ({probe} is a file)")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise ParameterError(f"{name} {folder}: {probe} is not writable (a read-only file system, or its permissions)")
    return folder


def _info(tally: _Tally, state: ChainState, wall: float, cached: bool, path) -> dict[str, Any]:
    return {
        **tally.summary(),
        "state_sha256": state.sha256(),
        "wall_seconds": round(float(wall), 3),
        "cached": cached,
        "cache_file": None if path is None else str(path),
    }


def _write(path: Path, state: ChainState, header: dict[str, Any]) -> None:
    from stickslip.run.checkpoint import write_state_npz

    write_state_npz(path, state, header)


def _read(path: Path, spec: dict[str, Any], params: ChainParams) -> tuple[ChainState, dict[str, Any]] | None:
    """The state and header kept at ``path`` if it is intact and made from ``spec``; else None."""
    from stickslip.run.checkpoint import read_state_npz

    found = read_state_npz(path, spec, params)
    if found is None:
        return None
    state, header, extra = found
    wall = header.get("wall_seconds")
    whole = isinstance(wall, (int, float)) and math.isfinite(wall) and isinstance(header.get("tally"), dict)
    return (state, header) if whole and not extra else None


def located_start(params: ChainParams, transient: float, *, start: str, perturbation: float, seed: int):
    """The located integrator's start at the end of ``transient``: the engine's run of eq. (4) or
    a relative up to there from ``start`` (:func:`loaded_state`), clock restarted.

    Parameters
    ----------
    params : ChainParams
        The chain.
    transient : float
        Model time run before the start; at 0 the start itself
        (:func:`stickslip.run.located.start_state`).
    start, perturbation, seed
        The initial state of :func:`stickslip.run.driver.run_chain`.

    Returns
    -------
    LocatedState
        The state at the end of the transient, at t = 0.
    """
    from stickslip.run.located import start_state

    if transient <= 0.0:
        return start_state(params, start, perturbation=perturbation, seed=seed)
    return loaded_state(params, transient, start=start, perturbation=perturbation, seed=seed).located(params)
