"""Eight blocks at once (kernels/lanes.py) and the run stages built on it (kernels/stages.py).

The lanes' arithmetic is checked against the same expressions evaluated in plain Python floats
(IEEE double, each lane one scalar expression); the masked loads and stores against sentinels
around the blocks they may touch, and against a page that may not be read at all; each stage
evaluated as lanes against its loop (which predates the lanes and is checked against the dense
reference elsewhere), bit for bit, on every length of the last, masked group.
"""

from __future__ import annotations

import math
import subprocess
import sys
import textwrap

import numba
import numpy as np
import pytest

from stickslip.kernels import lanes, stages
from stickslip.models.drive import end as end_drive
from stickslip.models.drive import plate as plate_drive
from stickslip.models.friction import rate_state, strengthening
from stickslip.models.friction import state as state_law
from stickslip.models.params import ChainParams
from stickslip.models.threshold import constant as constant_threshold
from stickslip.run.driver import run_chain

WIDTH = 8

# ---------------------------------------------------------------------------------------------
# Arithmetic


class _F(float):
    """A Python float whose division by zero gives IEEE's inf or NaN instead of raising (the other
    operations of Python floats already are IEEE's: round to nearest, overflow to inf)."""

    def __add__(self, o):
        return _F(float(self) + float(o))

    def __radd__(self, o):
        return _F(float(o) + float(self))

    def __sub__(self, o):
        return _F(float(self) - float(o))

    def __rsub__(self, o):
        return _F(float(o) - float(self))

    def __mul__(self, o):
        return _F(float(self) * float(o))

    def __rmul__(self, o):
        return _F(float(o) * float(self))

    def __truediv__(self, o):
        return _F(_div(float(self), float(o)))

    def __rtruediv__(self, o):
        return _F(_div(float(o), float(self)))


def _div(a: float, b: float) -> float:
    if b != 0.0:
        return a / b
    if a == 0.0 or math.isnan(a) or math.isnan(b):
        return math.nan
    return math.copysign(math.inf, a) * math.copysign(1.0, b)


# Each expression of five lanes a..e and a float64 s, as the pieces write theirs: the state law's
# rate, a law's accel, the plate drive's force, and scalars on either side of each operator.
EXPRESSIONS = {
    "state-rate": lambda a, b, c, d, e, s: a * (1.0 - b) - 2.5 * a * c + 5.0 * ((d - a) - (a - e)),
    "accel": lambda a, b, c, d, e, s: a - b - s * c,
    "plate-force": lambda a, b, c, d, e, s: 10.0 * ((a - b) - (b - c)) + s * (d - b),
    "lanes-only": lambda a, b, c, d, e, s: (a + b) * (c - d) / e,
    "scalar-left": lambda a, b, c, d, e, s: (s - a) + (s * b) + (s / c) + (1.0 / d) + (0.5 - e),
    "scalar-right": lambda a, b, c, d, e, s: (a - s) * (b + s) - (c / s) + d * 3.0 - e / 3.0,
    "plain": lambda a, b, c, d, e, s: a + b,
    "difference": lambda a, b, c, d, e, s: a - b,
    "product": lambda a, b, c, d, e, s: a * b,
    "quotient": lambda a, b, c, d, e, s: a / b,
    "scalar-quotient": lambda a, b, c, d, e, s: s / a,
}

SPECIAL = [
    0.0,
    -0.0,
    5e-324,  # the smallest subnormal
    -5e-324,
    1e-310,  # subnormal
    -2.2250738585072014e-308,  # the smallest normal
    2.2250738585072009e-308,  # the largest subnormal
    1e-300,
    1.0,
    -1.0,
    0.1,
    1.5,
    3.0,
    1e300,
    -1.7976931348623157e308,
    math.inf,
    -math.inf,
    math.nan,
]


def _inputs(seed: int, groups: int = 48) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(5):
        size = WIDTH * groups
        special = rng.choice(np.array(SPECIAL), size)
        ordinary = rng.standard_normal(size) * 10.0 ** rng.integers(-320, 300, size)
        out.append(np.where(rng.random(size) < 0.5, special, ordinary))
    return out


@pytest.mark.parametrize("name", list(EXPRESSIONS))
def test_arithmetic_is_each_lanes_scalar_ieee_expression(name):
    expr = EXPRESSIONS[name]
    fn = numba.njit(inline="always")(expr)

    @numba.njit
    def kernel(a, b, c, d, e, s, out):
        A, B, C, D, E, O = a.ctypes.data, b.ctypes.data, c.ctypes.data, d.ctypes.data, e.ctypes.data, out.ctypes.data
        for g in range(len(a) // 8):
            i = g * 8
            l = lanes.load
            r = fn(l(A, i, 8), l(B, i, 8), l(C, i, 8), l(D, i, 8), l(E, i, 8), s)
            lanes.store(O, i, 8, r)

    for seed in range(3):
        a, b, c, d, e = _inputs(seed)
        for s in (2.5, -0.0, 0.0, 5e-324, -1e-310, 1e300, math.inf, -math.inf, math.nan):
            out = np.full(a.size, 12345.0)
            kernel(a, b, c, d, e, s, out)
            want = np.array([float(expr(*(_F(v) for v in vals), _F(s))) for vals in zip(a, b, c, d, e, strict=True)])
            nan = np.isnan(want)
            assert np.array_equal(np.isnan(out), nan), (name, s)
            # Bit for bit where the result is a number (signed zeros and subnormals included); the
            # payload of a NaN is not fixed by IEEE when both operands are NaNs.
            assert np.array_equal(out[~nan].view(np.int64), want[~nan].view(np.int64)), (name, s)


def test_the_arithmetic_sees_signed_zeros_subnormals_and_infinities():
    # Expected values written out, not computed: (a + b) * 0.5 lane by lane.
    a = np.array([-0.0, -0.0, 0.0, 5e-324, 1e-310, math.inf, math.inf, 1.0])
    b = np.array([-0.0, 0.0, -0.0, 5e-324, -1e-310, math.inf, -math.inf, math.nan])
    out = np.full(8, 7.0)
    _half_sum(a, b, out)
    want = np.array([-0.0, 0.0, 0.0, 5e-324, 0.0, math.inf])
    assert np.array_equal(out[:6].view(np.int64), want.view(np.int64))
    assert np.isnan(out[6:]).all()


@numba.njit
def _half_sum(a, b, out):
    lanes.store(out.ctypes.data, 0, 8, (lanes.load(a.ctypes.data, 0, 8) + lanes.load(b.ctypes.data, 0, 8)) * 0.5)


# ---------------------------------------------------------------------------------------------
# Masked loads and stores


@numba.njit
def _copy(src, i, dst, j, n):
    lanes.store(dst.ctypes.data, j, n, lanes.load(src.ctypes.data, i, n))


@numba.njit
def _load_all(src, i, n, dst):
    """Lanes 0..7 of load(src, i, n) into dst[0:8]."""
    lanes.store(dst.ctypes.data, 0, 8, lanes.load(src.ctypes.data, i, n))


@numba.njit
def _fill(dst, j, n, value):
    lanes.store(dst.ctypes.data, j, n, value)


@pytest.mark.parametrize("n", range(WIDTH + 1))
def test_masked_store_writes_exactly_its_n_elements(n):
    size = 20
    src = np.arange(size, dtype=np.float64) + 0.25
    for i in range(size - n + 1):
        for j in (0, 1, size - n - 1, size - n):
            if j < 0:
                continue
            dst = np.full(size, -777.0)
            _copy(src, i, dst, j, n)
            want = np.full(size, -777.0)
            want[j : j + n] = src[i : i + n]
            assert np.array_equal(dst.view(np.int64), want.view(np.int64)), (i, j, n)
    # A float64 stored in each of the n elements
    for j in (0, size - n):
        dst = np.full(size, -777.0)
        _fill(dst, j, n, -0.0)
        want = np.full(size, -777.0)
        want[j : j + n] = -0.0
        assert np.array_equal(dst.view(np.int64), want.view(np.int64)), (j, n)


@pytest.mark.parametrize("n", range(WIDTH + 1))
def test_masked_load_gives_its_elements_in_the_first_lanes_and_zeros_after(n):
    size = 20
    src = -(np.arange(size, dtype=np.float64) + 1.5)
    for i in range(size - n + 1):
        dst = np.full(WIDTH, np.nan)
        _load_all(src, i, n, dst)
        want = np.zeros(WIDTH)
        want[:n] = src[i : i + n]
        assert np.array_equal(dst.view(np.int64), want.view(np.int64)), (i, n)


_GUARD_SCRIPT = textwrap.dedent(
    """
    import ctypes, mmap, sys
    import numba, numpy as np
    from stickslip.kernels import lanes, stages
    from stickslip.models.drive import end
    from stickslip.models.friction import state
    from stickslip.models.threshold import constant

    PAGE = mmap.PAGESIZE
    libc = ctypes.CDLL(None, use_errno=True)
    libc.mprotect.argtypes = (ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int)
    keep = []

    def at_page_end(size, fill):
        # float64 array of `size` whose last element ends where a page that may not be read begins
        m = mmap.mmap(-1, 2 * PAGE)
        base = ctypes.addressof(ctypes.c_char.from_buffer(m))
        assert libc.mprotect(base + PAGE, PAGE, 0) == 0, ctypes.get_errno()
        a = np.frombuffer(m, dtype=np.float64, count=size, offset=PAGE - 8 * size)
        a[:] = fill
        keep.append(m)
        return a

    @numba.njit
    def copy(src, i, dst, j, n):
        lanes.store(dst.ctypes.data, j, n, lanes.load(src.ctypes.data, i, n))

    for n in range(9):
        src = at_page_end(16, 1.0)
        dst = at_page_end(16, 2.0)
        copy(src, 16 - n, dst, 16 - n, n)
        assert (dst[16 - n:] == 1.0).all() and (dst[:16 - n] == 2.0).all()

    END, STATE = end.__name__, state.__name__
    mp = (10.0, end.Params(), constant.Params(3.0), state.Params(1.0, 1.0, 5.0), None)

    @numba.njit
    def run(x, v, th, xs, vs, ths, mm, a1, b1, lo, hi):
        stages._stage1_run_lanes(x, v, th, xs, vs, ths, a1, b1, lo, hi, 0.0, 0.0, mp, 0.005, END, STATE)
        s = stages._stage2_run_lanes(x, v, th, xs, vs, ths, a1, b1, lo, hi, 0.0, 0.0, mp, 0.0025, END, STATE)
        stages._stage1_theta_lanes(x, v, th, xs, vs, ths, mm, b1, lo, hi, 0.0, mp, 0.005, END, STATE)
        stages._stage1_theta_only_lanes(v, th, ths, b1, lo, hi, 0.0, mp, 0.005, END, STATE)
        c = stages._stage2_theta_lanes(th, ths, v, vs, b1, lo, hi, 0.0, mp, 0.0025, END, STATE)
        return s, c

    N = 21
    for length in range(1, 17):
        arrays = [at_page_end(N + 2, 0.5) for _ in range(9)]
        run(*arrays, N - length + 1, N)
    print("ok")
    """
)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="mprotect of an anonymous map (Linux)")
def test_nothing_past_the_last_block_is_read_or_written():
    """Arrays that end where a page that may not be touched begins: a load or store of a lane past
    the masked group's n would stop the process."""
    out = subprocess.run([sys.executable, "-c", _GUARD_SCRIPT], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0 and out.stdout.strip().endswith("ok"), (out.returncode, out.stderr[-2000:])


# ---------------------------------------------------------------------------------------------
# The stop rule's and the change tracking's tests, and the lowest and highest lane of a mask


@numba.njit
def _any_not_positive(a, n):
    return lanes.any_not_positive(lanes.load(a.ctypes.data, 0, 8), n)


@numba.njit
def _changed(new, old, n):
    return lanes.changed(lanes.load(new.ctypes.data, 0, 8), lanes.load(old.ctypes.data, 0, 8), n)


BAD = [0.0, -0.0, -5e-324, -1.0, -math.inf, math.nan]
GOOD = [5e-324, 1e-310, 1.0, 1e308, math.inf]


def test_any_not_positive_looks_at_the_first_n_lanes_only():
    rng = np.random.default_rng(4)
    for bad in BAD:
        for k in range(WIDTH):
            a = rng.choice(np.array(GOOD), WIDTH)
            a[k] = bad
            for n in range(WIDTH + 1):
                assert _any_not_positive(a, n) == (k < n), (bad, k, n)
    for n in range(WIDTH + 1):
        a = rng.choice(np.array(GOOD), WIDTH)
        a[n:] = -1.0  # lanes past n ignored
        assert not _any_not_positive(a, n)
        assert _any_not_positive(np.full(WIDTH, math.nan), n) == (n > 0)


def test_changed_is_the_mask_of_the_first_n_lanes_that_differ():
    new = np.array([1.0, 0.0, math.nan, 2.0, -0.0, 5e-324, math.inf, 3.0])
    old = np.array([1.0, -0.0, math.nan, 2.5, 0.0, 0.0, math.inf, 3.0])
    # differ (!=): lane 2 (NaN), 3, 5; -0.0 and 0.0 are equal
    full = 0b00101100
    for n in range(WIDTH + 1):
        assert _changed(new, old, n) == full & ((1 << n) - 1), n
    assert _changed(old, old.copy(), 8) == 0b00000100  # NaN != NaN
    assert _changed(np.arange(8.0), np.arange(8.0) + 1.0, 8) == 0xFF
    assert _changed(np.arange(8.0), np.arange(8.0) + 1.0, 3) == 0b111
    rng = np.random.default_rng(5)
    for _ in range(50):
        a = rng.choice(np.array([0.0, -0.0, 1.0, math.nan]), WIDTH)
        b = rng.choice(np.array([0.0, -0.0, 1.0, math.nan]), WIDTH)
        n = int(rng.integers(0, WIDTH + 1))
        want = sum(1 << k for k in range(n) if a[k] != b[k] or math.isnan(a[k]))
        assert _changed(a, b, n) == want


@numba.njit
def _lowest_leading(bits):
    return lanes.lowest(bits), lanes.leading_zeros(bits)


@pytest.mark.parametrize(
    "bits, low, lead",
    [
        (1, 0, 63),
        (0b1000, 3, 60),
        (0b10100000, 5, 56),
        (0xFF, 0, 56),
        (0b110, 1, 61),
        (1 << 62, 62, 1),
        (-1, 0, 0),
        (-(1 << 63), 63, 0),
    ],
)
def test_lowest_and_leading_zeros(bits, low, lead):
    assert _lowest_leading(np.int64(bits)) == (low, lead)


# ---------------------------------------------------------------------------------------------
# The stages as lanes against their loops

N = 40
END, PLATE = end_drive.__name__, plate_drive.__name__
STATE, STRENGTHENING, RATE_STATE = state_law.__name__, strengthening.__name__, rate_state.__name__

# The paper's model (end drive, eq. 4's law) and the plate-driven train model's pieces.
_R = np.random.default_rng(11)


def _per_block(lo, hi):
    """Values per block, padded like x (docs/model.md, "Per-block parameters")."""
    return _R.uniform(lo, hi, N + 2)


PIECES = {
    "paper": (
        END,
        STATE,
        (10.0, end_drive.Params(), constant_threshold.Params(3.0), state_law.Params(1.0, 1.0, 5.0), None),
    ),
    "plate-strengthening": (
        PLATE,
        STRENGTHENING,
        (2.5, plate_drive.Params(1.0), constant_threshold.Params(3.0), strengthening.Params(0.5, 1.0), None),
    ),
    # Springs per bond, masses and the laws' parameters per block: the gather as lanes reads each
    # block's own values, as the loop does.
    "paper-per-block": (
        END,
        STATE,
        (
            _per_block(5.0, 15.0),
            end_drive.Params(),
            constant_threshold.Params(_per_block(2.0, 4.0)),
            state_law.Params(_per_block(0.5, 1.5), 1.0, _per_block(1.0, 6.0)),
            _per_block(0.5, 2.0),
        ),
    ),
    "plate-strengthening-per-block": (
        PLATE,
        STRENGTHENING,
        (
            2.5,
            plate_drive.Params(_per_block(0.5, 1.5)),
            constant_threshold.Params(3.0),
            strengthening.Params(_per_block(0.2, 0.8), _per_block(0.5, 1.5)),
            0.7,
        ),
    ),
}

# name: (loop, lanes, number of arrays, whether the stage reads the drive, time step)
PAIRS = {
    "stage1_run": (stages._stage1_run_loop, stages._stage1_run_lanes, 8, True, 0.005),
    "stage2_run": (stages._stage2_run_loop, stages._stage2_run_lanes, 8, True, 0.0025),
    "stage1_theta": (stages._stage1_theta_loop, stages._stage1_theta_lanes, 8, False, 0.005),
    "stage1_theta_only": (stages._stage1_theta_only_loop, stages._stage1_theta_only_lanes, 4, False, 0.005),
    "stage2_theta": (stages._stage2_theta_loop, stages._stage2_theta_lanes, 4, False, 0.0025),
}


def _wrapper(fn, n_arrays, with_drive, drive, friction):
    """An njit function calling the stage ``fn`` with the pieces as literals (and the drive's
    velocity q = 0.0, which only a law with a context reads: the engine passes 0.0 to the others)."""
    if with_drive:

        @numba.njit
        def call(a, lo, hi, p, mp, dt):
            return fn(a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7], lo, hi, p, 0.0, mp, dt, drive, friction)

    elif n_arrays == 8:

        @numba.njit
        def call(a, lo, hi, p, mp, dt):
            return fn(a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7], lo, hi, 0.0, mp, dt, drive, friction)

    elif "stage2_theta" in fn.py_func.__name__:
        # th, ths, v, vs (unread without a context: v in its place), b1

        @numba.njit
        def call(a, lo, hi, p, mp, dt):
            return fn(a[0], a[1], a[2], a[2], a[3], lo, hi, 0.0, mp, dt, drive, friction)

    else:

        @numba.njit
        def call(a, lo, hi, p, mp, dt):
            return fn(a[0], a[1], a[2], a[3], lo, hi, 0.0, mp, dt, drive, friction)

    return call


def _intervals():
    out = []
    for length in range(1, 21):
        out.append((1, length))  # from block 1
        out.append((N - length + 1, N))  # to block N
        lo = 2 + (7 * length) % (N - length - 1)
        out.append((lo, lo + length - 1))
    return out


def _arrays(rng, name, variant, lo, hi):
    """Inputs of the stage ``name`` (arrays of N + 2 blocks with their ghost cells)."""
    size = N + 2
    x = np.cumsum(rng.uniform(0.9, 1.1, size)) + 1e-3 * rng.standard_normal(size)
    v = rng.uniform(0.2, 2.0, size)
    th = rng.uniform(0.0, 1.0, size)
    scratch = [rng.standard_normal(size) for _ in range(5)]
    if name == "stage2_run":
        xs = x + 0.005 * v
        scratch[0] = xs
        scratch[1] = v + 0.005 * rng.standard_normal(size)
        scratch[3] = 1e-2 * rng.standard_normal(size)
        if variant == "stop-first":
            v[lo] = -0.5
        elif variant == "stop-last":
            v[hi] = -0.5  # the last block, in the masked group
        elif variant == "nan-last":
            v[hi] = math.nan  # NaN is not > 0: stops
        elif variant == "stop-outside":
            v[lo - 1] = v[hi + 1] = -5.0
    if name in ("stage1_theta", "stage1_theta_only", "stage2_theta") and variant != "dense":
        # Stopped blocks whose state variable mostly keeps every bit: zero rates and predictors
        # except at a few blocks, signed zeros and a NaN among theta.
        v[:] = 0.0
        keep = rng.random(size) < 0.8
        th = np.where(keep, rng.choice(np.array([0.0, -0.0, 0.25, math.nan]), size), th)
        for k in (2, 4):  # ths and b1
            scratch[k] = np.where(rng.random(size) < 0.85, 0.0, scratch[k])
        if variant == "none-change":
            scratch[2][:] = 0.0
            scratch[4][:] = 0.0
    if name in ("stage1_run", "stage2_run", "stage1_theta"):
        # x, v, th, then xs, vs, ths, a1, b1 (runs) or xs, vs, ths, mm, b1 (stage1_theta)
        return [x, v, th, *scratch]
    if name == "stage1_theta_only":  # v, th, ths, b1
        return [v, th, scratch[2], scratch[4]]
    return [th, scratch[2], v, scratch[4]]  # stage2_theta: th, ths, v, b1


VARIANTS = {
    "stage1_run": ("dense",),
    "stage2_run": ("dense", "stop-first", "stop-last", "nan-last", "stop-outside"),
    "stage1_theta": ("dense", "sparse"),
    "stage1_theta_only": ("dense", "sparse"),
    "stage2_theta": ("dense", "sparse", "none-change"),
}


def _default_pair(name: str, pieces: str) -> bool:
    """The default run's pairs: every stage with the paper's pieces per block (the gathers read
    each block's own values), and the stages that read the drive and the law with the plate's
    per-block pieces too (each pair compiles a kernel of its own; the scalar pieces' lanes run in
    every exact run of a preset, which the default run compares with the dense loops; the rest of
    the cross product runs with -m slow)."""
    return pieces == "paper-per-block" or (PAIRS[name][3] and pieces == "plate-strengthening-per-block")


@pytest.mark.parametrize(
    "name, pieces",
    [(n, c) if _default_pair(n, c) else pytest.param(n, c, marks=pytest.mark.slow) for c in PIECES for n in PAIRS],
)
def test_stage_as_lanes_equals_its_loop_bit_for_bit(name, pieces):
    drive, friction, mp = PIECES[pieces]
    loop, lane, n_arrays, with_drive, dt = PAIRS[name]
    by_loop = _wrapper(loop, n_arrays, with_drive, drive, friction)
    by_lanes = _wrapper(lane, n_arrays, with_drive, drive, friction)
    rng = np.random.default_rng(sum(map(ord, name + pieces)))
    results = set()
    for variant in VARIANTS[name]:
        for lo, hi in _intervals():
            a = _arrays(rng, name, variant, lo, hi)
            p = float(rng.uniform(0.0, 2.0))
            a_loop = tuple(x.copy() for x in a)
            a_lanes = tuple(x.copy() for x in a)
            r_loop = by_loop(a_loop, lo, hi, p, mp, dt)
            r_lanes = by_lanes(a_lanes, lo, hi, p, mp, dt)
            assert r_lanes == r_loop, (variant, lo, hi)
            results.add((r_loop, lo, hi))
            for k, (u, w, before) in enumerate(zip(a_loop, a_lanes, a, strict=True)):
                assert np.array_equal(u.view(np.int64), w.view(np.int64)), (variant, lo, hi, k)
                # Nothing outside lo..hi written (the loop's own contract, checked here once more).
                outside = np.r_[0:lo, hi + 1 : N + 2]
                assert np.array_equal(w[outside].view(np.int64), before[outside].view(np.int64)), (lo, hi, k)
    # The workloads reach the outcomes that differ: blocks that stop and do not; changes that
    # begin past lo and end before hi, and none.
    if name == "stage2_run":
        assert {r for r, _, _ in results} == {True, False}
    if name == "stage2_theta":
        assert any(r == (lo, hi) for r, lo, hi in results if lo < hi)  # all changed
        assert any(r == (hi + 1, lo - 1) for r, lo, hi in results if lo < hi)  # none
        assert any(lo < r[0] <= r[1] < hi for r, lo, hi in results)  # some, inside


# ---------------------------------------------------------------------------------------------
# Which version a kernel gets


def _stub_ir(friction: str, mp) -> str:
    @numba.njit
    def call(th, ths, v, b1, lo, hi, mp, h2):
        return stages._stage2_theta(th, ths, v, v, b1, lo, hi, 0.0, mp, h2, END, friction)

    a = np.linspace(0.1, 0.9, 20)
    call(a, a.copy(), a.copy(), a.copy(), 1, 18, mp, 0.0025)
    return call.inspect_llvm(call.signatures[0])


def test_the_pieces_choose_lanes_or_loop():
    mp_state = PIECES["paper"][2]
    mp_rs = (
        5.0,
        end_drive.Params(),
        constant_threshold.Params(3.0),
        rate_state.PIECE.kernel_params(ChainParams(friction="rate-state")),
        None,
    )
    assert "llvm.masked.load" in _stub_ir(STATE, mp_state)
    # Rate-and-state friction (a logarithm, not + - * /) keeps the loop.
    assert not rate_state.PIECE.lanes
    assert "llvm.masked.load" not in _stub_ir(RATE_STATE, mp_rs)


@pytest.mark.slow
def test_rate_state_chain_exact_equals_dense():
    """A law without lanes runs its loops in the exact integrator: same bits as the dense one."""
    p = ChainParams(N=5, K=5.0, friction="rate-state")
    runs = [run_chain(p, 200.0, integrator=i, start="steady", perturbation=1e-4) for i in ("dense", "exact")]
    assert len(runs[0].events) > 0
    assert runs[0].summary["state_sha256"] == runs[1].summary["state_sha256"]
    assert np.array_equal(runs[0].state.x.view(np.int64), runs[1].state.x.view(np.int64))
