"""The lattice reference integrator (stickslip.kernels.lattice): on the chain lattice, and on a
single row or column of the square, it gives the chain's reference bit for bit (the floors of
tests/test_floors.py); on small squares it equals a plain-numpy step of the 2-d equations written
here from docs/model.md, for every edge kind."""

from __future__ import annotations

import numpy as np
import pytest

from stickslip.models.lattice.params import on_lattice
from stickslip.models.params import ParameterError
from stickslip.models.presets import chain_params
from stickslip.run.driver import run_chain
from stickslip.run.lattice import LatticeState, initial_state, run_lattice
from stickslip.run.state import initial_state as chain_start
from test_floors import FLOORS

SIDES = ("top", "bottom", "left", "right")


def _chain_equal(case, shape=None, edges=None):
    model, overrides, t_end, start, perturbation, seed, sha, n_events = FLOORS[case]
    params = chain_params(model, **overrides)
    cs = chain_start(params, start, amplitude=perturbation, seed=seed)
    if shape is None:
        lp = on_lattice(params, "chain")
        state = LatticeState(cs.xg, cs.vg, cs.thg, cs.mov, cs.first_step, cs.x0ev, cs.ist)
    else:
        lp = on_lattice(params, "square", shape, edges)
        b = cs.blocks()
        grid = lambda a: np.asarray(a).reshape(shape)  # noqa: E731
        state = LatticeState.from_blocks(lp.lattice, grid(b["x"]), grid(b["v"]), grid(b["theta"]), grid(b["stopped"]))
    run = run_lattice(lp, t_end, start=state)
    assert (run.summary["state_sha256"], run.summary["events"]) == (sha, n_events)
    return params, run


def test_chain_lattice_gives_the_chain_reference_events():
    """Carlson-Langer's floor on the chain lattice: the state hash and every event's size, blocks
    and first block are the chain reference's."""
    params, run = _chain_equal("carlson-langer")
    ref = run_chain(params, 2e3, start="rest", perturbation=0.01, integrator="dense").events
    ev = run.events
    assert (ev["area"].to_numpy() == ref["n_blocks"].to_numpy()).all()
    assert ev["moment"].to_numpy().tobytes() == ref["S"].to_numpy().tobytes()
    assert (ev["epicentre_col"].to_numpy() == ref["start_block"].to_numpy()).all()
    assert (ev["col_max"].to_numpy() <= ref["max_block"].to_numpy()).all()
    assert (ev["step_start"].to_numpy() == ref["step_start"].to_numpy()).all()


def test_a_row_of_the_square_is_the_ring():
    """A 1 x 100 square with periodic sides is Carlson-Langer's ring, bit for bit."""
    _chain_equal("carlson-langer", (1, 100), "periodic")


@pytest.mark.slow
@pytest.mark.parametrize("case", sorted(c for c in FLOORS if "rate-state" not in c) + ["rate-state-end"])
def test_every_floor_on_the_chain_lattice(case):
    _chain_equal(case)


@pytest.mark.slow
@pytest.mark.parametrize("shape, edges", [((1, 49), None), ((49, 1), "top=driven")])
def test_the_papers_chain_as_a_row_and_a_column(shape, edges):
    _chain_equal("sakaguchi", shape, edges)


# -- the oracle: the 2-d equations of docs/model.md in plain numpy ----------------------------------


def _padded(a, kinds, p, theta):
    """a (rows, cols) with its ghost ring: free repeats the edge, fixed is the wall at 0, periodic
    the opposite side, driven the load point p; theta has no flux but through periodic sides."""
    top, bottom, left, right = kinds

    def ghost(kind, edge, other):
        if kind == "periodic":
            return other
        if theta or kind == "free":
            return edge
        return np.zeros_like(edge) + (p if kind == "driven" else 0.0)

    g = np.zeros((a.shape[0] + 2, a.shape[1] + 2))
    g[1:-1, 1:-1] = a
    g[1:-1, 0] = ghost(left, a[:, 0], a[:, -1])
    g[1:-1, -1] = ghost(right, a[:, -1], a[:, 0])
    g[0, 1:-1] = ghost(top, a[0, :], a[-1, :])
    g[-1, 1:-1] = ghost(bottom, a[-1, :], a[0, :])
    return g


def _laplacian(g):
    c = g[1:-1, 1:-1]
    return ((g[1:-1, :-2] - c) - (c - g[1:-1, 2:])) + ((g[:-2, 1:-1] - c) - (c - g[2:, 1:-1]))


def _rates(p, x, v, th, m, kinds, t):
    """(f, dv/dt, dtheta/dt) of docs/model.md on the lattice at time t, moving mask m."""
    load = p.V * t
    f = p.K * _laplacian(_padded(x, kinds, load, False))
    if p.drive == "plate":
        f = f + p.Kp * (load - x)
    lap_th = _laplacian(_padded(th, kinds, load, True))
    if p.friction == "state":
        a = m * (f - th - p.beta * v)
        b = th * (1.0 - th) - p.alpha * th * v + p.D * lap_th
    elif p.friction == "weakening":
        w = 1.0 - p.sigma
        a = m * (f - w / (1.0 + 2.0 * p.alpha * np.maximum(v, 0.0) / w))
        b = np.zeros_like(th)
    else:  # strengthening: F0 + beta v
        a = m * (f - p.F0 - p.beta * v)
        b = np.zeros_like(th)
    return f, a, b


def _oracle(p, kinds, x, v, th, mov, n_steps):
    """Heun with the start and stop rules (docs/model.md) and the events' area, moment,
    epicentre and bounding box, step by step."""
    dt = p.dt
    Fs = p.Fs if p.threshold == "constant" else None
    events, first, x0, active, n_moving = [], None, None, False, int(mov.sum())
    for n in range(n_steps):
        f, _, _ = _rates(p, x, v, th, mov, kinds, n * dt)
        m = np.where((mov != 0.0) | (f > (Fs if Fs is not None else th)), 1.0, 0.0)
        f, a1, b1 = _rates(p, x, v, th, m, kinds, n * dt)
        xs, vs, ths = x + dt * v, v + dt * a1, th + dt * b1
        _, a2, b2 = _rates(p, xs, vs, ths, m, kinds, (n + 1) * dt)
        if not active and n_moving == 0 and m.any():
            active, first, x0 = True, np.full(x.shape, -1), np.zeros(x.shape)
            epi = np.argwhere(m != 0.0)[0] + 1
            start = n
        if active:
            new = (m != 0.0) & (first < 0)
            first[new], x0[new] = n, x[new]
        th = th + 0.5 * dt * (b1 + b2)
        xn = np.where(m != 0.0, x + 0.5 * dt * (v + vs), x)
        vn = np.where(m != 0.0, v + 0.5 * dt * (a1 + a2), 0.0)
        mov = np.where(vn > 0.0, 1.0, 0.0)
        x, v = xn, np.where(vn > 0.0, vn, 0.0)
        n_moving = int(mov.sum())
        if active and n_moving == 0:
            moved = np.argwhere(first >= 0) + 1
            slip = (x - x0)[first >= 0]
            events.append((start, n, *epi, len(moved), slip.sum(), *moved.min(axis=0), *moved.max(axis=0)))
            active = False
    return x, v, th, mov, events


CASES = [
    # (preset, overrides, kinds (top, bottom, left, right), shape, perturbation)
    ("sakaguchi", dict(K=10.0), ("free", "free", "driven", "free"), (3, 4), 1.0),
    ("sakaguchi", dict(K=10.0, beta=0.5), ("periodic", "periodic", "driven", "fixed"), (5, 5), 1.0),
    ("sakaguchi", dict(K=10.0), ("fixed", "free", "fixed", "driven"), (4, 3), 1.0),
    ("carlson-langer", dict(), ("periodic",) * 4, (5, 5), 0.01),
    ("carlson-langer", dict(), ("free", "fixed", "free", "fixed"), (3, 4), 0.01),
    ("carlson-langer", dict(friction="state", threshold="state", D=2.0), ("fixed",) * 4, (5, 5), 0.05),
    ("train", dict(), ("periodic", "periodic", "driven", "free"), (3, 4), 1.0),
]


@pytest.mark.parametrize("preset, overrides, kinds, shape, amplitude", CASES)
def test_square_step_equals_the_plain_numpy_equations(preset, overrides, kinds, shape, amplitude):
    kinds_ok = kinds
    edges = dict(zip(SIDES, kinds_ok, strict=True))
    p = on_lattice(chain_params(preset, **overrides), "square", shape, edges)
    n_steps = 1500
    s0 = initial_state(p, "rest", amplitude=amplitude, seed=4)
    f0 = s0.fields(p.lattice)
    run = run_lattice(p, n_steps * p.dt, start=s0)
    fin = run.state.fields(p.lattice)
    mov0 = np.where(f0["stopped"], 0.0, 1.0)
    x, v, th, mov, events = _oracle(p, kinds_ok, f0["x"], f0["v"], f0["theta"], mov0, n_steps)
    assert len(events) >= 1
    for got, want in ((fin["x"], x), (fin["v"], v), (fin["theta"], th)):
        assert got.tobytes() == want.tobytes()
    assert (fin["stopped"] == (mov == 0.0)).all()
    ev = run.events
    cols = ["step_start", "step_end", "epicentre_row", "epicentre_col", "area", "moment"]
    got = ev[cols + ["row_min", "col_min", "row_max", "col_max"]].to_numpy(dtype=float)
    np.testing.assert_allclose(got, np.array(events, dtype=float), rtol=0, atol=1e-12)


def test_refusals():
    with pytest.raises(ParameterError, match="lattice must be one of"):
        on_lattice(chain_params(), "hexagonal", (3, 3))
    with pytest.raises(ParameterError, match="shape must be"):
        on_lattice(chain_params(), "square", "3by3")
    with pytest.raises(ParameterError, match="both be periodic"):
        on_lattice(chain_params("carlson-langer"), "square", (3, 3), "top=free")
    with pytest.raises(ParameterError, match="K must be one number"):
        on_lattice(chain_params(N=9, K=np.linspace(3, 4, 9)), "square", (3, 3))
    with pytest.raises(ParameterError, match="run_lattice needs"):
        run_lattice(chain_params(N=9), 1.0)
