"""Per-block parameters travel with a run: run.json (spec and SHA-256), state.nc (the arrays over
``block``), checkpoints, resume, ``--from``, ``save``/``load_run``; and the disordered bench
(docs/chain.md, "Per-block parameters and quenched disorder")."""

from __future__ import annotations

import hashlib
import json
import math
import shlex

import numpy as np
import pytest
import xarray as xr

from chain_helpers import assert_same_run
from stickslip import ChainParams, Quenched, chain_params, load_run
from stickslip.cli import main
from stickslip.models import physics
from stickslip.models.params import ParameterError
from stickslip.run import driver as C
from stickslip.run.driver import ChainRunError, resume_chain, run_chain
from stickslip.run.state import ChainState

# Fs and beta per block (the disordered bench's chain): one compilation for the whole file.
P = ChainParams(N=6, V=0.01, Fs=Quenched("uniform", 2.5, 3.5, seed=3), beta=Quenched("normal", 1.0, 0.1, seed=3))
T = 1500.0


@pytest.fixture(scope="module")
def full():
    run = run_chain(P, T, sample_interval=10.0)
    assert run.summary["n_events"] >= 2
    return run


@pytest.mark.slow  # Fs and beta per block compile a composition of their own (about 70 s, measured)
def test_run_json_and_state_nc_carry_the_spec_the_hash_and_the_arrays(tmp_path, full):
    full.save(tmp_path / "r")
    meta = json.loads((tmp_path / "r" / "run.json").read_text())
    fs = meta["params"]["Fs"]
    assert fs["spec"] == "uniform(2.5, 3.5)" and fs["seed"] == 3
    assert fs["sha256"] == hashlib.sha256(np.asarray(P.Fs.values, dtype="<f8").tobytes()).hexdigest()
    ds = xr.open_dataset(tmp_path / "r" / "state.nc")
    np.testing.assert_array_equal(ds["param_Fs"].values, P.Fs.values)
    np.testing.assert_array_equal(ds["param_beta"].values, P.beta.values)
    assert ds["param_Fs"].dims == ("block",) and ds["param_Fs"].attrs["sha256"] == fs["sha256"]
    ds.close()
    loaded = load_run(tmp_path / "r")
    assert loaded.params == P and loaded.params.Fs.spec == P.Fs.spec
    assert loaded.summary["state_sha256"] == full.summary["state_sha256"]
    assert loaded.events.equals(full.events)


@pytest.mark.slow  # Fs and beta per block compile a composition of their own (about 70 s, measured)
def test_resume_continues_the_same_medium_to_the_same_bits(tmp_path, full):
    run_chain(P, 700.0, out_dir=tmp_path, sample_interval=10.0, keep_checkpoint=True)
    run = resume_chain(tmp_path, t_end=T, expect_params=P)
    assert_same_run(run, full)
    other = P.replace(Fs=Quenched("uniform", 2.5, 3.5, seed=4))
    with pytest.raises(ChainRunError, match="other parameters"):
        resume_chain(tmp_path, t_end=T + 100.0, expect_params=other)


@pytest.mark.slow  # Fs and beta per block compile a composition of their own (about 70 s, measured)
def test_a_checkpoint_whose_arrays_do_not_match_their_hash_is_refused(tmp_path):
    run_chain(P, 300.0, out_dir=tmp_path, keep_checkpoint=True)
    path = C.Checkpointer(tmp_path).state_path
    arrays, header, _ = C.read_npz(path)
    header["params"]["Fs"]["values"][2] += 0.25
    C.write_npz(path, arrays, header)
    with pytest.raises(ChainRunError, match="SHA-256"):
        resume_chain(tmp_path, t_end=400.0)


@pytest.mark.slow  # Fs and beta per block compile a composition of their own (about 70 s, measured)
def test_from_continues_the_medium_of_the_run_it_names(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    argv = 'chain --N 6 --V 0.01 --Fs "uniform(2.5, 3.5)" --beta "normal(1, 0.1)" --disorder-seed 3 --t-end 300 --out a'
    assert main(shlex.split(argv)) in (0, None)
    assert main(shlex.split("chain --from a --N 6 --V 0.01 --t-end 600 --out b")) in (0, None)
    capsys.readouterr()
    a, b = load_run(tmp_path / "a"), load_run(tmp_path / "b")
    assert a.params.Fs == P.Fs and a.params.beta == P.beta
    assert b.params.Fs == P.Fs and b.params.beta == P.beta


@pytest.mark.slow  # Fs and beta per block compile a composition of their own (about 70 s, measured)
def test_bench_disordered_reports_both_chains_in_one_run(monkeypatch, capsys):
    main(shlex.split("bench --workload disordered --N 6 --V 0.01 --t-end 200 --json"))
    out = json.loads(capsys.readouterr().out)
    assert out["identical"] is True
    assert out["uniform"]["per_block"] == {}
    assert out["disordered"]["per_block"]["Fs"]["spec"] == "uniform(2.5, 3.5)"
    for key in ("ratio_to_uniform", "ratio_dense"):
        assert out[key] > 0
    assert out["uniform"]["ns_per_update_exact"] > 0 and out["disordered"]["exact_block_updates"] > 0
    # the exact runs are timed over ten times t_end: their updates are those of a run that long
    assert out["disordered"]["exact_t_end"] == 2000.0
    drawn = {"Fs": Quenched("uniform", 2.5, 3.5, seed=0), "beta": Quenched("normal", 1.0, 0.1, seed=0)}
    long = run_chain(chain_params(N=6, V=0.01, **drawn), 2000.0, start="paper")
    assert out["disordered"]["exact_block_updates"] == long.summary["block_updates"]


@pytest.mark.slow
def test_a_chain_without_a_closed_form_steady_state_runs_and_says_so():
    """Per-block alpha gives each block its own theta_0 = 1 - alpha_i V, which the diffusion D = 5
    couples: no closed-form steady sliding, so the run's L_steady is NaN, not an error."""
    p = chain_params("sakaguchi", N=9, alpha=Quenched("uniform", 0.5, 1.5, seed=1))
    with pytest.raises(physics.NoClosedForm):
        physics.chain_steady_length(p)
    run = run_chain(p, 200.0)
    assert math.isnan(run.summary["L_steady"])
    # A steady start is refused with the reason, as a bad parameter.
    with pytest.raises(ParameterError, match="start must be paper or rest for this chain: .*theta_0"):
        ChainState.steady(p)
