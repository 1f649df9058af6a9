"""A run compiles only the kernels its model uses (issue 27): the sparse path only for the plate
drive without a state variable, the plate's start steps only under the plate, the reference
only when asked for."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from stickslip.models.pieces import piece, stopped_blocks_still

_SCRIPT = """
import sys, warnings
from stickslip.kernels import dense, exact, plate, triggers
from stickslip.models.presets import PRESETS, chain_params
from stickslip.run.driver import run_chain
warnings.simplefilter("ignore")
p = chain_params(sys.argv[1])
run_chain(p.replace(N=8), 20 * p.dt, start=PRESETS[sys.argv[1]].start)
print(*(len(k.signatures) for k in (exact.run_exact, plate.run_sparse, dense.run_dense, triggers._plate_triggers)))
"""


@pytest.mark.slow  # a fresh process with an empty cache compiles the model (about 100 s, measured)
@pytest.mark.parametrize(
    ("model", "compiled"),
    [
        # run_exact, run_sparse, run_dense, the plate's start steps (triggers._plate_triggers)
        ("sakaguchi", "1 0 0 0"),
        pytest.param("carlson-langer", "0 1 0 0", marks=pytest.mark.slow),
    ],
)
def test_a_run_compiles_only_what_its_model_uses(model, compiled, tmp_path):
    # A cache of its own: a kernel loaded from the cache does not load the functions it calls.
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", _SCRIPT, model], capture_output=True, text=True, env=env)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == compiled.split()


@pytest.mark.parametrize(
    ("drive", "friction", "still"),
    [
        ("plate", "weakening", True),
        ("plate", "strengthening", True),
        ("plate", "state", False),  # theta of a stopped block evolves
        ("end", "weakening", False),  # no plate: no start steps known in advance
        ("end", "state", False),
    ],
)
def test_stopped_blocks_still_needs_the_plate_and_no_theta(drive, friction, still):
    assert stopped_blocks_still(piece("drive", drive), piece("friction", friction)) is still
