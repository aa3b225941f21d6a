"""The one ``expect:`` parser: every scenario kind's expectations, checked against its metrics.

An ``expect:`` entry names a metric of the kind (``min_clearance``) or a metric behind a
``max_``/``min_`` prefix (``max_duration`` checks ``duration``), and gives

- ``true`` / ``false`` for a boolean metric;
- a comparison ``"<op> <number> [unit]"`` with ``op`` one of ``>=, <=, >, <, ==``, e.g.
  ``">= 0.2 in"``, ``"<= 5 mm"``, ``"<= 0.1 deg"``, ``"< 90 deg/s"``, ``"== 13"``; ``==`` takes an
  optional tolerance, ``"== 0.26 in +- 0.01 in"``. A bare number is allowed for ``max_*`` (``<=``)
  and ``min_*`` (``>=``) keys. A number without a unit is in the file's unit of that quantity
  (``units:`` block; ``s`` for times). A metric holding several values passes when every value
  does;
- a list of names for a ``flags`` metric: each named flag must be true;
- ``{equals: <number or nested list>, tolerance: <number>}``: element-wise equality within the
  tolerance, both in the file's unit of the quantity.

Parsing happens during validation (it computes nothing); :func:`evaluate` runs after the kind.
"""

from __future__ import annotations

import math
import operator
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from lynxplan.scenarios.quantities import QUANTITY_UNITS, Quantity, Units, default_unit

#: Comparator text -> function (measured, expected) -> bool.
COMPARATORS: dict[str, Callable[[float, float], bool]] = {
    ">=": operator.ge,
    "<=": operator.le,
    ">": operator.gt,
    "<": operator.lt,
    "==": lambda measured, expected: math.isclose(measured, expected, rel_tol=1e-9, abs_tol=1e-12),
}

_NUMBER = r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?"
_PATTERN = re.compile(
    rf"^\s*(?P<op>>=|<=|==|>|<)?\s*(?P<number>{_NUMBER})\s*(?P<unit>[A-Za-z/^%23]*)\s*"
    rf"(\+-|±)?\s*(?P<tol>{_NUMBER})?\s*(?P<tolunit>[A-Za-z/^%23]*)\s*$"
)


@dataclass(frozen=True)
class ExpectationResult:
    """One ``expect:`` entry checked against a metric.

    Attributes:
        name: The key as written in ``expect:``.
        wanted: The expectation as written (e.g. ``">= 0.2 in"``).
        got: The measured value, in SI units (None for a value that is not a number).
        passed: Whether it held.
        message: A line saying what was measured against what was wanted.
    """

    name: str
    wanted: Any
    got: Any
    passed: bool
    message: str


@dataclass(frozen=True)
class ParsedExpectation:
    """One ``expect:`` entry, parsed.

    Attributes:
        key: The key as written.
        metric: The metric it checks.
        quantity: The metric's quantity.
        mode: ``"bool"``, ``"compare"``, ``"flags"`` or ``"equals"``.
        op: Comparator (``compare`` and ``equals``).
        value: Wanted value in SI units (bool, float, list of names, or an array).
        tolerance: Absolute tolerance in SI units (``==`` / ``equals``), or None.
        text: The entry as written, for messages and the report.
    """

    key: str
    metric: str
    quantity: Quantity
    mode: str
    op: str
    value: Any
    tolerance: float | None
    text: Any


def _short(value: Any, width: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= width else text[: width - 3] + "..."


def _factor(unit: str, quantity: str, units: Units, text: Any) -> float:
    table = QUANTITY_UNITS[quantity]
    unit = unit or default_unit(quantity, units)
    if unit not in table:
        valid = ", ".join(repr(u) for u in table) or "none"
        raise ValueError(f"unknown unit {unit!r} in {text!r} (a {quantity}); valid units: {valid}")
    return table[unit]


_PREFIXES = ("max_", "min_")


def _resolve(key: str, metrics: Mapping[str, Quantity]) -> tuple[str, str | None]:
    """(metric name, default comparator) of an ``expect:`` key."""
    prefix_op = {"max_": "<=", "min_": ">="}.get(key[:4])
    if key in metrics:
        return key, prefix_op
    if prefix_op is not None and key[4:] in metrics:
        return key[4:], prefix_op
    numeric = [
        m for m, q in metrics.items() if q not in ("bool", "flags") and m[:4] not in _PREFIXES
    ]
    valid = sorted({*metrics, *(f"max_{m}" for m in numeric), *(f"min_{m}" for m in numeric)})
    shown = ", ".join(valid) if valid else "none (this kind measures no metric)"
    raise ValueError(f"unknown expectation {key!r}; valid: {shown}")


def parse_comparison(
    text: Any, quantity: str, units: Units, default_op: str | None
) -> tuple[str, float, float | None]:
    """``"<op> <number> [unit] [+- tol [unit]]"`` -> (op, value in SI, tolerance in SI or None).

    Raises:
        ValueError: naming the comparators or units allowed.
    """
    if isinstance(text, bool) or not isinstance(text, (str, int, float)):
        raise ValueError(f"expected a comparison such as '>= 1.5', got {_short(text)}")
    match = _PATTERN.match(str(text))
    if match is None:
        raise ValueError(
            f"{text!r} is not a comparison '<op> <number> [unit]' "
            f"(op one of {', '.join(COMPARATORS)}; e.g. '>= 0.2 in')"
        )
    op = match["op"] or default_op
    if op is None:
        raise ValueError(f"{text!r} needs a comparator ({', '.join(COMPARATORS)})")
    value = float(match["number"]) * _factor(match["unit"], quantity, units, text)
    tolerance = None
    if match["tol"] is not None:
        if op != "==":
            raise ValueError(f"{text!r}: a tolerance (+-) goes with '==' only")
        tolunit = match["tolunit"] or match["unit"]
        tolerance = abs(float(match["tol"])) * _factor(tolunit, quantity, units, text)
    if not math.isfinite(value) or (tolerance is not None and not math.isfinite(tolerance)):
        raise ValueError(f"{text!r}: the numbers must be finite")
    return op, value, tolerance


def parse_expectation(
    key: str, text: Any, metrics: Mapping[str, Quantity], units: Units
) -> ParsedExpectation:
    """Parse one ``expect:`` entry against the kind's declared metrics.

    Raises:
        ValueError: a message naming what is allowed.
    """
    metric, default_op = _resolve(key, metrics)
    quantity = metrics[metric]
    if quantity == "bool":
        if not isinstance(text, bool):
            raise ValueError(f"{key} takes true or false, got {_short(text)}")
        return ParsedExpectation(key, metric, quantity, "bool", "==", text, None, text)
    if quantity == "flags":
        if not (isinstance(text, list) and all(isinstance(n, str) for n in text)):
            raise ValueError(f"{key} takes a list of names, got {_short(text)}")
        return ParsedExpectation(key, metric, quantity, "flags", "==", tuple(text), None, text)
    if isinstance(text, Mapping):
        return _parse_equals(key, metric, quantity, text, units)
    op, value, tolerance = parse_comparison(text, quantity, units, default_op)
    return ParsedExpectation(key, metric, quantity, "compare", op, value, tolerance, text)


def _parse_equals(
    key: str, metric: str, quantity: Quantity, text: Mapping[str, Any], units: Units
) -> ParsedExpectation:
    if set(text) - {"equals", "tolerance"} or "equals" not in text:
        raise ValueError(
            f"{key} takes {{equals: value, tolerance: number}}, got {_short(dict(text))}"
        )
    factor = _factor("", quantity, units, text)
    try:
        wanted = np.asarray(text["equals"], dtype=float) * factor
        tolerance = float(text.get("tolerance", 0.0)) * factor
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{key}.equals must be a number or nested lists of numbers") from exc
    if not (np.all(np.isfinite(wanted)) and math.isfinite(tolerance) and tolerance >= 0):
        raise ValueError(f"{key}: values must be finite and the tolerance >= 0")
    return ParsedExpectation(key, metric, quantity, "equals", "==", wanted, tolerance, dict(text))


def parse_expectations(
    expect: Mapping[str, Any], metrics: Mapping[str, Quantity], units: Units
) -> list[ParsedExpectation]:
    """Parse a whole ``expect:`` block.

    Raises:
        pydantic.ValidationError: located at ``expect.<key>``.
    """
    from pydantic import ValidationError
    from pydantic_core import InitErrorDetails, PydanticCustomError

    parsed = []
    for key, text in expect.items():
        try:
            parsed.append(parse_expectation(str(key), text, metrics, units))
        except ValueError as exc:
            error = PydanticCustomError("expectation", str(exc))
            raise ValidationError.from_exception_data(
                "expect", [InitErrorDetails(type=error, loc=("expect", str(key)), input=text)]
            ) from None
    return parsed


def _display(value: Any, quantity: str, units: Units) -> str:
    """A measured value in the file's unit of its quantity, e.g. ``0.2627 in``."""
    unit = default_unit(quantity, units)
    factor = QUANTITY_UNITS.get(quantity, {}).get(unit, 1.0)
    array = np.asarray(value, dtype=float) / factor
    text = (
        f"{float(array):.6g}"
        if array.ndim == 0
        else np.array2string(array, precision=6, threshold=20, separator=", ")
    )
    return f"{text} {unit}".rstrip()


def evaluate(parsed: ParsedExpectation, got: Any, units: Units | None = None) -> ExpectationResult:
    """Check one parsed expectation against the measured metric value (SI units).

    ``units`` (the file's) only changes how values are shown in the message.
    """
    units = units or Units()
    key, text = parsed.key, parsed.text
    if parsed.mode == "bool":
        passed = bool(got) == parsed.value
        message = f"{key}: expected {parsed.value}, measured {bool(got)}"
        return ExpectationResult(key, text, bool(got), passed, message)
    if parsed.mode == "flags":
        flags = dict(got)
        missing = [n for n in parsed.value if n not in flags]
        false = [n for n in parsed.value if n in flags and not flags[n]]
        passed = not missing and not false
        problems = ([f"unknown {missing} (valid: {sorted(flags)})"] if missing else []) + (
            [f"false for {false}"] if false else []
        )
        message = f"{key}: " + ("all true" if passed else "; ".join(problems))
        return ExpectationResult(key, list(text), flags, passed, message)
    values = np.asarray(got, dtype=float)
    if parsed.mode == "equals":
        return _evaluate_equals(parsed, values, got, units)
    if parsed.tolerance is not None:
        passed = bool(np.all(np.abs(values - parsed.value) <= parsed.tolerance))
    else:
        compare = COMPARATORS[parsed.op]
        passed = bool(values.size > 0 and all(compare(float(v), parsed.value) for v in values.flat))
    message = f"{key}: measured {_display(got, parsed.quantity, units)}, expected {text}"
    return ExpectationResult(key, text, got, passed, message)


def _evaluate_equals(
    parsed: ParsedExpectation, values: np.ndarray, got: Any, units: Units
) -> ExpectationResult:
    key, text, wanted = parsed.key, parsed.text, parsed.value
    if values.shape != wanted.shape:
        message = f"{key}: measured shape {values.shape}, expected {wanted.shape}"
        return ExpectationResult(key, text, got, False, message)
    error = np.abs(values - wanted)
    tolerance = parsed.tolerance or 0.0
    passed = bool(np.all(error <= tolerance))
    if passed:
        message = f"{key}: every value within {_display(tolerance, parsed.quantity, units)}"
    else:
        row = int(np.unravel_index(int(np.argmax(error)), error.shape)[0]) if error.ndim else 0
        measured, expected = (values[row], wanted[row]) if error.ndim else (values, wanted)
        message = (
            f"{key}[{row}]: measured {_display(measured, parsed.quantity, units)}, expected "
            f"{_display(expected, parsed.quantity, units)} within "
            f"{_display(tolerance, parsed.quantity, units)}"
        )
    return ExpectationResult(key, text, got, passed, message)
