"""The warning for chain runs too short to leave the loading (end drive, from x_i = 0)."""

import warnings

import pytest

from stickslip.cli import main
from stickslip.models.params import ChainParams
from stickslip.models.physics import chain_steady_length, loading_time
from stickslip.models.presets import chain_params
from stickslip.run.errors import ShortRunWarning
from stickslip.run.state import loading_warnings

pytestmark = pytest.mark.filterwarnings("always::stickslip.run.errors.ShortRunWarning")


def test_loading_time_is_steady_length_over_V():
    p = ChainParams(N=99)
    assert loading_time(p) == pytest.approx(chain_steady_length(p) / p.V)
    assert loading_time(p) == pytest.approx(4.851e5, rel=1e-3)
    assert loading_time(ChainParams(N=49)) == pytest.approx(1.176e5, rel=1e-3)


def test_messages_for_end_and_average_window():
    p = ChainParams(N=49)
    (end,) = loading_warnings(p, 1e5)
    assert "ends at t = 1e+05" in end and "1.18e+05" in end
    (avg,) = loading_warnings(p, 2e5)  # default average from t_end / 2 = 1e5 < 1.18e5
    assert "averages from t = 1e+05" in avg
    assert loading_warnings(p, 3e5, 1.5e5) == []
    assert loading_warnings(p, 1e5, start="steady") == []
    assert loading_warnings(chain_params("carlson-langer"), 10.0, start="rest") == []


def test_run_chain_warns_only_when_short():
    from stickslip.run.driver import run_chain

    p = ChainParams(N=5)  # loads until ~ 10 / 0.001 = 1e4
    with pytest.warns(ShortRunWarning, match="shows only the loading"):
        run_chain(p, 100.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ShortRunWarning)
        run_chain(p, 4e4, average_from=2e4)
        run_chain(p, 100.0, start="steady")


def test_cli_warns_on_stderr_and_succeeds(capsys):
    assert main(["chain", "--N", "5", "--t-end", "100", "--no-progress"]) == 0
    err = capsys.readouterr().err
    assert err.startswith("stickslip chain: warning: from x_i = 0 the chain of N = 5 loads")
    assert main(["chain", "--N", "5", "--t-end", "4e4", "--average-from", "2e4", "--no-progress"]) == 0
    assert "warning" not in capsys.readouterr().err


def test_sweep_warns_per_point_before_running():
    from stickslip.experiments.sweep_points import warn_short_chain_runs

    points = [{"beta": 0.6}, {"beta": 1.0}]
    with pytest.warns(ShortRunWarning) as record:
        warn_short_chain_runs(points, {"N": 99, "t_end": 1e5, "average_from": 5e4}, ["beta=0.6", "beta=1"])
    assert [str(w.message).split(":")[0] for w in record] == ["beta=0.6", "beta=1"]
    with warnings.catch_warnings():
        warnings.simplefilter("error", ShortRunWarning)
        warn_short_chain_runs(points, {"N": 49, "t_end": 3e5, "average_from": 1.5e5}, ["a", "b"])
