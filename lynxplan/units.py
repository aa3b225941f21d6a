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


class ImplausibleLengthWarning(UserWarning):
    """A length far beyond what the robot can reach: most likely a value in another unit (a
    file in mm read as metres). The CLI prints it as one line on stderr."""


#: A scenario length larger than this many times the robot's reach is warned about.
IMPLAUSIBLE_REACH_FACTOR = 100.0


def implausible_length(value: float, reach: float) -> bool:
    """Whether ``|value|`` [m] exceeds :data:`IMPLAUSIBLE_REACH_FACTOR` times ``reach`` [m]."""
    return reach > 0 and abs(value) > IMPLAUSIBLE_REACH_FACTOR * reach


def warn_implausible_length(
    key: str, value: float, reach: float, file_unit: str, others: int = 0
) -> None:
    """Warn (:class:`ImplausibleLengthWarning`, one line) that the length at ``key`` is
    implausible for the robot, suggesting the unit that would make it plausible.

    Args:
        key: Where the length comes from, e.g. ``obstacles[0].size``.
        value: The length, in [m] (converted from ``file_unit``).
        reach: The robot's reach, in [m].
        file_unit: The unit the file gave it in.
        others: How many more lengths of the same input are implausible too.
    """
    import warnings

    written = value / length_factor(file_unit)
    fits = [
        u for u in LENGTH_UNITS if u != file_unit and abs(written) * LENGTH_UNITS[u] <= 10 * reach
    ]
    hint = (
        f"is the file in {fits[0]}? (units: {{length: {fits[0]}}})"
        if fits
        else "check the file's units: block"
    )
    more = f" ({others} more lengths like it)" if others else ""
    warnings.warn(
        f"{key}: {written:.6g} {file_unit} is {abs(value) / reach:.0f} times the robot's reach "
        f"({reach / length_factor(file_unit):.3g} {file_unit}){more}; {hint}",
        ImplausibleLengthWarning,
        stacklevel=3,
    )
