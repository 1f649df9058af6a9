"""The friction laws of the model family, one module each (docs/models/rate-state.md, "Adding a law").

A law's module defines ``PIECE``, a :class:`~stickslip.models.piece.Piece` carrying its name,
meaning, parameters and their checks, steady sliding, start value of theta, linearisation and
figure label. :data:`stickslip.models.pieces.PIECES` lists them in the order of their kernel
codes (``FRICTION_*`` in :mod:`stickslip.kernels.layout`); the kernel expressions sit with the
other kernels in :mod:`stickslip.kernels.laws`.
"""
