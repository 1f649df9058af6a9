"""The norm in which two states of a model on a lattice are compared (docs/lyapunov.md,
docs/lattice.md): the separation of the Lyapunov exponents and of the decorrelation, for the
chain and for the square alike.

A state of block k is (x_k, v_k, theta_k, stopped_k). Forces read positions only through the
springs, so the separation of two states is measured in y = (sqrt(K) e, v, theta), e the
springs' extensions along each line from the pulled side (:meth:`Chain.strain
<stickslip.models.lattice.chain.Chain.strain>`, :meth:`Square.strain
<stickslip.models.lattice.square.Square.strain>`; the pulling point is the same for both states),
with the Euclidean norm: with unit mass ``|(sqrt(K) de, dv)|^2 / 2`` is the energy of the
perturbation along those lines. With a drive that holds every block by its own leaf spring Kp
(the plate), positions relative to the plate are the displacements themselves and y =
(sqrt(Kp) dx, v, theta). Every array here is over the blocks in the lattice's order (row-major),
of length n = the number of blocks; y has length 3 n.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["coordinates", "displacement", "distance", "lattice_of", "on_branch", "scale"]


def lattice_of(params: Any):
    """The lattice of ``params``: a lattice model's own, the chain of N blocks for a chain's
    (its end drive at block 1)."""
    lat = getattr(params, "lattice", None)
    if lat is not None and not isinstance(lat, str):
        return lat
    from stickslip.models.lattice import chain

    return chain.Chain(int(params.N), "driven", str(params.ends))


def scale(params: Any) -> tuple[bool, float]:
    """(leaf, s): whether the drive holds every block by a leaf spring (``leaf_spring`` of the
    drive piece), and s = sqrt(Kp) if so, else sqrt(K), the weight of the position part."""
    leaf = bool(params.drive_piece.leaf_spring)
    return leaf, math.sqrt(params.Kp if leaf else params.K)


def coordinates(lat, dx: np.ndarray, dv: np.ndarray, dth: np.ndarray, params: Any) -> np.ndarray:
    """y = (s e, dv, dth) of a separation (dx, dv, dth) over the blocks: e = the lattice's
    ``strain(dx)`` and s = sqrt(K), or e = dx and s = sqrt(Kp) with a leaf spring
    (:func:`scale`); length 3 n."""
    leaf, s = scale(params)
    return np.concatenate((s * (dx if leaf else lat.strain(dx)), dv, dth))


def displacement(lat, yx: np.ndarray, params: Any) -> np.ndarray:
    """The displacement dx of the blocks whose position part of :func:`coordinates` is ``yx``
    (the inverse: yx / s, through the lattice's ``unstrain`` without a leaf spring)."""
    leaf, s = scale(params)
    return yx / s if leaf else lat.unstrain(yx / s)


def on_branch(dy: np.ndarray, stopped: np.ndarray, has_state: bool = True) -> np.ndarray:
    """``dy`` (in y) without the velocity components of the blocks ``stopped`` (the constraint
    v = 0 of a stuck block), and without theta where the model has no state variable; a copy."""
    n = stopped.shape[0]
    out = dy.copy()
    out[n : 2 * n][stopped] = 0.0
    if not has_state:
        out[2 * n :] = 0.0
    return out


def distance(lat, a: tuple, b: tuple, params: Any) -> float:
    """The distance ``|y(b) - y(a)|`` of two states given as (x, v, theta) over the blocks of the
    padded layout (flat arrays of the lattice's ``size``, ghost cells included and not read).

    Examples
    --------
    >>> import numpy as np
    >>> from stickslip.models.lattice import norm
    >>> from stickslip.models.presets import chain_params
    >>> p = chain_params(N=3, K=4.0)
    >>> lat = norm.lattice_of(p)
    >>> zero = np.zeros(5)
    >>> x = np.array([0.0, -1.0, -1.0, -1.0, 0.0])  # every block moved back by 1: spring 1 stretched
    >>> norm.distance(lat, (zero, zero, zero), (x, zero, zero), p)  # sqrt(K) * 1
    2.0
    """
    blocks = lat.blocks()
    dx, dv, dth = (np.asarray(q)[blocks] - np.asarray(p_)[blocks] for p_, q in zip(a, b, strict=True))
    return float(np.linalg.norm(coordinates(lat, dx, dv, dth, params)))
