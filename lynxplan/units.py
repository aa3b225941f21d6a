"""Unit conversion at the edges. lynxplan works in SI inside: metres, radians, seconds."""

from __future__ import annotations

import math

from lynxplan.exceptions import UnknownUnitError

#: Metres per unit of length.
LENGTH_UNITS: dict[str, float] = {"m": 1.0, "mm": 1e-3, "in": 0.0254}
#: Radians per unit of angle.
ANGLE_UNITS: dict[str, float] = {"rad": 1.0, "deg": math.pi / 180.0}

INCH = LENGTH_UNITS["in"]


def length_factor(unit: str) -> float:
    """Metres per ``unit`` (``"m"``, ``"mm"`` or ``"in"``)."""
    try:
        return LENGTH_UNITS[unit]
    except KeyError:
        raise UnknownUnitError(unit, tuple(LENGTH_UNITS), "length") from None


def angle_factor(unit: str) -> float:
    """Radians per ``unit`` (``"rad"`` or ``"deg"``)."""
    try:
        return ANGLE_UNITS[unit]
    except KeyError:
        raise UnknownUnitError(unit, tuple(ANGLE_UNITS), "angle") from None
