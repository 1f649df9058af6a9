"""The state of the chain of eq. (4): :class:`ChainState`, the initial states, the distance from steady sliding.

The arrays carry ghost cells at index 0 and N + 1 (see :mod:`stickslip.kernels.layout`); the
initial states are the paper's (section 3) and exact discrete steady sliding (docs/model.md).
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from stickslip.kernels import layout
from stickslip.models import physics
from stickslip.models.params import MAX_PERTURBATION, ChainParams, ParameterError, check_number

STARTS = ("paper", "steady", "rest")


#: Bytes of a cache line: the exact path's vector loops run fastest from a line's start.
LINE = 64


def line_aligned(a: np.ndarray) -> np.ndarray:
    """A copy of the 1-d array ``a`` whose element 1 (block 1, after the ghost cell) starts a
    64-byte line, so that the exact path's vector loads and stores over a run of blocks from block
    1 do not straddle lines (docs/performance.md, "The run's bounds per run, and aligned arrays").
    The values are copied exactly."""
    a = np.asarray(a)
    per_line = LINE // a.itemsize
    buf = np.empty(a.size + per_line, dtype=a.dtype)
    off = (-(buf.ctypes.data + a.itemsize)) % LINE // a.itemsize
    out = buf[off : off + a.size]
    out[...] = a
    return out


@dataclass
class ChainState:
    """Everything the kernels need to continue a run.

    The public arrays hold the N blocks, block i at index i - 1: :attr:`x`, :attr:`v` and
    :attr:`theta` (views: ``run.state.v.mean()`` is the blocks' mean velocity), as
    :meth:`blocks` copies them. The kernels' arrays carry ghost cells at index 0 and N + 1 (see
    kernels) and are the fields: xg, vg, thg, mov: positions, velocities, state variables and
    moving mask (1.0/0.0) of blocks 1..N at index 1..N; first_step, x0ev: per-block bookkeeping
    of the event in progress; ist: the integer state vector (step count, event bookkeeping,
    active range); model: the model the state belongs to (:func:`model_of` its parameters),
    None when unknown (a state built from blocks).
    """

    xg: np.ndarray
    vg: np.ndarray
    thg: np.ndarray
    mov: np.ndarray
    first_step: np.ndarray
    x0ev: np.ndarray
    ist: np.ndarray
    model: dict[str, str] | None = None

    #: The arrays as files name them (checkpoints, state files), in order.
    ARRAYS = ("x", "v", "th", "mov", "first_step", "x0ev", "ist")
    #: The field holding each array of :data:`ARRAYS` (with its ghost cells).
    FIELDS = {"x": "xg", "v": "vg", "th": "thg"}

    def __post_init__(self):
        # The kernels' float arrays with block 1 at a line's start, wherever they came from.
        for name in ("xg", "vg", "thg", "mov"):
            a = getattr(self, name)
            if isinstance(a, np.ndarray) and a.ndim == 1 and a.dtype == np.float64:
                if (a.ctypes.data + a.itemsize) % LINE or not a.flags.c_contiguous:
                    setattr(self, name, line_aligned(a))

    @property
    def x(self) -> np.ndarray:
        """x_1..x_N (a view of the blocks, no ghost cells)."""
        return self.xg[1:-1]

    @property
    def v(self) -> np.ndarray:
        """v_1..v_N (a view of the blocks, no ghost cells)."""
        return self.vg[1:-1]

    @property
    def theta(self) -> np.ndarray:
        """theta_1..theta_N (a view of the blocks, no ghost cells)."""
        return self.thg[1:-1]

    def arrays(self) -> dict[str, np.ndarray]:
        """Every array by its name in :data:`ARRAYS` (the kernels' arrays, ghost cells included)."""
        return {k: getattr(self, self.FIELDS.get(k, k)) for k in self.ARRAYS}

    @classmethod
    def from_arrays(cls, arrays: dict[str, np.ndarray], model: dict[str, str] | None = None) -> ChainState:
        """A state from copies of the arrays named as :meth:`arrays` names them."""
        return cls(**{cls.FIELDS.get(k, k): np.array(arrays[k], copy=True) for k in cls.ARRAYS}, model=model)

    @property
    def N(self) -> int:
        return self.xg.shape[0] - 2

    @property
    def step(self) -> int:
        return int(self.ist[layout.STEP])

    @classmethod
    def from_blocks(cls, x, v, theta, stopped) -> ChainState:
        """Build a state from per-block arrays (length N) of x, v, theta and stopped flags."""
        x = np.asarray(x, dtype=np.float64)
        N = x.shape[0]
        shapes = {name: np.shape(a) for name, a in (("x", x), ("v", v), ("theta", theta), ("stopped", stopped))}
        if x.ndim != 1 or any(shape != (N,) for shape in shapes.values()):
            raise ValueError(f"the per-block arrays differ in shape: {shapes}")
        arrays = {}
        for name, values in (("xg", x), ("vg", v), ("thg", theta)):
            a = np.zeros(N + 2)
            # Adding 0.0 turns -0.0 into +0.0, so "changed" (a float compare) sees every bit.
            a[1:-1] = np.asarray(values, dtype=np.float64) + 0.0
            arrays[name] = a
        stopped = np.asarray(stopped, dtype=bool)
        mov = np.zeros(N + 2)
        mov[1:-1] = np.where(stopped, 0.0, 1.0)
        arrays["vg"][1:-1] = np.where(stopped, 0.0, arrays["vg"][1:-1])
        ist = np.zeros(layout.IST_SIZE, dtype=np.int64)
        ist[layout.N_MOVING] = int(np.count_nonzero(~stopped))
        ist[layout.ACT_LO], ist[layout.ACT_HI] = 1, N
        ist[layout.MECH_LO], ist[layout.MECH_HI] = 1, N
        return cls(
            first_step=np.full(N + 2, -1, dtype=np.int64),
            x0ev=np.zeros(N + 2),
            mov=mov,
            ist=ist,
            **arrays,
        )

    @classmethod
    def paper(cls, p: ChainParams) -> ChainState:
        """The paper's initial state (section 3): x_i = 0, v_i = 0.1, theta_i = 0.1, all moving."""
        N = p.N
        theta = np.full(N, p.friction_piece.start_theta(p))
        return cls.from_blocks(np.zeros(N), np.full(N, 0.1), theta, np.zeros(N, bool)).of(p)

    @classmethod
    def steady(cls, p: ChainParams, amplitude: float = 0.0, seed: int = 0) -> ChainState:
        """Exact discrete steady sliding (docs/model.md) at t = 0, all blocks moving.

        With ``amplitude`` > 0, x_i and v_i get independent uniform perturbations in
        [-amplitude, amplitude] drawn from numpy's default generator with ``seed``.
        """
        try:
            s = physics.chain_steady_state(p, 0.0)
        except physics.NoClosedForm as e:
            raise ParameterError(f"start must be paper or rest for this chain: {e}") from None
        state = cls.from_blocks(s["x"].copy(), s["v"].copy(), s["theta"], np.zeros(p.N, bool)).of(p)
        return state.perturbed(amplitude, seed)

    def perturbed(self, amplitude: float, seed: int) -> ChainState:
        """A copy with x_i and v_i of every moving block shifted by independent uniform numbers in
        [-amplitude, amplitude] (numpy's default generator with ``seed``: N numbers for x, then N
        for v), as :meth:`steady` perturbs steady sliding and the transition study's down ladder
        each hand-over."""
        s = self.copy()
        if amplitude > 0:
            rng = np.random.default_rng(seed)
            moving = s.mov[1:-1] != 0.0
            s.xg[1:-1] += np.where(moving, rng.uniform(-amplitude, amplitude, s.N), 0.0)
            s.vg[1:-1] += np.where(moving, rng.uniform(-amplitude, amplitude, s.N), 0.0)
        return s

    @classmethod
    def rest(cls, p: ChainParams, amplitude: float = 0.01, seed: int = 0) -> ChainState:
        """Every block stuck: v_i = 0, x_i = -A u_i with u_i = ``default_rng(seed).random(N)``
        (Carlson-Langer's start, docs/model.md), theta_i = 0.1 (the paper's) for state friction."""
        x = -amplitude * np.random.default_rng(seed).random(p.N) if amplitude > 0 else np.zeros(p.N)
        theta = np.full(p.N, p.friction_piece.start_theta(p))
        return cls.from_blocks(x, np.zeros(p.N), theta, np.ones(p.N, bool)).of(p)

    def of(self, p: ChainParams) -> ChainState:
        """This state, marked as one of the model of the parameters ``p`` (:func:`model_of`)."""
        self.model = model_of(p)
        return self

    def blocks(self) -> dict[str, np.ndarray]:
        """Per-block copies: x, v, theta (float64) and stopped (bool), block i at index i - 1."""
        return {
            "x": self.x.copy(),
            "v": self.v.copy(),
            "theta": self.theta.copy(),
            "stopped": self.mov[1:-1] == 0.0,
        }

    def sha256(self) -> str:
        """SHA-256 of x, v, theta (float64 little-endian, block order) then stopped (1 byte each)."""
        h = hashlib.sha256()
        for a in (self.x, self.v, self.theta):
            h.update(np.ascontiguousarray(a, dtype="<f8").tobytes())
        h.update((self.mov[1:-1] == 0.0).astype(np.uint8).tobytes())
        return h.hexdigest()

    def copy(self) -> ChainState:
        return ChainState.from_arrays(self.arrays(), model=self.model)

    def restore(self, saved: ChainState) -> None:
        """Put the values of ``saved`` (a :meth:`copy` of this state) back into this state's
        arrays, in place: whatever holds these arrays sees the restored values."""
        for name in self.ARRAYS:
            field = self.FIELDS.get(name, name)
            np.copyto(getattr(self, field), getattr(saved, field))
        self.model = saved.model


def model_of(p: ChainParams) -> dict[str, str]:
    """The model a state of the parameters ``p`` belongs to: the preset's name and the four pieces
    (docs/model.md), which decide what x, v and theta mean."""
    return {"model": p.model, **p.pieces}


def check_start_draw(start: str, perturbation: Any, seed: Any, *, cli: bool = False) -> None:
    """Refuse a perturbation or a seed (None: not given) with a start that draws no numbers (the
    paper's, section 3): the one check that ``run_chain`` and ``stickslip chain`` share. ``cli``
    spells the options (``--perturbation``, ``--start steady``) instead of the arguments."""
    if start != "paper":
        return
    if cli:
        steady, rest, amplitude, seed_name = "--start steady", "--start rest", "--perturbation", "--seed"
    else:
        steady, rest, amplitude, seed_name = "start='steady'", "start='rest'", "perturbation", "seed"
    if perturbation is not None:
        raise ParameterError(f"{amplitude} goes with {steady} or {rest} (the paper's start has none)")
    if seed is not None:
        raise ParameterError(f"{seed_name} goes with {steady} or {rest} (the paper's start draws no numbers)")


def initial_state(p: ChainParams, start: str = "paper", *, amplitude: float = 0.0, seed: int = 0) -> ChainState:
    """The initial state named by ``start``: 'paper' (section 3), 'steady' (docs/model.md) or 'rest'
    (every block stuck, x_i = -A u_i: Carlson-Langer's start, docs/model.md)."""
    amplitude = check_number("perturbation", amplitude, low=0.0, high=MAX_PERTURBATION)
    if start == "paper":
        state = ChainState.paper(p)
    elif start == "steady":
        state = ChainState.steady(p, amplitude, seed)
    elif start == "rest":
        state = ChainState.rest(p, amplitude, seed)
    else:
        raise ParameterError(f"start must be one of {', '.join(STARTS)} (got {start!r})")
    problem = first_step_problem(state, p)
    if problem is not None:
        raise ParameterError(f"start {start}: {problem}{_remedy(p, start)}")
    return state


def first_step_problem(state: ChainState, p: ChainParams) -> str | None:
    """Why the first step of Heun (docs/model.md) from ``state`` would make the friction law
    non-finite, or None.

    The law's dtheta/dt (its ``rate``, read in plain Python) at each moving block gives Heun's
    predictor theta + dt rate and the corrected theta + dt (rate + rate') / 2 at the block's
    velocity; where the law's force or rate is not finite at either, the run would die of a
    non-finite state at step 1. A start far from the law's steady sliding does that: Ruina's slip
    law at the paper's v = 0.1 has v theta / D_c = 100, and one step of dt = 0.005 sends theta
    below 0, where ln theta is not defined.
    """
    import importlib
    import types

    law = p.friction_piece
    if not law.has_state:
        return None
    module = importlib.import_module(law.module)
    rate, accel = module.rate.py_func, module.accel.py_func
    lp = law.kernel_params(p)
    low = law.theta_range[0] if law.theta_range is not None else -math.inf
    # A law that reads the stress rate (PIECE.context) is read here without it: the check looks
    # at its own terms in theta and v.
    ctx = (types.SimpleNamespace(**dict.fromkeys(law.context, 0.0)),) if law.context else ()

    def rate_at(i: int, th_i: float) -> float:
        """dtheta/dt of block i at theta th_i, NaN where the law is not finite there."""
        try:
            lpi = type(lp)(*(f[i] if np.ndim(f) == 1 else f for f in lp))  # per-block values at block i
            r = float(rate(th[i - 1], th_i, th[i + 1], v[i], lpi, *ctx))
            force = float(accel(0.0, v[i], th_i, lpi))
        except (ValueError, ZeroDivisionError, OverflowError):  # math.log of a negative theta
            return math.nan
        return r if math.isfinite(r) and math.isfinite(force) else math.nan

    th, v = state.thg, state.vg
    seen = set()
    for i in range(1, p.N + 1):
        key = (th[i - 1], th[i], th[i + 1], v[i])
        if state.mov[i] == 0.0 or key in seen:  # the named starts repeat one block N times
            continue
        seen.add(key)
        r = rate_at(i, th[i])
        pred = th[i] + p.dt * r
        corrected = th[i] + 0.5 * p.dt * (r + rate_at(i, pred))
        if math.isfinite(corrected) and math.isfinite(rate_at(i, corrected)):
            continue
        step = f"dt below {0.5 * (th[i] - low) / abs(r):.2g}" if r < 0 and th[i] > low else "a smaller dt"
        return (
            f"in the first step of dt = {p.dt:g} theta of block {i} goes from {th[i]:.3g} to {pred:.3g} "
            f"(dtheta/dt {r:.3g} at v = {v[i]:.3g}), where friction {p.friction} is not finite: the run "
            f"would become non-finite at once; {step}"
        )
    return None


def _remedy(p: ChainParams, start: str) -> str:
    """What to do instead of a start whose first step fails: steady sliding, where the law's theta
    rests, when the chain has it; else only a smaller dt (said by :func:`first_step_problem`)."""
    if start != "steady" and physics.has_steady_state(p):
        return (
            " (dt=... in Python, --dt on the command line), or start from steady sliding "
            "(start='steady', --start steady)"
        )
    return " (dt=... in Python, --dt on the command line)"


def closed_form(fn, p: ChainParams, *args):
    """``fn(p, *args)``, a closed form of :mod:`stickslip.models.physics`; NaN where the chain's
    per-block parameters leave it without one (:class:`~stickslip.models.physics.NoClosedForm`,
    docs/model.md, "Per-block parameters")."""
    try:
        return fn(p, *args)
    except physics.NoClosedForm:
        return float("nan")


def steady_deviation(state: ChainState, p: ChainParams) -> float:
    """Distance of a state from steady sliding of the chain (docs/model.md), in the frame moving with V.

    The largest of ``|v_i - V|``, ``|theta_i - theta_0|`` and ``|e_i - e_i^ss|`` over all blocks, where
    e_i = x_{i-1} - x_i are the spring extensions (x_0 = V t_n, or the ends' ghost cell under a
    force drive) and e_i^ss those of steady sliding ((c/K)(N - i + 1) for eq. 4); with the plate
    drive the positions against the plate's. Infinite unless every block is moving.
    """
    if np.any(state.mov[1:-1] == 0.0) or not physics.has_steady_state(p):
        return float("inf")
    if p.per_block():
        value = closed_form(lambda q: _deviation(state, q), p)
        return value if np.isfinite(value) else float("inf")
    return _deviation(state, p)


def _deviation(state: ChainState, p: ChainParams) -> float:
    """:func:`steady_deviation` of a chain that slides (the steady state's closed form)."""
    ss = physics.steady_reference(p)
    if ss["pinned"]:
        # Every block lags the plate by c / Kp: compare positions in the plate's frame.
        ss = physics.chain_steady_state(p, float(np.float64(state.step) * p.dt))
        return float(max(np.max(np.abs(state.v - ss["v"])), np.max(np.abs(state.x - ss["x"]))))
    x = state.x
    # x_0: the pulling point V t_n (end drive) or the ends' ghost cell (a force drive), as the kernels set it.
    x0 = physics.left_ghost(p, p.V * (np.float64(state.step) * p.dt), x[0], x[-1])
    ext = np.diff(np.concatenate(([x0], x))) * -1.0
    return float(
        max(
            np.max(np.abs(state.v - ss["v"])),
            np.max(np.abs(state.theta - ss["theta"])),
            np.max(np.abs(ext - ss["ext"])),
        )
    )


def loading_warnings(
    p: ChainParams, t_end: float, average_from: float | None = None, start: str = "paper"
) -> list[str]:
    """Why a run of the end-driven chain (eq. 4) is too short to show its stick-slip state, if it is.

    From a start with x_i = 0 ('paper', 'rest') the chain loads until t ~ L_ss / V
    (:func:`stickslip.models.physics.loading_time`). One message if the run ends before that, one if
    the <L> average (from ``average_from``, default t_end / 2) starts before it; none otherwise.
    """
    t_load = closed_form(physics.loading_time, p)
    if start not in ("paper", "rest") or not np.isfinite(t_load):
        return []
    where = (
        f"from x_i = 0 the chain of N = {p.N} loads until t ~ L_ss / V = {t_load:.3g} "
        f"(L_ss = {physics.chain_steady_length(p):.4g}, V = {p.V:g})"
    )
    if t_end < t_load:
        return [
            f"{where}; this run ends at t = {t_end:.3g} and shows only the loading: "
            f"use a t_end of a few times {t_load:.3g}, or fewer blocks"
        ]
    t_avg = t_end / 2.0 if average_from is None else average_from
    if t_avg < t_load:
        return [
            f"{where}; <L> averages from t = {t_avg:.3g}, before the chain has loaded: "
            f"average from t >= {t_load:.3g} (average_from) and run to well beyond it"
        ]
    return []
