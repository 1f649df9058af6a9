"""The largest Lyapunov exponent (Benettin et al. 1980): exactness, known answers, options, CLI.

Known answers, none computed by the code under test:
- steady sliding of the single block (the chain with N = 1) at beta = 1, V = 0.5: the exponent
  is the largest real part of the eigenvalues of eq. (2) (stickslip.analysis.dynamics.stability);
- the stick-slip cycle of the single block at the paper's parameters: a tiny twin starts each
  slip at the same step as the reference (the start rule is tested on the time grid), so the
  separation is multiplied once per cycle by m = d f_end / d Fs of the slip of eq. (3)
  (stickslip.analysis.dynamics.slip_limit, an adaptive integrator): lambda = ln|m| / T(V). A twin much farther
  away than the grid spacing V dt starts at another step and sees the neutral phase of the
  continuous-time cycle: lambda close to 0.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from matplotlib.figure import Figure

from chain_helpers import run_cli
from stickslip.analysis.dynamics.lyapunov import (
    largest_lyapunov,
    lyapunov_convergence,
    lyapunov_vs_beta,
    separation,
    twin_state,
)
from stickslip.analysis.dynamics.slip_limit import solve_slip_limit
from stickslip.analysis.dynamics.stability import block_eigenvalues, chain_finite_eigenvalues
from stickslip.models.params import BlockParams, ChainParams, ParameterError
from stickslip.plotting.lyapunov import plot_lyapunov_beta
from stickslip.run.driver import run_chain

PAPER_BLOCK = ChainParams(N=1, K=10.0, V=0.001, beta=1.0, Fs=3.0)


# ------------------------------------------------------------------------------------------
# Exactness


@pytest.mark.parametrize("interval", [7.3, 10.0])
def test_reference_equals_an_uninterrupted_run_bit_for_bit(interval):
    p = ChainParams(N=6, beta=0.5)
    res = largest_lyapunov(p, 3000.0, interval=interval, transient=500.0)
    assert res.reference_sha256 == run_chain(p, 3000.0).state.sha256()
    assert res.events > 0


def test_lean_engine_equals_public_run_chain():
    p = ChainParams(N=6, beta=0.5)
    kw = dict(interval=10.0, transient=200.0, segments=4)
    lean = largest_lyapunov(p, 1500.0, engine="lean", **kw)
    public = largest_lyapunov(p, 1500.0, engine="run_chain", **kw)
    assert np.array_equal(lean.log_growth, public.log_growth)
    assert lean.reference_sha256 == public.reference_sha256
    assert lean.lyapunov == public.lyapunov and lean.events == public.events


def test_twin_is_d0_away_on_the_reference_branch():
    p = ChainParams(N=8, beta=0.5)
    ev = run_chain(p, 2000.0).events
    ev = ev[(ev["n_blocks"] >= 2) & (ev["step_end"] - ev["step_start"] >= 10)].iloc[0]
    ref = run_chain(p, (ev["step_start"] + 2) * p.dt).state  # early in a slip: some blocks move
    stopped = ref.blocks()["stopped"]
    assert stopped.any() and not stopped.all()
    direction = np.random.default_rng(1).standard_normal(3 * p.N)
    twin = twin_state(ref, direction, 1e-8, p)
    b = twin.blocks()
    assert twin.step == ref.step
    assert np.array_equal(b["stopped"], stopped)
    assert np.all(b["v"][stopped] == 0.0)
    dy = separation(ref, twin, p)
    assert math.isclose(np.linalg.norm(dy), 1e-8, rel_tol=1e-5)
    assert np.all(dy[p.N : 2 * p.N][stopped] == 0.0)
    # the separation is along the projected direction
    u = direction.copy()
    u[p.N : 2 * p.N][stopped] = 0.0
    assert np.dot(dy, u) / (np.linalg.norm(dy) * np.linalg.norm(u)) > 1 - 1e-5


# ------------------------------------------------------------------------------------------
# Known answers


def test_steady_sliding_exponent_is_the_least_stable_eigenvalue_of_eq2():
    p = ChainParams(N=1, K=10.0, beta=1.0, V=0.5, Fs=3.0)
    expected = float(block_eigenvalues(BlockParams(K=10.0, beta=1.0, V=0.5, Fs=3.0))[0].real)
    res = largest_lyapunov(p, 200.0, interval=5.0, start="steady", perturbation=1e-3)
    assert expected < -0.4
    assert abs(res.lyapunov - expected) <= 0.02 * abs(expected)
    assert abs(res.lyapunov - expected) <= max(4 * res.lyapunov_err, 1e-3)


def test_steady_sliding_chain_exponent_is_the_least_stable_eigenvalue_of_eq5():
    p = ChainParams(N=4, beta=1.5, V=0.5)
    expected = float(chain_finite_eigenvalues(p)[0].real)
    res = largest_lyapunov(p, 400.0, interval=5.0, start="steady", perturbation=1e-3)
    assert expected < 0
    assert abs(res.lyapunov - expected) <= 0.03 * abs(expected)


def _heun_map_exponent(params: ChainParams) -> tuple[float, float]:
    """Eq. (2)'s least stable eigenvalue's real part, and that of one Heun step of it: Heun
    multiplies an eigenvector of a linear system by g = 1 + z + z^2 / 2, z = lambda dt (closed
    form), so the map the engine integrates decays at ln|g| / dt."""
    lam = complex(block_eigenvalues(BlockParams(K=params.K, beta=params.beta, V=params.V, Fs=params.Fs))[0])
    z = lam * params.dt
    return lam.real, math.log(abs(1 + z + z * z / 2)) / params.dt


@pytest.mark.slow  # the exponent at the command's defaults (about 15 s, measured)
def test_sliding_block_at_the_commands_defaults(capsys):
    """`stickslip lyapunov --N 1 --V 0.5 --json`: start paper, t_end 2e4, d0 1e-10, interval 10.
    Over an interval the separation decays by exp(-4.87), to 8e-13: below the rounding of
    positions x ~ V t = 1e4 (ulp 1.8e-12), above that of the twin's frame."""
    status, out, _ = run_cli(capsys, "lyapunov", "--N", "1", "--V", "0.5", "--json", "--no-progress")
    assert status == 0
    d = json.loads(out)
    exact, heun = _heun_map_exponent(ChainParams(N=1, V=0.5))
    assert exact == pytest.approx(-0.4865, abs=1e-4) and heun - exact == pytest.approx(-5.5e-5, abs=5e-6)
    assert d["frame"] == "centred" and d["t_end"] == 2e4 and d["merges"] == 0
    assert abs(d["lyapunov"] - heun) <= 3 * d["lyapunov_err"] + 1e-6
    assert abs(d["lyapunov"] - exact) <= abs(heun - exact) + 3 * d["lyapunov_err"]
    assert d["lyapunov_err"] < 1e-4


def test_sliding_block_in_the_absolute_frame_sinks_into_round_off():
    """The method before the frame: the same run with the twin beside the reference itself."""
    exact, _ = _heun_map_exponent(ChainParams(N=1, V=0.5))
    res = largest_lyapunov(ChainParams(N=1, V=0.5), 2e4, frame="absolute")
    assert res.lyapunov > exact + 0.1


@pytest.mark.slow
def test_sliding_block_ten_times_the_defaults():
    p = ChainParams(N=1, V=0.5)
    exact, heun = _heun_map_exponent(p)
    res = largest_lyapunov(p, 2e5)
    assert res.merges == 0 and res.lyapunov_err < 1e-5
    assert abs(res.lyapunov - heun) <= 3 * res.lyapunov_err + 1e-6
    assert abs(res.lyapunov - exact) <= abs(heun - exact) + 3 * res.lyapunov_err


@pytest.mark.slow
def test_twin_runs_in_a_frame_moved_back_along_the_drive():
    from stickslip.analysis.dynamics.lyapunov import GridEngine

    p = ChainParams(N=1, V=0.5)
    ref = run_chain(p, 1000.0).state
    eng = GridEngine(p)
    twin = eng.twin(ref, np.ones(3), 1e-10)
    assert twin.shift > 0 and abs(twin.base.x[0]) < 1.0 and ref.x[0] > 400
    # the copy is the reference's motion: same velocity, theta and spring force
    assert twin.base.v[0] == ref.v[0] and twin.base.theta[0] == ref.theta[0]
    f_ref = p.V * ref.step * p.dt - ref.x[0]
    assert p.V * twin.base.step * p.dt - twin.base.x[0] == pytest.approx(f_ref, abs=1e-12)
    ref, twin, _ = eng.advance(ref, twin, ref.step + round(10.0 / p.dt))
    assert abs(twin.base.x[0]) < 2.0 and twin.base.step + twin.shift == ref.step
    # fixed ends read t: the twin stays beside the reference
    wall = GridEngine(ChainParams(N=3, ends="fixed"))
    assert wall.twin(run_chain(ChainParams(N=3, ends="fixed"), 100.0).state, np.ones(9), 1e-10).base is None


@pytest.fixture(scope="module")
def grid_multiplier():
    """Per-cycle multiplier m = d f_end / d Fs of the slip of eq. (3), and the period T(V)."""
    h = 1e-4
    hi = solve_slip_limit(BlockParams(Fs=3.0 + h), dense=False)
    lo = solve_slip_limit(BlockParams(Fs=3.0 - h), dense=False)
    m = (hi.force_at_stop - lo.force_at_stop) / (2 * h)
    T = solve_slip_limit(BlockParams(Fs=3.0), dense=False).period(PAPER_BLOCK.V)
    return m, T


def test_periodic_stick_slip_contracts_by_the_slip_multiplier(grid_multiplier):
    m, T = grid_multiplier
    expected = math.log(abs(m)) / T
    res = largest_lyapunov(PAPER_BLOCK, 2e4, interval=50.0, transient=1000.0, d0=1e-10)
    counted_time = res.t_end - res.transient - res.align
    assert 0.5 < abs(m) < 0.9  # a contraction per cycle, not a numerical zero
    # never positive: a periodic orbit has no growing direction
    assert res.lyapunov <= 3 * res.lyapunov_err
    # one slip more or less inside the counted window changes the mean by |ln m| / window
    tol = abs(math.log(abs(m))) / counted_time + 3 * res.lyapunov_err
    assert abs(res.lyapunov - expected) <= tol
    assert tol < 0.05 * abs(expected)


def test_periodic_stick_slip_is_neutral_beyond_the_time_grid(grid_multiplier):
    m, T = grid_multiplier
    grid = math.log(abs(m)) / T
    # d0 = 1e-3 moves the start of each slip by some 60 steps (V dt = 5e-6): the phase of
    # the cycle is free again, as for the continuous-time eq. (1).
    res = largest_lyapunov(PAPER_BLOCK, 2e4, interval=50.0, transient=1000.0, d0=1e-3)
    assert abs(res.lyapunov) < 0.05 * abs(grid)


# ------------------------------------------------------------------------------------------
# Result object, tables, figure


def test_result_dict_and_truncation():
    p = ChainParams(N=5, beta=0.5)
    res = largest_lyapunov(p, 2000.0, interval=10.0, segments=5)
    d = res.to_dict()
    for key in (
        "lyapunov",
        "lyapunov_err",
        "t_end",
        "renormalisations",
        "d0",
        "interval",
        "segments",
        "params",
        "norm",
        "method",
    ):
        assert key in d, key
    json.dumps(d)
    assert d["renormalisations"] == int(np.count_nonzero(res.counted)) == 180
    assert len(d["segment_means"]) == 5
    shorter = largest_lyapunov(p, 1500.0, interval=10.0, segments=5, align=200.0)
    cut = res.truncated(1500.0)
    assert cut.lyapunov == shorter.lyapunov and cut.renormalisations == shorter.renormalisations


def test_convergence_and_beta_tables_and_figure():
    p = ChainParams(N=4, beta=0.5)
    conv = lyapunov_convergence(p, 1000.0, d0s=(1e-8, 1e-10), intervals=(10.0, 20.0), segments=4)
    assert list(conv["varied"]) == ["d0"] * 2 + ["interval"] * 2 + ["t_end"] * 3
    assert conv["lyapunov"].notna().all()
    table = lyapunov_vs_beta(p, [0.5, 1.2], 1000.0, segments=4)
    assert list(table["beta"]) == [0.5, 1.2]
    fig = plot_lyapunov_beta(table, p)
    assert isinstance(fig, Figure)


# ------------------------------------------------------------------------------------------
# Bad input


@pytest.mark.parametrize(
    "kw, name",
    [
        (dict(d0=0.0), "d0"),
        (dict(d0=0.1), "d0"),
        (dict(interval=0.001), "interval"),
        (dict(segments=1), "segments"),
        (dict(transient=2000.0), "transient"),
        (dict(engine="fast"), "engine"),
        (dict(interval=500.0), "t_end"),
    ],
)
def test_bad_options_name_the_parameter(kw, name):
    with pytest.raises(ParameterError, match=f"^{name} "):
        largest_lyapunov(ChainParams(N=2), 1000.0, **kw)


# ------------------------------------------------------------------------------------------
# Command line


def test_cli_json_is_one_document(capsys):
    status, out, err = run_cli(
        capsys,
        "lyapunov",
        "--N",
        "1",
        "--V",
        "0.5",
        "--start",
        "steady",
        "--perturbation",
        "1e-3",
        "--t-end",
        "100",
        "--interval",
        "5",
        "--json",
    )
    assert status == 0
    data = json.loads(out)
    for key in ("lyapunov", "lyapunov_err", "t_end", "renormalisations"):
        assert key in data, key
    assert data["t_end"] == 100.0 and data["renormalisations"] == 18
    expected = float(block_eigenvalues(BlockParams(V=0.5))[0].real)
    assert abs(data["lyapunov"] - expected) < 0.05 * abs(expected)


def test_cli_text_and_beta_table_with_plot(capsys, tmp_path):
    status, out, _ = run_cli(capsys, "lyapunov", "--N", "3", "--t-end", "500", "--segments", "4")
    assert status == 0 and "lyapunov" in out and "renormalisations" in out
    png = tmp_path / "l.png"
    status, out, _ = run_cli(
        capsys,
        "lyapunov",
        "--N",
        "3",
        "--t-end",
        "500",
        "--segments",
        "4",
        "--betas",
        "0.5,1.0",
        "--plot",
        str(png),
        "--json",
    )
    assert status == 0 and png.is_file() and png.with_suffix(".pdf").is_file()
    data = json.loads(out)
    assert data["outputs"] == [str(png), str(png.with_suffix(".pdf"))]
    assert [row["beta"] for row in data["table"]] == [0.5, 1.0]


@pytest.mark.parametrize(
    "argv, name",
    [
        (["--d0", "-1"], "d0"),
        (["--interval", "0"], "interval"),
        (["--segments", "1"], "segments"),
        (["--N", "0"], "N"),
        (["--beta", "-1"], "beta"),
        (["--betas", "0.5,x"], "betas"),
        (["--t-end", "nan"], "t_end"),
    ],
)
def test_cli_bad_input_is_one_line_and_status_2(capsys, argv, name):
    status, out, err = run_cli(capsys, "lyapunov", "--N", "2", "--t-end", "1000", *argv)
    assert status == 2 and out == ""
    assert err.count("\n") == 1 and name in err


def test_plate_drive_separation_round_trip():
    from stickslip.models.presets import chain_params

    p = chain_params("carlson-langer", N=7)
    ref = run_chain(p, 50.0, start="rest", perturbation=0.01, seed=1).state
    direction = np.random.default_rng(0).normal(size=3 * p.N)
    twin = twin_state(ref, direction, 1e-6, p)
    d = np.linalg.norm(separation(ref, twin, p))
    assert d == pytest.approx(1e-6, rel=1e-6)


@pytest.mark.slow  # the plate with the strengthening law: a composition no other default test compiles
def test_plate_drive_steady_sliding_decays_at_minus_beta_over_two():
    # A block on the plate with friction F0 + beta v slides steadily at v = V; a perturbation
    # obeys lambda^2 + beta lambda + Kp = 0: Re lambda = -beta / 2 for beta^2 < 4 Kp (closed form).
    p = ChainParams(
        N=1, drive="plate", friction="strengthening", ends="free", K=1.0, Kp=1.0, V=0.5, beta=0.4, F0=0.5, Fs=1.0
    )
    res = largest_lyapunov(p, 200.0, interval=2.0, d0=1e-8, transient=0.0, start="steady", perturbation=1e-3, seed=0)
    assert res.lyapunov == pytest.approx(-0.2, rel=0.02)


# ------------------------------------------------------------------------------------------
# The method over any engine


class _LinearEngine:
    """dy/dt = A y, advanced exactly (a matrix exponential per step): the largest exponent is
    the largest real part of A's eigenvalues, with no switching and no round-off floor."""

    method = norm = "linear"
    max_wait = 0

    def __init__(self, params, a):
        from scipy.linalg import expm

        self.params = params
        self.step_map = expm(a * params.dt)

    def advance(self, ref, twin, step):
        k = step - ref[0]
        P = np.linalg.matrix_power(self.step_map, k)
        return (step, P @ ref[1]), (step, P @ twin[1]), 0

    def step(self, ref):
        return ref[0]

    def separation(self, ref, twin):
        return twin[1] - ref[1]

    def twin(self, ref, direction, d0):
        return ref[0], ref[1] + d0 * direction / np.linalg.norm(direction)

    def on_branch(self, dy, ref):
        return dy

    def same_branch(self, ref, twin):
        return True

    def neutral(self, ref):
        return None

    def fingerprint(self, ref):
        return ""


def test_one_loop_serves_any_engine_linear_flow():
    from stickslip.analysis.dynamics.benettin import two_trajectory_exponent

    p = ChainParams(N=1, dt=0.01)
    # a damped oscillator (-0.2 +- 2 i) and a faster decay (-0.7)
    a = np.array([[-0.2, 2.0, 0.0], [-2.0, -0.2, 0.0], [0.0, 0.0, -0.7]])
    res = two_trajectory_exponent(
        _LinearEngine(p, a), (0, np.zeros(3)), 200.0, interval=5.0, d0=1e-6, transient=0.0, align=20.0, segments=5
    )
    assert res.lyapunov == pytest.approx(-0.2, rel=1e-9)
    assert res.renormalisations == 36 and res.waits == 0 and res.merges == 0
