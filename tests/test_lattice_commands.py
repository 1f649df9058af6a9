"""``--lattice``, ``--shape`` and ``--edges`` on the commands that take a model besides `stickslip
chain` (docs/lattice.md, "Commands"): `stability chain` analyses steady sliding on the square,
checked against eq. (5) written out here; `lyapunov` refuses what it does not yet do on one
(tests/test_lyapunov_lattice_cli.py), exit 2, and so does ``chain --from`` given a lattice run
(`period` reads one: tests/test_period_lattice.py; `sweep` runs one: tests/test_sweep_lattice.py)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from chain_helpers import one_line_error, run_cli
from stickslip import chain_params
from stickslip.run.lattice import run_lattice


def _eq5_growth(q, K, Kp, beta, alpha, D, V):
    """The largest real part of eq. (5)'s roots for a mode of Laplacian eigenvalue -q, friction
    theta + beta v and dtheta/dt = theta (1 - theta) - alpha theta v + D lap(theta), linearised
    about theta_0 = 1 - alpha V by hand."""
    th0 = 1.0 - alpha * V
    A = np.array(
        [
            [0.0, 1.0, 0.0],
            [-(K * q + Kp), -beta, -1.0],
            [0.0, -alpha * th0, (1.0 - 2.0 * th0 - alpha * V) - D * q],
        ]
    )
    return np.linalg.eigvals(A).real.max()


def test_stability_on_the_periodic_square_is_eq5_mode_by_mode(capsys):
    """A plate and eq. (4)'s law on the periodic 4 x 6 square: the modes are the Fourier modes
    q = 4 sin^2(pi a / 4) + 4 sin^2(pi b / 6), each with eq. (5)'s 3 x 3 matrix."""
    code, out, err = run_cli(
        capsys, "stability", "chain", "--model", "carlson-langer", "--friction", "state", "--threshold", "state",
        "--lattice", "square", "--shape", "4x6", "--K", "1", "--nu", "0.5", "--alpha", "1", "--beta", "0.5",
        "--D", "0.5", "--json",
    )  # fmt: skip
    assert code == 0, err
    got = json.loads(out)
    q = [4 * np.sin(np.pi * a / 4) ** 2 + 4 * np.sin(np.pi * b / 6) ** 2 for a in range(4) for b in range(6)]
    rates = [_eq5_growth(qi, 1.0, 1.0, 0.5, 1.0, 0.5, 0.5) for qi in q]
    assert got["max_growth_rate"] == pytest.approx(max(rates), rel=1e-10, abs=1e-14)
    assert got["unstable"] == (max(rates) > 0)


def test_stability_of_a_row_is_the_chains_first_mode(capsys):
    """A 1 x 12 square pulled at the left: its slowest mode is the chain's k_1 = pi / 25 (driven
    at one end, free at the other), whose eq. (5) growth rate `stability chain --N 12` reports."""
    common = ["--K", "1", "--D", "0.5", "--V", "0.5", "--beta", "0.9", "--json"]
    code, out, _ = run_cli(capsys, "stability", "chain", "--lattice", "square", "--shape", "1x12", *common)
    assert code == 0
    lattice = json.loads(out)
    code, out, _ = run_cli(capsys, "stability", "chain", "--N", "12", *common)
    chain = json.loads(out)["finite_chain"]
    assert chain["k1"] == pytest.approx(np.pi / 25)
    assert lattice["q_at_max"] == pytest.approx(4 * np.sin(np.pi / 50) ** 2, rel=1e-12)
    assert lattice["max_growth_rate"] == pytest.approx(chain["fourier_at_k1"], rel=1e-9)
    assert lattice["unstable"] and lattice["critical_beta_lattice"] < 1.0


@pytest.mark.parametrize(
    "argv, names",
    [
        (
            ["lyapunov", "--lattice", "square", "--shape", "4x4", "--switches", "located"],
            ["--lattice square", "lyapunov"],
        ),
        (["lyapunov", "--shape", "4x4"], ["--shape", "--lattice square"]),
        (["stability", "chain", "--lattice", "square", "--shape", "4x4", "--out", "OUT"], ["--out", "--lattice"]),
        (["stability", "chain", "--lattice", "square"], ["--shape"]),
        (["stability", "chain", "--lattice", "square", "--shape", "4x0"], ["shape"]),
        (["stability", "chain", "--model", "carlson-langer", "--lattice", "square", "--shape", "4x4"], ["weakening"]),
        (["stability", "chain", "--lattice", "square", "--shape", "4x4", "--edges", "top=fixed"], ["fixed"]),
        (["stability", "chain", "--lattice", "square", "--shape", "4x4", "--beta", "uniform(1, 2)"], ["per-block"]),
    ],
)
def test_commands_refuse_what_they_cannot_do_on_a_lattice(argv, names, tmp_path, capsys):
    from stickslip.cli import main

    argv = [a.replace("OUT", str(tmp_path / "out")) for a in argv]
    assert main(argv) == 2
    one_line_error(capsys, *names)


@pytest.fixture(scope="module")
def lattice_run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("lattice") / "run"
    p = chain_params("carlson-langer", lattice="square", shape=(3, 3))
    run_lattice(p, 5.0, start="rest", perturbation=0.01).write(out)
    return out


@pytest.mark.parametrize(
    "argv",
    [["chain", "--from", "RUN", "--t-end", "1"]],
)
def test_run_readers_refuse_a_lattice_run(argv, lattice_run_dir, capsys):
    from stickslip.cli import main

    assert main([a.replace("RUN", str(lattice_run_dir)) for a in argv]) == 2
    one_line_error(capsys, "lattice square 3x3", "not yet")
