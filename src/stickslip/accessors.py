"""Accessors a higher layer lends to a result of a lower one, looked up by name on first use:
``run.plot`` (the figures of :mod:`stickslip.plotting.run`) on a
:class:`~stickslip.run.outputs.ChainRun` without :mod:`stickslip.run` importing the plotting.
The package registers them when it is imported (``stickslip/__init__.py``)."""

from __future__ import annotations

from importlib import import_module
from typing import Any

__all__ = ["register", "accessor"]

#: Accessor name -> "module:attribute" of its class, set by :func:`register`.
_REGISTERED: dict[str, str] = {}


def register(name: str, target: str) -> None:
    """Lend the class at ``target`` ("module:attribute") as the accessor ``name``.

    Parameters
    ----------
    name : str
        The accessor's name (``plot``).
    target : str
        Where its class lives, imported only when it is first asked for.
    """
    _REGISTERED[name] = target


def accessor(name: str, obj: Any) -> Any:
    """The accessor ``name`` of ``obj``: its registered class built on ``obj``.

    Parameters
    ----------
    name : str
        A registered name.
    obj : object
        What it reads (a run).

    Returns
    -------
    object
        The accessor.

    Raises
    ------
    AttributeError
        Where nothing is registered as ``name``.
    """
    if name not in _REGISTERED:
        raise AttributeError(f"no accessor {name!r} is registered (import stickslip first)")
    module, attribute = _REGISTERED[name].split(":")
    return getattr(import_module(module), attribute)(obj)
