"""Every friction law from its model's default start: the run goes, or the refusal says what to do
(issue: Ruina's slip law from the paper's start, ``stickslip chain --N 1 --friction
rate-state-slip --K 20``, died of a non-finite state at step 1 with no word of ``--start steady``
or a smaller dt)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from stickslip import chain_params, run_chain
from stickslip.cli import main
from stickslip.models.params import ParameterError
from stickslip.models.pieces import CompositionError, check_composition, names
from stickslip.models.presets import PRESETS
from stickslip.run import state as state_mod
from stickslip.run.errors import NonFiniteState
from stickslip.run.state import initial_state


def _composes(pr, law) -> bool:
    try:
        check_composition(pr.pieces["drive"], law, pr.pieces["threshold"], pr.pieces["ends"])
    except CompositionError:
        return False
    return True


CASES = [
    pytest.param(model, law, N, K, id=f"{model}-{law}-N{N}-K{K:g}" if K else f"{model}-{law}-N{N}")
    for model, pr in PRESETS.items()
    for law in names("friction")
    if _composes(pr, law)
    for N, K in ((1, None), (1, 20.0), (5, None))
]


def _params(model, law, N, K):
    return chain_params(model, N=N, friction=law, **({"K": K} if K is not None else {}))


@pytest.mark.parametrize("model, law, N, K", CASES)
def test_a_default_start_is_taken_or_refused_with_what_to_do(model, law, N, K):
    p = _params(model, law, N, K)
    try:
        initial_state(p, PRESETS[model].start)
    except ParameterError as exc:
        text = str(exc)
        assert "--dt" in text and "dt below" in text, text
        if PRESETS[model].start != "steady":
            assert "--start steady" in text and "start='steady'" in text, text


def test_the_slip_law_from_the_papers_start_is_refused_with_what_to_do():
    p = chain_params(N=1, friction="rate-state-slip", K=20)
    with pytest.raises(
        ParameterError, match=r"start paper: in the first step of dt = 0.005 theta of block 1 goes from 1 to -1.3"
    ) as info:
        run_chain(p, 10.0)
    assert "--start steady" in str(info.value) and "dt below 0.0011" in str(info.value)


@pytest.mark.slow
def test_the_refusal_foresees_what_the_engine_does(monkeypatch):
    """Without the check, the run dies at step 1 as the refusal says it would."""
    monkeypatch.setattr(state_mod, "first_step_problem", lambda state, p: None)
    with pytest.raises(NonFiniteState, match=r"\(step 1\)"):
        run_chain(chain_params(N=1, friction="rate-state-slip", K=20), 10.0)


@pytest.mark.slow  # every remedy's run (about 80 s, measured)
def test_both_remedies_run():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        steady = run_chain(chain_params(N=1, friction="rate-state-slip", K=20), 50.0, start="steady")
        small = run_chain(chain_params(N=1, friction="rate-state-slip", K=20, dt=0.001), 50.0)
    for run in (steady, small):
        assert np.all(np.isfinite(run.state.blocks()["theta"]))


def test_the_command_says_it_in_one_line(capsys):
    assert main(["chain", "--N", "1", "--friction", "rate-state-slip", "--K", "20"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--start steady" in err and "--dt" in err, err


@pytest.mark.slow
@pytest.mark.parametrize("model, law, N, K", CASES)
def test_every_default_start_that_is_taken_runs(model, law, N, K):
    p = _params(model, law, N, K)
    try:
        initial_state(p, PRESETS[model].start)
    except ParameterError:
        return
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = run_chain(p, 20.0, start=PRESETS[model].start)
    assert np.all(np.isfinite(run.state.blocks()["x"]))
