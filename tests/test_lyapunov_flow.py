"""The exponent of the flow (stickslip.analysis.dynamics.lyapunov_flow): known answers, the neutral
direction, the extrapolation and the command line.

Known answers, none computed by the code under test:
- steady sliding of the single block at V = 0.5: the largest real part of the eigenvalues of
  eq. (2) (stickslip.analysis.dynamics.stability, a 3 x 3 eigenvalue problem), -0.4865;
- a periodic orbit (the single block's stick-slip cycle): the largest exponent of a limit cycle
  is zero, the exponent of a shift in time; with that direction removed the transverse exponent
  is negative (the stuck block's theta relaxes at rate about 1 and a stop contracts v);
- a perturbation along the flow is a shift in time: with the neutral direction removed it gives
  no growth at all;
- Richardson's model lambda_0 + c dt^2 fitted to data built from it gives lambda_0 back.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from chain_helpers import run_cli
from stickslip.analysis.dynamics.benettin import remove_flow
from stickslip.analysis.dynamics.lyapunov_flow import (
    extrapolate,
    flow_direction,
    flow_lyapunov,
    separation,
    twin_state,
)
from stickslip.analysis.dynamics.stability import block_eigenvalues
from stickslip.models.params import BlockParams, ChainParams, ParameterError
from stickslip.models.presets import chain_params
from stickslip.run.located import LocatedStepper, start_state

STEADY = ChainParams(N=1, K=10.0, V=0.5, beta=1.0, Fs=3.0)
CYCLE = ChainParams(N=1, K=10.0, V=0.05, beta=1.0, Fs=3.0)


def test_steady_sliding_of_the_block_decays_at_the_rate_of_eq_2():
    expected = float(block_eigenvalues(BlockParams(K=10.0, V=0.5, beta=1.0, Fs=3.0))[0].real)
    assert expected == pytest.approx(-0.4865, abs=1e-4)
    res = flow_lyapunov(STEADY, 600.0, start="steady", d0=1e-8)
    assert res.events == 0
    assert abs(res.lyapunov - expected) < max(4 * res.lyapunov_err, 2e-4)


def test_periodic_orbit_zero_along_the_flow_negative_across_it():
    kept = flow_lyapunov(CYCLE, 2000.0, start="rest", d0=1e-8, neutral="keep")
    removed = flow_lyapunov(CYCLE, 2000.0, start="rest", d0=1e-8, neutral="remove")
    assert kept.events > 100
    assert abs(kept.lyapunov) < 0.01
    assert removed.lyapunov < -0.5


def _along_the_flow(params, start, amplitude, t0, d0=1e-8):
    """Growth |dy| / d0 and what is left across the flow, for a twin placed d0 along F(y)."""
    stepper = LocatedStepper(params)
    ref = start_state(params, start, perturbation=amplitude)
    ref, _ = stepper.advance(ref, round(t0 / params.dt))
    twin = twin_state(ref, flow_direction(ref, params), d0, params)
    d_start = np.linalg.norm(separation(ref, twin, params))
    growth, across = [], []
    for _ in range(20):
        ref, _ = stepper.advance(ref, ref.step + round(5.0 / params.dt))
        twin, _ = stepper.advance(twin, ref.step)
        while not np.array_equal(ref.mov, twin.mov):
            ref, _ = stepper.advance(ref, ref.step + 1)
            twin, _ = stepper.advance(twin, ref.step)
        dy = separation(ref, twin, params)
        growth.append(np.linalg.norm(dy) / d_start)
        across.append(np.linalg.norm(remove_flow(dy, flow_direction(ref, params), 1e-9)) / d_start)
    return np.array(growth), np.array(across)


def test_a_perturbation_along_the_flow_does_not_grow():
    """Along the flow d swings with |F| (sticking against slipping); across it almost nothing is
    left. The located map commutes with a shift in time up to its discretisation error only (the
    error of a slip depends on where it starts on the grid), so the rest shrinks with dt."""
    growth, across = _along_the_flow(CYCLE, "rest", 0.0, 100.0)
    _, across_fine = _along_the_flow(CYCLE.replace(dt=CYCLE.dt / 4), "rest", 0.0, 100.0)
    assert growth.max() / growth.min() > 3.0
    assert across.max() < 1e-3
    assert across_fine.max() < across.max() / 3
    growth, across = _along_the_flow(chain_params("two-blocks"), "rest", 0.01, 500.0)
    assert growth.max() / growth.min() > 3.0
    assert across.max() < 1e-2


def test_extrapolation_returns_lambda_0_of_richardsons_model():
    dts = np.array([0.01, 0.005, 0.0025])
    lam0, err0, slope = extrapolate(dts, 0.3 + 2.0 * dts**2, [1e-3, 1e-3, 1e-3])
    assert lam0 == pytest.approx(0.3, abs=1e-12) and slope == pytest.approx(2.0, rel=1e-9)
    # the propagated error of a two-parameter fit, from the normal equations
    h = dts**2
    A = np.column_stack((np.ones(3), h)) / 1e-3
    assert err0 == pytest.approx(np.sqrt(np.linalg.inv(A.T @ A)[0, 0]), rel=1e-9)
    # scatter beyond the error bars widens the error by sqrt(chi^2 / dof)
    _, err_scatter, _ = extrapolate(dts, 0.3 + 2.0 * dts**2 + np.array([0.01, -0.02, 0.01]), [1e-3] * 3)
    assert err_scatter > 5 * err0


def test_neutral_must_be_named():
    with pytest.raises(ParameterError, match="neutral must be one of remove, keep"):
        flow_lyapunov(STEADY, 600.0, neutral="drop")


def test_cli_located_prints_the_ladder_and_its_extrapolation(capsys):
    status, out, _ = run_cli(
        capsys, "lyapunov", "--switches", "located", "--N", "1", "--V", "0.5", "--start", "steady",
        "--t-end", "300", "--json", "--no-progress",
    )  # fmt: skip
    assert status == 0
    d = json.loads(out)
    assert d["switches"] == "located" and d["neutral"] == "remove"
    assert [r["dt"] for r in d["ladder"]] == [0.005, 0.0025, 0.00125]
    assert {"dt", "lyapunov", "lyapunov_err"} <= set(d["ladder"][0])
    assert abs(d["lyapunov_dt0"] - (-0.4865)) < 3 * d["lyapunov_dt0_err"] + 1e-3


def test_cli_located_refuses_tables(capsys):
    status, _, err = run_cli(capsys, "lyapunov", "--switches", "located", "--betas", "1", "--N", "2")
    assert status == 2 and "--switches located runs one ladder" in err


@pytest.mark.slow
@pytest.mark.parametrize("t_end", [2e4, 2e5])
def test_block_steady_sliding_at_the_commands_defaults_and_ten_times_longer(t_end):
    """`stickslip lyapunov --switches located --N 1 --V 0.5` (start paper, t_end 2e4) and 10x: the
    positions relative to the drive keep the precision that absolute ones lose as V t grows."""
    expected = float(block_eigenvalues(BlockParams(K=10.0, V=0.5, beta=1.0, Fs=3.0))[0].real)
    res = flow_lyapunov(STEADY, t_end, d0=1e-10)
    assert abs(res.lyapunov - expected) < max(4 * res.lyapunov_err, 1e-4)
    assert max(res.segment_means) - min(res.segment_means) < 2e-3


@pytest.mark.slow
def test_cli_located_at_the_commands_defaults(capsys):
    """`stickslip lyapunov --switches located --N 1 --V 0.5 --json` (start paper, t_end 2e4, the
    ladder dt .. dt/4): extrapolated to dt -> 0, eq. (2)'s -0.4865 itself."""
    status, out, _ = run_cli(
        capsys, "lyapunov", "--switches", "located", "--N", "1", "--V", "0.5", "--json", "--no-progress"
    )
    assert status == 0
    d = json.loads(out)
    expected = float(block_eigenvalues(BlockParams(K=10.0, V=0.5, beta=1.0, Fs=3.0))[0].real)
    assert d["t_end"] == 2e4 and d["lyapunov_dt0_err"] < 1e-4
    assert abs(d["lyapunov_dt0"] - expected) <= 3 * d["lyapunov_dt0_err"]
