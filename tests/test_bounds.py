"""Work and memory an option implies are estimated before anything runs, and what cannot finish
is refused in one line (exit 2) naming the option, the estimate and the limit. Refusal is shown
by what was not done: no folder made, no run read, no transient run."""

from __future__ import annotations

import numpy as np
import pytest

import stickslip.run.budget as budget
from chain_helpers import one_line_error
from stickslip.analysis.dynamics.decorrelation import sequence_decorrelation
from stickslip.analysis.stats.catalog import MAX_BOOTSTRAP, MAX_GOF_SIMS, check_magnitude_bins
from stickslip.cli import main
from stickslip.models.params import ParameterError
from stickslip.models.presets import chain_params
from stickslip.run import run_chain


@pytest.mark.parametrize(
    "flags, option",
    [
        (["--sample-interval", "0.005"], "sample_interval"),  # L at every step of a 1e8 run: 2e10 samples
        (["--profile-window", "0.005"], "profile_window"),  # profiles at every step
    ],
)
def test_chain_outputs_no_machine_can_hold_are_refused_before_the_run(flags, option, tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["chain", "--N", "10", "--t-end", "1e8", *flags, "--out", str(out), "--no-progress"]) == 2
    err = one_line_error(capsys, option, "GiB of memory")
    assert "more than this machine's" in err
    assert not out.exists()
    with pytest.raises(ParameterError, match=option):
        run_chain(chain_params(N=10), 1e8, **{option: 0.005}, out_dir=tmp_path / "api")
    assert not (tmp_path / "api").exists()


def test_snapshots_beyond_memory_are_refused(monkeypatch, tmp_path):
    """2e7 snapshots of 99 blocks need 32 GB; on a machine of 1 GiB, 1e5 of 1000 blocks (1.6 GB)."""
    monkeypatch.setattr(budget, "physical_memory", lambda: 2**30)
    times = tuple(np.linspace(0.0, 1e3, 100_000))
    with pytest.raises(
        ParameterError, match=r"snapshot_times: 100000 snapshots of 1000 blocks would need about 1.49 GiB"
    ):
        run_chain(chain_params(N=1000), 1e3, snapshot_times=times, out_dir=tmp_path / "run")
    assert not (tmp_path / "run").exists()


@pytest.mark.parametrize(
    "option, value, limit", [("--bootstrap", "1000000000", MAX_BOOTSTRAP), ("--gof-sims", "1000000000", MAX_GOF_SIMS)]
)
def test_catalog_counts_without_end_are_refused_before_the_run_is_read(option, value, limit, tmp_path, capsys):
    # the run directory does not exist: the refusal is the count's, before anything is read
    assert main(["catalog", str(tmp_path / "no-run"), option, value]) == 2
    one_line_error(capsys, f"{option.lstrip('-')} must be <= {limit}")
    assert not (tmp_path / "no-run").exists()


def test_a_magnitude_bin_too_fine_is_refused_with_its_cost():
    M = np.array([-1.2, 0.0, 0.9])
    check_magnitude_bins(M, 1e-3)  # 2101 bins: fine
    with pytest.raises(ParameterError, match=r"dm = 1e-09 cuts the magnitudes .* into 2.1e\+09 bins, about 15.6 GiB"):
        check_magnitude_bins(M, 1e-9)


def test_catalog_dm_too_fine_writes_nothing(tmp_path, capsys):
    run = tmp_path / "run"
    assert main(["chain", "--model", "two-blocks", "--t-end", "2e4", "--out", str(run), "--no-progress"]) == 0
    capsys.readouterr()
    assert main(["catalog", str(run), "--dm", "1e-9", "--bootstrap", "0", "--gof-sims", "0"]) == 2
    one_line_error(capsys, "dm = 1e-09", "bins")
    assert not (run / "catalog").exists()


class NoEngine:
    """A source of sequences that fails if it is used: the refusal comes first."""

    params = chain_params(N=5)

    def __getattr__(self, name):
        raise AssertionError(f"the engine was used ({name})")


def test_decorrelation_slips_beyond_the_limit_are_refused_before_any_run(monkeypatch, capsys):
    with pytest.raises(ParameterError, match=r"ask for 4e\+12 slips simulated; at most 1e\+09"):
        sequence_decorrelation(NoEngine(), None, [1e-8, 1e-4, 1e-1], events=10**12)
    with pytest.raises(ParameterError, match=r"seeds = 1000000000"):
        sequence_decorrelation(NoEngine(), None, [1e-4], events=1000, seeds=10**9)
    import stickslip.cli.decorrelation as cli_dec

    def no_transient(*a, **k):
        raise AssertionError("the transient was run")

    monkeypatch.setattr(cli_dec, "_start", no_transient)
    assert main(["lyapunov", "--N", "5", "--decorrelation", "--events", "1000000000000"]) == 2
    one_line_error(capsys, "slips simulated")
    assert main(["lyapunov", "--N", "5", "--decorrelation", "--seeds", "1000000000"]) == 2
    one_line_error(capsys, "seeds = 1000000000")
