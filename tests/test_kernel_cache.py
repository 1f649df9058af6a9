"""The kernels' on-disk cache follows edits to any kernel module, not only the kernel's own."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import stickslip
from stickslip.kernels._cache import modules_digest

_SCRIPT = """
import numpy as np
from stickslip.kernels import triggers
# End drive, blocks 1 and 2 at rest: f_1 = K V n dt exceeds 0.5 first at n = 51.
from stickslip.kernels.entry import specialise_call
from stickslip.models.drive import end
args = (np.zeros(5), 3, 1.0, 0.01, 1.0, 0.5, 0, 1000, end.Params(), end.__name__, "stickslip.models.ends.free")
print(specialise_call(triggers._first_trigger, args, {9, 10}))
"""


def _run(root: Path) -> str:
    env = {"PYTHONPATH": str(root), "PATH": ""}
    out = subprocess.run([sys.executable, "-c", _SCRIPT], cwd=root, env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    return out.stdout.strip()


@pytest.mark.slow  # a kernel compiled twice in a fresh cache (about 20 s, measured)
def test_editing_a_called_module_recompiles_the_cached_kernel(tmp_path):
    # _first_trigger lives in triggers.py and inlines _pull from laws.py; numba's own stamp
    # covers triggers.py only and would load the kernel compiled before the edit.
    src = Path(stickslip.__file__).parent
    shutil.copytree(src, tmp_path / "stickslip", ignore=shutil.ignore_patterns("__pycache__"))
    assert _run(tmp_path) == "51"
    assert _run(tmp_path) == "51"  # from the cache
    laws = tmp_path / "stickslip" / "kernels" / "laws.py"
    text = laws.read_text()
    # The constant-velocity drives' pulling point, which _pull's overload compiles in.
    old = "lambda V, n, dt, dp, drive: V * (np.float64(n) * dt)"
    assert old in text
    laws.write_text(text.replace(old, "lambda V, n, dt, dp, drive: 2.0 * V * (np.float64(n) * dt)"))
    assert _run(tmp_path) == "26"


def test_digest_changes_with_any_module(tmp_path):
    a, b = tmp_path / "a.py", tmp_path / "b.py"
    a.write_text("x = 1\n")
    b.write_text("y = 2\n")
    before = modules_digest([a, b])
    assert modules_digest([b, a]) == before
    b.write_text("y = 3\n")
    assert modules_digest([a, b]) != before
