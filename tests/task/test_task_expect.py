"""Expectation strings: comparator + number + unit, converted to SI."""

from __future__ import annotations

import math

import pytest

from lynxplan.task.expect import parse_comparison
from lynxplan.units import INCH


def test_clearance_in_inches():
    comparison = parse_comparison(">= 0.2 in", "length", "m")
    assert comparison.op == ">="
    assert comparison.value == pytest.approx(0.2 * INCH, rel=1e-15)
    assert comparison.holds(0.2 * INCH)
    assert not comparison.holds(0.2 * INCH - 1e-9)


@pytest.mark.parametrize(
    ("text", "quantity", "default_unit", "default_op", "op", "value"),
    [
        ("<= 26 s", "time", "s", None, "<=", 26.0),
        ("< 300 ms", "time", "s", None, "<", 0.3),
        ("<= 90 deg/s", "angular_speed", "rad/s", None, "<=", math.pi / 2),
        ("==13", "count", "", None, "==", 13.0),
        ("1e-3", "length", "mm", "<=", "<=", 1e-6),
        (0.5, "length", "in", ">=", ">=", 0.5 * INCH),
        ("> -2.5 mm", "length", "in", None, ">", -2.5e-3),
    ],
)
def test_forms(text, quantity, default_unit, default_op, op, value):
    comparison = parse_comparison(text, quantity, default_unit, default_op)
    assert comparison.op == op
    assert comparison.value == pytest.approx(value, rel=1e-12)


def test_equality_tolerates_rounding_only():
    comparison = parse_comparison("== 26 s", "time", "s")
    assert comparison.holds(26.0 + 1e-12)
    assert not comparison.holds(26.001)


@pytest.mark.parametrize(
    ("text", "quantity", "default_op", "message"),
    [
        (">= 0.2 ft", "length", None, r"unknown unit 'ft' in '>= 0.2 ft'; valid units: 'm', 'mm'"),
        ("0.2 in", "length", None, r"'0.2 in' needs a comparator"),
        ("at least 3", "length", ">=", r"not a comparison '<op> <number> \[unit\]'"),
        (">= nan", "length", None, "not a comparison"),
        (">= 1e999 m", "length", None, "must be finite"),
        (True, "count", "<=", "expected a comparison"),
        ("<= 3 rad", "angular_speed", None, r"unknown unit 'rad'.*'rad/s', 'deg/s'"),
    ],
)
def test_errors(text, quantity, default_op, message):
    with pytest.raises(ValueError, match=message):
        parse_comparison(text, quantity, "m" if quantity == "length" else "", default_op)
