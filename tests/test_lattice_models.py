"""The three models of the square as the command line names them (docs/lattice.md, "The models
on the square"): the paper's model pulled at one edge, Carlson-Langer under a plate with periodic
sides, and Burridge-Knopoff with the train's friction F0 + beta v. Each runs from the command
line and is checked against numbers worked out here: the first event's step and epicentre from
the start rule applied by hand to the documented start, and steady sliding's closed form."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from chain_helpers import run_cli


def _laplacian(x, left, right, top, bottom):
    """The 5-point Laplacian of x (rows, cols) with ghost columns/rows given (arrays or scalars)."""
    g = np.zeros((x.shape[0] + 2, x.shape[1] + 2))
    g[1:-1, 1:-1] = x
    g[1:-1, 0], g[1:-1, -1], g[0, 1:-1], g[-1, 1:-1] = left, right, top, bottom
    c = g[1:-1, 1:-1]
    return ((g[1:-1, :-2] - c) - (c - g[1:-1, 2:])) + ((g[:-2, 1:-1] - c) - (c - g[2:, 1:-1]))


def _first_start(force, Fs, n_max):
    """The first step n whose force (a function of n, over the blocks) exceeds Fs somewhere, and
    the first such block in row-major order (1-based)."""
    for n in range(n_max):
        over = force(n) > Fs
        if over.any():
            r, c = np.argwhere(over)[0]
            return n, r + 1, c + 1
    raise AssertionError("no block reached its threshold")


def _run(capsys, tmp_path, *argv):
    out = tmp_path / "run"
    code, _, err = run_cli(capsys, "chain", "--lattice", "square", *argv, "--out", str(out))
    assert code == 0, err
    return pd.read_csv(out / "events.csv"), out


def test_papers_model_pulled_at_the_left_edge(capsys, tmp_path):
    """eq. (4) on a 6 x 8 square at rest (x = -A u): only the left column feels the pulling point,
    so the first event starts there, in the row whose block is nearest its threshold."""
    events, _ = _run(
        capsys, tmp_path, "--shape", "6x8", "--start", "rest", "--perturbation", "0.01", "--seed", "3",
        "--V", "0.01", "--t-end", "40",
    )  # fmt: skip
    x = -0.01 * np.random.default_rng(3).random(48).reshape(6, 8)
    K, V, dt, Fs = 10.0, 0.01, 0.005, 3.0

    def force(n):
        p = V * (n * dt)
        return K * _laplacian(x, p, x[:, -1], x[0], x[-1])

    n, row, col = _first_start(force, Fs, 8000)
    assert col == 1 and n > 5000
    first = events.iloc[0]
    assert (first["step_start"], first["epicentre_row"], first["epicentre_col"]) == (n, row, 1)


def test_carlson_langer_under_the_plate_with_periodic_sides(capsys, tmp_path):
    """Carlson-Langer (l = 10, nu = 0.01) on the periodic 6 x 6 square at rest: every block is
    loaded by its leaf spring, f = l^2 lap(x) + (nu t - x); the first to pass Fs = 1 starts."""
    events, _ = _run(
        capsys, tmp_path, "--model", "carlson-langer", "--shape", "6x6", "--perturbation", "0.002", "--seed", "1",
        "--t-end", "60",
    )  # fmt: skip
    x = -0.002 * np.random.default_rng(1).random(36).reshape(6, 6)
    K, V, dt = 100.0, 0.01, 0.005

    def force(n):
        return K * _laplacian(x, x[:, -1], x[:, 0], x[-1], x[0]) + 1.0 * (V * (n * dt) - x)

    n, row, col = _first_start(force, 1.0, 12000)
    assert n > 5000
    first = events.iloc[0]
    assert (first["step_start"], first["epicentre_row"], first["epicentre_col"]) == (n, row, col)


@pytest.mark.slow  # the square with the train's friction, compiled here first (23 s, measured)
def test_burridge_knopoff_with_the_trains_friction_slides_steadily(capsys, tmp_path):
    """Plate drive and F0 + beta v (velocity strengthening) on the periodic square: steady sliding
    x = nu t - (F0 + beta nu) / Kp, v = nu is stable, so a perturbed start returns to it."""
    events, out = _run(
        capsys, tmp_path, "--model", "carlson-langer", "--friction", "strengthening", "--F0", "0.5", "--beta", "1",
        "--shape", "4x5", "--start", "steady", "--perturbation", "0.01", "--nu", "0.1", "--t-end", "60",
    )  # fmt: skip
    assert len(events) == 0
    with xr.open_dataset(out / "state.nc", engine="h5netcdf") as ds:
        x, v = ds["x"].values, ds["v"].values
    nu, F0, beta = 0.1, 0.5, 1.0
    np.testing.assert_allclose(v, nu, rtol=0, atol=1e-9)
    np.testing.assert_allclose(x, nu * 60.0 - (F0 + beta * nu), rtol=0, atol=1e-9)


@pytest.mark.slow  # the square with the train's friction, compiled here first (23 s, measured)
def test_burridge_knopoff_with_the_trains_friction_sticks_and_slips(capsys, tmp_path):
    """The same model from rest with Fs = 1 above F0: stick-slip, each event's slip positive."""
    events, _ = _run(
        capsys, tmp_path, "--model", "carlson-langer", "--friction", "strengthening", "--F0", "0.5", "--beta", "1",
        "--shape", "4x5", "--t-end", "100",
    )  # fmt: skip
    assert len(events) >= 2 and (events["moment"] > 0).all()
