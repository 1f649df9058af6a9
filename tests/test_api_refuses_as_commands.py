"""The Python API refuses what the commands refuse, through the same checks
(:meth:`RunOptions.validated`, :func:`stickslip.run.state.check_start_draw`,
:func:`stickslip.analysis.stats.catalog.check_catalog_options`): before, ``run_chain`` took
``checkpoint_interval`` without ``out_dir``, ``profile_min_blocks=2.5`` (as 2),
``snapshot_times="10"`` (as the times 1 and 0), a seed with the paper's start; ``options={...}``
died of an AttributeError; ``run.save("")`` wrote into the working directory's name."""

from __future__ import annotations

import math

import pytest

from stickslip import RunOptions, chain_params, run_chain
from stickslip.analysis.stats.catalog import catalog_analysis
from stickslip.cli import main
from stickslip.models.params import ParameterError

P = chain_params(N=3)

REFUSED = [
    ({"checkpoint_interval": 5.0}, "checkpoint_interval needs out_dir"),
    ({"keep_checkpoint": True}, "keep_checkpoint needs out_dir"),
    ({"profile_min_blocks": 2.5, "profile_window": 1.0}, "profile_min_blocks must be an integer"),
    ({"snapshot_times": "10"}, "snapshot_times must be a sequence of times"),
    ({"snapshot_times": 10.0}, "snapshot_times must be a sequence of times"),
    ({"out_dir": ""}, "out_dir must name a directory"),
    ({"seed": 3}, "seed goes with start='steady' or start='rest'"),
    ({"perturbation": 0.1}, "perturbation goes with start='steady' or start='rest'"),
    ({"options": {"sample_interval": 5.0}}, "options must be a RunOptions"),
]


@pytest.mark.parametrize(
    "given, said", REFUSED, ids=[next(iter(g)) + ("" if i != 4 else "-number") for i, (g, _) in enumerate(REFUSED)]
)
def test_run_chain_refuses(given, said, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ParameterError, match=said.replace("(", r"\(")):
        run_chain(P, 20.0, **given)
    assert list(tmp_path.iterdir()) == [], "nothing written"


def test_the_same_checks_through_options(tmp_path):
    with pytest.raises(ParameterError, match="checkpoint_interval needs out_dir"):
        run_chain(P, 20.0, options=RunOptions(checkpoint_interval=5.0))


@pytest.mark.parametrize(
    "argv, said",
    [
        (["--checkpoint-interval", "5"], "--checkpoint-interval needs --out"),
        (["--keep-checkpoint"], "--keep-checkpoint needs --out"),
        (["--seed", "3"], "--seed goes with --start steady or --start rest"),
        (["--perturbation", "0.1"], "--perturbation goes with --start steady or --start rest"),
    ],
)
def test_the_command_says_it_in_its_own_words(argv, said, capsys):
    assert main(["chain", "--N", "3", "--t-end", "20", *argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and said in err, err


def test_save_refuses_an_empty_name(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    run = run_chain(P, 20.0)
    with pytest.raises(ParameterError, match="out_dir must name a directory"):
        run.save("")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "given, said",
    [
        ({"bootstrap": -1}, "bootstrap must be"),
        ({"gof_sims": -5}, "gof_sims must be"),
        ({"seed": -1}, "seed must be"),
        ({"bootstrap": 2.5}, "bootstrap must be an integer"),
        ({"dm": math.nan}, "dm must be a finite number"),
        ({"dm": 2.0}, r"dm must be >= 0 and <= 1"),
    ],
)
def test_catalog_analysis_refuses_before_reading(given, said, tmp_path):
    """Refused before the run is read: the folder named does not even exist."""
    with pytest.raises(ParameterError, match=said):
        catalog_analysis(tmp_path / "no-such-run", **given)


@pytest.mark.parametrize("argv", [["--seed", "3"], ["--perturbation", "0.1"]])
def test_lyapunov_refuses_a_draw_with_the_papers_start_through_the_same_check(argv, capsys):
    assert main(["lyapunov", "--N", "3", *argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "goes with --start steady or --start rest" in err, err


def test_snapshot_times_may_be_any_sequence_of_numbers():
    import numpy as np

    for times in ((5.0, 10.0), [5.0, 10.0], np.array([5.0, 10.0])):
        run = run_chain(P, 20.0, snapshot_times=times)
        assert run.snapshots.sizes["snapshot_time"] == 3  # the two and the final state
