"""`stickslip block` and `stickslip slip-limit`: JSON output, files written, bad input."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from chain_helpers import error_lines
from stickslip import io
from stickslip.cli import main


def run_cli(capsys, *argv):
    status = main(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


def test_block_json(capsys):
    status, out, err = run_cli(capsys, "block", "--t-end", "1000", "--every", "1000", "--json")
    assert status == 0
    data = json.loads(out)  # exactly one document: json.loads rejects trailing text
    for key in ("events", "period", "slip_duration", "force_at_stop"):
        assert key in data
    assert data["events"] == 3
    # the paper's law at K = 10, V = 0.001
    assert data["period"] == pytest.approx(1.035 + 3.432 / (10 * 0.001), rel=0.005)
    assert data["slip_duration"] == pytest.approx(1.035, abs=0.01)
    assert data["force_at_stop"] == pytest.approx(-0.432, abs=0.005)
    assert len(data["slips"]) == 3 and data["slips"][0]["period"] is None


def test_block_default_length_and_text(capsys):
    status, out, _ = run_cli(capsys, "block", "--V", "0.01")
    assert status == 0
    # first slip plus 3.5 periods: four slips, three periods
    assert "slips: 4" in out and "mean period" in out


def test_slip_limit_json(capsys):
    status, out, _ = run_cli(capsys, "slip-limit", "--json")
    assert status == 0
    data = json.loads(out)
    assert data["duration"] == pytest.approx(1.035, abs=0.005)
    assert data["force_at_stop"] == pytest.approx(-0.432, abs=5e-4)
    assert data["period_law_a"] == data["duration"]
    assert data["period_law_b"] == pytest.approx(3.0 - data["force_at_stop"])
    assert data["heun"]["duration"] == pytest.approx(1.04)
    status, out, _ = run_cli(capsys, "slip-limit", "--K", "5")
    assert status == 0 and "period law" in out and "paper" not in out


def test_block_out_writes_run_and_figures(capsys, tmp_path):
    out_dir = tmp_path / "run"
    status, out, _ = run_cli(
        capsys, "block", "--V", "0.01", "--t-end", "120", "--every", "7", "--out", str(out_dir), "--fig3", "--json"
    )
    assert status == 0
    data = json.loads(out)
    names = {p.split("/")[-1] for p in data["outputs"]}
    # The outputs convention: every figure as PNG and PDF, a figure's table as Parquet and CSV.
    assert {"series.nc", "slips.parquet", "run.json", "fig1.png", "fig1.pdf", "fig2.png", "fig2.pdf", "fig2.nc",
            "fig3.png", "fig3.pdf", "fig3.parquet", "fig3.csv"} <= names  # fmt: skip
    assert (out_dir / "fig3.pdf").read_bytes().startswith(b"%PDF")
    series = io.read_dataset(out_dir / "series.nc")
    assert series["t"].size == 120 / 0.005 // 7 + 2
    slips = io.read_table(out_dir / "slips.parquet")
    assert len(slips) == data["events"]
    meta = io.read_json(out_dir / "run.json")
    assert meta["params"]["V"] == 0.01 and meta["integrator"].startswith("heun")
    fig3 = io.read_table(out_dir / "fig3.parquet")
    pd.testing.assert_frame_equal(pd.read_csv(out_dir / "fig3.csv"), fig3, check_dtype=False)
    assert len(fig3) >= 12 and fig3["V"].min() == pytest.approx(1e-3) and fig3["V"].max() == pytest.approx(0.1)
    small = fig3[fig3["V"] <= 0.01 + 1e-12]
    assert np.all(np.abs(small["period"] / small["period_law"] - 1) < 0.005)


@pytest.mark.parametrize(
    "argv, name, allowed",
    [
        (["block", "--K", "-1"], "K", "> 0"),
        (["block", "--K", "0"], "K", "> 0"),
        (["block", "--dt", "0"], "dt", "> 0"),
        (["block", "--dt", "-0.1"], "dt", "> 0"),
        (["block", "--V", "nan"], "V", ">= 0"),
        (["block", "--beta", "inf"], "beta", ">= 0"),
        (["block", "--Fs", "0"], "Fs", "> 0"),
        (["block", "--t-end", "-1"], "t_end", "> 0"),
        (["block", "--every", "0"], "every", ">= 1"),
        (["block", "--fig3"], "--fig3", "--out"),
        (["slip-limit", "--Fs", "0.5"], "Fs", "> sigma"),
        (["slip-limit", "--K", "-2"], "K", "> 0"),
    ],
)
def test_bad_input(capsys, tmp_path, argv, name, allowed):
    out_dir = tmp_path / "out"
    extra = ["--out", str(out_dir)] if argv[0] == "block" and "--fig3" not in argv else []
    status, out, err = run_cli(capsys, *argv, *extra, "--json")
    assert status == 2
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and name in lines[0] and allowed in lines[0]
    assert "Traceback" not in err
    assert not out_dir.exists()


def test_unknown_option_exits_2(capsys, tmp_path):
    with pytest.raises(SystemExit) as exc:
        main(["block", "--bogus", "1", "--out", str(tmp_path / "out")])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert len(error_lines(err)) == 1 and "--bogus" in err
    assert not (tmp_path / "out").exists()


def test_entry_point_bad_input_no_traceback(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-c", "import sys; from stickslip.cli import main; sys.exit(main())",
         "block", "--K", "-1", "--out", str(tmp_path / "o")],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert proc.returncode == 2
    assert proc.stdout == ""
    assert proc.stderr.strip() == "stickslip block: error: K must be > 0 (got -1.0)"
    assert not (tmp_path / "o").exists()
