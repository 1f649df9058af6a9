"""The lab's state laws are the friction laws' own modules (issue 50, item 5): each law's module
holds its ``lab_rate``, the registry of friction laws lists them, and the quasi-static right-hand
side evaluates exactly those functions, which agree with the laws written out here."""

import importlib
import math

import numpy as np
import pytest

from stickslip.lab import LAWS, RateState
from stickslip.lab.compiled import lab_laws, law_rates
from stickslip.lab.laws import rhs
from stickslip.models.pieces import FRICTIONS, PIECES

LAB = dict(a=0.005, mu0=0.6, V0=1.0)

#: The laws written out from their papers (x = v theta / (s D_c)), independent of the package.
WRITTEN = {
    "aging": lambda x, th, cb, dtau: 1.0 - x,
    "slip": lambda x, th, cb, dtau: -x * math.log(x),
    "prz": lambda x, th, cb, dtau: 1.0 - x * x,
    "nagata": lambda x, th, cb, dtau: 1.0 - x - cb * th * dtau,
}


def test_the_lab_laws_are_the_registrys_friction_modules():
    mods = {f"stickslip.models.friction.{m}" for m in FRICTIONS}
    assert set(LAWS) == set(WRITTEN)
    assert [law.code for law in LAWS.values()] == list(range(len(LAWS)))
    for name, law in LAWS.items():
        assert law.module in mods
        piece = next(p for p in PIECES["friction"] if p.module == law.module)
        assert piece.lab.name == name and piece.lab.scale == law.scale
        assert callable(importlib.import_module(law.module).lab_rate)
    assert [p.lab.name for p in lab_laws()] == list(LAWS)
    assert LAWS["prz"].scale == 2.0 and LAWS["aging"].scale == 1.0
    assert [n for n, law in LAWS.items() if law.reads_stress_rate] == ["nagata"]


@pytest.mark.parametrize("law", sorted(WRITTEN))
def test_rhs_evaluates_each_laws_own_module_and_its_written_form(law):
    m = RateState(**LAB, b=0.01, Dc=10.0, k=2e-3, law=law, c=1.5 if law == "nagata" else 0.0)
    args = m.arrays()
    out = np.empty(2)
    scale = 2.0 if law == "prz" else 1.0
    for tau, th, vlp in ((0.61, 12.0, 3.0), (0.58, 2.5, 0.0), (0.6, 40.0, 10.0)):
        y = np.array([tau, th])
        v = rhs(0.0, y, out, vlp, *args)
        psi = 0.6 + 0.01 * math.log(th / (scale * 10.0))
        assert v == pytest.approx(math.exp((tau - psi) / 0.005), rel=1e-12)  # log form, no damping
        dtau = 2e-3 * (vlp - v)
        assert out[0] == pytest.approx(dtau, rel=1e-12, abs=1e-18)
        x = v * th / (scale * 10.0)
        cb = 1.5 / 0.01 if law == "nagata" else 0.0
        assert out[1] == pytest.approx(WRITTEN[law](x, th, cb, dtau), rel=1e-12, abs=1e-15)
        # the module's own function, called from Python, gives the compiled result to the bit
        assert out[1] == importlib.import_module(LAWS[law].module).lab_rate.py_func(x, th, cb, dtau)
        py = np.empty(2)
        law_rates(args[9], v, y, 1, args[7], args[8], dtau, py)
        assert py[1] == out[1]


def test_two_state_variables_each_follow_their_own_law():
    m = RateState(**LAB, b=(0.006, 0.004), Dc=(5.0, 50.0), k=1e-3, law=("prz", "slip"))
    out = np.empty(3)
    y = np.array([0.6, 7.0, 30.0])
    v = rhs(0.0, y, out, 1.0, *m.arrays())
    psi = 0.6 + 0.006 * math.log(7.0 / 10.0) + 0.004 * math.log(30.0 / 50.0)
    assert v == pytest.approx(math.exp((0.6 - psi) / 0.005), rel=1e-12)
    x1, x2 = v * 7.0 / 10.0, v * 30.0 / 50.0
    assert out[1] == pytest.approx(1.0 - x1 * x1, rel=1e-12)
    assert out[2] == pytest.approx(-x2 * math.log(x2), rel=1e-12)


def test_the_lab_is_cached_where_an_edit_to_a_law_compiles_it_afresh(tmp_path):
    """The lab's compiled functions call the laws' modules, so they are cached in the directory
    named by the digest of the kernels and the model modules (``stickslip.kernels._cache``), not
    beside ``lab/compiled.py`` (where numba would stamp them with that file alone)."""
    import os
    import subprocess
    import sys

    from stickslip.kernels import _cache

    code = (
        "from stickslip.lab import RateState\n"
        "from stickslip.lab.laws import friction_of\n"
        "print(friction_of(RateState(a=0.005, b=0.01, Dc=10.0, mu0=0.6, V0=1.0), 2.0, 5.0))\n"
    )
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert float(out.stdout) == pytest.approx(0.6 + 0.005 * math.log(2.0) + 0.01 * math.log(0.5), rel=1e-12)
    digest_dir = tmp_path / f"stickslip-{_cache.DIGEST[:20]}"
    cached = [p.name for p in digest_dir.rglob("compiled.friction-*.nbi")]
    assert cached, sorted(p.name for p in tmp_path.rglob("*"))[:20]


def test_the_command_line_names_the_registrys_laws():
    from stickslip.cli.lab import _lab_laws

    assert _lab_laws() == list(LAWS) == ["aging", "slip", "prz", "nagata"]
