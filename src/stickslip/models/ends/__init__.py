"""The end conditions of the chain, one module each (docs/model.md, "The family the paper stands in").

An end condition's module defines ``ghost(edge, other, wall)``, the value of a ghost cell beyond
one end of the chain (``edge`` the value at that end, ``other`` the value at the opposite end,
``wall`` the position of a wall there in the frame of the caller: 0 for x, -V t for u = x - V t,
the edge value itself for the state variable, which has no-flux ends), compiled and called by
every integrator through :func:`stickslip.kernels.laws.call`, and ``PIECE`` (``ring``: the chain
closes, so blocks 1 and N are neighbours; ``wall``: a spring to a wall at x = 0, which makes the
equations in the drive's frame depend on t). :data:`stickslip.models.pieces.ENDS` lists them.
"""
