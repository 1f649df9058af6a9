"""`stickslip --help`, `--version` and argument errors load no numba, scipy, pandas, xarray or
matplotlib (before, `--help` imported them all: two seconds of CPU, 9-15 s on a busy machine).
Shown by what a fresh interpreter has imported, not by a clock."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from chain_helpers import cli_env

HEAVY = ("numba", "scipy", "pandas", "xarray", "matplotlib", "dask", "jinja2")

CODE = (
    "import json, sys\n"
    "from stickslip.cli import main\n"
    "try:\n"
    "    status = main(sys.argv[1:])\n"
    "except SystemExit as exc:\n"
    "    status = exc.code\n"
    f"heavy = {HEAVY!r}\n"
    "loaded = sorted(m for m in sys.modules if m.split('.')[0] in heavy)\n"
    "print(json.dumps({'status': status, 'loaded': loaded}), file=sys.stderr)\n"
)


def _loaded(*argv: str) -> tuple[int, list[str]]:
    proc = subprocess.run(
        [sys.executable, "-c", CODE, *argv], capture_output=True, text=True, env=cli_env(), timeout=300
    )
    last = json.loads(proc.stderr.strip().splitlines()[-1])
    return last["status"], last["loaded"]


@pytest.mark.parametrize(
    "argv, status",
    [
        (["--help"], 0),
        (["--version"], 0),
        (["chain", "--help"], 0),
        (["study", "--help"], 0),
        (["chain", "--bogus"], 2),
        (["chane"], 2),
        (["chain", "--N", "-1"], 2),
        (["bench", "--model", "nosuch"], 2),
        (["catalog", "--dm", "x", "somewhere"], 2),
    ],
    ids=lambda v: " ".join(v) if isinstance(v, list) else str(v),
)
def test_help_version_and_argument_errors_load_no_heavy_module(argv, status):
    got, loaded = _loaded(*argv)
    assert got == status
    assert loaded == [], f"`stickslip {' '.join(argv)}` imported {loaded}"


def test_importtime_of_help_names_no_heavy_module():
    """As ``python -X importtime -m stickslip.cli --help`` shows it."""
    proc = subprocess.run(
        [sys.executable, "-X", "importtime", "-m", "stickslip.cli", "--help"],
        capture_output=True,
        text=True,
        env=cli_env(),
        timeout=300,
    )
    assert proc.returncode == 0 and "usage: stickslip" in proc.stdout
    imported = {line.split("|")[-1].strip() for line in proc.stderr.splitlines() if line.startswith("import time:")}
    assert not {m for m in imported if m.split(".")[0] in HEAVY}


def test_a_pieces_functions_compile_when_first_asked_for_into_the_kernels_cache():
    """The pieces (models/) decorate their compiled functions on first use, after the kernels'
    cache directory is set, as the kernels read them; called from Python they work too."""
    code = (
        "import sys, stickslip\n"
        "from stickslip import chain_params\n"
        "from stickslip.models.friction import rate_state as rs\n"
        "assert 'numba' not in sys.modules\n"
        "value = rs.mu(chain_params(friction='rate-state'), 0.001, 1.0)\n"  # calls mu_lp from Python
        "import numba\n"
        "from stickslip.kernels import _cache\n"
        "d = rs.accel\n"
        "assert isinstance(d, numba.core.registry.CPUDispatcher) and d is rs.accel\n"
        "assert str(_cache.cache_dir()) in d._cache._cache_path, d._cache._cache_path\n"
        "print(repr(value))\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=cli_env(), timeout=300)
    assert proc.returncode == 0, proc.stderr
    # mu(V = v0, theta = D_c / v0) = a asinh(exp(mu0 / a) / 2) ~ mu0 (module docstring of rate_state)
    import math

    assert float(proc.stdout) == pytest.approx(0.01 * math.asinh(0.5 * math.exp(0.6 / 0.01)), rel=1e-12)
