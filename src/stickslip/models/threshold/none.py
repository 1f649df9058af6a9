"""No static threshold, for rate-and-state friction (the laboratory's reading of the law).

A rate-and-state block has no static friction of its own: its friction sigma_n mu(v, theta)
depends on the slip rate v, and the regularised law (:mod:`stickslip.models.friction.rate_state`)
holds no force at v = 0 (mu(0, theta) = 0; the log form's mu tends to -infinity there). So a
block held at rest by any positive spring force slips at once: v > 0 at all times, at a rate the
state variable sets (during a hold v decays but never reaches 0), which is what the quasi-static
spring-slider k (p - x) = mu(v, theta) solves (:func:`stickslip.lab.quasi_static`).

On the grid integrators this is the start rule with the threshold 0, the friction a block at
v = 0 can hold: a stopped block moves in the next step as soon as f_i > 0. The stop rule stays
(v <= 0 at the end of a step sets v = 0); it only catches Heun's overshoot, and such a block
restarts at the next step. Without Fs, holds (V = 0) and slide-hold-slide tests run on the
inertial chain, with no stop and restart at each of hundreds of thousands of steps; as the mass
M goes to 0 the inertial solution tends to the quasi-static one, linearly in M.
"""

from __future__ import annotations

from stickslip.models.piece import Piece, kernel_params, njit

READS: tuple[str, ...] = ()
Params = kernel_params(__name__, READS)


@njit(cache=True, inline="always")
def value(th, tp):
    """0: the force a rate-and-state block at v = 0 holds (mu(0, theta) = 0)."""
    return 0.0


PIECE = Piece(
    "threshold",
    "none",
    "no static threshold (rate-and-state): a stuck block starts as soon as f_i > 0, the friction it holds at v = 0",
    READS,
    module=__name__,
)
