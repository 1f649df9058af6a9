"""The random-medium drives (models/drive/constant_force.py, force_ramp.py): a constant force F on
every block and a force ramp F_start + r t, with nothing pulling block 1.

dense = exact bit for bit (exact takes the plate's paths: the sparse lists without theta, the
interval with theta); the plain-Python step of docs/model.md is in tests/test_models_exact.py
(COVER); a force below the static threshold moves nothing; above it the strengthening law slides
at the closed-form v = (F - F0) / beta, which is also the steady stop's target.
"""

from __future__ import annotations

import numpy as np
import pytest

from chain_helpers import assert_same_run
from stickslip import chain_params
from stickslip.models import physics
from stickslip.models.params import ParameterError
from stickslip.run.driver import ChainState, run_chain


def _rest(p, seed=1):
    return ChainState.rest(p, amplitude=0.05, seed=seed)


# The default run takes the compositions the rest of it compiles (tests/test_models_exact.py's
# COVER, whose force drive with theta is there); the others compile for -m slow alone.
@pytest.mark.parametrize(
    "over, t_end",
    [
        ({"drive": "constant-force", "friction": "strengthening", "F": 3.2}, 200.0),
        pytest.param(
            {"drive": "constant-force", "friction": "state", "F": 3.1, "D": 1.0, "beta": 0.5},
            200.0,
            marks=pytest.mark.slow,
        ),
        ({"drive": "force-ramp", "friction": "strengthening", "F_start": 2.0, "r": 0.01}, 300.0),
        pytest.param(
            {"drive": "force-ramp", "friction": "state", "F_start": 2.5, "r": 0.01, "D": 1.0},
            200.0,
            marks=pytest.mark.slow,
        ),
        pytest.param(
            {"drive": "force-ramp", "friction": "weakening", "ends": "periodic", "F_start": 2.5, "r": 0.02},
            200.0,
            marks=pytest.mark.slow,
        ),
    ],
)
def test_dense_equals_exact(over, t_end):
    p = chain_params("sakaguchi", N=24, **over) if over["friction"] == "state" else _chain(**over)
    runs = [run_chain(p, t_end, integrator=i, start=_rest(p), sample_interval=1.0) for i in ("dense", "exact")]
    assert_same_run(*runs)
    assert runs[0].summary["n_events"] > 0 or not np.array_equal(runs[0].state.x, _rest(p).x)


def _chain(**over):
    from stickslip.models.params import ChainParams

    return ChainParams(**{"N": 24, "Fs": 3.0, **over})


def test_force_below_the_threshold_moves_nothing():
    # F < Fs = 3 and springs stretched by at most K * 4e-3 = 0.04: every block pinned.
    p = _chain(drive="constant-force", friction="strengthening", F=2.9)
    start = ChainState.rest(p, amplitude=1e-3, seed=1)
    for integrator in ("dense", "exact"):
        run = run_chain(p, 500.0, integrator=integrator, start=start.copy(), sample_interval=50.0)
        assert run.summary["n_events"] == 0
        assert run.state.sha256() == start.sha256()
    # The fast path jumps: with every block pinned there is no step to compute.
    assert run.summary["steps_computed"] == 0


def test_force_above_the_threshold_slides_at_the_closed_form_velocity():
    F, F0, beta = 3.2, 1.0, 0.5
    p = _chain(drive="constant-force", friction="strengthening", F=F, F0=F0, beta=beta)
    v_ss = (F - F0) / beta
    assert physics.steady_velocity(p) == pytest.approx(v_ss, rel=1e-14)
    run = run_chain(p, 60.0, start=_rest(p), sample_interval=1.0)
    v = run.state.blocks()["v"]
    assert not run.state.blocks()["stopped"].any()
    # The springs' forces sum to zero, so the mean velocity relaxes as exp(-beta t) (e^-30 here);
    # the springs' modes ring down more slowly.
    assert float(np.mean(v)) == pytest.approx(v_ss, rel=1e-10)
    np.testing.assert_allclose(v, v_ss, rtol=1e-6)
    # The steady stop reaches the closed-form state.
    stopped = run_chain(p, 1e4, start=_rest(p), sample_interval=1.0, until_steady=1e-8)
    assert stopped.summary["stopped_early"]
    assert stopped.summary["t_steady"] < 100.0 and stopped.summary["steady_deviation"] <= 1e-8


def test_disordered_constant_force_steady_velocity():
    # sum_i (F - F0_i - beta_i v) = 0 gives v = (N F - sum F0_i) / sum beta_i.
    p = _chain(drive="constant-force", friction="strengthening", F=3.2, N=8)
    q = p.replace()
    F0 = np.linspace(0.5, 1.5, 8)
    beta = np.linspace(0.4, 0.9, 8)
    object.__setattr__(q, "F0", F0)
    object.__setattr__(q, "beta", beta)
    v = (8 * 3.2 - F0.sum()) / beta.sum()
    ss = physics.chain_steady_state(q, 0.0)
    assert ss["v"][0] == pytest.approx(v, rel=1e-14)
    # Each block's force balance: K (x_{i-1} - 2 x_i + x_{i+1}) + F = F0_i + beta_i v, free ends.
    x = ss["x"]
    X = np.concatenate(([x[0]], x, [x[-1]]))
    f = p.K * ((X[:-2] - X[1:-1]) - (X[1:-1] - X[2:])) + 3.2
    np.testing.assert_allclose(f, F0 + beta * v, rtol=0, atol=1e-12)


def test_ramp_reads_its_rate_as_the_pull_velocity():
    p = _chain(drive="force-ramp", friction="strengthening", F_start=0.5, r=2e-3, V=0.7)
    assert p.drive_piece.kernel_velocity(p) == 2e-3
    assert not physics.has_steady_state(p)
    assert "r" in p.used() and "F_start" in p.used()
    # From rest the first block starts when 0.5 + r t exceeds Fs plus its springs' pull: every
    # block alike at a flat start, so at t = (Fs - F_start) / r = 1250 (to a step).
    p_flat = p.replace(N=5)
    rest = ChainState.rest(p_flat, amplitude=0.0)
    before = run_chain(p_flat, 1250.0 - 2 * p.dt, start=rest.copy(), sample_interval=10.0)
    assert before.state.sha256() == rest.sha256()
    after = run_chain(p_flat, 1250.0 + 2 * p.dt, start=rest.copy(), sample_interval=10.0)
    assert not after.state.blocks()["stopped"].any()


def test_force_drives_refuse_the_located_integrator_and_the_end_ring():
    from stickslip.run.located import LocatedStepper

    with pytest.raises(ParameterError, match="located"):
        LocatedStepper(_chain(drive="constant-force", friction="strengthening"))
    with pytest.raises(ParameterError, match="acts on every block"):
        _chain(drive="end", friction="strengthening", ends="periodic")


def test_command_line_composes_the_drives(capsys):
    from stickslip.cli import main

    assert main(["models", "--json"]) == 0
    out = capsys.readouterr().out
    assert "constant-force" in out and "force-ramp" in out
    args = ["chain", "--drive", "constant-force", "--friction", "strengthening", "--F", "3.2", "--N", "8"]
    assert main(args + ["--t-end", "20", "--start", "rest", "--json"]) == 0
    capsys.readouterr()
    args = ["chain", "--drive", "force-ramp", "--friction", "strengthening", "--F-start", "0", "--r", "1e-4"]
    assert main(args + ["--N", "8", "--t-end", "20", "--start", "rest", "--json"]) == 0
    capsys.readouterr()
    assert main(["chain", "--drive", "constant-force", "--F", "-1", "--N", "8", "--t-end", "20"]) == 2
    assert "F must be >= 0" in capsys.readouterr().err
