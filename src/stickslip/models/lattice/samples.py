"""The samples of a run on a lattice as declared reductions (docs/lattice.md, "Outputs"): each a
name, its meaning and the function that reduces a state at step n to one number; a run's
samples table has the column ``t`` and one column per entry of :data:`SAMPLES`, in that order.

The mean stress is the force that the springs and the drive put on a block, the one the
friction balances (eq. (4) with the lattice's Laplacian, docs/lattice.md "What is computed"):

    f_k = the drive's ``force_lap(K lap(x)_k, x_k, K, p(t_n), ...)``

that is K lap(x)_k for an edge drive (the paper's model on the square: the driven side's ghost
cells at the load point p(t_n) = V t_n), K lap(x)_k + Kp (V t_n - x_k) for a plate
(Carlson-Langer), K lap(x)_k + F for a constant force. It is evaluated with the lattice's own
ghost cells and stencil and the drive's own function, the expression of the integrators' stage 1,
so a stuck block holds while f_k is below its threshold, and in steady sliding every f_k is the
friction at v = V.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from stickslip.models.lattice import module_of

__all__ = ["SAMPLES", "Reduction", "forces", "load_point", "sample"]


def load_point(p: Any, n: int) -> float:
    """The drive's load point p(t_n) at step n as the kernels compute it
    (:func:`stickslip.kernels.laws.pull_point`): V t_n, or a load history's p(t_n)."""
    from stickslip.kernels.laws import pull_point

    dp = p.kernel_params(p.drive_piece)
    return float(pull_point(p.drive_piece.kernel_velocity(p.chain), n, p.dt, dp, p.drive_piece.module))


def forces(p: Any, xg: np.ndarray, thg: np.ndarray, n: int) -> np.ndarray:
    """The force f_k of the springs and the drive on every block at step n (module docstring).

    Parameters
    ----------
    p : LatticeParams
        The model on its lattice.
    xg, thg : ndarray
        x and theta in the lattice's padded flat layout (not changed: the ghost cells are filled
        on copies).
    n : int
        The step, whose load point p(t_n) the driven sides read.

    Returns
    -------
    ndarray
        f over (row, col), in the order of the lattice's ``grid``.
    """
    lat = p.lattice
    geometry = importlib.import_module(module_of(lat.name))
    drive = importlib.import_module(p.drive_piece.module)
    load = load_point(p, n)
    x, th = np.array(xg, dtype=np.float64), np.array(thg, dtype=np.float64)
    geometry.fill(x, th, lat.geometry(), load)
    k = lat.blocks()
    lap = geometry.lap.py_func(x, k, lat.width)  # the stencil at every block at once
    dp = p.kernel_params(p.drive_piece)
    per_block = {f: v[k] for f, v in dp._asdict().items() if isinstance(v, np.ndarray) and v.ndim == 1}
    K = p.K if isinstance(p.K, float) else float(p.K.values[0])  # one spring K on a lattice
    f = drive.force_lap.py_func(lap, x[k], K, load, dp._replace(**per_block))
    return np.asarray(f, dtype=np.float64).reshape(lat.shape)


@dataclass(frozen=True)
class Reduction:
    """One column of a lattice run's samples: ``name``, its meaning (``doc``, the column's
    description) and ``reduce(p, state, n)``, the number at step n of a state with the padded
    arrays ``xg``, ``vg``, ``thg``, ``mov`` and the kernels' ``ist``."""

    name: str
    doc: str
    reduce: Callable[[Any, Any, int], float]


def _slip_deficit(p: Any, s: Any, n: int) -> float:
    return float(np.mean(load_point(p, n) - p.lattice.grid(s.xg)))


def _stress(p: Any, s: Any, n: int) -> float:
    return float(np.mean(forces(p, s.xg, s.thg, n)))


def _mean_v(p: Any, s: Any, n: int) -> float:
    return float(np.mean(p.lattice.grid(s.vg)))


def _moving(p: Any, s: Any, n: int) -> int:
    from stickslip.kernels.layout import N_MOVING

    return int(s.ist[N_MOVING])


#: The declared samples of a lattice run, in the order of the table's columns (after ``t``).
SAMPLES: tuple[Reduction, ...] = (
    Reduction(
        "mean_slip_deficit",
        "the mean over the blocks of the load point p(t) (V t, or a history's) less x",
        _slip_deficit,
    ),
    Reduction("mean_v", "the mean velocity of the blocks", _mean_v),
    Reduction("moving", "the number of moving blocks", _moving),
    Reduction(
        "mean_stress",
        "the mean over the blocks of the force of the springs and the drive, K lap(x) plus the drive's term "
        "(Kp (V t - x) of a plate, F of a constant force), the force the friction balances",
        _stress,
    ),
)


def sample(p: Any, s: Any, n: int) -> tuple:
    """(t_n, then each of :data:`SAMPLES` at step n) of the state ``s``: one row of the samples.

    Examples
    --------
    >>> from stickslip.models.lattice.samples import SAMPLES
    >>> ["t", *(r.name for r in SAMPLES)]
    ['t', 'mean_slip_deficit', 'mean_v', 'moving', 'mean_stress']
    """
    return (n * p.dt, *(r.reduce(p, s, n) for r in SAMPLES))
