"""Finite-size Lyapunov exponents (stickslip.analysis.dynamics.fsle).

Known answer: the Lorenz system (sigma 10, rho 28, beta 8/3), whose largest exponent is 0.9056
(Sprott, Chaos and Time-Series Analysis, 2003), run through the same finite_size_exponents that
the command uses for the models: in the linear range the growth of small separations gives it.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from stickslip.analysis.dynamics.fsle import finite_size_exponents, thresholds
from stickslip.cli import main
from stickslip.models.params import ParameterError

LORENZ_EXPONENT = 0.9056


class Lorenz:
    """Reference and twin of the Lorenz system, RK4 in plain floats (a Pair)."""

    def __init__(self, dt: float = 0.01):
        self.dt = dt
        a = (1.0, 1.0, 20.0)
        for _ in range(2000):  # onto the attractor
            a = self._rk4(a)
        self.a = self.b = a

    @staticmethod
    def _f(y):
        x, yy, z = y
        return (10.0 * (yy - x), x * (28.0 - z) - yy, x * yy - 8.0 / 3.0 * z)

    def _rk4(self, y):
        h = self.dt
        k1 = self._f(y)
        k2 = self._f(tuple(p + 0.5 * h * k for p, k in zip(y, k1, strict=True)))
        k3 = self._f(tuple(p + 0.5 * h * k for p, k in zip(y, k2, strict=True)))
        k4 = self._f(tuple(p + h * k for p, k in zip(y, k3, strict=True)))
        return tuple(p + h / 6.0 * (q + 2 * r + 2 * s + w) for p, q, r, s, w in zip(y, k1, k2, k3, k4, strict=True))

    def advance(self, steps):
        for _ in range(steps):
            self.a, self.b = self._rk4(self.a), self._rk4(self.b)

    def distance(self):
        return math.dist(self.a, self.b)

    def reset(self, delta):
        d = [q - p for p, q in zip(self.a, self.b, strict=True)]
        n = math.hypot(*d)
        if n == 0.0:
            d, n = [1.0, 0.0, 0.0], 1.0
        self.b = tuple(p + delta * q / n for p, q in zip(self.a, d, strict=True))


def test_lorenz_exponent_from_the_growth_of_small_separations():
    res = finite_size_exponents(Lorenz(), thresholds(1e-8, 1e-4), cycles=60, pooled_below=1e-4)
    rate, err = res.extra["pooled_rate"], res.extra["pooled_rate_err"]
    assert err < 0.04
    assert abs(rate - LORENZ_EXPONENT) < 3 * err, (rate, err)
    assert len(res.rows) == len(thresholds(1e-8, 1e-4)) - 1
    assert all(r["cycles"] == 60 for r in res.rows)


def test_thresholds_double_and_are_checked():
    assert np.allclose(thresholds(1e-3, 1e-2), [1e-3, 2e-3, 4e-3, 8e-3])
    with pytest.raises(ParameterError, match="delta_max must be >= ratio"):
        thresholds(1e-3, 1.5e-3)


def test_cli_finite_size_rows(capsys):
    argv = [
        "lyapunov", "--model", "two-blocks", "--switches", "located", "--finite-size", "--transient", "200",
        "--t-end", "2000", "--delta-min", "1e-8", "--delta-max", "1e-6", "--cycles", "2", "--check", "0.5", "--json",
    ]  # fmt: skip
    assert main(argv) == 0
    d = json.loads(capsys.readouterr().out)
    assert [r["delta"] for r in d["fsle"]] == pytest.approx([1e-8 * 2**k for k in range(6)])
    assert {"delta", "rate", "rate_err"} <= set(d["fsle"][0])
    assert d["cycles"] == 2


def test_cli_finite_size_needs_located(capsys):
    try:
        status = main(["lyapunov", "--finite-size", "--N", "2"])
    except SystemExit as exc:
        status = exc.code
    assert status == 2 and "--finite-size goes with --switches located" in capsys.readouterr().err
