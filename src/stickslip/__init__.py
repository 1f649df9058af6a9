"""stickslip: stick-slip friction in block-spring systems.

Implements the model of H. Sakaguchi, "Stick-Slip Motion and Phase Transition in a
Block-Spring System": a single block with state-variable and static friction (eq. 1),
its slip in the limit V -> 0 (eq. 3), the linear stability of steady sliding (eqs. 2, 5)
and a chain of N blocks pulled at one end (eq. 4).

Layout: :mod:`stickslip.models` (parameters, closed-form physics), :mod:`stickslip.kernels`
(compiled integrators), :mod:`stickslip.run` (running the block and the chain, checkpoints,
run directories), :mod:`stickslip.analysis` (stability, eq. (3), statistics, hysteresis),
:mod:`stickslip.experiments` (the paper's experiments, sweeps on Dask, ``reproduce``),
:mod:`stickslip.report`, :mod:`stickslip.plotting`, and the command line :mod:`stickslip.cli`.

The main API is importable from here; the simulators load on first use, so that
``import stickslip`` stays light.
"""

from importlib.metadata import PackageNotFoundError
from importlib.metadata import version as _version

from stickslip.lazy import lazy_names

try:
    __version__ = _version("stickslip")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0.0.0+unknown"

# The pieces' compiled functions (models/) are decorated when first asked for, after the kernels'
# cache directory is set (models/piece.py, kernels/_cache.py): importing the package loads no numba.
from stickslip.models.params import BlockParams, ChainParams, ParameterError  # noqa: E402

#: Names loaded on first use, and the module that holds each.
_LAZY = {
    "run_chain": "stickslip.run.driver",
    "RunOptions": "stickslip.run.options",
    "Hook": "stickslip.run.loop",
    "chain_params": "stickslip.models.presets",
    "largest_lyapunov": "stickslip.analysis.dynamics.lyapunov",
    "resume_chain": "stickslip.run.driver",
    "load_run": "stickslip.run.rundir",
    "simulate_block": "stickslip.run.block",
    "Quenched": "stickslip.models.disorder",
}

__all__ = ["BlockParams", "ChainParams", "ParameterError", "__version__", *_LAZY]

# A run's figures, lent by the plotting to the runs (``run.plot.sizes()``, ``run.plot_sizes()``)
# from above the layers: stickslip.run never imports stickslip.plotting.
from stickslip import accessors as _accessors  # noqa: E402

_accessors.register("plot", "stickslip.plotting.run:RunPlots")
_accessors.register("lattice_plot", "stickslip.plotting.lattice:LatticePlots")


__getattr__, __dir__ = lazy_names(__name__, _LAZY)
