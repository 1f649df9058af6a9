"""What the linear stability of every model shares: mode ordering, the lattice Laplacian's q.

The discrete Laplacian on exp(i k j) has the eigenvalue -q, q = 4 sin^2(k/2) (eq. 5, Fig. 4);
the finite chain's sine modes are those of docs/model.md's ends. Used by
:mod:`stickslip.analysis.dynamics.stability` (eq. 2, eq. 5) and :mod:`stickslip.analysis.dynamics.stability_modes`.
"""

from __future__ import annotations

import numpy as np

#: A growth rate below this (in absolute value) counts as zero: the round-off of a 3 x 3 or
#: 3N x 3N eigenvalue problem with entries of order K is far below it.
GROWTH_TOL = 1e-10


def _sorted_by_real_part(eig: np.ndarray) -> np.ndarray:
    """Eigenvalues along the last axis, largest real part first (ties: positive imag first)."""
    order = np.lexsort((-eig.imag, -eig.real), axis=-1)
    return np.take_along_axis(eig, order, axis=-1)


def lattice_q(k: np.ndarray | float) -> np.ndarray:
    """Eigenvalue -q of the discrete Laplacian on exp(i k j): q = 2 (1 - cos k) = 4 sin^2(k/2)."""
    return 4.0 * np.sin(0.5 * np.asarray(k, dtype=float)) ** 2


def finite_chain_wavenumbers(N: int) -> np.ndarray:
    """Wavenumbers k_m = (2m - 1) pi / (2N + 1), m = 1..N, of the spring Laplacian of the chain.

    With dx_0 = 0 and dx_{N+1} = dx_N the eigenvectors are sin(k_m i); the smallest,
    k_1 ~ pi / (2N), is the longest wave the finite chain holds.
    """
    m = np.arange(1, N + 1)
    return (2 * m - 1) * np.pi / (2 * N + 1)
