"""The static thresholds of the start rule, one module each (docs/model.md, "The family the
paper stands in").

A threshold's module defines ``READS`` and ``Params`` (the parameters its compiled function
reads, :func:`stickslip.models.piece.kernel_params`), ``value(th, tp)``, the threshold a stuck
block's spring force must exceed for the block to start (``th`` its state variable, ``tp`` the
``Params``), compiled and called by every integrator through :func:`stickslip.kernels.laws.call`,
and ``PIECE`` (``has_state``: the threshold reads theta, so a stuck block's threshold moves
with it). :data:`stickslip.models.pieces.THRESHOLDS` lists them.
"""
