"""Names a package loads on first use (module ``__getattr__``, PEP 562), so that importing the
package stays light: ``stickslip``, ``stickslip.run`` and ``stickslip.plotting`` load the
compiled kernels and matplotlib only when a name that needs them is asked for."""

from __future__ import annotations

import sys
from importlib import import_module


def lazy_names(package: str, table: dict[str, str]):
    """The module-level ``__getattr__`` and ``__dir__`` of ``package`` for the names of ``table``.

    Parameters
    ----------
    package : str
        The package's name (its ``__name__``).
    table : dict of str to str
        Each name loaded on first use, and the module that defines it.

    Returns
    -------
    tuple of callable
        ``__getattr__`` (loads a name of ``table`` from its module and keeps it in the package;
        AttributeError for any other) and ``__dir__`` (the package's names and those of ``table``).
    """

    def __getattr__(name: str):
        if name in table:
            value = getattr(import_module(table[name]), name)
            setattr(sys.modules[package], name, value)
            return value
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__():
        return sorted(set(vars(sys.modules[package])) | set(table))

    return __getattr__, __dir__
