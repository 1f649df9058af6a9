"""Per-block parameters on the integrators: dense = exact = plain Python, bit for bit.

The oracle (``het_heun_step``) is written from docs/model.md, "Per-block parameters": the springs
per bond K_i (x_{i-1} - x_i) - K_{i+1} (x_i - x_{i+1}) plus the drive's force with K = 0, the
friction of each law with block i's parameters, divided by the mass M_i, and the start rule
against block i's threshold. It shares no code with the package. The property test draws
distributions and seeds (the values, not the types, so each model compiles once).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from chain_helpers import assert_bits_equal, assert_same_run, heun_frame, oracle_run, random_start
from stickslip import Quenched
from stickslip.models.params import ChainParams
from stickslip.run.driver import ChainState, run_chain

LIVELY = dict(K=5.0, V=0.2, Kp=1.0, beta=0.5, alpha=0.7, sigma=0.2, F0=0.5, D=2.0, Fs=0.9, dt=0.005)

# (pieces, the parameters drawn per block): every parameter the composition reads, the springs
# and the masses; the plate with weakening friction runs the sparse path.
CASES = {
    "end-state-constant-free": (("end", "state", "constant", "free"), ("K", "M", "beta", "alpha", "D", "Fs")),
    "plate-weakening-constant-periodic": (
        ("plate", "weakening", "constant", "periodic"),
        ("K", "M", "Kp", "alpha", "sigma", "Fs"),
    ),
    "end-strengthening-constant-fixed": (("end", "strengthening", "constant", "fixed"), ("K", "M", "beta", "F0", "Fs")),
    "plate-state-state-free": (("plate", "state", "state", "free"), ("K", "M", "Kp", "beta", "alpha", "D")),
}
FAST = ("end-state-constant-free", "plate-weakening-constant-periodic")
#: The default run's case (every kind of per-block parameter: springs per bond, masses, the law's
#: and the threshold's); the others, among them the plate's sparse path, run with -m slow.
DEFAULT = ("end-state-constant-free",)


def _cases(names):
    return [c if c in DEFAULT else pytest.param(c, marks=pytest.mark.slow) for c in names]


def _spread(name, value, rng, N, width=0.3):
    """Values around ``value``, within every range these parameters allow."""
    lo = value * (1.0 - width)
    if name == "sigma":
        return rng.uniform(0.05, 0.4, N)
    return rng.uniform(lo, value * (1.0 + width), N)


def _params(case, N, seed, **extra):
    pieces, drawn = CASES[case]
    rng = np.random.default_rng(seed)
    values = {k: _spread(k, LIVELY.get(k, 1.0), rng, N) for k in drawn}
    d, f, t, e = pieces
    return ChainParams(N=N, drive=d, friction=f, threshold=t, ends=e, **{**LIVELY, **values, **extra})


def _value(p, name):
    """Parameter ``name`` at blocks 1..N (index 0..N-1) from ChainParams."""
    value = getattr(p, name)
    return list(value.values) if hasattr(value, "values") else [float(value)] * p.N


def het_heun_step(x, v, th, moving, n, p):
    """One Heun step of the heterogeneous chain ``p`` (docs/model.md, "Per-block parameters")
    from t_n = n dt; blocks 1..N at index 0..N-1."""
    K = _value(p, "K")
    bonds = len(set(K)) > 1
    # K_{N+1}: K_1 on a ring (the same spring), K_N otherwise.
    Kb = [K[0]] + K + ([K[0]] if p.ends == "periodic" else [K[-1]])
    Kp, beta, alpha, D = (_value(p, k) for k in ("Kp", "beta", "alpha", "D"))
    sigma, F0, Fs, M = (_value(p, k) for k in ("sigma", "F0", "Fs", "M"))
    unit = not hasattr(p.M, "values") and p.M == 1.0

    def force(X, i, plate):
        j = i - 1
        if bonds:
            g = 0.0 * ((X[i - 1] - X[i]) - (X[i] - X[i + 1]))
            if p.drive == "plate":
                g = g + Kp[j] * (plate - X[i])
            return (Kb[i] * (X[i - 1] - X[i]) - Kb[i + 1] * (X[i] - X[i + 1])) + g
        f = K[0] * ((X[i - 1] - X[i]) - (X[i] - X[i + 1]))
        if p.drive == "plate":
            f = f + Kp[j] * (plate - X[i])
        return f

    def accel(f, thi, vi, i):
        j = i - 1
        if p.friction == "state":
            a = f - thi - beta[j] * vi
        elif p.friction == "weakening":
            s = sigma[j]
            a = f - (1 - s) / (1 + 2 * alpha[j] * max(vi, 0.0) / (1 - s))
        else:
            a = f - F0[j] - beta[j] * vi
        return a if unit else a / M[j]

    def dtheta(TH, i, vi):
        if p.friction != "state":
            return 0.0
        j = i - 1
        return TH[i] * (1.0 - TH[i]) - alpha[j] * TH[i] * vi + D[j] * ((TH[i - 1] - TH[i]) - (TH[i] - TH[i + 1]))

    def threshold(TH, i):
        return TH[i] if p.threshold == "state" else Fs[i - 1]

    return heun_frame(x, v, th, moving, n, p, lambda X, i, plate, step: force(X, i, plate), accel, dtheta, threshold)


def _start(p, seed, pstop=0.5):
    return random_start(p, seed, pstop)


def _runs(p, start, steps):
    x, v, th, stopped = start
    runs = {}
    for integrator in ("dense", "exact"):
        s = ChainState.from_blocks(x, v, th, stopped)
        runs[integrator] = run_chain(p, steps * p.dt, integrator=integrator, start=s, sample_interval=p.dt)
    return runs


@pytest.mark.parametrize("case", _cases(CASES))
def test_heterogeneous_chain_matches_plain_python(case):
    p = _params(case, 9, seed=5)
    assert set(p.per_block()) == set(CASES[case][1])
    start = _start(p, seed=2)
    steps = 2500
    ref = oracle_run(*(a.tolist() for a in start[:3]), (~start[3]).tolist(), p, steps, step=het_heun_step)
    assert ref.nonfinite is None
    runs = _runs(p, start, steps)
    for integrator, run in runs.items():
        b = run.state.blocks()
        assert_bits_equal(b["x"], ref.x, f"{integrator} x")
        assert_bits_equal(b["v"], ref.v, f"{integrator} v")
        assert_bits_equal(b["theta"], ref.th, f"{integrator} theta")
        assert_bits_equal(run.samples["L"].values, ref.L, f"{integrator} L")
        assert len(run.events) == len(ref.events)
    assert_same_run(runs["dense"], runs["exact"])
    assert len(ref.events) >= 1 or any(ref.moving)


# Every parameter of eq. (4) as an array (with -m slow), and the springs with the thresholds and
# the friction's beta, the per-block parameters of tests/test_disorder_runs.py (one composition
# compiled for both in the default run).
@pytest.mark.parametrize(
    "names", [("K", "Fs", "beta"), pytest.param(("K", "beta", "alpha", "D", "Fs"), marks=pytest.mark.slow)]
)
def test_uniform_values_given_as_arrays_give_the_scalar_chain_bits(names):
    """Parameters as arrays of equal values (read at each block) give the scalar chain's bits;
    equal springs keep the uniform expression."""
    N = 12
    scalar = ChainParams(N=N, **LIVELY)
    arrays = ChainParams(N=N, **{**LIVELY, **{k: np.full(N, LIVELY[k]) for k in names}})
    assert set(arrays.per_block()) == set(names)
    start = _start(scalar, seed=4)
    a, b = _runs(scalar, start, 3000), _runs(arrays, start, 3000)
    for integrator in ("dense", "exact"):
        assert_same_run(a[integrator], b[integrator])


@pytest.mark.slow
def test_unit_masses_given_as_an_array_divide_by_one():
    """M_i = 1 divides by 1, which changes no bit: the chain of unit masses."""
    p = _params("end-state-constant-free", 10, seed=1)
    q = p.replace(M=np.ones(10))
    r = p.replace(M=1.0)
    start = _start(p, seed=3)
    assert_same_run(_runs(q, start, 1500)["exact"], _runs(r, start, 1500)["dense"])


DISTS = st.sampled_from(
    [
        ("uniform", 0.6, 1.4),
        ("normal", 1.0, 0.2),
        ("lognormal", 0.0, 0.2),
        ("weibull", 4.0, 1.0),
        ("exponential", 1.0),
        ("asperities", 1.5, 0.8),
    ]
)


@pytest.mark.parametrize("case", _cases(FAST))
@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(dist=DISTS, seed=st.integers(0, 2**16), N=st.integers(8, 20))
def test_drawn_disorder_dense_equals_exact(case, dist, seed, N):
    """dense = exact bit for bit over distributions, seeds and models (each parameter the
    composition reads scaled by a drawn factor)."""
    pieces, drawn = CASES[case]
    name, *args = dist
    factors = {k: Quenched(name, *args, seed=seed + j).draw(k, N, 0.0, None) for j, k in enumerate(drawn)}
    values = {k: LIVELY.get(k, 1.0) * np.clip(factors[k], 0.3, 3.0) for k in drawn}
    if "sigma" in values:
        values["sigma"] = np.clip(values["sigma"], 0.0, 0.9)
    d, f, t, e = pieces
    p = ChainParams(N=N, drive=d, friction=f, threshold=t, ends=e, **{**LIVELY, **values})
    runs = _runs(p, _start(p, seed), 1500)
    assert_same_run(runs["dense"], runs["exact"])
