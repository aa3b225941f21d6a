"""The one expect: parser: comparisons with units, booleans, flags, equality with tolerance."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lynxplan.scenarios.base import Units
from lynxplan.scenarios.expect import evaluate, parse_comparison, parse_expectation
from lynxplan.units import INCH

METRICS = {
    "min_clearance": "length",
    "duration": "time",
    "joint_speed": "angular_speed",
    "contacts": "count",
    "collision_free": "bool",
    "within_speed_limits": "flags",
    "solutions": "angle",
    "volume": "volume",
    "area": "area",
}
INCH_DEG = Units(length="in", angle="deg")


def _check(key, text, got, units=INCH_DEG):
    return evaluate(parse_expectation(key, text, METRICS, units), got, units)


def test_clearance_in_inches():
    parsed = parse_expectation("min_clearance", ">= 0.2 in", METRICS, Units())
    assert (parsed.metric, parsed.op) == ("min_clearance", ">=")
    assert parsed.value == pytest.approx(0.2 * INCH, rel=1e-15)
    assert _check("min_clearance", ">= 0.2 in", 0.2 * INCH).passed
    assert not _check("min_clearance", ">= 0.2 in", 0.2 * INCH - 1e-9).passed


@pytest.mark.parametrize(
    ("text", "quantity", "units", "default_op", "op", "value"),
    [
        ("<= 26 s", "time", Units(), None, "<=", 26.0),
        ("< 300 ms", "time", Units(), None, "<", 0.3),
        ("<= 90 deg/s", "angular_speed", Units(), None, "<=", math.pi / 2),
        ("==13", "count", Units(), None, "==", 13.0),
        ("1e-3", "length", Units(length="mm"), "<=", "<=", 1e-6),
        (0.5, "length", INCH_DEG, ">=", ">=", 0.5 * INCH),
        ("> -2.5 mm", "length", INCH_DEG, None, ">", -2.5e-3),
        ("<= 0.1 deg", "angle", Units(), None, "<=", math.radians(0.1)),
        ("<= 5 mm", "length", INCH_DEG, None, "<=", 5e-3),
        (9000, "volume", INCH_DEG, ">=", ">=", 9000 * INCH**3),
        ("<= 7 mm^2", "area", Units(), None, "<=", 7e-6),
    ],
)
def test_forms(text, quantity, units, default_op, op, value):
    got_op, got_value, tolerance = parse_comparison(text, quantity, units, default_op)
    assert got_op == op
    assert got_value == pytest.approx(value, rel=1e-12)
    assert tolerance is None


def test_prefixes_resolve_to_metrics_with_their_direction():
    parsed = parse_expectation("max_duration", "26", METRICS, Units())
    assert (parsed.metric, parsed.op, parsed.value) == ("duration", "<=", 26.0)
    parsed = parse_expectation("min_volume", 9000, METRICS, INCH_DEG)
    assert (parsed.metric, parsed.op) == ("volume", ">=")
    assert parsed.value == pytest.approx(9000 * INCH**3)


def test_equality_tolerates_rounding_only_or_the_given_tolerance():
    assert _check("duration", "== 26 s", 26.0 + 1e-12).passed
    assert not _check("duration", "== 26 s", 26.001).passed
    assert _check("min_clearance", "== 0.26 in +- 0.01 in", 0.265 * INCH).passed
    assert not _check("min_clearance", "== 0.26 in +- 0.01 in", 0.275 * INCH).passed


def test_booleans_flags_and_arrays():
    assert _check("collision_free", True, True).passed
    failed = _check("collision_free", True, False)
    assert not failed.passed
    assert failed.message == "collision_free: expected True, measured False"
    flags = {"pinv": False, "dls": True, "tr": True}
    assert _check("within_speed_limits", ["dls", "tr"], flags).passed
    failed = _check("within_speed_limits", ["pinv", "nope"], flags)
    assert not failed.passed
    assert "unknown ['nope']" in failed.message
    assert "false for ['pinv']" in failed.message
    assert _check("max_area", 70000, [58406e-6, 63121e-6], Units(length="mm")).passed
    assert not _check("max_area", 60000, [58406e-6, 63121e-6], Units(length="mm")).passed
    assert not _check("min_clearance", ">= 0", [], Units()).passed  # nothing measured


def test_equals_with_tolerance_names_the_worst_row():
    want = [[10.0, 20.0], [30.0, 40.0]]
    got = np.radians([[10.0, 20.0], [30.0, 40.01]])
    spec = {"equals": want, "tolerance": 0.02}
    assert _check("solutions", spec, got).passed
    failed = _check("solutions", {"equals": want, "tolerance": 1e-3}, got)
    assert not failed.passed
    assert failed.message.startswith("solutions[1]: measured [30.  , 40.01] deg")
    assert not _check("solutions", {"equals": [[1.0, 2.0]], "tolerance": 1.0}, got).passed


@pytest.mark.parametrize(
    ("key", "text", "message"),
    [
        ("min_clearance", ">= 0.2 ft", r"unknown unit 'ft' in '>= 0.2 ft' \(a length\)"),
        ("duration", "2 s", r"'2 s' needs a comparator"),
        ("min_clearance", "at least 3", r"not a comparison '<op> <number> \[unit\]'"),
        ("min_clearance", ">= nan", "not a comparison"),
        ("min_clearance", ">= 1e999 m", "must be finite"),
        ("contacts", True, "expected a comparison"),
        ("joint_speed", "<= 3 rad", r"unknown unit 'rad'.*'rad/s', 'deg/s'"),
        ("min_clearance", ">= 1 in +- 0.1 in", r"tolerance \(\+-\) goes with '==' only"),
        ("colour", "red", r"unknown expectation 'colour'; valid: area, collision_free, contacts"),
        ("collision_free", "yes", "takes true or false"),
        ("within_speed_limits", "dls", "takes a list of names"),
        ("solutions", {"equals": "x"}, "must be a number or nested lists"),
        ("solutions", {"value": 1}, r"takes \{equals: value, tolerance: number\}"),
        ("solutions", {"equals": 1, "tolerance": float("nan")}, "finite"),
    ],
)
def test_errors(key, text, message):
    with pytest.raises(ValueError, match=message):
        parse_expectation(key, text, METRICS, Units())
