"""Where a one-line error is promised there is one, not a traceback: a state cache that cannot be
used, the located switches at extreme d0 or where the ladder has no answer, a catalogue of a run
whose events table is damaged (missing column, another table, text, NaN, inf, repeated rows)."""

from __future__ import annotations

import math
import shutil

import numpy as np
import pandas as pd
import pytest

from chain_helpers import one_line_error
from stickslip.cli import main
from stickslip.models.params import ParameterError
from stickslip.models.presets import chain_params


@pytest.fixture
def no_transient(monkeypatch):
    """The decorrelation's transient fails if it is run: a refusal comes first."""
    import stickslip.cli.decorrelation as dec

    def fail(*a, **k):
        raise AssertionError("the transient was run")

    monkeypatch.setattr(dec, "_start", fail)


@pytest.mark.parametrize("where", ["a file", "under a file", "read-only"])
def test_a_state_cache_that_cannot_be_used_is_one_line_before_the_transient(
    where, tmp_path, monkeypatch, no_transient, capsys
):
    (tmp_path / "afile").write_text("")
    cache = {"a file": tmp_path / "afile", "under a file": tmp_path / "afile" / "cache"}.get(where)
    if where == "read-only":
        import os

        cache = tmp_path / "ro" / "cache"
        (tmp_path / "ro").mkdir()
        real = os.access
        monkeypatch.setattr(os, "access", lambda p, m: False if str(p).startswith(str(tmp_path / "ro")) else real(p, m))
    argv = ["lyapunov", "--N", "5", "--decorrelation", "--transient", "100", "--state-cache", str(cache)]
    assert main(argv) == 2
    one_line_error(capsys, "--state-cache", str(cache))
    assert not (tmp_path / "ro" / "cache").exists()


def test_a_state_cache_that_is_a_file_is_refused_from_python(tmp_path):
    from stickslip.run.loaded import loaded_state

    (tmp_path / "afile").write_text("")
    with pytest.raises(ParameterError, match="cache .*afile is a file, not a folder"):
        loaded_state(chain_params(N=5), 100.0, cache=tmp_path / "afile")


@pytest.mark.parametrize("d0", ["1e-300", "1e-20"])
def test_located_switches_refuse_a_d0_below_rounding(d0, capsys):
    assert main(["lyapunov", "--N", "5", "--switches", "located", "--t-end", "200", "--d0", d0]) == 2
    one_line_error(capsys, "d0 must be >= 1e-15")


@pytest.mark.parametrize("error", [np.linalg.LinAlgError("Singular matrix"), FloatingPointError("overflow")])
def test_a_located_ladder_without_answer_isone_line_error(error, monkeypatch, capsys):
    import stickslip.analysis.dynamics.lyapunov_flow as flow

    def fails(*a, **k):
        raise error

    monkeypatch.setattr(flow, "flow_ladder", fails)
    assert main(["lyapunov", "--N", "5", "--switches", "located", "--t-end", "200"]) == 2
    one_line_error(capsys, "--switches located at dt = 0.005")


def test_extrapolation_of_non_finite_exponents_says_which():
    from stickslip.analysis.dynamics.lyapunov_flow import extrapolate

    with pytest.raises(ValueError, match=r"the exponent at dt = 0.0025 is not finite"):
        extrapolate([0.005, 0.0025], [0.1, math.nan], [0.01, 0.01])
    lam0, err, c = extrapolate(
        [0.005, 0.0025, 0.00125], [0.1 + 4 * 0.005**2, 0.1 + 4 * 0.0025**2, 0.1 + 4 * 0.00125**2], [0.01] * 3
    )
    assert lam0 == pytest.approx(0.1) and c == pytest.approx(4.0)


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("damaged") / "run"
    assert main(["chain", "--model", "two-blocks", "--t-end", "2e4", "--out", str(out), "--no-progress"]) == 0
    return out


def _events(run):
    return pd.read_parquet(run / "events.parquet")


def _put(run, table):
    table.to_parquet(run / "events.parquet")


def _with(column, values_of):
    def damage(run):
        t = _events(run)
        t[column] = values_of(t[column])
        _put(run, t)

    return damage


DAMAGE = [
    ("no S column", lambda run: _put(run, _events(run).drop(columns=["S"])), "lacks the column(s) S"),
    ("first_move in its place", lambda run: shutil.copy(run / "first_move.parquet", run / "events.parquet"), "lacks"),
    ("S as text", _with("S", lambda s: s.astype(str)), "values, not numbers"),
    ("NaN in S", _with("S", lambda s: s.where(s.index != 3, np.nan)), "column S holds 1 non-finite"),
    ("inf in t_start", _with("t_start", lambda s: s.where(s.index != 5, np.inf)), "column t_start holds 1 non-finite"),
    ("repeated rows", lambda run: _put(run, pd.concat([_events(run)] * 2, ignore_index=True)), "events repeated"),
]


@pytest.mark.parametrize("what, damage, says", DAMAGE, ids=[d[0] for d in DAMAGE])
def test_catalog_of_a_damaged_events_table_isone_line_error(what, damage, says, run_dir, tmp_path, capsys):
    from stickslip.run.rundir import RunDirDamaged, load_run

    run = tmp_path / "run"
    shutil.copytree(run_dir, run)
    damage(run)
    capsys.readouterr()
    assert main(["catalog", str(run), "--bootstrap", "0", "--gof-sims", "0"]) == 2
    one_line_error(capsys, "events.parquet", says)
    assert not (run / "catalog").exists()
    with pytest.raises(RunDirDamaged, match=says.replace("(", r"\(").replace(")", r"\)")):
        load_run(run)
