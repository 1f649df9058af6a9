"""A refusal names what the user gave, or says what the command cannot do; it never blames an
option the user did not give (issue: ``bench --switches located --model two-blocks`` said
``--beta is not a parameter of this model``; ``lyapunov --decorrelation --transient 1e15`` was
refused as ``t_end``)."""

from __future__ import annotations

import argparse

import pytest

from stickslip.cli import main
from stickslip.cli._common import chain_params_from_args
from stickslip.models.params import ParameterError, steps_for


def _args(**given):
    ns = argparse.Namespace(model=None, drive=None, friction=None, threshold=None, ends=None)
    for k, v in given.items():
        setattr(ns, k, v)
    return ns


@pytest.mark.parametrize("model", ["two-blocks", "carlson-langer"])
def test_a_commands_own_defaults_are_not_refused_as_the_users(model):
    """The bench workloads' beta = 0.5 where the model has no beta: left out, not blamed on --beta."""
    p = chain_params_from_args(_args(model=model), beta=0.5, N=7)
    assert "beta" not in p.used() and p.N == 7


def test_a_law_without_beta_takes_the_workloads_N_only():
    p = chain_params_from_args(_args(friction="rate-state"), beta=0.5, N=9)
    assert p.N == 9 and "beta" not in p.used()


def test_what_the_user_gave_is_still_refused():
    with pytest.raises(ParameterError, match="--beta is not a parameter"):
        chain_params_from_args(_args(model="two-blocks", param_beta=2.0), N=7)


@pytest.mark.parametrize("model", ["two-blocks", "carlson-langer"])
def test_bench_located_on_another_model_is_not_refused_for_beta(model, capsys, monkeypatch):
    """The command reaches its workload (stopped there: the timing itself is not the test)."""
    from stickslip.run import bench

    seen = {}

    def located(params, **kw):
        seen["params"] = params
        raise SystemExit(0)

    monkeypatch.setattr(bench, "located", located)
    with pytest.raises(SystemExit):
        main(["bench", "--switches", "located", "--model", model])
    assert "not a parameter" not in capsys.readouterr().err
    assert seen["params"].model == model and seen["params"].N == (2 if model == "two-blocks" else 100)


def test_steps_for_names_the_time_it_was_given():
    with pytest.raises(ParameterError, match="^transient must be <="):
        steps_for(1e15, 0.005, "transient")
    with pytest.raises(TypeError):
        steps_for(1.0, 0.005)  # the caller says which time it converts


@pytest.mark.parametrize(
    "argv",
    [
        ["lyapunov", "--N", "3", "--decorrelation", "--transient", "1e15"],
        ["lyapunov", "--N", "3", "--decorrelation", "--switches", "located", "--transient", "1e15"],
    ],
    ids=["grid", "located"],
)
def test_a_huge_transient_is_refused_as_the_transient(argv, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "transient" in err and "t_end" not in err, err
