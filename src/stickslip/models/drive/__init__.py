"""The drives of the chain, one module each (docs/model.md, "The family the paper stands in").

A drive's module defines ``READS`` and ``Params`` (the parameters its compiled functions read,
:func:`stickslip.models.piece.kernel_params`) and the compiled functions every integrator calls
through :func:`stickslip.kernels.laws.call`:

* ``force(xl, xc, xr, K, p, dp)``: the spring force on a block between xl and xr with the drive
  at p = V t (in the drive's own frame, p = 0), in the drive's own order of operations;
* ``force_lap(lap, xc, K, p, dp)``: the same force with the lattice's Laplacian of x ``lap`` in
  place of the neighbours (:mod:`stickslip.models.lattice`), in ``force``'s order of operations;
* ``force_rate(vl, vc, vr, K, q, dp)``: d/dt of ``force`` at the velocities vl, vc, vr with the
  drive's velocity q (the stress rate a law with ``PIECE.context`` reads; ghost cells from ``left``
  and the ends' ``ghost`` at the velocities, :func:`stickslip.kernels.laws.set_velocity_ghosts`);
* ``leaf(dp)``: the stiffness of the spring joining every block to the drive (0 when it pulls
  block 1 only), which the start-step searches and rounding bounds read;
* ``left(p, ghost)``: x_0, the ghost cell left of block 1: the pulling point p, or the ends'
  ``ghost`` where the drive does not pull there;

and ``PIECE`` (``leaf_spring``: the drive reaches every block, so stopped blocks start at steps
known in advance). :data:`stickslip.models.pieces.DRIVES` lists them.
"""
