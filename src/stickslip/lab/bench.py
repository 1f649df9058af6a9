"""The lab's speed, measured as ratios in one run: the quasi-static spring-slider against a
plain-Python odeint model of the same equations, the CPU time of a four-parameter fit, and the
inertial route (the chain's single block with a small mass, rate-and-state without a static
threshold) driven by a slide-hold-slide load history against the same run at a constant V.

The case is the field's standard velocity step: a = 0.005, b = 0.01, D_c = 10, mu0 = 0.6, V0 = 1,
k = 1e-3, the load point stepping 1 -> 10 at t = 10, run to t = 100 with 1001 outputs, at rtol 1e-10
in both. Every timing is CPU time (``process_time``: on a shared machine wall-clock time counts the
other processes' turns), after one run that compiles; a call of a millisecond or so is timed in
batches long enough for the clock (:class:`timeit.Timer`'s ``autorange``), the three ways taken
in turn in each of ``repeats`` rounds, and each keeps its least time per call. How the numbers
compare with the targets is in docs/lab.md and docs/performance.md.
"""

from __future__ import annotations

import time
import timeit

import numpy as np

from stickslip.lab.fitting import fit
from stickslip.lab.history import LoadHistory
from stickslip.lab.laws import RateState
from stickslip.lab.records import synthetic
from stickslip.lab.reference import odeint_one_state
from stickslip.lab.spring_slider import quasi_static, solve

__all__ = ["bench", "inertial_history_cost"]

CASE = dict(a=0.005, b=0.01, Dc=10.0, mu0=0.6, V0=1.0, k=1e-3)


def _best_interleaved(fns: dict, repeats: int) -> dict:
    """The least CPU time per call of each function, timed in turn in each of ``repeats`` rounds
    (module docstring), so that a change of the machine's load falls on all of them alike."""
    timers = {name: timeit.Timer(fn, timer=time.process_time) for name, fn in fns.items()}
    number = {name: max(1, timer.autorange()[0]) for name, timer in timers.items()}
    best = dict.fromkeys(fns, np.inf)
    for _ in range(repeats):
        for name, timer in timers.items():
            best[name] = min(best[name], timer.timeit(number[name]) / number[name])
    return best


def inertial_history_cost(repeats: int = 7, M: float = 1e-3) -> dict:
    """The inertial route's cost with a load history against its cost at a constant V: the chain's
    single block (N = 1, mass ``M``, dt = M / 4, the exact integrator) with the case's
    rate-and-state law and no static threshold, from steady sliding over the same 276,000 steps,
    driven three ways: a slide-hold-slide history (V = 1 for 20, a hold of 10, V = 1 for 40;
    drive ``history``), a history at the one velocity V = 1 (drive ``history``: the same
    trajectory, bit for bit, as the constant V, so it isolates the cost of reading the load point
    from a table), and the end drive at V = 1.

    Each run is timed in CPU time (``process_time``: on a shared machine wall-clock time counts the
    waits for a core, which a busy neighbour makes longer for one run than for another); each
    timing is the least of ``repeats`` runs, taken in turns, after one that compiles.

    Returns
    -------
    dict
        ``history_s``, ``flat_history_s``, ``constant_s`` (CPU seconds), the ratios ``ratio``
        (slide-hold-slide over constant V; target: at most 1.1) and ``flat_ratio``, the median
        ratios ``ratio_median`` and ``flat_ratio_median``, ``steps``, ``same_steps``,
        ``flat_same_state`` (the history at one V ends in the constant V's state, bit for bit) and
        ``repeats``.
    """
    from stickslip.lab.laws import friction_of
    from stickslip.models.presets import chain_params
    from stickslip.run.driver import ChainState, run_chain

    law = dict(
        friction="rate-state", threshold="none", rs_a=CASE["a"], rs_b=CASE["b"], Dc=CASE["Dc"], v0=CASE["V0"],
        mu0=CASE["mu0"], sigma_n=1.0, K=CASE["k"], M=M, dt=M / 4, V=1.0,
    )  # fmt: skip
    t_end = 69.0
    shs = LoadHistory.steps([1.0, 0.0, 1.0], [20.0, 10.0, 40.0])
    flat = LoadHistory.steps([1.0], [t_end])
    x0 = -friction_of(RateState(**CASE, form="asinh"), 1.0, np.array([CASE["Dc"]])) / CASE["k"]
    runs = {
        "history": chain_params("sakaguchi", N=1, drive="history", history=shs, **law),
        "flat_history": chain_params("sakaguchi", N=1, drive="history", history=flat, **law),
        "constant": chain_params("sakaguchi", N=1, **law),
    }
    go = {
        name: lambda p=p: run_chain(
            p, t_end, integrator="exact", start=ChainState.from_blocks([x0], [1.0], [CASE["Dc"]], [False])
        )
        for name, p in runs.items()
    }
    first = {name: fn() for name, fn in go.items()}
    steps = {name: r.summary["steps"] for name, r in first.items()}
    times = {name: [] for name in go}
    for _ in range(repeats):  # interleaved, so a change in the machine's load meets all alike
        for name, fn in go.items():
            t0 = time.process_time()
            fn()
            times[name].append(time.process_time() - t0)
    best = {name: min(v) for name, v in times.items()}
    median = {name: float(np.median(v)) for name, v in times.items()}
    return {
        "history_s": best["history"],
        "flat_history_s": best["flat_history"],
        "constant_s": best["constant"],
        "ratio": best["history"] / best["constant"],
        "flat_ratio": best["flat_history"] / best["constant"],
        "ratio_median": median["history"] / median["constant"],
        "flat_ratio_median": median["flat_history"] / median["constant"],
        "steps": int(steps["constant"]),
        "same_steps": len(set(steps.values())) == 1,
        "flat_same_state": first["flat_history"].state.sha256() == first["constant"].state.sha256(),
        "repeats": repeats,
    }


def bench(repeats: int = 5) -> dict:
    """Time the velocity step both ways and a four-parameter fit (module docstring).

    Returns
    -------
    dict
        ``quasi_static_s`` (the Dataset), ``arrays_s`` (:func:`~stickslip.lab.spring_slider.solve`,
        arrays as odeint returns them), ``odeint_s``, ``speed_ratio`` and ``speed_ratio_arrays``
        (odeint's time over each), ``max_abs_mu_difference``,
        ``fit_cpu_s`` (a, b, D_c, mu0 from a noisy 500-sample record), ``fit_evaluations``, the
        fitted values with their standard errors, and ``inertial_history``
        (:func:`inertial_history_cost`).
    """
    model = RateState(**CASE)
    history = LoadHistory.steps([1.0, 10.0], [10.0, 90.0])
    t = np.linspace(0.0, 100.0, 1001)
    qs = lambda: quasi_static(model, history, t=t, rtol=1e-10)
    ref = lambda: odeint_one_state(
        CASE["a"], CASE["b"], CASE["Dc"], CASE["mu0"], CASE["V0"], CASE["k"], history, t, rtol=1e-10
    )
    arrays = lambda: solve(model, history, t, rtol=1e-10)
    ds = qs()
    mu_ref = ref()[0]
    times = _best_interleaved({"qs": qs, "arrays": arrays, "ref": ref}, repeats)
    t_qs, t_arrays, t_ref = times["qs"], times["arrays"], times["ref"]
    rec = synthetic(model, history, n=500, noise=1e-4, rng=0)
    start = model.with_values(a=0.007, b=0.007, Dc=5.0, mu0=0.59)
    fit(rec, start, ("a", "b", "Dc", "mu0"))  # compiles nothing new; warms the caches
    cpu = np.inf
    for _ in range(max(1, repeats // 2)):
        res = fit(rec, start, ("a", "b", "Dc", "mu0"))
        cpu = min(cpu, res.cpu_seconds)
    return {
        "case": {**CASE, "law": "aging", "step": "V 1 -> 10 at t = 10, t_end = 100, 1001 outputs, rtol 1e-10"},
        "quasi_static_s": t_qs,
        "odeint_s": t_ref,
        "speed_ratio": t_ref / t_qs,
        "arrays_s": t_arrays,
        "speed_ratio_arrays": t_ref / t_arrays,
        "max_abs_mu_difference": float(np.max(np.abs(ds.mu.values - mu_ref))),
        "quasi_static_steps": int(ds.attrs["steps"]),
        "fit_cpu_s": cpu,
        "fit_evaluations": res.evaluations,
        "fit": {
            n: {"value": float(v), "stderr": float(e)}
            for n, v, e in zip(res.names, res.values, res.errors, strict=True)
        },
        "fit_truth": {"a": CASE["a"], "b": CASE["b"], "Dc": CASE["Dc"], "mu0": CASE["mu0"]},
        "inertial_history": inertial_history_cost(max(3, repeats)),
        "repeats": repeats,
    }
