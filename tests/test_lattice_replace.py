"""LatticeParams.replace: a changed model on the same lattice (before, it returned the chain's
ChainParams, so a perturbed parameter lost the lattice)."""

from __future__ import annotations

import pytest

from stickslip.analysis.dynamics.decorrelation import _check_parameter_perturbation
from stickslip.models.lattice.params import LatticeParams
from stickslip.models.params import ParameterError
from stickslip.models.presets import chain_params


def test_replace_keeps_the_lattice_and_changes_the_model():
    p = chain_params("carlson-langer", lattice="square", shape=(4, 6))
    q = p.replace(Fs=1.1)
    assert isinstance(q, LatticeParams)
    assert q.lattice == p.lattice and q.N == 24 and q.Fs == 1.1 and p.Fs == 1.0
    assert q.chain == p.chain.replace(Fs=1.1)


def test_replace_keeps_edges_given_per_side():
    p = chain_params("sakaguchi", lattice="square", shape=(3, 5), edges="top=fixed")
    q = p.replace(beta=1.5)
    assert q.lattice.edges == p.lattice.edges and q.beta == 1.5
    assert p.replace(ends="fixed").to_dict()["edges"]["top"] == "fixed"


@pytest.mark.parametrize(
    ("changes", "message"),
    [({"N": 5}, "N of a model on a lattice is its shape's"), ({"Fs": -1.0}, "Fs")],
)
def test_replace_refuses_in_one_line(changes, message):
    p = chain_params("carlson-langer", lattice="square", shape=(4, 6))
    with pytest.raises(ParameterError, match=message):
        p.replace(**changes)


def test_a_parameter_perturbation_of_a_lattice_model_is_checked_on_the_lattice():
    p = chain_params("carlson-langer", lattice="square", shape=(4, 6))
    _check_parameter_perturbation(p, "Fs", [1e-3, 1e-2])  # in range: no error
    with pytest.raises(ParameterError):
        _check_parameter_perturbation(p, "Fs", [-2.0])
