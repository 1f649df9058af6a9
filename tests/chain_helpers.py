"""Shared pieces of the chain tests: an independent plain-Python Heun step of eq. (4) with
its slip events (docs/model.md), bitwise comparison of two chain runs, and the command line."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from stickslip.kernels import layout

# Integer state entries that describe the model (not how much work an integrator did).
IST_MODEL = {
    "STEP": layout.STEP, "N_MOVING": layout.N_MOVING, "EV_ACTIVE": layout.EV_ACTIVE,
    "EV_START_STEP": layout.EV_START_STEP, "EV_START_BLOCK": layout.EV_START_BLOCK,
    "EV_MAX_BLOCK": layout.EV_MAX_BLOCK, "EV_N_MOVED": layout.EV_N_MOVED, "N_EVENTS": layout.N_EVENTS,
    "NEXT_SAMPLE": layout.NEXT_SAMPLE, "NEXT_PROFILE": layout.NEXT_PROFILE,
}  # fmt: skip

# Summary entries that depend on the integrator or the machine, not on the model.
SUMMARY_WORK = {"wall_seconds", "steps_computed", "block_updates", "full_block_updates", "integrator"}


def _is_work(key: str) -> bool:
    return key in SUMMARY_WORK or key.endswith("_updates") or key.startswith("wall")


def bits(a) -> np.ndarray:
    """The float64 bit patterns of ``a`` (so that -0.0 != 0.0 and NaN == NaN when equal)."""
    return np.ascontiguousarray(np.asarray(a, dtype=np.float64)).view(np.uint64)


def assert_bits_equal(a, b, what: str) -> None:
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape, f"{what}: shapes {a.shape} != {b.shape}"
    if a.dtype.kind == "f" or b.dtype.kind == "f":
        diff = np.flatnonzero(bits(a).ravel() != bits(b).ravel())
    else:
        diff = np.flatnonzero(a.ravel() != b.ravel())
    assert diff.size == 0, f"{what}: {diff.size} entries differ, first at flat index {diff[0]}"


def assert_same_state(a, b, skip: tuple[str, ...] = ()) -> None:
    """Two ChainStates hold the same model state bit for bit (ghost cells excluded)."""
    assert a.sha256() == b.sha256()
    for name in ("x", "v", "th", "mov", "first_step", "x0ev"):
        assert_bits_equal(a.arrays()[name][1:-1], b.arrays()[name][1:-1], f"state.{name}")
    for name, idx in IST_MODEL.items():
        if name in skip:
            continue
        assert a.ist[idx] == b.ist[idx], f"ist[{name}]: {a.ist[idx]} != {b.ist[idx]}"


def assert_same_run(a, b, *, state: bool = True) -> None:
    """Two ChainRuns are identical: final state, events, first moves, L samples, snapshots,
    profiles and the model part of the summary."""
    if state:
        assert_same_state(a.state, b.state)
    assert a.summary["state_sha256"] == b.summary["state_sha256"]
    assert a.events.equals(b.events), "event tables differ"
    for col in ("S", "t_start", "t_end", "duration"):
        assert_bits_equal(a.events[col].to_numpy(), b.events[col].to_numpy(), f"events.{col}")
    assert a.first_move.equals(b.first_move), "first-move tables differ"
    assert_bits_equal(a.samples["t"].values, b.samples["t"].values, "sample times")
    assert_bits_equal(a.samples["L"].values, b.samples["L"].values, "L samples")
    assert_bits_equal(a.snapshots["snapshot_time"].values, b.snapshots["snapshot_time"].values, "snapshot times")
    assert_bits_equal(a.snapshots.values, b.snapshots.values, "snapshots")
    assert_bits_equal(a.profiles["profile_dx"].values, b.profiles["profile_dx"].values, "profiles dx")
    for c in ("profile_event", "profile_t", "profile_t_next"):
        assert_bits_equal(a.profiles[c].values, b.profiles[c].values, f"profiles {c}")
    for key in set(a.summary) | set(b.summary):
        if _is_work(key):
            continue
        va, vb = a.summary.get(key), b.summary.get(key)
        if isinstance(va, float) and isinstance(vb, float) and np.isnan(va) and np.isnan(vb):
            continue
        assert va == vb, f"summary[{key!r}]: {va!r} != {vb!r}"


# --------------------------------------------------------------------------------------
# Plain-Python Heun step of eq. (4), written from docs/model.md and the kernel module's docstring.


#: A partly stuck state of four blocks at step N_START (block 2 stuck, the others moving, theta
#: from 0.05 to 40): the start of the rate-and-state laws' kernel-step tests against their plain
#: Heun steps.
PARTLY_STUCK_BLOCKS = (
    [-0.30, -0.46, -0.70, -0.93],
    [0.002, 0.0, 0.03, 1e-9],
    [0.8, 3.0, 0.05, 40.0],
    [True, False, True, True],
)
N_START = 20_000


def partly_stuck_start():
    """:data:`PARTLY_STUCK_BLOCKS` as the engine's state held at t_n, n = :data:`N_START`."""
    from stickslip.run.driver import ChainState

    x, v, th, moving = PARTLY_STUCK_BLOCKS
    start = ChainState.from_blocks(np.array(x), np.array(v), np.array(th), ~np.array(moving))
    start.ist[0] = N_START  # the state held is at t_n
    return start


def heun_step(x, v, th, moving, n, p):
    """One Heun step of the chain from t_n = n dt; lists of blocks 1..N at index 0..N-1.

    Returns (x, v, th, moving, mid) of the new state, with ``mid`` the blocks that moved
    during the step (start rule applied). Ghost cells: pulling point V t, free end
    x_{N+1} = x_N, no-flux ends of theta.
    """
    N = len(x)
    dt, Kc, D, V, beta, alpha, Fs = p.dt, p.K, p.D, p.V, p.beta, p.alpha, p.Fs
    h2 = 0.5 * dt

    def padded(xa, tha, step):
        return [V * (float(step) * dt)] + list(xa) + [xa[-1]], [tha[0]] + list(tha) + [tha[-1]]

    X, TH = padded(x, th, n)
    mid, a1, b1, xs, vs, ths = [], [], [], [], [], []
    for i in range(1, N + 1):
        f = Kc * ((X[i - 1] - X[i]) - (X[i] - X[i + 1]))
        m = moving[i - 1] or f > Fs  # start rule, tested at the beginning of the step
        a = (f - TH[i] - beta * v[i - 1]) if m else 0.0
        b = TH[i] * (1.0 - TH[i]) - alpha * TH[i] * v[i - 1] + D * ((TH[i - 1] - TH[i]) - (TH[i] - TH[i + 1]))
        mid.append(m)
        a1.append(a)
        b1.append(b)
        xs.append(x[i - 1] + dt * v[i - 1])
        vs.append(v[i - 1] + dt * a)
        ths.append(th[i - 1] + dt * b)
    XS, THS = padded(xs, ths, n + 1)
    xn, vn, thn, mn = [], [], [], []
    for i in range(1, N + 1):
        f2 = Kc * ((XS[i - 1] - XS[i]) - (XS[i] - XS[i + 1]))
        m = mid[i - 1]
        a2 = (f2 - THS[i] - beta * vs[i - 1]) if m else 0.0
        b2 = (THS[i] * (1.0 - THS[i]) - alpha * THS[i] * vs[i - 1]
              + D * ((THS[i - 1] - THS[i]) - (THS[i] - THS[i + 1])))  # fmt: skip
        thn.append(th[i - 1] + h2 * (b1[i - 1] + b2))
        if m:
            xn.append(x[i - 1] + h2 * (v[i - 1] + vs[i - 1]))
            vel = v[i - 1] + h2 * (a1[i - 1] + a2)
            if vel <= 0.0:  # stop rule, at the end of the step
                vn.append(0.0)
                mn.append(False)
            else:
                vn.append(vel)
                mn.append(True)
        else:  # stopped: x fixed, v = 0
            xn.append(x[i - 1])
            vn.append(0.0)
            mn.append(False)
    return xn, vn, thn, mn, mid


@dataclass
class OracleRun:
    """The outcome of :func:`oracle_run`: final state, L after each step, events, first moves."""

    x: list
    v: list
    th: list
    moving: list
    L: list = field(default_factory=list)  # L at t_0, t_1, ..., t_n_steps
    events: list = field(default_factory=list)  # dicts with the event-table columns
    first_moves: list = field(default_factory=list)  # (event, block, step)
    nonfinite: tuple | None = None  # (step after which the state is non-finite, first bad block)


def oracle_run(x, v, th, moving, p, n_steps: int, step=None) -> OracleRun:
    """Step :func:`heun_step` n_steps times from step 0 and find the slip events (docs/model.md):
    an event starts with the first step in which any block moves after a step that ended with
    every block stopped (the initial state counts as such), and ends with the first step that
    ends with every block stopped again; S = sum_i (x_i(end) - x_i(start))."""
    x, v, th, moving = list(x), list(v), list(th), list(moving)
    N = len(x)
    out = OracleRun(x, v, th, moving, L=[x[0] - x[-1]])
    in_event = False
    for n in range(n_steps):
        all_stopped_before = not any(moving)
        x_before = list(x)
        x, v, th, moving, mid = (step or heun_step)(x, v, th, moving, n, p)
        if not in_event and all_stopped_before and any(mid):
            in_event = True
            ev = {"event": len(out.events), "step_start": n, "start_block": mid.index(True) + 1}
            x_start = x_before
            first = {}
        if in_event:
            for i in range(N):
                if mid[i] and (i + 1) not in first:
                    first[i + 1] = n
        bad = [i + 1 for i in range(N) if not all(map(math.isfinite, (x[i], v[i], th[i])))]
        if bad:
            out.nonfinite = (n + 1, bad[0])
            break
        if in_event and not any(moving):
            S = 0.0
            for i in range(N):
                S += x[i] - x_start[i]
            ev.update(step_end=n, S=S, max_block=max(first), n_blocks=len(first))
            out.events.append(ev)
            out.first_moves += [(ev["event"], b, first[b]) for b in sorted(first)]
            in_event = False
        out.L.append(x[0] - x[-1])
    out.x, out.v, out.th, out.moving = x, v, th, moving
    return out


# --------------------------------------------------------------------------------------
# Command line in a subprocess


def _package_root() -> Path:
    """The folder holding the ``stickslip`` package these tests import."""
    import stickslip

    return Path(stickslip.__file__).resolve().parents[1]


def stickslip_cmd() -> list[str]:
    """``python -m stickslip.cli`` of this interpreter, on the package these tests import
    (:func:`cli_env` puts it first on PYTHONPATH, so an installed copy elsewhere is not used)."""
    return [sys.executable, "-m", "stickslip.cli"]


def cli_env() -> dict[str, str]:
    env = dict(os.environ)
    env.pop("PYTHONWARNINGS", None)
    env["PYTHONPATH"] = os.pathsep.join([str(_package_root())] + [p for p in [env.get("PYTHONPATH")] if p])
    return env


def run_cli_subprocess(*argv: str, timeout: float = 120.0) -> subprocess.CompletedProcess:
    return subprocess.run(stickslip_cmd() + list(argv), capture_output=True, text=True, timeout=timeout,
                          env=cli_env())  # fmt: skip


def signal_when_running(argv: list[str], started, signum, *, settle: float = 1.0, timeout: float = 120.0):
    """Run ``stickslip ARGV``; once ``started()`` holds (a point began) and ``settle`` seconds more
    have passed, send ``signum`` to the command alone; return (exit status, stdout, stderr)."""
    import signal
    import time

    proc = subprocess.Popen(
        stickslip_cmd() + list(argv),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=cli_env(),
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),  # even where a shell ignores it
    )
    try:
        deadline = time.monotonic() + timeout
        while not started():
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() < deadline, f"nothing started within {timeout:g} s"
            time.sleep(0.05)
        time.sleep(settle)  # into the run
        assert proc.poll() is None
        proc.send_signal(signum)
        stdout, stderr = proc.communicate(timeout=timeout)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    return proc.returncode, stdout, stderr


# --------------------------------------------------------------------------------------
# Plain-Python Heun step of any model of the family (docs/model.md, "The family the paper
# stands in"), written from its text: ghost cells from the drive and the ends, the force with
# the plate's leaf spring, the three friction laws and the two thresholds.


def _ghosts(xa, tha, step, p):
    N = len(xa)
    pull = p.V * (float(step) * p.dt)
    periodic = p.ends == "periodic"
    if p.drive == "end":
        left = pull
    elif periodic:
        left = xa[N - 1]
    elif p.ends == "fixed":
        left = 0.0
    else:
        left = xa[0]
    if periodic:
        right, thl, thr = xa[0], tha[N - 1], tha[0]
    else:
        right = 0.0 if p.ends == "fixed" else xa[N - 1]
        thl, thr = tha[0], tha[N - 1]
    return [left] + list(xa) + [right], [thl] + list(tha) + [thr], pull


def random_start(p, seed: int, pstop: float):
    """A random chain state for the exactness tests: x in [-0.3, 0.3], v in [0, 0.2], theta in
    [0.3, 1] (0 for a law without theta), each block stopped (v = 0) with probability ``pstop``;
    returns (x, v, theta, stopped)."""
    rng = np.random.default_rng(seed)
    x = rng.uniform(-0.3, 0.3, p.N)
    v = rng.uniform(0.0, 0.2, p.N)
    th = rng.uniform(0.3, 1.0, p.N) if p.friction == "state" else np.zeros(p.N)
    stopped = rng.random(p.N) < pstop
    return x, np.where(stopped, 0.0, v), th, stopped


def heun_frame(x, v, th, moving, n, p, force, accel, dtheta, threshold):
    """One Heun step from t_n = n dt (docs/model.md) with the model's pieces given as plain
    functions: ``force(X, i, plate, step)``, ``accel(f, theta_i, v_i, i)``, ``dtheta(TH, i, v_i)``
    and ``threshold(TH, i)``; the start rule at the beginning of the step, the stop rule at its
    end. Lists of blocks 1..N at index 0..N-1; returns (x, v, th, moving, mid)."""
    N = len(x)
    dt, h2 = p.dt, 0.5 * p.dt
    X, TH, plate = _ghosts(x, th, n, p)
    mid, a1, b1, xs, vs, ths = [], [], [], [], [], []
    for i in range(1, N + 1):
        f = force(X, i, plate, n)
        m = moving[i - 1] or f > threshold(TH, i)  # start rule, at the beginning of the step
        a = accel(f, TH[i], v[i - 1], i) if m else 0.0
        b = dtheta(TH, i, v[i - 1])
        mid.append(m)
        a1.append(a)
        b1.append(b)
        xs.append(x[i - 1] + dt * v[i - 1])
        vs.append(v[i - 1] + dt * a)
        ths.append(th[i - 1] + dt * b)
    XS, THS, plate2 = _ghosts(xs, ths, n + 1, p)
    xn, vn, thn, mn = [], [], [], []
    for i in range(1, N + 1):
        m = mid[i - 1]
        a2 = accel(force(XS, i, plate2, n + 1), THS[i], vs[i - 1], i) if m else 0.0
        b2 = dtheta(THS, i, vs[i - 1])
        thn.append(th[i - 1] + h2 * (b1[i - 1] + b2) if p.friction == "state" else th[i - 1])
        if m:
            xn.append(x[i - 1] + h2 * (v[i - 1] + vs[i - 1]))
            vel = v[i - 1] + h2 * (a1[i - 1] + a2)
            if vel <= 0.0:  # stop rule, at the end of the step
                vn.append(0.0)
                mn.append(False)
            else:
                vn.append(vel)
                mn.append(True)
        else:  # stuck: x fixed, v = 0
            xn.append(x[i - 1])
            vn.append(0.0)
            mn.append(False)
    return xn, vn, thn, mn, mid


def model_heun_step(x, v, th, moving, n, p):
    """One Heun step of the model ``p`` (ChainParams with pieces) from t_n = n dt; lists of
    blocks 1..N at index 0..N-1. Returns (x, v, th, moving, mid) as :func:`heun_step`."""

    def force(X, i, plate, step):
        f = p.K * ((X[i - 1] - X[i]) - (X[i] - X[i + 1]))
        if p.drive == "plate":
            f = f + p.Kp * (plate - X[i])
        elif p.drive == "constant-force":
            f = f + p.F
        elif p.drive == "force-ramp":
            f = f + (p.F_start + p.r * (float(step) * p.dt))  # F_start + r t_n, t_n = n dt
        return f

    def accel(f, thi, vi):
        if p.friction == "state":
            return f - thi - p.beta * vi
        if p.friction == "weakening":
            phi = (1 - p.sigma) / (1 + 2 * p.alpha * max(vi, 0.0) / (1 - p.sigma))
            return f - phi
        return f - p.F0 - p.beta * vi

    def dtheta(TH, i, vi):
        if p.friction != "state":
            return 0.0
        return (TH[i] * (1.0 - TH[i]) - p.alpha * TH[i] * vi
                + p.D * ((TH[i - 1] - TH[i]) - (TH[i] - TH[i + 1])))  # fmt: skip

    threshold = (lambda TH, i: TH[i]) if p.threshold == "state" else (lambda TH, i: p.Fs)
    return heun_frame(x, v, th, moving, n, p, force, lambda f, thi, vi, i: accel(f, thi, vi), dtheta, threshold)


def error_lines(err: str) -> list[str]:
    """The lines of stderr after argparse's usage block (``usage: ...`` and its indented
    continuation lines): a bad input must leave exactly one there."""
    lines = err.rstrip("\n").splitlines()
    k = 0
    if lines and lines[0].startswith("usage: "):
        k = 1
        while k < len(lines) and lines[k].startswith(" "):
            k += 1
    return lines[k:]


def is_real_command(command: str) -> bool:
    """Whether each ``stickslip ...`` part of ``command`` is accepted by the real CLI parser.

    Parts are joined by ``&&``; a trailing ``(...)`` remark is not part of the command.
    """
    import contextlib
    import io
    import shlex

    from stickslip.cli import build_parser

    for part in command.split(" && "):
        words = shlex.split(part.split("  (")[0])
        if not words or words[0] != "stickslip":
            return False
        try:
            with contextlib.redirect_stderr(io.StringIO()):
                build_parser().parse_args(words[1:])
        except SystemExit:
            return False
    return True


def one_line_error(capsys, *names: str) -> str:
    """stderr as ``capsys`` read it, after checking it is one line, no traceback and nothing on
    stdout, and that it names each of ``names``."""
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and "Traceback" not in err, err
    for name in names:
        assert name in err, err
    return err


def run_cli(capsys, *argv: str) -> tuple[int, str, str]:
    """``stickslip ARGV`` in this process: (exit status, stdout, stderr) read through ``capsys``;
    argparse errors, which leave through SystemExit(2), give their status too."""
    from stickslip.cli import main

    try:
        status = main(list(argv))
    except SystemExit as exc:
        status = exc.code
    out, err = capsys.readouterr()
    return status, out, err


def record_lock_tries(monkeypatch) -> list:
    """The ``timeout`` of every try at a run directory's lock from now on (0: tried, not waited
    for), so that a test shows "refused at once" by what was done rather than by a clock."""
    import filelock

    tries: list = []
    acquire = filelock.FileLock.acquire

    def spy(self, *args, **kwargs):
        tries.append(kwargs.get("timeout", args[0] if args else None))
        return acquire(self, *args, **kwargs)

    monkeypatch.setattr(filelock.FileLock, "acquire", spy)
    return tries


def same_findings(a, b, *, none_is_nan: bool = False) -> bool:
    """Equal structures, numbers to 1e-9 relative, NaN equal to NaN (and to None where
    ``none_is_nan``, as a study's JSON writes NaN): a study's findings derived again against the
    ones kept beside its page."""
    import pytest

    nan = lambda x: isinstance(x, float) and math.isnan(x)
    if none_is_nan and (a is None or b is None or nan(a) or nan(b)):
        return (a is None or nan(a)) and (b is None or nan(b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same_findings(a[k], b[k], none_is_nan=none_is_nan) for k in a)
    if isinstance(a, list | tuple) and isinstance(b, list | tuple):
        return len(a) == len(b) and all(same_findings(x, y, none_is_nan=none_is_nan) for x, y in zip(a, b, strict=True))
    if isinstance(a, float) or isinstance(b, float):
        return b == pytest.approx(a, rel=1e-9, nan_ok=True)
    return a == b
