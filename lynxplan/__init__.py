"""lynxplan: modelling and planning for small robot arms and planar parallel robots."""

from __future__ import annotations

__version__ = "0.1.0"

from lynxplan.exceptions import LynxplanError

__all__ = ["LynxplanError", "__version__"]
