"""Per-block parameters and quenched disorder (docs/model.md, "Per-block parameters").

Any numeric parameter a piece reads, the springs K (per bond) and the masses M may differ from
block to block: a float (every block alike), an array of N values, or a quenched-disorder spec
(:class:`Quenched`) drawn here, outside the kernels, with numpy's :class:`~numpy.random.Generator`.
A :class:`ChainParams <stickslip.models.params.ChainParams>` holds the drawn values as a
:class:`PerBlock`; the kernels receive them padded like the positions (index i = block i,
:meth:`PerBlock.padded`) and read them through a compile-time gather
(:func:`stickslip.kernels.laws.at`), so a uniform chain's code is unchanged.

The distributions (Sakaguchi and Kadowaki's random media, arXiv:1705.06410, draw the thresholds
Fs; earthquake models draw thresholds and asperities):

* ``uniform(a, b)``: a <= b, each block uniform on [a, b];
* ``normal(mu, s)``: normal with mean mu and standard deviation s, truncated to the parameter's
  allowed range (scipy's ``truncnorm``);
* ``lognormal(mu, s)``: exp of a normal with mean mu and standard deviation s;
* ``weibull(k, scale=1)``: Weibull of shape k, times ``scale``;
* ``exponential(scale)``: exponential with mean ``scale``;
* ``asperities(a, b, p=0.1)``: round(p N) blocks, at places drawn at random, at the value a,
  the rest at b.

The draws of a parameter P with seed S come from ``SeedSequence(S, spawn_key=(crc32(P),))``, so
two parameters given the same seed are drawn independently, and the same spec and seed give the
same values on every machine (numpy's generators are stable for a given version).
"""

from __future__ import annotations

import ast
import hashlib
import math
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

#: the distributions of a quenched-disorder spec and the number of positional parameters each takes
DISTRIBUTIONS = {
    "uniform": (2, 2),
    "normal": (2, 2),
    "lognormal": (2, 2),
    "weibull": (1, 2),
    "exponential": (1, 1),
    "asperities": (2, 2),
}

#: parameters that may never be per block: the chain's size, the drive's velocity and the step
NOT_PER_BLOCK = ("N", "V", "dt")


class DisorderError(ValueError):
    """A per-block value that cannot be used; :class:`~stickslip.models.params.ChainParams`
    turns it into its one-line ``ParameterError`` naming the parameter and its range."""


@dataclass(frozen=True, init=False)
class Quenched:
    """A quenched-disorder spec: a distribution, its parameters and a seed.

    Parameters
    ----------
    dist : str
        One of :data:`DISTRIBUTIONS` (module docstring).
    *args : float
        The distribution's parameters, e.g. ``Quenched("uniform", 2.5, 3.5)``.
    p : float, optional
        ``asperities`` only: the fraction of blocks at the first value (default 0.1).
    seed : int, optional
        Seed of the draw; None takes the run's disorder seed (``--disorder-seed``, default 0).

    Examples
    --------
    >>> Quenched("uniform", 2.5, 3.5, seed=1)
    Quenched('uniform(2.5, 3.5)', seed=1)
    """

    dist: str
    args: tuple[float, ...]
    p: float | None
    seed: int | None

    def __init__(self, dist: str, *args: float, p: float | None = None, seed: int | None = None) -> None:
        object.__setattr__(self, "dist", str(dist))
        object.__setattr__(self, "args", tuple(float(a) for a in args))
        object.__setattr__(self, "p", None if p is None else float(p))
        object.__setattr__(self, "seed", None if seed is None else int(seed))

    @property
    def text(self) -> str:
        """The spec as the command line writes it, e.g. ``asperities(3, 6, p=0.1)``."""
        parts = [f"{a:g}" for a in self.args]
        if self.p is not None:
            parts.append(f"p={self.p:g}")
        return f"{self.dist}({', '.join(parts)})"

    def __repr__(self) -> str:
        seed = "" if self.seed is None else f", seed={self.seed}"
        return f"Quenched({self.text!r}{seed})"

    def draw(self, name: str, n: int, low: float | None, high: float | None, seed: int = 0) -> np.ndarray:
        """N values of parameter ``name`` (allowed range low..high, for the truncated normal)."""
        lo_n, hi_n = DISTRIBUTIONS.get(self.dist, (None, None))
        if lo_n is None:
            raise DisorderError(f"unknown distribution {self.dist!r} (one of {', '.join(DISTRIBUTIONS)})")
        if not lo_n <= len(self.args) <= hi_n or (self.p is not None and self.dist != "asperities"):
            raise DisorderError(f"{self.text} takes {lo_n}{'' if lo_n == hi_n else f'-{hi_n}'} numbers")
        if not all(math.isfinite(a) for a in self.args):
            raise DisorderError(f"{self.text} has a number that is not finite")
        s = self.seed if self.seed is not None else seed
        rng = np.random.default_rng(np.random.SeedSequence(s, spawn_key=(zlib.crc32(name.encode()),)))
        a = self.args
        if self.dist == "uniform":
            if a[0] > a[1]:
                raise DisorderError(f"{self.text}: lower bound above upper")
            return rng.uniform(a[0], a[1], n)
        if self.dist == "normal":
            if a[1] < 0:
                raise DisorderError(f"{self.text}: standard deviation < 0")
            if a[1] == 0:
                return np.full(n, a[0])
            from scipy.stats import truncnorm

            lo = -np.inf if low is None else (low - a[0]) / a[1]
            hi = np.inf if high is None else (high - a[0]) / a[1]
            return truncnorm.rvs(lo, hi, loc=a[0], scale=a[1], size=n, random_state=rng)
        if self.dist == "lognormal":
            if a[1] < 0:
                raise DisorderError(f"{self.text}: standard deviation < 0")
            return rng.lognormal(a[0], a[1], n)
        if self.dist == "weibull":
            scale = a[1] if len(a) > 1 else 1.0
            if a[0] <= 0 or scale <= 0:
                raise DisorderError(f"{self.text}: shape and scale must be > 0")
            return scale * rng.weibull(a[0], n)
        if self.dist == "exponential":
            if a[0] <= 0:
                raise DisorderError(f"{self.text}: scale must be > 0")
            return rng.exponential(a[0], n)
        p = 0.1 if self.p is None else self.p
        if not 0.0 <= p <= 1.0:
            raise DisorderError(f"{self.text}: p must be in [0, 1]")
        values = np.full(n, a[1])
        values[rng.choice(n, size=int(round(p * n)), replace=False)] = a[0]
        return values


class PerBlock:
    """The values of a parameter at blocks 1..N (read-only float64), and where they came from.

    Two are equal when their values are, bit for bit; ``spec`` (a :class:`Quenched`, a file name
    or ``"array"``) and ``seed`` are provenance (run.json, ``stickslip.models.disorder``).
    """

    __slots__ = ("values", "spec", "seed", "_sha")

    def __init__(self, values: np.ndarray, spec: Any = "array", seed: int | None = None) -> None:
        v = np.array(values, dtype=np.float64)
        v.setflags(write=False)
        self.values = v
        self.spec = spec
        self.seed = seed
        self._sha = hashlib.sha256(np.ascontiguousarray(v).tobytes()).hexdigest()

    @property
    def sha256(self) -> str:
        """SHA-256 of the values' float64 bytes (little-endian on the machines numba runs on)."""
        return self._sha

    @property
    def spec_text(self) -> str:
        """The spec as the command line writes it."""
        return self.spec.text if isinstance(self.spec, Quenched) else str(self.spec)

    def padded(self, ring: bool = False) -> np.ndarray:
        """The values at index 1..N of an array of N + 2 (as the positions; the ends repeat the
        first and last value, which nothing reads but the springs of :meth:`bonds`)."""
        v = self.values
        return np.concatenate(([v[0]], v, [v[0] if ring else v[-1]]))

    def bonds(self, ring: bool = False) -> np.ndarray:
        """Springs per bond as the kernels read them: index i (1..N) the spring between blocks
        i-1 and i (block 0 the pulling point or the ghost cell), index N + 1 the spring to the
        right of block N: K_1 again on a ring (the same spring), else K_N (docs/model.md)."""
        return self.padded(ring)

    def describe(self) -> dict[str, Any]:
        """Provenance for run.json: spec, seed, SHA-256 and a summary of the values."""
        v = self.values
        return {
            "spec": self.spec_text,
            "seed": self.seed,
            "sha256": self.sha256,
            "n": int(v.size),
            "mean": float(v.mean()),
            "min": float(v.min()),
            "max": float(v.max()),
        }

    def record(self) -> dict[str, Any]:
        """:meth:`describe` and the values themselves: what ``ChainParams.to_dict`` holds, so that
        run.json, checkpoints and ``load_run`` carry the arrays and :func:`resolve` rebuilds them,
        checking them against their SHA-256."""
        return {**self.describe(), "values": [float(x) for x in self.values]}

    def __format__(self, spec: str) -> str:
        """The spec where a number would be formatted (``f"{p.Fs:g}"`` in a title or a summary)."""
        return self.spec_text

    def __len__(self) -> int:
        return int(self.values.size)

    def __array__(self, dtype=None, copy=None) -> np.ndarray:
        """The values at blocks 1..N, so that numpy reads a per-block parameter as its array
        (the closed forms of :mod:`stickslip.models.physics` and the Jacobian take either)."""
        return self.values if dtype is None else self.values.astype(dtype)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, PerBlock) and other._sha == self._sha and other.values.size == self.values.size

    def __hash__(self) -> int:
        return hash(self._sha)

    def __repr__(self) -> str:
        seed = "" if self.seed is None or not isinstance(self.spec, Quenched) else f", seed={self.seed}"
        return f"PerBlock({self.spec_text!r}{seed}, sha256={self.sha256[:12]!r})"


def parse(text: str) -> Quenched | str | float:
    """A command-line value: a number, ``file:PATH`` (a .npy or text file of N values) or a
    distribution expression such as ``uniform(2.5, 3.5)`` or ``asperities(3, 6, p=0.1)``."""
    text = text.strip()
    if text.startswith("file:"):
        return text
    try:
        return float(text)
    except ValueError:
        pass
    try:
        node = ast.parse(text, mode="eval").body
    except SyntaxError:
        raise DisorderError(f"cannot read {text!r} (a number, file:PATH or e.g. uniform(2.5, 3.5))") from None
    if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)):
        raise DisorderError(f"cannot read {text!r} (a number, file:PATH or e.g. uniform(2.5, 3.5))")
    try:
        args = [float(ast.literal_eval(a)) for a in node.args]
        kw = {k.arg: ast.literal_eval(k.value) for k in node.keywords}
    except (ValueError, TypeError, SyntaxError):
        raise DisorderError(f"cannot read {text!r}: the distribution's parameters must be numbers") from None
    unknown = set(kw) - {"p", "seed"}
    if unknown:
        raise DisorderError(f"cannot read {text!r}: unknown keyword {sorted(unknown)[0]}")
    return Quenched(node.func.id, *args, **kw)


def _load(path: str) -> np.ndarray:
    p = Path(path)
    try:
        return np.load(p) if p.suffix == ".npy" else np.loadtxt(p, ndmin=1)
    except (OSError, ValueError) as exc:
        raise DisorderError(f"cannot read {path}: {exc}") from None


def resolve(name: str, value: Any, n: int, low: float | None, high: float | None, seed: int = 0) -> PerBlock | None:
    """``value`` as a :class:`PerBlock` of N values, or None where it is one number for every
    block (left to the usual check). Raises :class:`DisorderError` for a value that cannot be
    used (the caller adds the parameter's name and range); the range itself is checked by the
    caller on :attr:`PerBlock.values`."""
    if isinstance(value, PerBlock):
        if len(value) == n:
            return value
        if isinstance(value.spec, Quenched):
            # A drawn medium follows N (``replace(N=...)``): the same spec and seed, N values.
            return resolve(name, value.spec, n, low, high, value.seed if value.seed is not None else seed)
        raise DisorderError(f"needs N = {n} values (got {len(value)})")
    if isinstance(value, dict):
        return _from_record(value, n)
    if isinstance(value, str) and not value.startswith("file:"):
        try:
            float(value)
            return None
        except ValueError:
            value = parse(value)
    if isinstance(value, Quenched):
        return PerBlock(value.draw(name, n, low, high, seed), value, value.seed if value.seed is not None else seed)
    spec: Any = "array"
    if isinstance(value, str):
        spec = value
        value = _load(value[len("file:") :])
    elif isinstance(value, (int, float, np.integer, np.floating)) or value is None:
        return None
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise DisorderError("must be a number, an array of N values or a Quenched spec") from None
    if arr.ndim == 0:
        return None
    if arr.ndim != 1 or arr.size != n:
        raise DisorderError(f"needs N = {n} values (got {arr.size if arr.ndim == 1 else arr.shape})")
    return PerBlock(arr, spec)


def _from_record(record: dict[str, Any], n: int) -> PerBlock:
    """A :class:`PerBlock` from :meth:`PerBlock.record` (run.json, a checkpoint's header), its
    values checked against the SHA-256 recorded with them."""
    try:
        values = np.asarray(record["values"], dtype=np.float64)
    except (KeyError, TypeError, ValueError):
        raise DisorderError("a recorded per-block value needs its values") from None
    if values.ndim != 1 or values.size != n:
        raise DisorderError(f"needs N = {n} values (got {values.size})")
    text = str(record.get("spec", "array"))
    seed = record.get("seed")
    spec: Any = text
    if "(" in text:
        try:
            q = parse(text)
            spec = Quenched(q.dist, *q.args, p=q.p, seed=seed) if isinstance(q, Quenched) else text
        except DisorderError:
            spec = text
    pb = PerBlock(values, spec, None if seed is None else int(seed))
    if "sha256" in record and record["sha256"] != pb.sha256:
        raise DisorderError(
            f"the recorded values do not have their recorded SHA-256 ({pb.sha256[:12]} != {str(record['sha256'])[:12]})"
        )
    return pb
