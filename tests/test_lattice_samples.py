"""The samples of a lattice run as declared reductions (docs/lattice.md, "Outputs"): the mean
stress of a written run against a plain-numpy evaluation of the 2-d force from its snapshots, and
at steady sliding against the friction at v = V in closed form."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from stickslip.models.lattice.samples import SAMPLES
from stickslip.models.presets import chain_params
from stickslip.run.lattice import run_lattice


def numpy_force(x: np.ndarray, edges: tuple[str, str, str, str], load: float, K: float, Kp: float) -> np.ndarray:
    """K times the 5-point Laplacian of x (rows, cols) plus Kp (load - x), written out here: the
    ghost beyond a side (top, bottom, left, right) is the edge block (free), 0 (fixed), the
    opposite edge (periodic) or the load point (driven)."""
    g = np.pad(x, 1)
    top, bottom, left, right = edges
    ghost = {
        "free": lambda edge, other: edge,
        "fixed": lambda edge, other: 0.0 * edge,
        "periodic": lambda edge, other: other,
        "driven": lambda edge, other: 0.0 * edge + load,
    }
    g[0, 1:-1] = ghost[top](x[0], x[-1])
    g[-1, 1:-1] = ghost[bottom](x[-1], x[0])
    g[1:-1, 0] = ghost[left](x[:, 0], x[:, -1])
    g[1:-1, -1] = ghost[right](x[:, -1], x[:, 0])
    lap = g[:-2, 1:-1] + g[2:, 1:-1] + g[1:-1, :-2] + g[1:-1, 2:] - 4.0 * x
    return K * lap + Kp * (load - x)


CASES = [
    # the paper's model pulled at the left side: free, and periodic top and bottom with a wall at the right
    ("sakaguchi", dict(beta=0.5), None, 0.0),
    ("sakaguchi", dict(beta=0.5), "top=periodic,bottom=periodic,right=fixed", 0.0),
    # Carlson-Langer: the plate, periodic sides, and with a free top and a fixed bottom
    ("carlson-langer", {}, None, 1.0),
    ("carlson-langer", {}, "top=free,bottom=fixed", 1.0),
]


@pytest.mark.parametrize("model, extra, edges, Kp", CASES)
def test_mean_stress_is_the_force_of_the_snapshots(tmp_path, model, extra, edges, Kp):
    p = chain_params(model, lattice="square", shape=(4, 5), edges=edges, **extra)
    start = "paper" if model == "sakaguchi" else "rest"
    run = run_lattice(p, 20.0, start=start, perturbation=0.01, snapshot_every=5.0, sample_every=5.0)
    out = run.write(tmp_path / "run")
    samples = pd.read_csv(out / "samples.csv").set_index("t")
    assert list(samples.columns) == [r.name for r in SAMPLES]
    with xr.open_dataset(out / "state.nc", engine="h5netcdf") as ds:
        times, xs = ds["time"].values, ds["snapshot_x"].values
    assert list(times) == [0.0, 5.0, 10.0, 15.0, 20.0]
    stresses = []
    for t, x in zip(times, xs, strict=True):
        f = numpy_force(x, p.lattice.edges, p.V * t, p.K, Kp)
        assert samples.loc[t, "mean_stress"] == pytest.approx(f.mean(), rel=1e-9, abs=1e-9)
        stresses.append(f.mean())
        if p.lattice.edges == ("free", "free", "driven", "free"):
            # the springs inside cancel in the sum: only those to the load point remain
            assert f.mean() == pytest.approx(p.K * np.sum(p.V * t - x[:, 0]) / x.size, rel=1e-9, abs=1e-9)
        if p.lattice.edges == ("periodic",) * 4:
            # every spring joins two blocks: the mean stress is the plate's, Kp times the slip deficit
            assert samples.loc[t, "mean_stress"] == pytest.approx(Kp * samples.loc[t, "mean_slip_deficit"], abs=1e-12)
    assert np.ptp(stresses) > 1e-6  # the force changes over the run: the check above sees something


@pytest.mark.parametrize(
    "model, extra, edges, friction",
    [
        # eq. (4)'s law: theta_0 = 1 - alpha V, c = theta_0 + beta V
        ("sakaguchi", dict(beta=1.5), None, lambda p: 1.0 - p.alpha * p.V + p.beta * p.V),
        ("sakaguchi", dict(beta=1.5), "top=periodic,bottom=periodic", lambda p: 1.0 - p.alpha * p.V + p.beta * p.V),
        # Carlson-Langer's weakening at v = V: (1 - sigma) / (1 + 2 alpha V / (1 - sigma))
        ("carlson-langer", {}, None, lambda p: (1 - p.sigma) / (1 + 2 * p.alpha * p.V / (1 - p.sigma))),
    ],
)
def test_mean_stress_at_steady_sliding_is_the_friction(model, extra, edges, friction):
    p = chain_params(model, lattice="square", shape=(6, 8), edges=edges, **extra)
    run = run_lattice(p, 1.0, start="steady", sample_every=0.5)
    c = friction(p)
    assert run.samples["t"].tolist() == [0.0, 0.5, 1.0]
    np.testing.assert_allclose(run.samples["mean_stress"], c, rtol=0, atol=1e-9)
    np.testing.assert_allclose(run.samples["mean_v"], p.V, rtol=0, atol=1e-12)
    assert (run.samples["moving"] == p.N).all()
