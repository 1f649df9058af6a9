"""`stickslip period RUN_DIR` on a lattice run (docs/lattice.md, "Periods"): a slip is its epicentre,
area and moment. A 2 x 2 square of the paper's model that settles on an orbit whose slips start in
both rows, checked against the rule written out here with pandas; a planted sequence; a chain run's
result as before."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from chain_helpers import run_cli
from stickslip.analysis.stats.periodicity import find_period
from stickslip.models.presets import chain_params
from stickslip.run.lattice import run_lattice

RTOL = 1e-6


def _match(ev: pd.DataFrame, i: np.ndarray, p: int) -> np.ndarray:
    """Whether slip i matches slip i + p: the same epicentre (row and column) and area, moments
    within RTOL of the larger."""
    a, b = ev.iloc[i].reset_index(drop=True), ev.iloc[i + p].reset_index(drop=True)
    same = (a["epicentre_row"] == b["epicentre_row"]) & (a["epicentre_col"] == b["epicentre_col"])
    same &= a["area"] == b["area"]
    near = (a["moment"] - b["moment"]).abs() <= RTOL * np.maximum(a["moment"].abs(), b["moment"].abs())
    return (same & near).to_numpy()


@pytest.fixture(scope="module")
def square_dir(tmp_path_factory):
    """The paper's model on 2 x 2, pulled at the left, beta = 0.5, V = 0.05, from rest (A = 0.05, seed 1)."""
    out = tmp_path_factory.mktemp("period") / "run"
    p = chain_params(lattice="square", shape=(2, 2), beta=0.5, V=0.05)
    run_lattice(p, 3000.0, start="rest", perturbation=0.05, seed=1).write(out)
    return out


def test_square_settles_on_an_orbit_by_the_rule(square_dir, capsys):
    code, out, err = run_cli(capsys, "period", str(square_dir), "--json")
    assert code == 0, err
    got = json.loads(out)
    ev = pd.read_csv(square_dir / "events.csv")
    n, p, s = len(ev), got["period_slips"], got["settled_from_slip"]
    assert got["n_slips"] == n and p is not None and got["lattice"].startswith("square 2x2")
    assert "epicentre and area are equal" in got["rule"] and got["t_reached"] == 3000.0
    longest = min(500, n // 3)
    # every slip from s on matches the one p later, slip s - 1 does not, and the stretch is long enough
    assert _match(ev, np.arange(s, n - p), p).all()
    assert s == 0 or not _match(ev, np.array([s - 1]), p)[0]
    assert n - s >= max(3 * p, p + longest)
    # no shorter period holds over the last stretch it needs
    for q in range(1, p):
        need = max(3 * q, q + longest)
        assert not _match(ev, np.arange(n - need, n - q), q).all(), q
    # a two-dimensional orbit: its slips start in both rows
    assert set(ev["epicentre_row"].iloc[s:]) == {1, 2}
    assert got["settled_from_t"] == ev["t_start"].iloc[s]


def test_planted_sequence(square_dir, tmp_path, capsys):
    """Ten irregular slips, then three slips repeated, two of them at the same column in
    different rows (the flat epicentre tells them apart)."""
    out = tmp_path / "planted"
    out.mkdir()
    for name in ("run.json", "state.nc"):
        (out / name).write_bytes((square_dir / name).read_bytes())
    pattern = [(1, 2, 2, 0.5), (2, 2, 2, 0.5), (2, 1, 4, 3.0)]
    rows = [(1 + k % 2, 1, 1, 10.0 + k) for k in range(10)] + pattern * 12
    ev = pd.DataFrame(rows, columns=["epicentre_row", "epicentre_col", "area", "moment"])
    ev["t_start"] = np.arange(len(ev)) * 2.0
    ev.to_csv(out / "events.csv", index=False)
    code, text, err = run_cli(capsys, "period", str(out), "--json")
    assert code == 0, err
    got = json.loads(text)
    assert (got["period_slips"], got["settled_from_slip"], got["settled_from_t"], got["period_t"]) == (3, 10, 20.0, 6.0)
    # the rows of one column differ: one slip moved to the other row breaks the orbit there
    ev.loc[20, "epicentre_row"] = 1
    ev.to_csv(out / "events.csv", index=False)
    code, text, _ = run_cli(capsys, "period", str(out), "--json")
    assert code == 0 and json.loads(text)["settled_from_slip"] == 21


def test_a_lattice_run_without_its_state_is_refused_in_one_line(square_dir, tmp_path, capsys):
    out = tmp_path / "partial"
    out.mkdir()
    for name in ("run.json", "events.csv"):
        (out / name).write_bytes((square_dir / name).read_bytes())
    code, text, err = run_cli(capsys, "period", str(out))
    assert code == 2 and text == "" and err.count("\n") == 1 and "lattice run directory" in err, err


def test_the_chains_rule_is_worded_as_before():
    r = find_period([1, 2] * 6, [1, 1] * 6, [1.0, 2.0] * 6)
    assert r.period_slips == 2
    assert r.rule.startswith("slip i matches slip i + p when start_block and n_blocks are equal and |S_i - S_(i+p)|")
