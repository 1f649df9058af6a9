"""The model pieces answer what the package asks of them (models/pieces.py, docs/model.md).

The expected numbers are written here from the equations or copied from docs/model.md, not
computed by the pieces' own code.
"""

from __future__ import annotations

import numpy as np
import pytest

from stickslip.analysis.dynamics import stability as st
from stickslip.models import pieces
from stickslip.models.params import BlockParams, ChainParams
from stickslip.models.presets import PRESETS, chain_params

#: A drive, a threshold and an end condition reach the kernels as the import paths of their modules.
PIECE_MODULES = {
    "drive": {
        "end": "stickslip.models.drive.end",
        "plate": "stickslip.models.drive.plate",
        "constant-force": "stickslip.models.drive.constant_force",
        "force-ramp": "stickslip.models.drive.force_ramp",
        "history": "stickslip.models.drive.history",
    },
    "threshold": {
        "constant": "stickslip.models.threshold.constant",
        "state": "stickslip.models.threshold.state",
        "none": "stickslip.models.threshold.none",
    },
    "ends": {
        "free": "stickslip.models.ends.free",
        "fixed": "stickslip.models.ends.fixed",
        "periodic": "stickslip.models.ends.periodic",
    },
}

#: A friction law reaches the kernels as the import path of its own module.
LAW_MODULES = {
    "state": "stickslip.models.friction.state",
    "weakening": "stickslip.models.friction.weakening",
    "strengthening": "stickslip.models.friction.strengthening",
    "rate-state": "stickslip.models.friction.rate_state",
}


@pytest.mark.parametrize("kind", list(PIECE_MODULES))
def test_thresholds_and_ends_are_their_modules(kind):
    assert pieces.names(kind) == tuple(PIECE_MODULES[kind])
    for name, module in PIECE_MODULES[kind].items():
        pc = pieces.piece(kind, name)
        assert pieces.code(kind, name) == module == pc.module


def test_threshold_values_and_ghost_cells():
    # The compiled functions the integrators call, run as Python: Fs; theta_i; the ghost beyond
    # an end (free: the end block; fixed: the wall; periodic: the other end).
    from stickslip.models.ends import fixed, free, periodic
    from stickslip.models.threshold import constant, state

    assert constant.value.py_func(0.7, constant.Params(3.0)) == 3.0
    assert state.value.py_func(0.7, state.Params()) == 0.7
    assert free.ghost.py_func(1.5, -2.0, 0.0) == 1.5
    assert fixed.ghost.py_func(1.5, -2.0, -0.25) == -0.25
    assert periodic.ghost.py_func(1.5, -2.0, 0.0) == -2.0
    assert pieces.piece("ends", "periodic").ring and pieces.piece("ends", "fixed").wall
    assert not pieces.piece("ends", "free").ring and not pieces.piece("ends", "free").wall


@pytest.mark.parametrize("name", list(LAW_MODULES))
def test_friction_laws_are_their_modules(name):
    law = pieces.piece("friction", name)
    assert pieces.code("friction", name) == LAW_MODULES[name] == law.module
    p = ChainParams(friction=name, **({"sigma": 0.01} if name == "weakening" else {}))
    lp = law.kernel_params(p)
    # the named tuple the compiled functions read: the law's parameters, by name, in its order,
    # then its optional ones (eq. (1)'s sigma of the state law), unset for a chain
    n = len(law.reads)
    assert lp._fields[:n] == law.reads and all(getattr(lp, k) == getattr(p, k) for k in law.reads)
    assert lp._fields[n:] == (("sigma",) if name == "state" else ()) and lp[n:] == (None,) * len(lp._fields[n:])


def test_params_hand_out_their_pieces():
    p = ChainParams(drive="plate", friction="weakening", ends="periodic", sigma=0.01)
    assert (p.drive_piece.name, p.friction_piece.name, p.threshold_piece.name, p.ends_piece.name) == (
        "plate",
        "weakening",
        "constant",
        "periodic",
    )
    assert p.codes == (
        PIECE_MODULES["drive"]["plate"],
        LAW_MODULES["weakening"],
        PIECE_MODULES["threshold"]["constant"],
        PIECE_MODULES["ends"]["periodic"],
    )
    assert BlockParams(threshold="state").threshold_piece.has_state
    assert not BlockParams().threshold_piece.has_state


def test_start_state_and_state_variable():
    # eq. (4) starts theta_i at 0.1 (section 3); the laws without theta keep it at 0.
    assert pieces.piece("friction", "state").theta0 == 0.1
    assert pieces.piece("friction", "state").has_state
    for name in ("weakening", "strengthening"):
        f = pieces.piece("friction", name)
        assert f.theta0 == 0.0 and not f.has_state


def _weakening_phi(v, alpha, sigma):
    """CL's phi(v) = (1 - sigma) / (1 + 2 alpha v / (1 - sigma)), written from docs/model.md."""
    return (1.0 - sigma) / (1.0 + 2.0 * alpha * v / (1.0 - sigma))


@pytest.mark.parametrize(("alpha", "sigma", "V"), [(2.5, 0.01, 0.01), (1.0, 0.5, 0.3), (4.0, 0.2, 0.0)])
def test_weakening_slope_against_the_law(alpha, sigma, V):
    p = ChainParams(drive="plate", friction="weakening", ends="periodic", alpha=alpha, sigma=sigma, V=V)
    h = 1e-6
    numeric = (_weakening_phi(V + h, alpha, sigma) - _weakening_phi(V - h, alpha, sigma)) / (2 * h)
    assert p.friction_piece.slope(p) == pytest.approx(numeric, rel=1e-7)
    assert st.friction_slope(p) == p.friction_piece.slope(p)


@pytest.mark.parametrize("beta", [0.0, 0.3, 2.0])
def test_strengthening_slope_is_beta(beta):
    p = chain_params("train", beta=beta)
    assert p.friction_piece.slope(p) == beta


def test_state_law_has_no_scalar_slope():
    # Its linearisation is the 3 x 3 block of eq. (5); the scalar mode equation refuses it.
    p = chain_params("sakaguchi")
    assert p.friction_piece.slope is None
    with pytest.raises(ValueError, match="state variable"):
        st.friction_slope(p)


def test_weakening_extras_match_model_md():
    # docs/model.md, CL at l = 10, alpha = 2.5, sigma = 0.01, nu = 0.01: alpha g = 2.2653.
    p = chain_params("carlson-langer", l=10.0, alpha=2.5, sigma=0.01, nu=0.01)
    extras = p.friction_piece.stability_extras(p)
    assert set(extras) == {"alpha_g"}
    assert abs(extras["alpha_g"] - 2.2653) < 1e-4
    assert abs(st.mode_stability(p).max_growth_rate - 4.298) < 5e-4
    assert chain_params("train").friction_piece.stability_extras is None


def test_end_pieces():
    assert not pieces.piece("ends", "fixed").steady_sliding
    assert pieces.piece("ends", "periodic").ring
    assert not pieces.piece("ends", "free").ring
    p = ChainParams(drive="plate", friction="weakening", ends="fixed", sigma=0.01)
    with pytest.raises(ValueError, match="ends fixed have no steady sliding"):
        st.normal_modes(p)


def test_leaf_spring_adds_kp_to_every_mode():
    k = np.linspace(0.0, np.pi, 5)
    plate = ChainParams(drive="plate", friction="weakening", ends="periodic", sigma=0.01, K=3.0, Kp=2.0)
    end = chain_params("train", K=3.0)
    q = 4.0 * np.sin(k / 2.0) ** 2
    assert plate.drive_piece.leaf_spring and not end.drive_piece.leaf_spring
    np.testing.assert_allclose(st.mode_frequency_squared(plate, k), 2.0 + 3.0 * q)
    np.testing.assert_allclose(st.mode_frequency_squared(end, k), 3.0 * q)


def test_only_model_notes_marked_for_runs():
    marked = {name for name, pr in PRESETS.items() if pr.note_in_runs}
    assert marked == {"batista-carlson", "train"}


def _theta_law(theta, v, alpha):
    """eq. (4)'s theta law without diffusion, written from docs/model.md."""
    return theta * (1.0 - theta) - alpha * theta * v


@pytest.mark.parametrize(("alpha", "V"), [(1.0, 0.001), (1.0, 0.3), (2.0, 0.1), (1.0, 1.5)])
def test_state_law_linearisation_against_the_law(alpha, V):
    lin = pieces.piece("friction", "state").linear(ChainParams(alpha=alpha, V=V))
    theta0, d_v, d_theta = lin.theta0, lin.g_v, lin.g_theta
    assert (lin.phi_v, lin.phi_theta, lin.diffusion) == (1.0, 1.0, 5.0)  # theta + beta v, beta = 1; D
    assert theta0 == max(1.0 - alpha * V, 0.0)
    if theta0 > 0:
        assert _theta_law(theta0, V, alpha) == pytest.approx(0.0, abs=1e-15)  # a steady state
    h = 1e-6
    num_v = (_theta_law(theta0, V + h, alpha) - _theta_law(theta0, V - h, alpha)) / (2 * h)
    num_t = (_theta_law(theta0 + h, V, alpha) - _theta_law(theta0 - h, V, alpha)) / (2 * h)
    assert d_v == pytest.approx(num_v, rel=1e-7, abs=1e-12)
    assert d_theta == pytest.approx(num_t, rel=1e-7, abs=1e-12)
    assert pieces.piece("friction", "weakening").linear is None


def test_paper_stability_numbers_unchanged():
    # docs/stability.md and the paper: long waves of eq. (5) are unstable exactly for beta < alpha
    # (K = 10, D = 5); Fig. 4's beta = 0.5 has a growing band, beta = 1.5 none.
    p = chain_params("sakaguchi")
    assert st.chain_critical_beta(p) == 1.0
    assert st.chain_stability(p.replace(beta=0.5)).max_growth_rate > 0.0
    assert st.chain_stability(p.replace(beta=1.5)).max_growth_rate < 0.0
    with pytest.raises(ValueError, match="no state variable"):
        st.chain_mode_matrix(chain_params("train"), 0.3)


def test_force_drives_compiled_functions():
    # The force on a block from the drive's own compiled function, run as Python: the springs
    # K ((x_{i-1} - x_i) - (x_i - x_{i+1})) plus F, or F_start + p with p = r t_n; no leaf spring;
    # x_0 is the ghost cell.
    from stickslip.models.drive import constant_force, force_ramp

    cf = constant_force.Params(3.2)
    assert constant_force.force.py_func(1.0, 0.5, 0.25, 10.0, 99.0, cf) == 10.0 * (0.5 - 0.25) + 3.2
    assert constant_force.leaf.py_func(cf) == 0.0 and constant_force.left.py_func(99.0, 0.5) == 0.5
    fr = force_ramp.Params(0.5, 1e-3)
    assert force_ramp.force.py_func(1.0, 0.5, 0.25, 10.0, 0.2, fr) == 10.0 * (0.5 - 0.25) + (0.5 + 0.2)
    assert force_ramp.leaf.py_func(fr) == 0.0 and force_ramp.left.py_func(99.0, 0.5) == 0.5
    for name in ("constant-force", "force-ramp"):
        pc = pieces.piece("drive", name)
        assert pc.leaf_spring and not pc.located
