"""Expectations of a task scenario: ``">= 0.2 in"`` parsed into a comparison in SI units.

An expectation is a comparator, a number and (optionally) a unit: ``">= 0.2 in"``,
``"<= 26 s"``, ``"< 90 deg/s"``, ``"== 13"``. A bare number is allowed for keys that name their
direction (``max_*`` means ``<=``, ``min_*`` means ``>=``). Without a unit the number is in the
scenario file's unit of that quantity (length, angle/s) or in seconds.
"""

from __future__ import annotations

import math
import operator
import re
from collections.abc import Callable
from typing import NamedTuple

from lynxplan.units import ANGLE_UNITS, LENGTH_UNITS

#: Comparator text -> function (measured, expected) -> bool.
COMPARATORS: dict[str, Callable[[float, float], bool]] = {
    ">=": operator.ge,
    "<=": operator.le,
    ">": operator.gt,
    "<": operator.lt,
    "==": lambda measured, expected: math.isclose(measured, expected, rel_tol=1e-9, abs_tol=1e-12),
}

#: Quantity -> unit name -> SI factor (length [m], time [s], angular speed [rad/s], count [1]).
QUANTITY_UNITS: dict[str, dict[str, float]] = {
    "length": dict(LENGTH_UNITS),
    "time": {"s": 1.0, "ms": 1e-3},
    "angular_speed": {f"{name}/s": factor for name, factor in ANGLE_UNITS.items()},
    "count": {"": 1.0},
}

_PATTERN = re.compile(
    r"^\s*(?P<op>>=|<=|==|>|<)?\s*(?P<number>[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?)\s*"
    r"(?P<unit>[A-Za-z/]*)\s*$"
)


class Comparison(NamedTuple):
    """A parsed expectation: ``measured <op> value``."""

    op: str
    """Comparator, one of :data:`COMPARATORS`."""
    value: float
    """Expected value, in SI units (m, s, rad/s) or a count."""
    text: str
    """The expectation as the scenario wrote it (for messages)."""

    def holds(self, measured: float) -> bool:
        """Whether ``measured`` (SI units) satisfies the comparison."""
        return bool(COMPARATORS[self.op](measured, self.value))


def parse_comparison(
    text: str | float, quantity: str, default_unit: str, default_op: str | None = None
) -> Comparison:
    """Parse ``"<op> <number> [unit]"`` (or a bare number when ``default_op`` is given).

    Args:
        text: The expectation, e.g. ``">= 0.2 in"``, or a number.
        quantity: ``"length"``, ``"time"``, ``"angular_speed"`` or ``"count"``.
        default_unit: Unit of a number written without one (the scenario's unit).
        default_op: Comparator of a bare number (None: a comparator is required).

    Raises:
        ValueError: with a message naming the valid comparators or units.
    """
    units = QUANTITY_UNITS[quantity]
    if isinstance(text, bool):
        raise ValueError(f"expected a comparison such as '>= 1.5', got {text!r}")
    if isinstance(text, (int, float)):
        text = str(text)
    match = _PATTERN.match(text)
    if match is None:
        raise ValueError(
            f"{text!r} is not a comparison '<op> <number> [unit]' "
            f"(op one of {', '.join(COMPARATORS)}; e.g. '>= 0.2 in')"
        )
    op = match["op"] or default_op
    if op is None:
        raise ValueError(f"{text!r} needs a comparator ({', '.join(COMPARATORS)})")
    unit = match["unit"] or default_unit
    if unit not in units:
        valid = ", ".join(repr(u) for u in units)
        raise ValueError(f"unknown unit {unit!r} in {text!r}; valid units: {valid}")
    value = float(match["number"]) * units[unit]
    if not math.isfinite(value):
        raise ValueError(f"{text!r}: the number must be finite")
    return Comparison(op, value, text.strip())
