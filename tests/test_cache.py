"""Spec hashing and the cache store shared by ``reproduce``, sweeps and studies.

The keys are checked against SHA-256 of JSON text written out here by hand: a run directory's
name is what lets a later command find and reuse its results, so it must not move.
"""

from __future__ import annotations

import hashlib
import json

import pytest

from stickslip import __version__
from stickslip.experiments.cache import canonical, read_done, sealed, spec_key
from stickslip.experiments.studies import Study, figs1_4, figs5_8, study


def _sha12(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()[:12]


def test_canonical_form_of_a_spec():
    assert canonical({"b": (0.5, 1.0), "a": 10.0, "c": {"z": 2.5, "y": True}}) == {
        "a": 10,
        "b": [0.5, 1],
        "c": {"y": True, "z": 2.5},
    }
    assert list(canonical({"b": 1, "a": 2})) == ["a", "b"]


def test_spec_key_is_the_sha256_of_compact_sorted_json():
    assert spec_key({"b": [1, 2], "a": "x"}) == _sha12('{"a":"x","b":[1,2]}')


def test_an_experiment_of_the_paper_names_its_folder_by_its_settings():
    point = canonical({"experiment": "slip-limit", "params": {"K": 10.0, "beta": 0.5}, "options": {"w": (1, 2)}})
    text = '{"experiment":"slip-limit","options":{"w":[1,2]},"params":{"K":10,"beta":0.5}}'
    assert figs1_4.point_name(point) == f"slip-limit-{_sha12(text)}"


def test_study_key_leaves_out_its_points():
    spec = Study("exponents", "quick", common={"N": 199, "K": 10.0}, points=({"beta": 0.2},))
    text = f'{{"common":{{"K":10,"N":199}},"study":"exponents","version":"{__version__}"}}'
    assert spec.key() == _sha12(text)
    assert Study("exponents", "full", common={"K": 10, "N": 199}).dirname == f"exponents-{_sha12(text)}"


def test_every_study_names_its_folder_the_same_way():
    for spec in (study("transition", "tiny"), study("chaos", "tiny"), figs5_8.build("tiny")):
        name = spec.name
        text = json.dumps(
            {"common": spec.common, "study": name, "version": __version__}, sort_keys=True, separators=(",", ":")
        )
        assert spec.dirname == f"{name}-{_sha12(text)}"


def test_read_done_only_for_the_same_spec_and_a_sealed_record(tmp_path):
    spec = {"kind": "block_run", "version": __version__}
    path = tmp_path / "done.json"
    assert read_done(path, spec) == (None, None)  # not there
    record = {"spec": spec, "summary": {"x": 1}, "files": {}}
    path.write_text(json.dumps(record))
    assert read_done(path, spec) == (None, "it records no checksum of itself")
    path.write_text(json.dumps(sealed(record)))
    assert read_done(path, spec)[0]["summary"] == {"x": 1}
    assert read_done(path, {**spec, "version": "other"}) == (None, None)  # another spec's record
    path.write_text(json.dumps({**sealed(record), "summary": {"x": 2}}))
    assert "changed after it was written" in read_done(path, spec)[1]
    path.write_text('{"spec": ')
    assert read_done(path, spec) == (None, "done.json is unreadable")
    path.write_text("[1, 2]")
    assert read_done(path, spec) == (None, None)


@pytest.mark.parametrize("value", [1.5, 2**53 + 2.0])
def test_canonical_keeps_floats_that_are_not_small_whole_numbers(value):
    assert canonical({"x": value})["x"] == value and isinstance(canonical({"x": value})["x"], float)
