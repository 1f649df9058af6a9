"""stickslip: stick-slip friction in block-spring systems.

Implements the model of H. Sakaguchi, "Stick-Slip Motion and Phase Transition in a
Block-Spring System": a single block with state-variable and static friction (eq. 1),
its slip in the limit V -> 0 (eq. 3), the linear stability of steady sliding (eqs. 2, 5)
and a chain of N blocks pulled at one end (eq. 4).
"""

from importlib.metadata import PackageNotFoundError, version as _version

try:
    __version__ = _version("stickslip")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0.0.0+unknown"

from stickslip.params import BlockParams, ChainParams, ParameterError  # noqa: E402

__all__ = ["BlockParams", "ChainParams", "ParameterError", "__version__"]
