"""Valid ranges of scalar inputs: angles, lengths, durations, rates, tolerances, counts, seeds
(finite, within the bounds below, in SI units)."""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import replace
from typing import Any

import numpy as np

from lynxplan.exceptions import InputError, NonFiniteInputError, OutOfRangeError, ResourceLimitError
from lynxplan.guards.limits import ResourceLimits, check_size, current_limits, limits_in_force

#: Largest accepted |angle|, in [rad]. Larger values are errors, not wrapped: nobody means 1e19 rad.
MAX_ABS_ANGLE = 100.0
#: Largest accepted |length| or |coordinate|, in [m].
MAX_ABS_LENGTH = 1000.0
#: Longest accepted duration, in [s].
MAX_DURATION = 86_400.0
#: Highest accepted sample rate, in [Hz].
MAX_SAMPLE_RATE = 1e6
#: Seeds are integers in ``[0, MAX_SEED)``.
MAX_SEED = 2**63


def real(name: str, value: Any) -> float:
    """``value`` as a finite float; InputError naming ``name`` otherwise (bools are refused)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Real, np.number)):
        if isinstance(value, str):
            try:
                value = float(value)
            except ValueError:
                raise InputError(f"{name}: {value!r} is not a number") from None
        else:
            raise InputError(f"{name} must be a number. Got: {type(value).__name__} {value!r:.60}")
    try:
        result = float(value)
    except (OverflowError, ValueError):  # e.g. an int beyond the float range
        raise OutOfRangeError(name, value, "a finite number") from None
    if not math.isfinite(result):
        raise NonFiniteInputError(name, f"{name} = {result}")
    return result


def in_range(
    name: str, value: Any, low: float, high: float, unit: str = "", *, low_open: bool = False
) -> float:
    """Finite ``value`` with ``low <= value <= high`` (``low < value`` if ``low_open``)."""
    x = real(name, value)
    if x > high or x < low or (low_open and x == low):
        op = "<" if low_open else "<="
        u = f" {unit}" if unit else ""
        raise OutOfRangeError(name, x, f"finite, {low:g}{u} {op} {name} <= {high:g}{u}")
    return x


def angle(name: str, value: Any) -> float:
    """A finite angle with ``|value| <=`` :data:`MAX_ABS_ANGLE`, in [rad]."""
    return in_range(name, value, -MAX_ABS_ANGLE, MAX_ABS_ANGLE, "rad")


def angle_deg(name: str, value: Any) -> float:
    """A finite angle in degrees within :data:`MAX_ABS_ANGLE` (about 5730 deg); returns degrees."""
    bound = math.degrees(MAX_ABS_ANGLE)
    return in_range(name, value, -bound, bound, "deg")


def length(name: str, value: Any, unit_scale: float = 1.0, unit: str = "m") -> float:
    """A finite coordinate, ``|value * unit_scale| <=`` :data:`MAX_ABS_LENGTH`; returns value."""
    bound = MAX_ABS_LENGTH / unit_scale
    return in_range(name, value, -bound, bound, unit)


def positive(name: str, value: Any, unit: str = "", high: float = math.inf) -> float:
    """A finite value ``> 0`` (and ``<= high``)."""
    if math.isinf(high):
        x = real(name, value)
        if x <= 0:
            u = f" {unit}" if unit else ""
            raise OutOfRangeError(name, x, f"a finite number > 0{u}")
        return x
    return in_range(name, value, 0.0, high, unit, low_open=True)


def positive_length(name: str, value: Any, unit_scale: float = 1.0, unit: str = "m") -> float:
    """A size, step or cell: finite, ``0 < value * unit_scale <=`` :data:`MAX_ABS_LENGTH`."""
    return positive(name, value, unit, MAX_ABS_LENGTH / unit_scale)


def duration(name: str, value: Any) -> float:
    """A duration: finite, ``0 < t <=`` :data:`MAX_DURATION`, in [s]."""
    return positive(name, value, "s", MAX_DURATION)


def sample_rate(name: str, value: Any) -> float:
    """A sample rate: finite, ``0 < rate <=`` :data:`MAX_SAMPLE_RATE`, in [Hz]."""
    return positive(name, value, "Hz", MAX_SAMPLE_RATE)


def tolerance(name: str, value: Any, unit: str = "") -> float:
    """A tolerance: finite and ``>= 0`` (NaN would silently disable the check it bounds)."""
    x = real(name, value)
    if x < 0:
        raise OutOfRangeError(name, x, f"a finite number >= 0{' ' + unit if unit else ''}")
    return x


def count(name: str, value: Any, *, minimum: int = 1, limit: int | None = -1) -> int:
    """An integer count ``>= minimum``; ``limit=-1`` checks it against ``max_samples``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Integral, float)):
        raise InputError(f"{name} must be an integer. Got: {value!r:.60}")
    if isinstance(value, float) and not (math.isfinite(value) and value.is_integer()):
        raise InputError(f"{name} must be an integer. Got: {value!r}")
    n = int(value)
    if n < minimum:
        raise OutOfRangeError(name, n, f"an integer >= {minimum}")
    if limit == -1:
        check_size(name, n)
    elif limit is not None and n > limit:
        raise OutOfRangeError(name, n, f"an integer <= {limit}")
    return n


def seed(name: str, value: Any) -> int:
    """A random seed: an integer with ``0 <= seed <`` :data:`MAX_SEED`."""
    n = count(name, value, minimum=0, limit=None)
    if n >= MAX_SEED:
        raise OutOfRangeError(name, n, f"an integer with 0 <= {name} < 2**63")
    return n


# The limits' own inputs are scalars, checked here (guards.limits, below, holds the limits).


@contextmanager
def raised_limits(
    max_samples: int | None = None, max_planning_time: float | None = None
) -> Iterator[ResourceLimits]:
    """Change the resource limits inside a ``with`` block (values are checked first)."""
    changes: dict[str, Any] = {}
    if max_samples is not None:
        changes["max_samples"] = count("max_samples", max_samples, minimum=1, limit=None)
    if max_planning_time is not None:
        changes["max_planning_time"] = positive("max_planning_time", max_planning_time, "s")
    with limits_in_force(replace(current_limits(), **changes)) as limits:
        yield limits


def planning_time(name: str, value: Any) -> float:
    """A planning time limit: ``0 < t <= max_planning_time``, in [s]."""
    x = positive(name, value, "s")
    limit = current_limits().max_planning_time
    if x > limit:
        raise ResourceLimitError(
            f"{name} (planning time in s)",
            x,
            limit,
            "raise it with raised_limits(max_planning_time=S) in Python",
        )
    return x
