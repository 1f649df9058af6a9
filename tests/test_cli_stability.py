"""`stickslip stability block|chain` and `stickslip hysteresis` on the command line."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from chain_helpers import error_lines
from stickslip import io
from stickslip.cli import main


def run_json(capsys, *argv):
    status = main(list(argv) + ["--json"])
    out = capsys.readouterr().out
    assert status == 0
    return json.loads(out)


def test_block_hopf_point(capsys):
    d = run_json(capsys, "stability", "block", "--K", "10", "--beta", "0.08")
    assert abs(d["hopf_V"] - 0.106) < 1e-3
    assert "eigenvalues" not in d and "stable" not in d


def test_block_eigenvalues_at_V(capsys):
    below = run_json(capsys, "stability", "block", "--K", "10", "--beta", "0.08", "--V", "0.1")
    above = run_json(capsys, "stability", "block", "--K", "10", "--beta", "0.08", "--V", "0.12")
    assert below["stable"] is False and above["stable"] is True
    assert len(below["eigenvalues"]) == 3
    # a1 = sum of roots with the sign flipped: beta + theta0 = 0.08 + 0.9 (eq. 2)
    assert sum(e["real"] for e in below["eigenvalues"]) == pytest.approx(-(0.08 + 0.9), rel=1e-10)


def test_block_beta_one_has_no_hopf_point(capsys):
    d = run_json(capsys, "stability", "block", "--K", "10", "--beta", "1")
    assert d["hopf_V"] is None


@pytest.mark.parametrize("beta,unstable", [(0.5, True), (1.5, False)])
def test_chain(capsys, beta, unstable):
    d = run_json(capsys, "stability", "chain", "--K", "10", "--D", "5", "--beta", str(beta))
    assert d["critical_beta"] == 1.0
    assert d["unstable"] is unstable
    assert (d["max_growth_rate"] > 0) is unstable


def test_chain_finite_check(capsys):
    d = run_json(capsys, "stability", "chain", "--beta", "0.5", "--N", "60")
    assert d["finite_chain"]["N"] == 60 and d["finite_chain"]["unstable"] is True


def test_hysteresis_default(capsys):
    d = run_json(capsys, "hysteresis")
    assert abs(d["V_up"] - 0.345) <= 0.005 + 1e-12
    assert d["V_down"] is None
    assert d["sweep"]["dV"] <= 0.005


@pytest.mark.slow  # every output of the stability commands (about 18 s, measured)
def test_outputs_written(capsys, tmp_path):
    d = run_json(capsys, "stability", "block", "--beta", "0.08", "--V", "0.2", "--out", str(tmp_path / "b"))
    assert (tmp_path / "b" / "stability_map.png").stat().st_size > 0
    assert io.read_dataset(tmp_path / "b" / "stability_map.nc")["V_c"].size > 10
    names = sorted(p.split("/")[-1] for p in d["outputs"])
    assert names == ["stability_block.json", "stability_map.nc", "stability_map.pdf", "stability_map.png"]
    run_json(capsys, "stability", "chain", "--out", str(tmp_path / "c"))
    ds = io.read_dataset(tmp_path / "c" / "fig4.nc")
    assert set(ds["beta"].values) == {0.5, 1.0, 1.5}
    assert (tmp_path / "c" / "fig4.png").exists()
    run_json(capsys, "hysteresis", "--V-min", "0.3", "--V-max", "0.4", "--dV", "0.01",
             "--time-per-step", "100", "--out", str(tmp_path / "h"))  # fmt: skip
    ds = io.read_dataset(tmp_path / "h" / "hysteresis.nc")
    assert ds.sizes == {"direction": 2, "V": 11}
    meta = io.read_json(tmp_path / "h" / "hysteresis.json")
    assert meta["command"] == "hysteresis" and meta["params"]["beta"] == 1.0


@pytest.mark.parametrize(
    "argv",
    [
        ["stability", "block", "--K", "-1"],
        ["stability", "block", "--V", "-0.1"],
        ["stability", "chain", "--N", "0"],
        ["stability", "chain", "--D", "-1"],
        ["hysteresis", "--dV", "0"],
        ["hysteresis", "--V-min", "0.5", "--V-max", "0.4"],
        ["hysteresis", "--transient", "1"],
        ["hysteresis", "--time-per-step", "0"],
    ],
)
def test_bad_input_one_line_exit_2_nothing_written(capsys, tmp_path, argv):
    out = tmp_path / "out"
    status = main(argv + ["--out", str(out), "--json"])
    captured = capsys.readouterr()
    assert status == 2
    assert captured.out == ""
    assert len(captured.err.strip().splitlines()) == 1
    assert not out.exists()


@pytest.mark.parametrize("argv", [["stability"], ["stability", "block", "--K", "abc"], ["hysteresis", "--dV", "x"]])
def test_parse_errors_exit_2(capsys, argv):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    assert len(error_lines(capsys.readouterr().err)) == 1


def test_console_script():
    proc = subprocess.run(
        [sys.executable, "-c", "import sys; from stickslip.cli import main; sys.exit(main())",
         "stability", "block", "--beta", "0.08", "--json"],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert abs(json.loads(proc.stdout)["hopf_V"] - 0.106) < 1e-3
