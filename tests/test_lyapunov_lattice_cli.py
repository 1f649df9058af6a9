"""`stickslip lyapunov --lattice square --shape RxC` (docs/lattice.md, "Lyapunov exponents and the
lattice's norm"): the exponent and the decorrelation of a model on the square from the command
line, against the Python API, and a square of one row against the chain's own command."""

from __future__ import annotations

import json

import numpy as np
import pytest

from chain_helpers import run_cli
from stickslip.analysis.dynamics.decorrelation import sequence_decorrelation
from stickslip.analysis.dynamics.lyapunov_lattice import LatticeSequences, lattice_lyapunov
from stickslip.models.presets import chain_params
from stickslip.run.lattice import initial_state, run_lattice


def _json(capsys, *argv):
    code, out, err = run_cli(capsys, "lyapunov", *argv, "--no-progress", "--json")
    assert code == 0, err
    return json.loads(out)


def test_square_exponent_is_the_python_apis(capsys):
    """Carlson-Langer on 6 x 6 from the preset's start (rest, A = 0.01, seed 0)."""
    got = _json(capsys, "--model", "carlson-langer", "--lattice", "square", "--shape", "6x6", "--t-end", "200")
    p = chain_params("carlson-langer", lattice="square", shape=(6, 6))
    want = lattice_lyapunov(p, 200.0, start="rest", perturbation=0.01, seed=0)
    assert got["lyapunov"] == want.lyapunov and got["lyapunov_err"] == want.lyapunov_err
    assert got["reference_sha256"] == want.reference_sha256
    assert got["frame"] == "absolute" and got["lattice"].startswith("square 6x6")
    assert got["renormalisations"] == 18 and got["params"]["shape"] == "6x6"


def test_one_row_gives_the_chains_command_in_the_absolute_frame(capsys):
    """A square of one row pulled at the left is the chain bit for bit (tests/test_lyapunov_lattice.py):
    the same exponent, segments and events as `stickslip lyapunov --N 9 --frame absolute`."""
    row = _json(capsys, "--lattice", "square", "--shape", "1x9", "--t-end", "1000")
    chain = _json(capsys, "--N", "9", "--frame", "absolute", "--t-end", "1000")
    for key in ("lyapunov", "lyapunov_err", "segment_means", "renormalisations", "events", "max_log_growth"):
        assert row[key] == chain[key], key
    assert chain["frame"] == "absolute"
    assert _json(capsys, "--N", "9", "--t-end", "200")["frame"] == "centred"  # the chain's default is kept


def test_one_row_decorrelation_is_the_chains(capsys):
    """The slips of a row (epicentre, area, moment) are the chain's (start block, blocks moved,
    size): the same n(delta) from the same start."""
    argv = ("--beta", "0.5", "--decorrelation", "--events", "8", "--deltas", "0,1e-10,1e-2")
    row = _json(capsys, "--lattice", "square", "--shape", "1x9", *argv)
    chain = _json(capsys, "--N", "9", *argv)
    assert row["decorrelation"] == chain["decorrelation"]
    assert row["decorrelation_windows"] == chain["decorrelation_windows"]
    assert row["decorrelation"][0]["events"] == 8 and not row["decorrelation"][0]["decorrelated"]


def test_square_decorrelation_is_the_python_apis(capsys):
    got = _json(
        capsys, "--model", "carlson-langer", "--lattice", "square", "--shape", "5x5",
        "--decorrelation", "--events", "30", "--deltas", "0,1e-3",
    )  # fmt: skip
    p = chain_params("carlson-langer", lattice="square", shape=(5, 5))
    want = sequence_decorrelation(
        LatticeSequences(p), initial_state(p, "rest", amplitude=0.01), [0.0, 1e-3], events=30
    ).to_dict()
    assert got["decorrelation"] == want["decorrelation"]
    assert got["decorrelation"][0] == {
        "delta": 0.0,
        "seed": 0,
        "events": 30,
        "decorrelated": False,
        "t_decorrelated": None,
    }


def test_lattice_sequences_are_the_events_table():
    """Each slip: t_start, moment, the epicentre's row-major index (0-based) and area."""
    p = chain_params("carlson-langer", lattice="square", shape=(4, 5))
    s0 = initial_state(p, "rest", amplitude=0.01, seed=2)
    state, rows = LatticeSequences(p).run(p, s0, 4000)
    ev = run_lattice(p, 20.0, start=s0).events
    assert len(rows) == len(ev) > 0
    np.testing.assert_array_equal(rows[:, 0], ev["t_start"])
    np.testing.assert_array_equal(rows[:, 1], ev["moment"])
    np.testing.assert_array_equal(
        rows[:, 2], [(r - 1) * 5 + (c - 1) for r, c in zip(ev["epicentre_row"], ev["epicentre_col"], strict=True)]
    )
    np.testing.assert_array_equal(rows[:, 3], ev["area"])
    assert state.step == 4000


@pytest.mark.parametrize(
    "argv, names",
    [
        (["--switches", "located"], ["--switches located", "not yet", "--lattice square"]),
        (["--convergence"], ["--convergence", "not yet"]),
        (["--betas", "0.5,1"], ["--betas", "not yet"]),
        (["--frame", "centred"], ["--frame centred", "not yet"]),
        (["--lifetimes", "9"], ["--lifetimes", "not yet"]),
        (["--decorrelation", "--perturb", "Fs"], ["--perturb Fs", "not yet"]),
        (["--decorrelation", "--state-cache", "somewhere"], ["--state-cache", "not yet"]),
        (["--shape", "0x3"], ["shape"]),
    ],
)
def test_what_does_not_go_with_a_lattice_is_refused_in_one_line(capsys, argv, names):
    code, out, err = run_cli(capsys, "lyapunov", "--lattice", "square", "--shape", "3x3", *argv)
    assert code == 2 and out == "" and err.count("\n") == 1 and "Traceback" not in err, err
    assert all(name in err for name in names), err


def test_frame_goes_with_the_grids_exponent(capsys):
    code, _, err = run_cli(capsys, "lyapunov", "--N", "5", "--frame", "absolute", "--switches", "located")
    assert code == 2 and err.count("\n") == 1 and "--frame" in err, err
