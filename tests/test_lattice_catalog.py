"""The catalogue of lattice runs (docs/lattice.md, "The catalogue"): magnitudes from the moments,
M = (2/3) log10 moment, on a hand-made events table; the b-value of a synthetic Gutenberg-Richter
catalogue of known b; `stickslip catalog` on a lattice run directory."""

from __future__ import annotations

import json
import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from chain_helpers import run_cli
from stickslip.analysis.stats.lattice_catalog import lattice_catalog, lattice_catalog_analysis
from stickslip.models.params import ParameterError
from stickslip.models.presets import chain_params


def _events(moments, t_start=None, area=None):
    n = len(moments)
    t = np.arange(n, dtype=float) if t_start is None else np.asarray(t_start, dtype=float)
    return pd.DataFrame(
        {
            "event": np.arange(n),
            "t_start": t,
            "t_end": t + 0.25,
            "moment": np.asarray(moments, dtype=float),
            "area": np.ones(n, dtype=np.int64) if area is None else np.asarray(area),
            "epicentre_row": np.full(n, 2),
            "epicentre_col": np.full(n, 3),
            "row_min": np.full(n, 1),
            "row_max": np.full(n, 2),
            "col_min": np.full(n, 2),
            "col_max": np.full(n, 4),
        }
    )


def test_magnitudes_of_known_moments():
    """M = (2/3) log10 moment: 1 -> 0, 10^1.5 -> 1, 1000 -> 2, 10^-3 -> -2; no magnitude for 0."""
    cat = lattice_catalog(_events([1.0, 10**1.5, 1000.0, 1e-3, 0.0], area=[1, 2, 16, 1, 1]), 16)
    np.testing.assert_allclose(cat["magnitude"].to_numpy()[:4], [0.0, 1.0, 2.0, -2.0], rtol=0, atol=1e-15)
    assert math.isnan(cat["magnitude"].iloc[4])
    assert cat["duration"].tolist() == [0.25] * 5
    assert cat["spans"].tolist() == [False, False, True, False, False]
    assert cat["rows"].tolist() == [2] * 5 and cat["cols"].tolist() == [3] * 5


def test_window_keeps_events_from_t_from():
    cat = lattice_catalog(_events([1.0, 2.0, 3.0], t_start=[0.0, 5.0, 10.0]), 4, t_from=5.0)
    assert cat["event"].tolist() == [1, 2]


def _gr_run(b, n, seed=3):
    """A run-like object whose moments follow Gutenberg-Richter with ``b`` above M = 0:
    M = Exp(b ln 10), moment = 10^(3 M / 2)."""
    M = np.random.default_rng(seed).exponential(1.0 / (b * math.log(10.0)), n)
    p = chain_params("carlson-langer", lattice="square", shape=(4, 4))
    events = _events(10.0 ** (1.5 * M), t_start=np.sort(np.random.default_rng(seed + 1).uniform(0, 100, n)))
    return SimpleNamespace(params=p, events=events, summary={"t_end": 100.0})


def test_b_value_of_a_synthetic_gutenberg_richter_catalogue():
    """b = 1 drawn, b recovered within three of its errors, continuous magnitudes (dm = 0);
    tau of the moments is 1 + 2 b / 3 = 5/3 (b = (3/2)(tau - 1))."""
    cat = lattice_catalog_analysis(_gr_run(1.0, 4000), t_from=0.0, dm=0.0, bootstrap=0)
    bv = cat.summary["frequency_magnitude"]["b_value"]
    assert abs(bv["b"] - 1.0) < 3 * bv["b_err_shi_bolt"] and bv["b_err_shi_bolt"] < 0.05
    assert abs(cat.size_fit.tau - 5.0 / 3.0) < 0.05
    assert cat.summary["n_events"] == 4000 and cat.summary["N"] == 16


def test_the_frequency_magnitude_figure_says_what_the_magnitude_is_read_from():
    """The x label is the catalogue's own: the moment on a lattice, S on the chain (the label it
    has always had), from each catalogue's definition of its magnitude."""
    from stickslip.analysis.stats.catalog import _frequency_magnitude
    from stickslip.plotting.catalog import frequency_magnitude_figure

    cat = lattice_catalog_analysis(_gr_run(1.0, 400), t_from=0.0, bootstrap=0)
    label = frequency_magnitude_figure(cat).axes[0].get_xlabel()
    assert label == r"magnitude $M = \frac{2}{3}\log_{10} \mathrm{moment}$"
    M = cat.table["magnitude"].to_numpy()
    chain_fm = _frequency_magnitude(M, cat.table["moment"].to_numpy(), None, dm=0.1, bootstrap=0, seed=0)
    chain = SimpleNamespace(table=cat.table, summary={**cat.summary, "frequency_magnitude": chain_fm})
    assert frequency_magnitude_figure(chain).axes[0].get_xlabel() == r"magnitude $M = \frac{2}{3}\log_{10} S$"


def test_too_few_events_is_refused():
    with pytest.raises(ParameterError, match="at least 50"):
        lattice_catalog_analysis(_gr_run(1.0, 40), t_from=0.0)


def test_catalog_command_on_a_lattice_run_directory(tmp_path, capsys):
    out = tmp_path / "run"
    status, _, err = run_cli(
        capsys, "chain", "--model", "carlson-langer", "--lattice", "square", "--shape", "6x6",
        "--t-end", "600", "--out", str(out),
    )  # fmt: skip
    assert status == 0, err
    status, text, err = run_cli(capsys, "catalog", str(out), "--bootstrap", "0", "--json")
    assert status == 0, err
    data = json.loads(text)
    events = pd.read_csv(out / "events.csv")
    window = events[events["t_start"] >= 300.0]
    assert data["n_events"] == len(window)
    table = pd.read_csv(out / "catalog" / "catalog.csv")
    np.testing.assert_allclose(table["magnitude"], (2.0 / 3.0) * np.log10(window["moment"]), rtol=1e-14)
    assert (out / "catalog" / "frequency_magnitude.png").is_file()


def test_examples_in_the_docstrings_run():
    import doctest

    import stickslip.analysis.stats.lattice_catalog as module

    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS, verbose=False)
    assert result.attempted > 0 and result.failed == 0, result
