"""The Jacobian of the chain about steady sliding, assembled from the pieces (eq. 5 and its
relatives, docs/model.md), for uniform and per-block parameters.

Every block slides at the steady velocity v (:func:`stickslip.models.physics.steady_velocity`).
Linearised about it, in the variables (dx_1..dx_N, dv_1..dv_N[, dtheta_1..dtheta_N]):

    d dx_i/dt     = dv_i
    M_i d dv_i/dt = K (dx_{i-1} - 2 dx_i + dx_{i+1}) - k_i dx_i - phi_v,i dv_i - phi_theta,i dtheta_i
    d dtheta_i/dt = g_v,i dv_i + g_theta,i dtheta_i + D_i (dtheta_{i-1} - 2 dtheta_i + dtheta_{i+1})

where each piece gives its part:

* the drive its stiffness k_i (its compiled ``leaf``: Kp for the plate, 0 for the end drive and
  the force drives; :func:`stickslip.models.physics.drive_stiffness`) and whether x_0 is its
  pulling point (which moves with steady sliding, so dx_0 = 0) or the ends' ghost cell;
* the ends the ghost cells' rows (their compiled ``ghost``, :func:`stickslip.models.physics.ghost_rows`);
* the friction law each block's linearisation at its own parameters
  (:class:`~stickslip.models.piece.Linearisation`; a law without theta its slope phi'(v), and then
  the matrix is 2N x 2N without the theta rows).

M_i is the block's mass where the parameters carry one (``M``), else 1. For eq. (4) this is the
3N x 3N matrix of eq. (5) with the ends of docs/model.md; for a uniform chain its eigenvalues are
the Fourier modes' (:func:`stickslip.analysis.dynamics.stability.chain_mode_matrix`, Fig. 4, and
:func:`stickslip.analysis.dynamics.stability_modes.mode_roots`) where the modes diagonalise it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from stickslip.models import physics
from stickslip.models.piece import Linearisation


def block_linearisations(p: Any, v: float | None = None) -> list[Linearisation]:
    """Each block's friction law linearised at steady sliding at velocity ``v`` (default: the
    chain's steady velocity), at its own parameters (:class:`~stickslip.models.physics.BlockView`):
    the law's ``linear``, or for a law without theta its ``slope`` as phi_v (the rest 0).

    Raises ValueError where there is no steady sliding.
    """
    if not physics.has_steady_state(p):
        raise ValueError(f"the chain with drive {p.drive} and ends {p.ends} has no steady sliding")
    law = p.friction_piece
    v = physics.steady_velocity(p) if v is None else v
    over = {} if v == p.V else {"V": float(v)}

    def one(q: Any) -> Linearisation:
        if law.linear is not None:
            return law.linear(q)
        if law.slope is None:
            raise ValueError(f"friction {p.friction} declares no linearisation")
        return Linearisation(0.0, law.slope(q), 0.0, 0.0, 0.0)

    if physics.is_uniform(p):
        return [one(physics.uniform_view(p, **over))] * p.N
    return [one(physics.BlockView(p, i, **over)) for i in range(p.N)]


def chain_jacobian(p: Any) -> np.ndarray:
    """The Jacobian of the chain about steady sliding, from its pieces (module docstring).

    Parameters
    ----------
    p : ChainParams
        The chain; each per-block parameter a float or an array of N values. Laws with a state
        variable give a 3N x 3N matrix (eq. 5 for eq. (4)'s law), laws without one 2N x 2N.

    Returns
    -------
    numpy.ndarray
        The matrix, variables ordered (dx_1..dx_N, dv_1..dv_N[, dtheta_1..dtheta_N]).

    Raises
    ------
    ValueError
        Where there is no steady sliding (fixed ends, a force ramp, a force below the friction).

    Examples
    --------
    >>> from stickslip import chain_params
    >>> from stickslip.analysis.dynamics.jacobian import chain_jacobian
    >>> chain_jacobian(chain_params(N=3)).shape
    (9, 9)
    >>> chain_jacobian(chain_params("train", N=3)).shape
    (6, 6)
    """
    N = p.N
    lins = block_linearisations(p)
    rows = physics.ghost_rows(p)
    A = p.K * physics.laplacian(N, (rows["x0"], rows["xN1"])) - np.diag(physics.drive_stiffness(p))
    phi_v = np.array([lin.phi_v for lin in lins])
    eye, zero = np.eye(N), np.zeros((N, N))
    mass = physics.per_block(p, "M") if hasattr(p, "M") else None
    if not p.friction_piece.has_state:
        dv = [A, -phi_v[:, None] * eye]
        if mass is not None:
            dv = [m / mass[:, None] for m in dv]
        return np.block([[zero, eye], dv])
    phi_t = np.array([lin.phi_theta for lin in lins])
    g_v = np.array([lin.g_v for lin in lins])
    g_t = np.array([lin.g_theta for lin in lins])
    diff = np.array([lin.diffusion for lin in lins])
    lap_t = physics.laplacian(N, (rows["th0"], rows["thN1"]))
    dv = [A, -phi_v[:, None] * eye, -phi_t[:, None] * eye]
    if mass is not None:
        dv = [m / mass[:, None] for m in dv]
    return np.block([[zero, eye, zero], dv, [zero, g_v[:, None] * eye, g_t[:, None] * eye + diff[:, None] * lap_t]])
