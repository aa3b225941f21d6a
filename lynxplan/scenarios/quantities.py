"""The quantities and units of scenario values: the base schema model, a file's ``units:`` block,
each quantity's units with their SI factors (shared by the ``expect:`` parser and the result)."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

from lynxplan.units import ANGLE_UNITS, LENGTH_UNITS

#: Physical quantity of a metric: selects the units an expectation may use.
Quantity = Literal[
    "length",
    "angle",
    "time",
    "angular_speed",
    "area",
    "volume",
    "count",
    "ratio",
    "bool",
    "flags",
]


class StrictModel(BaseModel):
    """Base of every scenario schema: unknown keys are errors, values are frozen, and NaN or
    infinity is refused in every float field (issue 12: a NaN tolerance disables a check)."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class Units(StrictModel):
    """Units in which a scenario states lengths and angles (converted to SI on load)."""

    length: Literal["m", "mm", "in"] = Field("m", description="Length unit of the file.")
    angle: Literal["rad", "deg"] = Field("rad", description="Angle unit of the file.")


_LENGTHS = {**LENGTH_UNITS, "cm": 1e-2}

#: Quantity -> unit name -> SI factor.
QUANTITY_UNITS: dict[str, dict[str, float]] = {
    "length": _LENGTHS,
    "angle": dict(ANGLE_UNITS),
    "time": {"s": 1.0, "ms": 1e-3},
    "angular_speed": {f"{name}/s": factor for name, factor in ANGLE_UNITS.items()},
    "area": {f"{name}^2": factor**2 for name, factor in _LENGTHS.items()},
    "volume": {f"{name}^3": factor**3 for name, factor in _LENGTHS.items()},
    "count": {"": 1.0},
    "ratio": {"": 1.0, "%": 0.01},
}


def default_unit(quantity: str, units: Units) -> str:
    """Unit of a number written without one, from the file's ``units:`` block."""
    return {
        "length": units.length,
        "angle": units.angle,
        "time": "s",
        "angular_speed": f"{units.angle}/s",
        "area": f"{units.length}^2",
        "volume": f"{units.length}^3",
    }.get(quantity, "")
