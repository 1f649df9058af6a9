"""The friction laws of the model family, one module each (docs/models/rate-state.md, "Adding a law").

A law's module defines

* ``READS``, the parameters it reads, and ``Params``, their named tuple
  (:func:`stickslip.models.piece.kernel_params`), from which the driver packs the kernels' copy;
* ``accel(f, v, th, lp)``, the force f on a moving block less the law's friction, and
  ``rate(thl, th, thr, v, lp)``, the state variable's rate (0 for a law without one): compiled
  functions that every integrator calls (dense, exact, sparse, located switches; the contract is
  in :mod:`stickslip.kernels.laws`), and ``rate_lap(lap, th, v, lp)``, the same rate with the
  lattice's Laplacian of theta ``lap`` in place of the neighbours (:mod:`stickslip.models.lattice`,
  :mod:`stickslip.kernels.lattice`), in ``rate``'s order of operations;
* for a law whose rate reads the stress rate (the Nagata law), ``rate(thl, th, thr, v, lp, ctx)``
  with ``ctx.stress_rate`` the rate of the elastic force on the block, and ``PIECE.context =
  ("stress_rate",)``: only its kernels build the context (:func:`stickslip.kernels.laws._dtheta_in`);
* for a law the rock-friction lab offers, ``lab_rate(x, th, cb, dtau)``, its dtheta/dt as the
  lab's quasi-static spring-slider evaluates it (:mod:`stickslip.lab.compiled`), and
  ``PIECE.lab``, its :class:`~stickslip.models.piece.LabLaw` (the name :data:`stickslip.lab.LAWS`
  lists it under);
* ``PIECE``, a :class:`~stickslip.models.piece.Piece` carrying its name, meaning, parameters and
  their checks, steady sliding, start value of theta, linearisation and figure label.

:data:`stickslip.models.pieces.FRICTIONS` lists them: a new law is its module and one line there.
"""
