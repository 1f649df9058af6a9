"""Growth rates of steady sliding of the plate drive (Carlson-Langer) and the train model.

Each normal mode obeys lambda^2 + phi'(V) lambda + w_k^2 = 0; the numbers are docs/model.md's
("The family the paper stands in", CL linear stability).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment

from stickslip.analysis.dynamics import stability as st
from stickslip.cli import main
from stickslip.models.presets import chain_params
from stickslip.plotting.stability import plot_mode_growth

#: docs/model.md, CL at l = 10, alpha = 2.5, sigma = 0.01, nu = 0.01 (quoted to the digits given there).
MODEL_ALPHA_G = 2.2653
MODEL_K0_GROWTH = 4.298


def test_cl_closed_form_numbers():
    p = chain_params("carlson-langer", l=10.0, alpha=2.5, sigma=0.01, nu=0.01)
    assert p.K == 100.0 and p.Kp == 1.0
    alpha_g = p.alpha * st.weakening_g(p)
    assert abs(alpha_g - MODEL_ALPHA_G) < 1e-4
    assert st.friction_slope(p) == pytest.approx(-2.0 * alpha_g)
    s = st.mode_stability(p)
    assert s.all_unstable and not s.stable
    assert s.k_at_max == 0.0
    assert abs(s.max_growth_rate - MODEL_K0_GROWTH) < 5e-4
    assert s.min_growth_rate == pytest.approx(alpha_g, rel=1e-12)  # Re lambda >= alpha g
    assert (s.growth["growth_rate"] >= alpha_g - 1e-12).all()


@pytest.mark.parametrize("ends", ["periodic", "free"])
def test_cl_every_mode_grows(ends):
    s = st.mode_stability(chain_params("carlson-langer", ends=ends))
    assert s.all_unstable and s.min_growth_rate > 2.0


@pytest.mark.parametrize("beta", [0.01, 0.1, 0.5, 1.0, 3.0, 10.0])
def test_train_stable_for_every_beta(beta):
    s = st.mode_stability(chain_params("train", beta=beta))
    assert s.stable and not s.all_unstable
    assert s.max_growth_rate < 0.0
    assert s.friction_slope == beta


def _match(p) -> float:
    eig = np.linalg.eigvals(st.chain_jacobian_2n(p))
    closed = st.mode_roots(p, st.normal_modes(p)[0]).ravel()
    cost = np.abs(eig[:, None] - closed[None, :])
    i, j = linear_sum_assignment(cost)
    return float(cost[i, j].max())


@pytest.mark.parametrize(
    "p",
    [
        chain_params("carlson-langer"),
        chain_params("carlson-langer", ends="free", N=37),
        chain_params("two-blocks"),
        chain_params("train", N=60, beta=0.3),
        chain_params("train", N=25, beta=5.0),
        chain_params("carlson-langer", friction="strengthening", beta=0.7, N=30),
    ],
    ids=["cl-periodic", "cl-free", "two-blocks", "train-0.3", "train-5", "plate-strengthening"],
)
def test_jacobian_eigenvalues_equal_closed_form(p):
    assert _match(p) < 1e-9


def test_fixed_ends_and_state_friction_refused():
    with pytest.raises(ValueError, match="fixed"):
        st.normal_modes(chain_params("carlson-langer", ends="fixed"))
    with pytest.raises(ValueError, match="state"):
        st.friction_slope(chain_params("sakaguchi"))


def test_plot_mode_growth():
    p = chain_params("train")
    fig = plot_mode_growth(st.mode_dispersion(p), st.mode_growth_rates(p))
    assert fig.axes


def run_json(capsys, *argv):
    status = main(list(argv) + ["--json"])
    out = capsys.readouterr().out
    assert status == 0
    return json.loads(out)


def test_cli_carlson_langer(capsys, tmp_path):
    d = run_json(capsys, "stability", "chain", "--model", "carlson-langer", "--out", str(tmp_path / "cl"))
    for key in ("all_unstable", "min_growth_rate", "max_growth_rate", "mode_table", "alpha_g", "modes"):
        assert key in d
    assert d["all_unstable"] is True
    assert abs(d["alpha_g"] - MODEL_ALPHA_G) < 1e-4
    assert abs(d["max_growth_rate"] - MODEL_K0_GROWTH) < 5e-4
    assert d["min_growth_rate"] == pytest.approx(d["alpha_g"])
    assert len(d["mode_table"]) == 100
    assert set(d["mode_table"][0]) >= {"k", "omega2", "growth_rate"}
    assert (tmp_path / "cl" / "mode_growth.png").stat().st_size > 0


def test_cli_train_and_composed(capsys):
    d = run_json(capsys, "stability", "chain", "--model", "train", "--beta", "0.2")
    assert d["all_unstable"] is False and d["stable"] is True and d["max_growth_rate"] < 0.0
    d = run_json(capsys, "stability", "chain", "--drive", "plate", "--friction", "weakening",
                 "--ends", "free", "--N", "20", "--K", "50")  # fmt: skip
    assert d["all_unstable"] is True and len(d["mode_table"]) == 20
    d = run_json(capsys, "stability", "chain", "--model", "carlson-langer", "--l", "5", "--nu", "0.02")
    assert d["params"]["K"] == 25.0 and d["params"]["V"] == 0.02


def test_cli_paper_model_unchanged(capsys):
    d = run_json(capsys, "stability", "chain", "--K", "10", "--D", "5", "--beta", "0.5")
    assert d["critical_beta"] == 1.0 and d["unstable"] is True and "all_unstable" not in d


@pytest.mark.parametrize(
    "argv",
    [
        ["stability", "chain", "--model", "carlson-langer", "--D", "3"],
        ["stability", "chain", "--model", "carlson-langer", "--ends", "fixed"],
        ["stability", "chain", "--model", "carlson-langer", "--nu", "0"],
        ["stability", "chain", "--model", "train", "--beta", "-1"],
        ["stability", "chain", "--drive", "plate", "--ends", "periodic"],
        ["stability", "chain", "--Fs", "2"],
        ["stability", "chain", "--model", "train", "--ends", "periodic"],
    ],
)
def test_cli_bad_input(capsys, tmp_path, argv):
    out = tmp_path / "out"
    status = main(argv + ["--out", str(out), "--json"])
    captured = capsys.readouterr()
    assert status == 2 and captured.out == ""
    assert len(captured.err.strip().splitlines()) == 1
    assert not out.exists()
