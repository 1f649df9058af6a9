"""Rate-and-state without a static threshold (threshold none) on the inertial route: a slide-hold-
slide test on the single block (N = 1, end of a load history) with a small mass M tends to the
quasi-static spring-slider k (p - x) = mu(v, theta) of the laboratory (stickslip.lab.quasi_static,
an adaptive integrator that shares no code with the kernels) linearly in M.
"""

from __future__ import annotations

import numpy as np
import pytest

from stickslip.lab import LoadHistory, quasi_static
from stickslip.lab.laws import RateState, friction_of
from stickslip.models.params import ParameterError
from stickslip.models.presets import chain_params
from stickslip.run.driver import ChainState, run_chain

# The lab's standard case (a, b, D_c, mu0, V0, k) with sigma_n = 1, so K = k; the asinh form is
# the chain's rate-state law.
A, B, DC, MU0, V0, K = 0.005, 0.01, 10.0, 0.6, 1.0, 1e-3
SHS = LoadHistory.steps([1.0, 0.0, 1.0], [20.0, 10.0, 40.0])
T = (10.0, 25.0, 30.0, 35.0, 40.0, 50.0)
T_END = 69.0


def _slip_error(M):
    model = RateState(a=A, b=B, Dc=DC, mu0=MU0, V0=V0, k=K, form="asinh")
    qs = quasi_static(model, SHS, t=np.array([*T, T_END]))
    x0 = -friction_of(model, 1.0, np.array([DC])) / K  # steady sliding at V = 1: K (0 - x0) = mu_ss
    p = chain_params(
        "sakaguchi", N=1, drive="history", history=SHS, friction="rate-state", threshold="none",
        rs_a=A, rs_b=B, Dc=DC, v0=V0, mu0=MU0, sigma_n=1.0, K=K, M=M, dt=M / 4, V=1.0,
    )  # fmt: skip
    start = ChainState.from_blocks([x0], [1.0], [DC], [False])
    run = run_chain(p, T_END, integrator="exact", start=start, snapshot_times=T)
    slip = run.snapshots.values[:, 0] - x0
    assert run.snapshots.shape == (len(T) + 1, 1)
    # the block slides through the hold: its slip rate stays > 0
    assert float(run.state.blocks()["v"][0]) > 0.0
    return float(np.max(np.abs(slip - qs.slip.values)))


def test_inertial_slide_hold_slide_tends_to_the_quasi_static_one_linearly_in_the_mass():
    masses = np.array([1e-3, 5e-4, 2.5e-4])
    errors = np.array([_slip_error(M) for M in masses])
    slope = np.polyfit(np.log(masses), np.log(errors), 1)[0]
    assert 0.9 < slope < 1.1, (slope, errors)
    assert errors[-1] < 0.05  # of a slip of 60 (D_c = 10)
    # error / M: the same constant at each mass (the first-order term of the expansion in M)
    np.testing.assert_allclose(errors / masses, errors[-1] / masses[-1], rtol=0.05)


def test_threshold_none_needs_rate_and_state():
    with pytest.raises(ParameterError, match="threshold none needs a rate-and-state friction"):
        chain_params("sakaguchi", N=3, threshold="none")
