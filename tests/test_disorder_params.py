"""Per-block parameters in Python and on the command line: drawn values, their checks and the
one-line refusals (docs/model.md and docs/chain.md, "Per-block parameters")."""

from __future__ import annotations

import shlex
import zlib

import numpy as np
import pytest
from scipy import stats

from chain_helpers import error_lines, run_cli
from stickslip import ChainParams, ParameterError, Quenched, chain_params
from stickslip.models.disorder import PerBlock, parse


def test_a_spec_draws_from_numpys_generator_with_a_stream_per_parameter():
    p = ChainParams(N=50, Fs=Quenched("uniform", 2.5, 3.5, seed=7))
    rng = np.random.default_rng(np.random.SeedSequence(7, spawn_key=(zlib.crc32(b"Fs"),)))
    np.testing.assert_array_equal(p.Fs.values, rng.uniform(2.5, 3.5, 50))
    assert p.Fs.seed == 7 and p.per_block() == {"Fs": p.Fs}
    # the same seed for another parameter: another stream
    q = ChainParams(N=50, Fs=Quenched("uniform", 2.5, 3.5, seed=7), beta=Quenched("uniform", 2.5, 3.5, seed=7))
    assert not np.array_equal(q.Fs.values, q.beta.values)
    assert q.Fs == p.Fs and hash(q.Fs) == hash(p.Fs)


def test_a_drawn_medium_follows_n_and_an_array_does_not():
    """replace(N=...) draws a spec's medium anew for N blocks, from numpy's stream of its seed;
    an array of the old length is refused with the lengths."""
    p = ChainParams(N=8, Fs=Quenched("uniform", 2.5, 3.5, seed=3), beta=Quenched("uniform", 0.5, 1.5))
    q = p.replace(N=12)
    rng = np.random.default_rng(np.random.SeedSequence(3, spawn_key=(zlib.crc32(b"Fs"),)))
    np.testing.assert_array_equal(q.Fs.values, rng.uniform(2.5, 3.5, 12))
    assert q.Fs.spec_text == p.Fs.spec_text and len(q.beta) == 12 and q.beta.seed == p.beta.seed
    assert q.replace(N=8).per_block() == p.per_block()
    with pytest.raises(ParameterError, match="needs N = 12 values \\(got 8\\)"):
        ChainParams(N=8, Fs=np.linspace(2.5, 3.5, 8)).replace(N=12)


def test_the_truncated_normal_stays_in_the_range_and_follows_its_law():
    p = ChainParams(N=4000, beta=Quenched("normal", 0.05, 0.2, seed=1))
    b = p.beta.values
    assert b.min() >= 0.0
    # Kolmogorov-Smirnov against the normal truncated at 0 (beta >= 0)
    law = stats.truncnorm((0 - 0.05) / 0.2, np.inf, loc=0.05, scale=0.2)
    assert stats.kstest(b, law.cdf).pvalue > 1e-3


@pytest.mark.parametrize(
    "spec, mean",
    [
        (Quenched("lognormal", 0.0, 0.25), np.exp(0.25**2 / 2)),
        (Quenched("weibull", 2.0, 3.0), 3.0 * 0.886226925452758),  # scale Gamma(1 + 1/k)
        (Quenched("exponential", 2.0), 2.0),
        (Quenched("uniform", 1.0, 5.0), 3.0),
    ],
)
def test_distributions_have_their_means(spec, mean):
    v = ChainParams(N=20000, Fs=spec).Fs.values
    assert abs(v.mean() - mean) < 5 * v.std() / np.sqrt(v.size)


def test_asperities_put_a_fraction_p_of_blocks_at_the_first_value():
    v = ChainParams(N=200, Fs=Quenched("asperities", 3.0, 6.0, p=0.1, seed=2)).Fs.values
    assert np.count_nonzero(v == 3.0) == 20 and np.count_nonzero(v == 6.0) == 180


def test_arrays_files_and_the_command_lines_expressions(tmp_path):
    fs = np.linspace(2.0, 4.0, 9)
    np.save(tmp_path / "fs.npy", fs)
    np.savetxt(tmp_path / "fs.txt", fs)
    for value in (fs, list(fs), f"file:{tmp_path / 'fs.npy'}", f"file:{tmp_path / 'fs.txt'}"):
        p = chain_params(N=9, Fs=value)
        np.testing.assert_array_equal(p.Fs.values, fs)
    assert parse("asperities(3, 6, p=0.1)") == Quenched("asperities", 3, 6, p=0.1)
    assert parse("2.5") == 2.5
    assert chain_params(N=9, Fs="normal(3, 0.1)").Fs.spec == Quenched("normal", 3, 0.1)
    # one number stays one number
    assert chain_params(N=9, Fs=3.5).Fs == 3.5 and not chain_params(N=9, Fs=np.float64(3.5)).per_block()


def test_the_pieces_checks_read_the_extreme_values():
    # state law: (2 D + 1) dt <= 1; D = 120 at one block breaks it for dt = 0.005
    D = np.full(5, 5.0)
    D[3] = 120.0
    with pytest.raises(ParameterError, match="D\\*dt"):
        ChainParams(N=5, D=D)


BAD = [
    (dict(Fs=Quenched("gauss", 1, 2)), "Fs must be > 0 at every block: unknown distribution 'gauss'"),
    (dict(Fs=Quenched("uniform", -1, 2)), "Fs must be > 0 at every block (got"),
    (dict(Fs=Quenched("uniform", 3, 2)), "Fs must be > 0 at every block: uniform(3, 2): lower bound above upper"),
    (dict(Fs=np.ones(4)), "Fs must be > 0 at every block: needs N = 5 values (got 4)"),
    (dict(beta=np.array([1, 1, np.nan, 1, 1.0])), "beta must be >= 0 at every block (got nan at block 3"),
    (dict(M=np.array([1, 1, -1, 1, 1.0])), "M must be > 0 at every block (got -1 at block 3"),
    (dict(sigma=Quenched("uniform", 0.5, 1.5), drive="plate", friction="weakening"), "sigma must be >= 0 and < 1"),
    (dict(V=np.ones(5)), "V cannot differ from block to block"),
]


@pytest.mark.parametrize("kw, words", BAD, ids=[w.split(" ")[0] + str(i) for i, (_, w) in enumerate(BAD)])
def test_bad_per_block_values_raise_parameter_error(kw, words):
    with pytest.raises(ParameterError) as info:
        ChainParams(N=5, **kw)
    assert words in str(info.value) and "\n" not in str(info.value)


CLI_BAD = [
    ('chain --N 5 --t-end 1 --Fs "gauss(1, 2)"', "Fs must be > 0 at every block: unknown distribution 'gauss'"),
    ('chain --N 5 --t-end 1 --Fs "uniform(-1, 2)"', "Fs must be > 0 at every block (got"),
    ('chain --N 5 --t-end 1 --Fs "uniform(3, 2)"', "lower bound above upper"),
    ("chain --N 5 --t-end 1 --Fs file:missing.npy", "Fs must be > 0 at every block: cannot read missing.npy"),
    ('chain --N 5 --t-end 1 --M "uniform(-2, -1)"', "M must be > 0 at every block"),
    ('chain --N 5 --t-end 1 --Fs "uniform(2, "', "Fs must be > 0 at every block: cannot read"),
    ("chain --N 5 --t-end 1 --Fs nan", "Fs must be a finite number > 0 (got nan)"),
]


@pytest.mark.parametrize("argv, words", CLI_BAD, ids=[c.split("--Fs ")[-1] for c, _ in CLI_BAD])
def test_bad_specs_on_the_command_line_are_one_line_and_exit_2(argv, words, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    status, out, err = run_cli(capsys, *shlex.split(argv))
    assert status == 2, err
    assert "Traceback" not in err and len(error_lines(err)) == 1, err
    assert words in err, err


def test_the_command_line_draws_with_the_disorder_seed():
    import argparse

    from stickslip.cli._common import add_model_options, chain_params_from_args

    parser = argparse.ArgumentParser()
    add_model_options(parser)
    args = parser.parse_args(shlex.split('--N 30 --Fs "uniform(2.5, 3.5)" --disorder-seed 4 --beta 0.5'))
    p = chain_params_from_args(args)
    assert p.Fs == ChainParams(N=30, Fs=Quenched("uniform", 2.5, 3.5, seed=4)).Fs
    assert p.beta == 0.5
    args = parser.parse_args(shlex.split('--N 30 --Fs "uniform(2.5, 3.5)"'))
    assert chain_params_from_args(args).Fs.seed == 0
    assert isinstance(chain_params_from_args(args).Fs, PerBlock)
