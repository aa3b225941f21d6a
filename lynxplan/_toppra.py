"""toppra without its import-time ``matplotlib.pyplot`` (about 1 s of a cold start).

toppra imports ``matplotlib.pyplot`` at the top of two modules but calls it only in its plotting
methods. :func:`import_toppra` imports toppra with placeholders for ``matplotlib`` and
``matplotlib.pyplot`` in ``sys.modules`` (removed again right after), so toppra's ``plt`` is a
stand-in that imports the real pyplot on first attribute access.
"""

from __future__ import annotations

import importlib
import sys
import types
from typing import Any

_TOPPRA_MODULES = ("toppra", "toppra.algorithm", "toppra.constraint")


class _DeferredModule(types.ModuleType):
    """Stands for a module until an attribute is used; then imports the real one."""

    def __init__(self, name: str, children: dict[str, types.ModuleType] | None = None) -> None:
        super().__init__(name)
        self._children = children or {}

    def __getattr__(self, attribute: str) -> Any:
        if attribute in self._children:
            return self._children[attribute]
        return getattr(importlib.import_module(self.__name__), attribute)


def import_toppra() -> types.ModuleType:
    """The ``toppra`` package with ``toppra.algorithm`` and ``toppra.constraint`` loaded."""
    if "toppra" in sys.modules or "matplotlib" in sys.modules:
        return _import_all()
    pyplot = _DeferredModule("matplotlib.pyplot")
    placeholders = {
        "matplotlib": _DeferredModule("matplotlib", {"pyplot": pyplot}),
        "matplotlib.pyplot": pyplot,
    }
    sys.modules.update(placeholders)
    try:
        return _import_all()
    finally:
        for name, placeholder in placeholders.items():
            if sys.modules.get(name) is placeholder:
                del sys.modules[name]


def _import_all() -> types.ModuleType:
    for name in _TOPPRA_MODULES:
        importlib.import_module(name)
    return sys.modules["toppra"]
