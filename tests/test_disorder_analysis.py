"""The Lyapunov exponent and the decorrelation of slip sequences on chains with per-block
parameters (docs/model.md, "Per-block parameters"): the analyses run them as they run a
uniform chain, with the same exactness checks."""

from __future__ import annotations

import numpy as np
import pytest

from stickslip import ChainParams, Quenched
from stickslip.analysis.dynamics.decorrelation import event_decorrelation
from stickslip.analysis.dynamics.lyapunov import largest_lyapunov
from stickslip.models.presets import chain_params
from stickslip.run.driver import run_chain

# The per-block chain of tests/test_disorder_runs.py (Fs and beta per block): compiled once.
P = ChainParams(N=6, V=0.01, Fs=Quenched("uniform", 2.5, 3.5, seed=3), beta=Quenched("normal", 1.0, 0.1, seed=3))


def test_lyapunov_reference_is_the_run_and_both_engines_agree():
    kw = dict(interval=10.0, transient=200.0, segments=4)
    lean = largest_lyapunov(P, 1500.0, engine="lean", **kw)
    public = largest_lyapunov(P, 1500.0, engine="run_chain", **kw)
    assert lean.reference_sha256 == run_chain(P, 1500.0).state.sha256()
    assert np.array_equal(lean.log_growth, public.log_growth)
    assert lean.lyapunov == public.lyapunov and lean.events == public.events > 0


@pytest.mark.slow
def test_located_decorrelation_of_a_disordered_pair_of_blocks():
    """Two blocks with thresholds 0.9 and 1.1 (located switches): the run against itself never
    decorrelates, and a tiny kick does within the window, as for the uniform pair."""
    params = chain_params("two-blocks", Fs=np.array([0.9, 1.1]))
    state = run_chain(params, 500.0, start="rest", perturbation=0.01).state
    same = event_decorrelation(params, state, (0.0,), t_max=1500.0)
    assert same.rows[0]["decorrelated"] is False and same.reference_events > 20
    kicked = event_decorrelation(params, state, (1e-6,), t_max=1500.0)
    assert kicked.rows[0]["events"] < kicked.reference_events
