"""Per-block parameters and quenched disorder on the square (docs/lattice.md, "Per-block
parameters"): the lattice reference with values that differ from block to block equals a plain
numpy step of the 2-d equations written here, the active-set path equals the reference, a
square of one row is the chain's per-block run bit for bit, and the values are given over
(row, col) or drawn with a seed as for the chain."""

from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr

from chain_helpers import one_line_error, run_cli
from stickslip import Quenched, chain_params
from stickslip.models.params import ParameterError
from stickslip.run.driver import run_chain
from stickslip.run.lattice import LatticeState, initial_state, run_lattice
from stickslip.run.state import initial_state as chain_start
from test_lattice_dense import _laplacian, _padded

SIDES = ("top", "bottom", "left", "right")


def _grid(p, name):
    """A parameter over (row, col): its per-block values, or the number at every block."""
    value = getattr(p, name)
    values = getattr(value, "values", None)
    return np.full(p.lattice.shape, float(value)) if values is None else np.reshape(values, p.lattice.shape)


def _rates(p, g, x, v, th, m, kinds, load):
    """(f, dv/dt, dtheta/dt) of docs/model.md at every block, each parameter read at its block,
    the drive's load point at ``load``."""
    f = p.K * _laplacian(_padded(x, kinds, load, False))
    if p.drive == "plate":
        f = f + g["Kp"] * (load - x)
    if p.friction == "state":
        a = m * ((f - th - g["beta"] * v) / g["M"])
        b = th * (1.0 - th) - g["alpha"] * th * v + g["D"] * _laplacian(_padded(th, kinds, load, True))
    else:  # weakening
        w = 1.0 - g["sigma"]
        a = m * ((f - w / (1.0 + 2.0 * g["alpha"] * np.maximum(v, 0.0) / w)) / g["M"])
        b = np.zeros_like(th)
    return f, a, b


def _oracle(p, kinds, x, v, th, mov, n_steps, pull=None):
    """Heun with the start and stop rules, every block with its own parameters; the event count.
    The load point at step n is ``pull(n)``, V t_n by default."""
    pull = pull or (lambda n: p.V * (n * p.dt))
    g = {k: _grid(p, k) for k in ("Fs", "beta", "alpha", "D", "M", "Kp", "sigma") if hasattr(p.chain, k)}
    dt, n_events, n_moving, active = p.dt, 0, int(mov.sum()), False
    for n in range(n_steps):
        f, _, _ = _rates(p, g, x, v, th, mov, kinds, pull(n))
        m = np.where((mov != 0.0) | (f > g["Fs"]), 1.0, 0.0)
        _, a1, b1 = _rates(p, g, x, v, th, m, kinds, pull(n))
        xs, vs, ths = x + dt * v, v + dt * a1, th + dt * b1
        _, a2, b2 = _rates(p, g, xs, vs, ths, m, kinds, pull(n + 1))
        active = active or (n_moving == 0 and bool(m.any()))
        th = th + 0.5 * dt * (b1 + b2)
        xn = np.where(m != 0.0, x + 0.5 * dt * (v + vs), x)
        vn = np.where(m != 0.0, v + 0.5 * dt * (a1 + a2), 0.0)
        mov = np.where(vn > 0.0, 1.0, 0.0)
        x, v = xn, np.where(vn > 0.0, vn, 0.0)
        n_moving = int(mov.sum())
        if active and n_moving == 0:
            n_events, active = n_events + 1, False
    return x, v, th, mov, n_events


RNG = np.random.default_rng(11)
CASES = [
    # eq. (4) pulled at the left edge, its threshold, friction, state law and masses per block
    (
        "sakaguchi",
        dict(
            K=10.0,
            Fs=RNG.uniform(2.5, 3.5, (3, 4)),
            beta=RNG.uniform(0.5, 1.5, 12),
            alpha=RNG.uniform(0.8, 1.2, (3, 4)),
            D=RNG.uniform(1.0, 5.0, (3, 4)),
            M=RNG.uniform(0.5, 2.0, (3, 4)),
        ),
        ("free", "free", "driven", "free"),
        (3, 4),
        1.0,
    ),
    # Carlson-Langer on the periodic square: thresholds, plate springs and weakening per block
    (
        "carlson-langer",
        dict(
            Fs=Quenched("uniform", 0.8, 1.2, seed=5), Kp=RNG.uniform(0.5, 1.5, (4, 3)), sigma=RNG.uniform(0, 0.05, 12)
        ),
        ("periodic",) * 4,
        (4, 3),
        0.02,
    ),
]


@pytest.mark.parametrize("preset, overrides, kinds, shape, amplitude", CASES)
def test_per_block_square_step_equals_the_plain_numpy_equations(preset, overrides, kinds, shape, amplitude):
    p = chain_params(preset, lattice="square", shape=shape, edges=dict(zip(SIDES, kinds, strict=True)), **overrides)
    assert set(p.per_block()) >= {k for k in overrides if k != "K"}
    n_steps = 1500
    s0 = initial_state(p, "rest", amplitude=amplitude, seed=4)
    f0 = s0.fields(p.lattice)
    run = run_lattice(p, n_steps * p.dt, start=s0, integrator="dense")
    fin = run.state.fields(p.lattice)
    x, v, th, mov, n_events = _oracle(
        p, kinds, f0["x"], f0["v"], f0["theta"], np.where(f0["stopped"], 0.0, 1.0), n_steps
    )
    assert n_events >= 1 and len(run.events) == n_events
    for got, want in ((fin["x"], x), (fin["v"], v), (fin["theta"], th)):
        assert got.tobytes() == want.tobytes()
    assert (fin["stopped"] == (mov == 0.0)).all()


@pytest.mark.slow  # disordered squares, each compiled here first (about 30 s, measured)
def test_active_set_path_keeps_the_references_bits_with_disorder():
    """Carlson-Langer with drawn thresholds, plate springs and masses: exact (active set) equals
    dense."""
    p = chain_params(
        "carlson-langer",
        lattice="square",
        shape=(4, 5),
        Fs=Quenched("uniform", 0.8, 1.2, seed=3),
        Kp=Quenched("uniform", 0.8, 1.2, seed=3),
        M=Quenched("uniform", 0.5, 1.5, seed=3),
    )
    dense = run_lattice(p, 100.0, start="rest", perturbation=0.01, seed=2, integrator="dense")
    exact = run_lattice(p, 100.0, start="rest", perturbation=0.01, seed=2, integrator="exact")
    assert exact.summary["integrator"] == "exact" and len(dense.events) > 10
    assert exact.summary["state_sha256"] == dense.summary["state_sha256"]
    assert exact.events.equals(dense.events)


@pytest.mark.slow  # disordered squares, each compiled here first (about 30 s, measured)
def test_a_row_of_the_square_is_the_chains_per_block_run():
    """eq. (4) with thresholds and friction per block: a 1 x 12 square pulled at the left, free
    elsewhere, ends with the chain's state hash and events."""
    over = dict(Fs=Quenched("uniform", 2.5, 3.5, seed=7), beta=Quenched("normal", 1.0, 0.1, seed=7), V=0.01)
    chain = chain_params("sakaguchi", N=12, **over)
    ref = run_chain(chain, 1000.0, integrator="dense")
    sq = chain_params("sakaguchi", lattice="square", shape=(1, 12), **over)
    assert sq.Fs == chain.Fs and sq.beta == chain.beta
    cs = chain_start(chain, "paper")
    b = cs.blocks()
    grid = lambda a: np.asarray(a).reshape(1, 12)  # noqa: E731
    start = LatticeState.from_blocks(sq.lattice, grid(b["x"]), grid(b["v"]), grid(b["theta"]), grid(b["stopped"]))
    run = run_lattice(sq, 1000.0, start=start)
    assert ref.summary["n_events"] >= 2
    assert (run.summary["state_sha256"], len(run.events)) == (ref.summary["state_sha256"], ref.summary["n_events"])


def test_values_over_rows_and_cols_and_draws():
    fs = np.arange(12.0).reshape(3, 4) + 2.0
    p = chain_params("sakaguchi", lattice="square", shape=(3, 4), Fs=fs)
    assert p.N == 12 and np.array_equal(p.Fs.values, fs.ravel())
    assert np.array_equal(p.pad(p.Fs.values).reshape(5, 6)[1:-1, 1:-1], fs)
    flat = chain_params("sakaguchi", lattice="square", shape="3x4", Fs=fs.ravel())
    assert flat.Fs == p.Fs
    # a drawn medium: the chain's draw for the lattice's number of blocks, same spec and seed
    q = Quenched("uniform", 2.5, 3.5, seed=9)
    drawn = chain_params("sakaguchi", lattice="square", shape=(3, 4), Fs=q)
    assert drawn.Fs == chain_params("sakaguchi", N=12, Fs=q).Fs


def test_values_from_a_table_file(tmp_path):
    fs = np.arange(6.0).reshape(2, 3) + 2.0
    np.savetxt(tmp_path / "fs.txt", fs)
    p = chain_params("sakaguchi", lattice="square", shape=(2, 3), Fs=f"file:{tmp_path / 'fs.txt'}")
    assert np.array_equal(p.Fs.values, fs.ravel())


def test_refusals():
    with pytest.raises(ParameterError, match=r"Fs must be 3x4 values over \(row, col\), or 12"):
        chain_params("sakaguchi", lattice="square", shape=(3, 4), Fs=np.ones((4, 3)) * 3)
    with pytest.raises(ParameterError, match="Fs must be > 0 at every block"):
        chain_params("sakaguchi", lattice="square", shape=(3, 4), Fs=-np.ones((3, 4)))
    with pytest.raises(ParameterError, match="needs N = 12 values"):
        chain_params("sakaguchi", lattice="square", shape=(3, 4), Fs=np.ones(11) * 3)
    with pytest.raises(ParameterError, match="K must be one number on lattice square"):
        chain_params("sakaguchi", lattice="square", shape=(3, 4), K=Quenched("uniform", 5, 10))
    with pytest.raises(ParameterError, match="start steady with per-block parameters"):
        p = chain_params("sakaguchi", lattice="square", shape=(3, 4), Fs=Quenched("uniform", 2.5, 3.5))
        initial_state(p, "steady")


def test_command_line_takes_per_block_values_over_the_square(tmp_path, capsys):
    fs = np.array([[3.0, 3.5, 3.0], [2.5, 3.0, 3.2]])
    np.savetxt(tmp_path / "fs.txt", fs)
    out = tmp_path / "run"
    code, _, err = run_cli(
        capsys, "chain", "--lattice", "square", "--shape", "2x3", "--Fs", f"file:{tmp_path / 'fs.txt'}",
        "--beta", "uniform(0.8, 1.2)", "--disorder-seed", "4", "--V", "0.1", "--t-end", "20", "--out", str(out),
    )  # fmt: skip
    assert code == 0, err
    meta = json.loads((out / "run.json").read_text())
    assert meta["params"]["Fs"]["values"] == fs.ravel().tolist()
    beta = chain_params("sakaguchi", N=6, beta=Quenched("uniform", 0.8, 1.2, seed=4)).beta
    assert meta["params"]["beta"]["sha256"] == beta.sha256
    with xr.open_dataset(out / "state.nc", engine="h5netcdf") as ds:
        assert ds["param_Fs"].dims == ("row", "col")
        np.testing.assert_array_equal(ds["param_Fs"].values, fs)


@pytest.mark.parametrize(
    "argv, names",
    [
        (["--shape", "3x3", "--Fs", "FILE"], ["--Fs", "3x3", "2x3"]),
        (["--shape", "2x3", "--K", "uniform(5, 10)"], ["K", "one number"]),
        (["--shape", "2x3", "--Fs", "uniform(-2, -1)"], ["Fs", "> 0"]),
    ],
)
def test_command_line_refusals(argv, names, tmp_path, capsys):
    np.savetxt(tmp_path / "fs.txt", np.full((2, 3), 3.0))
    argv = [a.replace("FILE", f"file:{tmp_path / 'fs.txt'}") for a in argv]
    from stickslip.cli import main

    assert main(["chain", "--lattice", "square", *argv, "--t-end", "1"]) == 2
    one_line_error(capsys, *names)


def test_the_leaf_spring_of_a_per_block_kp_is_its_values_over_the_square():
    """LatticeParams.leaf(): Kp as given over (row, col) where it differs from block to block, the
    number where it does not, 0 for the edge drive; the stability analysis, which takes one
    number per parameter, refuses per-block Kp in one line."""
    from stickslip.analysis.dynamics.lattice_stability import lattice_stability

    Kp = np.linspace(0.9, 1.1, 20).reshape(4, 5)
    p = chain_params("carlson-langer", lattice="square", shape=(4, 5), Kp=Kp)
    np.testing.assert_array_equal(p.leaf(), Kp)
    drawn = chain_params("carlson-langer", lattice="square", shape=(3, 4), Kp=Quenched("uniform", 0.5, 1.5, seed=7))
    np.testing.assert_array_equal(drawn.leaf(), np.reshape(drawn.Kp.values, (3, 4)))  # the draw, row by row
    one = chain_params("carlson-langer", lattice="square", shape=(4, 5), Kp=1.25)
    assert type(one.leaf()) is float and one.leaf() == 1.25
    assert chain_params(lattice="square", shape=(4, 5)).leaf() == 0.0
    with pytest.raises(ParameterError, match="per block: Kp"):
        lattice_stability(chain_params(lattice="square", shape=(4, 5), drive="plate", Kp=Kp))
