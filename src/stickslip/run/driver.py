"""The chain of eq. (4): running it, its slip events, and long resumable runs.

:func:`run_chain` integrates the chain of N blocks pulled at one end (MODEL.md, section
"Chain") with one of two integrators that give the same answer bit for bit:

* ``dense``: the reference, Heun over every block at every step;
* ``exact`` (default): the same arithmetic, skipping only work whose result is known in
  advance (see :mod:`stickslip.kernels.chain`).

A run returns a :class:`ChainRun`: the slip-event table (MODEL.md, "Slip events"), the time
each block first moved in each event (rupture fronts, Fig. 6), L(t) = x_1 - x_N sampled at a
fixed interval (Fig. 5b), snapshots of x_i (Fig. 5a), optional displacement profiles over
windows (Fig. 6), and the final state with its SHA-256.

Long runs write checkpoints into their run directory (atomically, with checksums) at a
wall-clock interval and on SIGINT/SIGTERM; :func:`resume_chain` continues from one and ends
bit for bit where an uninterrupted run does.
"""

from __future__ import annotations

import hashlib
import io as _io
import json
import math
import os
import signal
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np
import pandas as pd
import xarray as xr

from stickslip import __version__
from stickslip import physics
from stickslip.kernels import chain as K
from stickslip.params import ChainParams, ParameterError, check_number, steps_for

INTEGRATORS = ("exact", "dense")
STARTS = ("paper", "steady")
# Bump whenever the layout of the state arrays (kernels.chain.IST_SIZE included) changes.
CHECKPOINT_FORMAT = 2

_KERNELS = {"dense": K.run_dense, "exact": K.run_exact}


class ChainRunError(RuntimeError):
    """A chain run cannot go on (non-finite state, bad checkpoint)."""


class NonFiniteState(ChainRunError):
    """The state of the chain became non-finite; the message names the time and the block."""


class Interrupted(Exception):
    """A run was stopped by a signal after writing its checkpoint."""

    def __init__(self, checkpoint: Path | None, t: float):
        super().__init__(f"interrupted at t = {t:g}; checkpoint in {checkpoint}")
        self.checkpoint = checkpoint
        self.t = t


# --------------------------------------------------------------------------------------
# State


@dataclass
class ChainState:
    """Everything the kernels need to continue a run (arrays with ghost cells, see kernels).

    x, v, th, mov: positions, velocities, state variables and moving mask (1.0/0.0) of
    blocks 1..N at index 1..N; first_step, x0ev: per-block bookkeeping of the event in
    progress; ist: the integer state vector (step count, event bookkeeping, active range).
    """

    x: np.ndarray
    v: np.ndarray
    th: np.ndarray
    mov: np.ndarray
    first_step: np.ndarray
    x0ev: np.ndarray
    ist: np.ndarray

    ARRAYS = ("x", "v", "th", "mov", "first_step", "x0ev", "ist")

    @property
    def N(self) -> int:
        return self.x.shape[0] - 2

    @property
    def step(self) -> int:
        return int(self.ist[K.STEP])

    @classmethod
    def from_blocks(cls, x, v, theta, stopped) -> "ChainState":
        """Build a state from per-block arrays (length N) of x, v, theta and stopped flags."""
        x = np.asarray(x, dtype=np.float64)
        N = x.shape[0]
        arrays = {}
        for name, values in (("x", x), ("v", v), ("th", theta)):
            a = np.zeros(N + 2)
            # Adding 0.0 turns -0.0 into +0.0, so "changed" (a float compare) sees every bit.
            a[1:-1] = np.asarray(values, dtype=np.float64) + 0.0
            arrays[name] = a
        stopped = np.asarray(stopped, dtype=bool)
        mov = np.zeros(N + 2)
        mov[1:-1] = np.where(stopped, 0.0, 1.0)
        arrays["v"][1:-1] = np.where(stopped, 0.0, arrays["v"][1:-1])
        ist = np.zeros(K.IST_SIZE, dtype=np.int64)
        ist[K.N_MOVING] = int(np.count_nonzero(~stopped))
        ist[K.ACT_LO], ist[K.ACT_HI] = 1, N
        ist[K.MECH_LO], ist[K.MECH_HI] = 1, N
        return cls(
            first_step=np.full(N + 2, -1, dtype=np.int64), x0ev=np.zeros(N + 2), mov=mov,
            ist=ist, **arrays,
        )

    @classmethod
    def paper(cls, p: ChainParams) -> "ChainState":
        """The paper's initial state (section 3): x_i = 0, v_i = 0.1, theta_i = 0.1, all moving."""
        N = p.N
        return cls.from_blocks(np.zeros(N), np.full(N, 0.1), np.full(N, 0.1), np.zeros(N, bool))

    @classmethod
    def steady(cls, p: ChainParams, amplitude: float = 0.0, seed: int = 0) -> "ChainState":
        """Exact discrete steady sliding (MODEL.md) at t = 0, all blocks moving.

        With ``amplitude`` > 0, x_i and v_i get independent uniform perturbations in
        [-amplitude, amplitude] drawn from numpy's default generator with ``seed``.
        """
        s = physics.chain_steady_state(p, 0.0)
        x, v = s["x"].copy(), s["v"].copy()
        if amplitude > 0:
            rng = np.random.default_rng(seed)
            x += rng.uniform(-amplitude, amplitude, p.N)
            v += rng.uniform(-amplitude, amplitude, p.N)
        return cls.from_blocks(x, v, s["theta"], np.zeros(p.N, bool))

    def blocks(self) -> dict[str, np.ndarray]:
        """Per-block copies: x, v, theta (float64) and stopped (bool), block i at index i - 1."""
        return {
            "x": self.x[1:-1].copy(),
            "v": self.v[1:-1].copy(),
            "theta": self.th[1:-1].copy(),
            "stopped": self.mov[1:-1] == 0.0,
        }

    def sha256(self) -> str:
        """SHA-256 of x, v, theta (float64 little-endian, block order) then stopped (1 byte each)."""
        h = hashlib.sha256()
        for a in (self.x, self.v, self.th):
            h.update(np.ascontiguousarray(a[1:-1], dtype="<f8").tobytes())
        h.update((self.mov[1:-1] == 0.0).astype(np.uint8).tobytes())
        return h.hexdigest()

    def copy(self) -> "ChainState":
        return ChainState(**{k: getattr(self, k).copy() for k in self.ARRAYS})


def initial_state(p: ChainParams, start: str = "paper", *, amplitude: float = 0.0, seed: int = 0) -> ChainState:
    """The initial state named by ``start``: 'paper' (section 3) or 'steady' (MODEL.md)."""
    if start == "paper":
        return ChainState.paper(p)
    if start == "steady":
        return ChainState.steady(p, amplitude, seed)
    raise ParameterError(f"start must be one of {', '.join(STARTS)} (got {start!r})")


def steady_deviation(state: ChainState, p: ChainParams) -> float:
    """Distance of a state from steady sliding of the chain (MODEL.md), in the frame moving with V.

    The largest of |v_i - V|, |theta_i - theta_0| and |e_i - e_i^ss| over all blocks, where
    e_i = x_{i-1} - x_i are the spring extensions (x_0 = V t_n) and e_i^ss = (c/K)(N - i + 1)
    those of steady sliding. Infinite unless every block is moving.
    """
    if np.any(state.mov[1:-1] == 0.0):
        return float("inf")
    ss = physics.chain_steady_state(p)
    x = state.x[1:-1]
    x0 = p.V * (np.float64(state.step) * p.dt)
    ext = np.diff(np.concatenate(([x0], x))) * -1.0
    return float(max(
        np.max(np.abs(state.v[1:-1] - ss["v"])),
        np.max(np.abs(state.th[1:-1] - ss["theta"])),
        np.max(np.abs(ext - ss["ext"])),
    ))


# --------------------------------------------------------------------------------------
# Options and results


@dataclass(frozen=True)
class RunOptions:
    """What a run records besides its state. Times are in the model's time units.

    sample_interval: L = x_1 - x_N is sampled every this long (Fig. 5b);
    average_from: <L> is the mean of the samples with t >= average_from (default t_end / 2);
    snapshot_times: times at which all x_i are stored (Fig. 5a); the final state is always kept;
    profile_window: if set, x_i is stored every this long during each event, for the
    displacement over windows of Fig. 6, for events with >= profile_min_blocks moved blocks;
    until_steady: if set, the run stops at the first sampling time at which every block slides
    and the state is within this tolerance of steady sliding (:func:`steady_deviation`).
    """

    t_end: float
    sample_interval: float = 10.0
    average_from: float | None = None
    snapshot_times: tuple[float, ...] = ()
    profile_window: float | None = None
    profile_min_blocks: int = 0
    until_steady: float | None = None

    def validated(self, dt: float) -> "RunOptions":
        check_number("t_end", self.t_end, low=0.0)
        check_number("sample_interval", self.sample_interval, low=0.0, low_open=True)
        if round(self.sample_interval / dt) < 1:
            raise ParameterError(f"sample_interval must be >= dt = {dt:g} (got {self.sample_interval!r})")
        if self.average_from is not None:
            check_number("average_from", self.average_from, low=0.0)
        for t in self.snapshot_times:
            check_number("snapshot time", t, low=0.0, high=self.t_end)
        if self.profile_window is not None:
            check_number("profile_window", self.profile_window, low=0.0, low_open=True)
            if round(self.profile_window / dt) < 1:
                raise ParameterError(f"profile_window must be >= dt = {dt:g} (got {self.profile_window!r})")
        check_number("profile_min_blocks", self.profile_min_blocks, low=0, integer=True)
        if self.until_steady is not None:
            check_number("until_steady", self.until_steady, low=0.0, low_open=True)
        return self

    def to_dict(self) -> dict[str, Any]:
        return {
            "t_end": self.t_end,
            "sample_interval": self.sample_interval,
            "average_from": self.average_from,
            "snapshot_times": list(self.snapshot_times),
            "profile_window": self.profile_window,
            "profile_min_blocks": self.profile_min_blocks,
            "until_steady": self.until_steady,
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "RunOptions":
        d = dict(d)
        d["snapshot_times"] = tuple(d.get("snapshot_times", ()))
        return cls(**d)


EVENT_COLUMNS = ["event", "step_start", "step_end", "t_start", "t_end", "duration", "S",
                 "start_block", "max_block", "n_blocks"]


@dataclass
class ChainRun:
    """The result of a chain run (eq. 4): events, first moves, L(t), snapshots, profiles, state."""

    params: ChainParams
    options: RunOptions
    integrator: str
    start: dict[str, Any]
    state: ChainState
    events: pd.DataFrame
    first_move: pd.DataFrame
    samples: xr.Dataset
    snapshots: xr.DataArray
    profiles: xr.Dataset
    summary: dict[str, Any]

    @property
    def t_end(self) -> float:
        return self.options.t_end

    @property
    def steps(self) -> int:
        return self.state.step


class _Outputs:
    """Output buffers shared with the kernels, and what has been flushed from them."""

    def __init__(self, N: int, profiling: bool):
        self.ev_int = np.zeros((4096, K.EV_INT_COLS), dtype=np.int64)
        self.ev_S = np.zeros(4096)
        self.fm = np.zeros((max(65536, 4 * (N + 1)), 3), dtype=np.int64)
        self.samp_L = np.zeros(65536)
        self.samp_step = np.zeros(65536, dtype=np.int64)
        rows = 256 if profiling else 2
        self.prof_x = np.zeros((rows, N))
        self.prof_meta = np.zeros((rows, 2), dtype=np.int64)
        self.parts: dict[str, list[np.ndarray]] = {k: [] for k in PART_KEYS}

    def kernel_args(self):
        return (self.ev_int, self.ev_S, self.fm, self.samp_L, self.samp_step, self.prof_x, self.prof_meta)

    def flush(self, ist: np.ndarray) -> None:
        """Move filled buffer rows into Python-side lists and reset the counts."""
        ne, nf, ns, npr = (int(ist[K.EV_COUNT]), int(ist[K.FM_COUNT]), int(ist[K.S_COUNT]), int(ist[K.P_COUNT]))
        if ne:
            self.parts["ev_int"].append(self.ev_int[:ne].copy())
            self.parts["ev_S"].append(self.ev_S[:ne].copy())
        if nf:
            self.parts["fm"].append(self.fm[:nf].copy())
        if ns:
            self.parts["samp_L"].append(self.samp_L[:ns].copy())
            self.parts["samp_step"].append(self.samp_step[:ns].copy())
        if npr:
            self.parts["prof_x"].append(self.prof_x[:npr].copy())
            self.parts["prof_meta"].append(self.prof_meta[:npr].copy())
        ist[K.EV_COUNT] = ist[K.FM_COUNT] = ist[K.S_COUNT] = ist[K.P_COUNT] = 0
        ist[K.EV_P_FIRST] = 0

    def add_snapshot(self, step: int, x: np.ndarray) -> None:
        self.parts["snap_step"].append(np.array([step], dtype=np.int64))
        self.parts["snap_x"].append(x[1:-1].copy()[None, :])

    def take_new(self, since: dict[str, int]) -> dict[str, np.ndarray]:
        """Concatenate the parts added since ``since`` (counts per key); updates ``since``."""
        out = {}
        for key in PART_KEYS:
            new = self.parts[key][since.get(key, 0):]
            since[key] = len(self.parts[key])
            out[key] = _concat(key, new)
        return out

    def all(self) -> dict[str, np.ndarray]:
        return {key: _concat(key, self.parts[key]) for key in PART_KEYS}


PART_KEYS = ("ev_int", "ev_S", "fm", "samp_L", "samp_step", "prof_x", "prof_meta", "snap_step", "snap_x")
_PART_SHAPES = {"ev_int": (0, K.EV_INT_COLS), "ev_S": (0,), "fm": (0, 3), "samp_L": (0,),
                "samp_step": (0,), "prof_x": None, "prof_meta": (0, 2), "snap_step": (0,), "snap_x": None}
_PART_DTYPES = {"ev_int": np.int64, "fm": np.int64, "samp_step": np.int64, "prof_meta": np.int64,
                "snap_step": np.int64}


def _concat(key: str, arrays: list[np.ndarray]) -> np.ndarray:
    if arrays:
        return np.concatenate(arrays, axis=0)
    shape = _PART_SHAPES[key] or (0, 0)
    return np.zeros(shape, dtype=_PART_DTYPES.get(key, np.float64))


# --------------------------------------------------------------------------------------
# Checkpoints


def _checksum(arrays: dict[str, np.ndarray], header: dict[str, Any]) -> str:
    h = hashlib.sha256(json.dumps(header, sort_keys=True).encode())
    for key in sorted(arrays):
        a = np.ascontiguousarray(arrays[key])
        h.update(key.encode())
        h.update(str(a.dtype).encode())
        h.update(str(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def _write_npz(path: Path, arrays: dict[str, np.ndarray], header: dict[str, Any]) -> str:
    """Write arrays + a JSON header + their checksum to ``path`` atomically; returns the checksum."""
    from stickslip.io import atomic_path

    digest = _checksum(arrays, header)
    payload = dict(arrays)
    payload["__header__"] = np.frombuffer(json.dumps(header, sort_keys=True).encode(), dtype=np.uint8)
    payload["__checksum__"] = np.frombuffer(digest.encode(), dtype=np.uint8)
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez(fh, **payload)
            fh.flush()
            os.fsync(fh.fileno())
    return digest


def _read_npz(path: Path) -> tuple[dict[str, np.ndarray], dict[str, Any], str]:
    """Read and verify a file written by :func:`_write_npz`; raises ChainRunError if corrupt."""
    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
        header = json.loads(arrays.pop("__header__").tobytes().decode())
        stored = arrays.pop("__checksum__").tobytes().decode()
    except Exception as exc:  # any damage to the file: refuse it
        raise ChainRunError(f"checkpoint file {path} is unreadable or corrupt ({type(exc).__name__})") from None
    if _checksum(arrays, header) != stored:
        raise ChainRunError(f"checkpoint file {path} is corrupt (checksum mismatch)")
    return arrays, header, stored


def _check_layout(arrays: dict[str, np.ndarray], header: dict[str, Any]) -> None:
    """Refuse state arrays that do not fit the header's N or this version's layout."""
    try:
        N = int(header["params"]["N"])
    except (KeyError, TypeError, ValueError):
        raise ChainRunError("checkpoint header has no valid N") from None
    expected = {
        "x": (np.float64, (N + 2,)), "v": (np.float64, (N + 2,)), "th": (np.float64, (N + 2,)),
        "mov": (np.float64, (N + 2,)), "x0ev": (np.float64, (N + 2,)),
        "first_step": (np.int64, (N + 2,)), "ist": (np.int64, (K.IST_SIZE,)),
    }
    for name, (dtype, shape) in expected.items():
        a = arrays[name]
        if a.dtype != dtype or a.shape != shape:
            raise ChainRunError(
                f"checkpoint array {name} has shape {a.shape} and type {a.dtype}, "
                f"expected {shape} and {np.dtype(dtype)} for N = {N}"
            )


class Checkpointer:
    """Checkpoints of one run directory: ``checkpoint/state.npz`` plus append-only output parts.

    Each checkpoint first writes the outputs produced since the last one as a new part file,
    then atomically replaces the state file, which lists the parts (with their checksums)
    that belong to it. A kill at any moment leaves the previous checkpoint intact; parts not
    listed by the state file are ignored and removed on resume.
    """

    def __init__(self, run_dir: Path):
        self.dir = Path(run_dir) / "checkpoint"
        self.parts: list[dict[str, str]] = []
        self.since: dict[str, int] = {}

    @property
    def state_path(self) -> Path:
        return self.dir / "state.npz"

    def write(self, state: ChainState, outputs: _Outputs, header: dict[str, Any]) -> Path:
        self.dir.mkdir(parents=True, exist_ok=True)
        new = outputs.take_new(self.since)
        name = f"part-{len(self.parts):06d}.npz"
        digest = _write_npz(self.dir / name, new, {"format": CHECKPOINT_FORMAT})
        self.parts.append({"file": name, "sha256": digest})
        arrays = {k: getattr(state, k) for k in ChainState.ARRAYS}
        full_header = dict(header, format=CHECKPOINT_FORMAT, parts=self.parts, version=__version__,
                           ist_size=K.IST_SIZE)
        _write_npz(self.state_path, arrays, full_header)
        return self.state_path

    def load(self) -> tuple[ChainState, dict[str, Any], dict[str, list[np.ndarray]]]:
        if not self.state_path.exists():
            raise ChainRunError(f"no checkpoint in {self.dir.parent} (missing {self.state_path.name})")
        arrays, header, _ = _read_npz(self.state_path)
        if header.get("format") != CHECKPOINT_FORMAT:
            raise ChainRunError(
                f"checkpoint format {header.get('format')} is not supported (this version reads {CHECKPOINT_FORMAT})"
            )
        missing = [k for k in ChainState.ARRAYS if k not in arrays]
        if missing:
            raise ChainRunError(f"checkpoint is missing arrays {missing}")
        _check_layout(arrays, header)
        state = ChainState(**{k: arrays[k].copy() for k in ChainState.ARRAYS})
        parts: dict[str, list[np.ndarray]] = {k: [] for k in PART_KEYS}
        listed = header.get("parts", [])
        for entry in listed:
            part_arrays, _, digest = _read_npz(self.dir / entry["file"])
            if digest != entry["sha256"]:
                raise ChainRunError(f"checkpoint part {entry['file']} does not match the state file")
            for key in PART_KEYS:
                if key in part_arrays and part_arrays[key].shape[0]:
                    parts[key].append(part_arrays[key])
        keep = {entry["file"] for entry in listed}
        for stray in self.dir.glob("part-*.npz"):
            if stray.name not in keep:
                stray.unlink()
        for tmp in self.dir.glob(".*.tmp"):  # left by a write that was killed
            tmp.unlink()
        self.parts = list(listed)
        return state, header, parts


# --------------------------------------------------------------------------------------
# Running


@dataclass
class _Progress:
    """Progress on a terminal: time reached, events so far, speed, time left."""

    t_end: float
    enabled: bool
    bar: Any = None
    t_last: float = 0.0

    def __post_init__(self):
        if self.enabled:
            from tqdm import tqdm

            self.bar = tqdm(total=self.t_end, unit="t", unit_scale=True, dynamic_ncols=True,
                            desc="chain", file=sys.stderr, smoothing=0.1)

    def update(self, t: float, n_events: int) -> None:
        if self.bar is not None:
            self.bar.update(t - self.t_last)
            self.bar.set_postfix(events=n_events, refresh=False)
            self.t_last = t

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


class _SignalFlag:
    """Turns SIGINT/SIGTERM into a flag checked between chunks (main thread only)."""

    def __init__(self, enabled: bool):
        self.set = False
        self.enabled = enabled and _in_main_thread()
        self.previous: dict[int, Any] = {}

    def __enter__(self):
        if self.enabled:
            for sig in (signal.SIGINT, signal.SIGTERM):
                self.previous[sig] = signal.signal(sig, self._handler)
        return self

    def _handler(self, signum, frame):
        self.set = True

    def __exit__(self, *exc):
        for sig, handler in self.previous.items():
            signal.signal(sig, handler)
        return False


def _in_main_thread() -> bool:
    import threading

    return threading.current_thread() is threading.main_thread()


def _finite(state: ChainState) -> bool:
    return bool(np.isfinite(state.x).all() and np.isfinite(state.v).all() and np.isfinite(state.th).all())


def _par(p: ChainParams) -> np.ndarray:
    par = np.zeros(K.PAR_SIZE)
    par[K.P_K], par[K.P_D], par[K.P_V] = p.K, p.D, p.V
    par[K.P_BETA], par[K.P_ALPHA], par[K.P_FS], par[K.P_DT] = p.beta, p.alpha, p.Fs, p.dt
    return par


def _check_state(state: ChainState, p: ChainParams) -> None:
    if state.N != p.N:
        raise ParameterError(f"initial state has {state.N} blocks but N = {p.N}")


def run_chain(
    params: ChainParams,
    t_end: float,
    *,
    integrator: str = "exact",
    start: str | ChainState = "paper",
    perturbation: float = 0.0,
    seed: int = 0,
    sample_interval: float = 10.0,
    average_from: float | None = None,
    snapshot_times: Sequence[float] = (),
    profile_window: float | None = None,
    profile_min_blocks: int = 0,
    until_steady: float | None = None,
    out_dir: str | Path | None = None,
    checkpoint_interval: float | None = None,
    progress: bool = False,
    handle_signals: bool = False,
) -> ChainRun:
    """Integrate the chain of eq. (4) from ``start`` to ``t_end`` (MODEL.md, "Chain").

    ``integrator`` is 'exact' (default) or 'dense'; both give the same result bit for bit.
    ``start`` is 'paper' (x = 0, v = 0.1, theta = 0.1, all moving), 'steady' (exact steady
    sliding, optionally perturbed by ``perturbation`` with ``seed``) or a :class:`ChainState`.
    With ``until_steady`` = TOL the run stops at the first sampling time at which every block
    slides within TOL of steady sliding; L is then taken from the steady solution up to t_end.
    With ``out_dir``, checkpoints are written there every ``checkpoint_interval`` wall-clock
    seconds and on SIGINT/SIGTERM (``handle_signals``), and the results at the end.
    """
    if integrator not in INTEGRATORS:
        raise ParameterError(f"integrator must be one of {', '.join(INTEGRATORS)} (got {integrator!r})")
    options = RunOptions(
        t_end=float(check_number("t_end", t_end, low=0.0)),
        sample_interval=sample_interval,
        average_from=average_from,
        snapshot_times=tuple(float(t) for t in snapshot_times),
        profile_window=profile_window,
        profile_min_blocks=int(profile_min_blocks),
        until_steady=until_steady,
    ).validated(params.dt)
    if checkpoint_interval is not None:
        check_number("checkpoint_interval", checkpoint_interval, low=0.0, low_open=True)
    check_number("perturbation", perturbation, low=0.0)
    if isinstance(start, ChainState):
        state = start.copy()
        _check_state(state, params)
        start_info: dict[str, Any] = {"kind": "state", "sha256": start.sha256()}
    else:
        state = initial_state(params, start, amplitude=perturbation, seed=seed)
        start_info = {"kind": start, "perturbation": perturbation, "seed": seed}
    state.ist[K.NEXT_SAMPLE] = state.step
    outputs = _Outputs(params.N, options.profile_window is not None)
    return _drive(params, options, integrator, start_info, state, outputs,
                  out_dir=out_dir, checkpointer=Checkpointer(Path(out_dir)) if out_dir else None,
                  checkpoint_interval=checkpoint_interval, progress=progress,
                  handle_signals=handle_signals, wall_before=0.0)


def resume_chain(
    run_dir: str | Path,
    *,
    t_end: float | None = None,
    checkpoint_interval: float | None = None,
    progress: bool = False,
    handle_signals: bool = False,
    expect_params: ChainParams | None = None,
) -> ChainRun:
    """Continue the run in ``run_dir`` from its checkpoint to its t_end (or a later ``t_end``).

    A corrupt checkpoint, one of another format, or one whose parameters differ from
    ``expect_params`` is refused with :class:`ChainRunError`.
    """
    run_dir = Path(run_dir)
    ckpt = Checkpointer(run_dir)
    state, header, parts = ckpt.load()
    try:
        params = ChainParams(**header["params"])
        options = RunOptions.from_dict(header["options"])
        integrator = header["integrator"]
    except (KeyError, TypeError, ParameterError) as exc:
        raise ChainRunError(f"checkpoint in {run_dir} has an unusable header ({exc})") from None
    if expect_params is not None and expect_params != params:
        raise ChainRunError(
            f"checkpoint in {run_dir} was made with other parameters: {params.to_dict()} != {expect_params.to_dict()}"
        )
    if t_end is not None:
        t_end = float(check_number("t_end", t_end, low=0.0))
        if steps_for(t_end, params.dt) < state.step:
            raise ParameterError(f"t_end must be >= the checkpoint's time {state.step * params.dt:g} (got {t_end:g})")
        options = RunOptions(**{**options.__dict__, "t_end": t_end})
    outputs = _Outputs(params.N, options.profile_window is not None)
    outputs.parts = parts
    ckpt.since = {k: len(v) for k, v in parts.items()}
    return _drive(params, options, integrator, header["start"], state, outputs, out_dir=run_dir,
                  checkpointer=ckpt, checkpoint_interval=checkpoint_interval, progress=progress,
                  handle_signals=handle_signals, wall_before=float(header.get("wall_seconds", 0.0)))


def _drive(params, options, integrator, start_info, state, outputs, *, out_dir, checkpointer,
           checkpoint_interval, progress, handle_signals, wall_before) -> ChainRun:
    kernel = _KERNELS[integrator]
    par = _par(params)
    N = params.N
    scratch = [np.zeros(N + 2) for _ in range(6)]
    n_end = steps_for(options.t_end, params.dt)
    sample_every = int(round(options.sample_interval / params.dt))
    profile_every = int(round(options.profile_window / params.dt)) if options.profile_window else 0
    stops = sorted({steps_for(t, params.dt) for t in options.snapshot_times} | {n_end})
    done_snaps = set(int(s) for a in outputs.parts["snap_step"] for s in a)
    steady_at: dict[str, float] = {}
    header = {
        "params": params.to_dict(), "options": options.to_dict(), "integrator": integrator,
        "start": start_info,
    }
    bar = _Progress(options.t_end, progress and sys.stderr.isatty())
    t0 = time.perf_counter()
    last_ckpt = t0
    chunk = 200_000
    if out_dir is not None:
        Path(out_dir).mkdir(parents=True, exist_ok=True)
    with _SignalFlag(handle_signals) as flag:
        try:
            while True:
                n = state.step
                if n in stops and n not in done_snaps and n != n_end:
                    outputs.add_snapshot(n, state.x)
                    done_snaps.add(n)
                if options.until_steady is not None and n % sample_every == 0:
                    dev = steady_deviation(state, params)
                    if dev <= options.until_steady:
                        steady_at = {"t_steady": n * params.dt, "deviation": dev}
                        break
                next_stop = min((s for s in stops if s > n), default=n_end)
                if options.until_steady is not None:
                    # Check on a fixed grid of steps, so the stop does not depend on timing.
                    next_stop = min(next_stop, (n // sample_every + 1) * sample_every)
                if n >= n_end:
                    # One more call services outputs due at the final step (its sample).
                    status = kernel(state.x, state.v, state.th, state.mov, *scratch, state.first_step,
                                    state.x0ev, state.ist, par, *outputs.kernel_args(), n_end,
                                    sample_every, profile_every, options.profile_min_blocks)
                    if status != K.DONE and status != K.NONFINITE:
                        outputs.flush(state.ist)
                        continue
                    break
                target = min(next_stop, n + chunk)
                before = state.copy() if integrator == "exact" else None
                c0 = time.perf_counter()
                status = kernel(state.x, state.v, state.th, state.mov, *scratch, state.first_step,
                                state.x0ev, state.ist, par, *outputs.kernel_args(), target,
                                sample_every, profile_every, options.profile_min_blocks)
                elapsed = time.perf_counter() - c0
                if before is not None and not _finite(state):
                    # The fast kernel does not look for non-finite values; replay this call
                    # with the reference, which follows the same arithmetic and checks each step.
                    state = before
                    status = K.run_dense(state.x, state.v, state.th, state.mov, *scratch, state.first_step,
                                         state.x0ev, state.ist, par, *outputs.kernel_args(), target,
                                         sample_every, profile_every, options.profile_min_blocks)
                if status == K.NONFINITE:
                    bad = int(state.ist[K.BAD_BLOCK])
                    raise NonFiniteState(
                        f"state became non-finite at t = {state.step * params.dt:.6g} (step {state.step}) "
                        f"in block {bad}"
                    )
                if status != K.DONE:
                    outputs.flush(state.ist)
                # Aim at about a quarter second per call: responsive to signals and progress.
                if status == K.DONE and elapsed > 0:
                    chunk = int(min(max(chunk * 0.25 / elapsed, 10_000), 50_000_000))
                now = time.perf_counter()
                bar.update(state.step * params.dt, int(state.ist[K.N_EVENTS]))
                if checkpointer is not None and (
                    flag.set or (checkpoint_interval is not None and now - last_ckpt >= checkpoint_interval)
                ):
                    outputs.flush(state.ist)
                    checkpointer.write(state, outputs, dict(header, wall_seconds=wall_before + now - t0))
                    last_ckpt = now
                if flag.set:
                    raise Interrupted(checkpointer.state_path if checkpointer else None, state.step * params.dt)
        finally:
            bar.close()
    outputs.flush(state.ist)
    wall = wall_before + time.perf_counter() - t0
    run = _assemble(params, options, integrator, start_info, state, outputs, wall, steady_at)
    if out_dir is not None:
        if checkpointer is not None:
            checkpointer.write(state, outputs, dict(header, wall_seconds=wall))
        write_run(run, out_dir)
    return run


# --------------------------------------------------------------------------------------
# Results


def _assemble(params, options, integrator, start_info, state, outputs, wall, steady_at=None) -> ChainRun:
    dt = params.dt
    parts = outputs.all()
    ev = parts["ev_int"]
    events = pd.DataFrame({
        "event": ev[:, K.E_ID],
        "step_start": ev[:, K.E_START_STEP],
        "step_end": ev[:, K.E_END_STEP],
        "t_start": ev[:, K.E_START_STEP] * dt,
        "t_end": (ev[:, K.E_END_STEP] + 1) * dt,
        "duration": (ev[:, K.E_END_STEP] + 1 - ev[:, K.E_START_STEP]) * dt,
        "S": parts["ev_S"],
        "start_block": ev[:, K.E_START_BLOCK],
        "max_block": ev[:, K.E_MAX_BLOCK],
        "n_blocks": ev[:, K.E_N_BLOCKS],
    }, columns=EVENT_COLUMNS)
    fm = parts["fm"]
    first_move = pd.DataFrame({"event": fm[:, 0], "block": fm[:, 1], "step": fm[:, 2], "t_first": fm[:, 2] * dt})
    t_samples = parts["samp_step"] * dt
    samples = xr.Dataset(
        {"L": ("t", parts["samp_L"], {"long_name": "total length x_1 - x_N"})},
        coords={"t": ("t", t_samples, {"units": "model time"})},
    )
    blocks = np.arange(1, params.N + 1)
    snap_steps = list(parts["snap_step"]) + [state.step]
    snap_x = np.vstack([parts["snap_x"].reshape(-1, params.N), state.x[1:-1][None, :]])
    order = np.argsort(snap_steps, kind="stable")
    snapshots = xr.DataArray(
        snap_x[order], dims=("time", "block"),
        coords={"time": np.asarray(snap_steps)[order] * dt, "block": blocks}, name="x",
        attrs={"long_name": "block positions x_i"},
    )
    profiles = _profiles(parts, events, options, params)
    L_final = float(state.x[1] - state.x[-2])
    avg_from = options.average_from if options.average_from is not None else options.t_end / 2
    sel = t_samples >= avg_from - 0.5 * dt
    L_values = parts["samp_L"][sel]
    early: dict[str, Any] = {"stopped_early": False}
    if steady_at:
        # From the stop on, the chain is taken to slide steadily: L = L_ss at the remaining samples.
        L_ss = physics.chain_steady_length(params)
        sample_every = int(round(options.sample_interval / dt))
        n_end = steps_for(options.t_end, dt)
        later = np.arange((state.step // sample_every + 1) * sample_every, n_end + 1, sample_every) * dt
        n_virtual = int(np.count_nonzero(later >= avg_from - 0.5 * dt))
        L_values = np.concatenate([L_values, np.full(n_virtual, L_ss)])
        L_final = L_ss
        early = {
            "stopped_early": True,
            "reason": (f"steady sliding reached at t = {steady_at['t_steady']:g}: every block slides "
                       f"within {options.until_steady:g} of the steady state (deviation "
                       f"{steady_at['deviation']:.3g}); L taken from the steady solution from then on"),
            "t_steady": steady_at["t_steady"],
            "steady_deviation": steady_at["deviation"],
            "until_steady": options.until_steady,
            "L_final_simulated": float(state.x[1] - state.x[-2]),
        }
    L_mean = float(np.mean(L_values)) if len(L_values) else float("nan")
    summary = {
        "n_events": int(len(events)),
        "event_in_progress": bool(state.ist[K.EV_ACTIVE]),
        "L_final": L_final,
        "L_mean": L_mean,
        "L_mean_from": avg_from,
        "L_steady": physics.chain_steady_length(params),
        "t_end": options.t_end if steady_at else state.step * dt,
        "t_reached": state.step * dt,
        "steps": state.step,
        "steps_computed": int(state.ist[K.STEPS_COMPUTED]),
        "block_updates": int(state.ist[K.BLOCK_UPDATES]),
        "full_block_updates": int(state.ist[K.FULL_UPDATES]) if integrator == "exact" else int(state.ist[K.BLOCK_UPDATES]),
        "n_moving": int(state.ist[K.N_MOVING]),
        "wall_seconds": wall,
        "integrator": integrator,
        "state_sha256": state.sha256(),
        **early,
    }
    return ChainRun(params, options, integrator, start_info, state, events, first_move, samples,
                    snapshots, profiles, summary)


def _profiles(parts, events, options, params) -> xr.Dataset:
    """Displacements dx_i = x_i(t + W) - x_i(t) over the stored windows of each event (Fig. 6)."""
    px, pm = parts["prof_x"].reshape(-1, params.N), parts["prof_meta"]
    keep_ids = set(events.loc[events["n_blocks"] >= options.profile_min_blocks, "event"].tolist())
    rows_dx, rows_ev, rows_t0, rows_t1 = [], [], [], []
    for eid in sorted(set(pm[:, 0].tolist()) & keep_ids) if len(pm) else []:
        idx = np.flatnonzero(pm[:, 0] == eid)
        idx = idx[np.argsort(pm[idx, 1], kind="stable")]
        for a, b in zip(idx[:-1], idx[1:]):
            rows_dx.append(px[b] - px[a])
            rows_ev.append(eid)
            rows_t0.append(pm[a, 1] * params.dt)
            rows_t1.append(pm[b, 1] * params.dt)
    dx = np.array(rows_dx).reshape(-1, params.N)
    return xr.Dataset(
        {"dx": (("row", "block"), dx, {"long_name": "displacement over the window"})},
        coords={
            "event": ("row", np.array(rows_ev, dtype=np.int64)),
            "t": ("row", np.array(rows_t0, dtype=np.float64)),
            "t_next": ("row", np.array(rows_t1, dtype=np.float64)),
            "block": np.arange(1, params.N + 1),
        },
        attrs={"window": options.profile_window if options.profile_window else 0.0},
    )


def write_run(run: ChainRun, out_dir: str | Path) -> Path:
    """Write a run directory: run.json, state.nc (labelled arrays), events.parquet, first_move.parquet."""
    from stickslip import io

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    blocks = run.snapshots["block"].values
    b = run.state.blocks()
    ds = xr.Dataset(
        {
            "x": ("block", b["x"]), "v": ("block", b["v"]), "theta": ("block", b["theta"]),
            "stopped": ("block", b["stopped"].astype(np.int8)),
            "L": run.samples["L"].rename({"t": "t_sample"}),
            "snapshot_x": run.snapshots.rename({"time": "snapshot_time"}),
            "profile_dx": run.profiles["dx"].rename({"row": "profile_row"}),
            "profile_event": ("profile_row", run.profiles["event"].values),
            "profile_t": ("profile_row", run.profiles["t"].values),
            "profile_t_next": ("profile_row", run.profiles["t_next"].values),
        },
        coords={"block": blocks},
        attrs={"params": json.dumps(run.params.to_dict()), "integrator": run.integrator,
               "version": __version__, "t": run.summary["t_end"]},
    )
    ds = ds.drop_vars([c for c in ("event", "t_next") if c in ds.coords], errors="ignore")
    io.write_dataset(out / "state.nc", ds)
    io.write_table(out / "events.parquet", run.events)
    io.write_table(out / "first_move.parquet", run.first_move)
    meta = io.run_metadata(run.params, integrator=run.integrator, options=run.options.to_dict(),
                           start=run.start, summary=run.summary)
    io.write_json(out / "run.json", meta)
    return out


def load_run(run_dir: str | Path) -> ChainRun:
    """Read a run directory written by :func:`write_run` back into a :class:`ChainRun`."""
    from stickslip import io

    run_dir = Path(run_dir)
    meta = io.read_json(run_dir / "run.json")
    ds = io.read_dataset(run_dir / "state.nc")
    params = ChainParams(**meta["params"])
    state = ChainState.from_blocks(ds["x"].values, ds["v"].values, ds["theta"].values,
                                   ds["stopped"].values.astype(bool))
    state.ist[K.STEP] = int(meta["summary"]["steps"])
    samples = xr.Dataset({"L": ("t", ds["L"].values)}, coords={"t": ds["t_sample"].values})
    snapshots = ds["snapshot_x"].rename({"snapshot_time": "time"}).rename("x")
    profiles = xr.Dataset(
        {"dx": (("row", "block"), ds["profile_dx"].values)},
        coords={"event": ("row", ds["profile_event"].values), "t": ("row", ds["profile_t"].values),
                "t_next": ("row", ds["profile_t_next"].values), "block": ds["block"].values},
    )
    return ChainRun(params, RunOptions.from_dict(meta["options"]), meta["integrator"], meta["start"], state,
                    io.read_table(run_dir / "events.parquet"), io.read_table(run_dir / "first_move.parquet"),
                    samples, snapshots, profiles, meta["summary"])
