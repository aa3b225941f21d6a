"""Shared helpers for sub-commands: JSON output and number parsing (IK answers:
:mod:`lynxplan.commands._ik_answer`)."""

from __future__ import annotations

import json
import math
import sys
from typing import Any

import numpy as np

from lynxplan.exceptions import InputError


def to_jsonable(value: Any) -> Any:
    """Numpy arrays/scalars -> nested lists/floats; NaN -> None (JSON has no NaN)."""
    if isinstance(value, np.ndarray):
        return to_jsonable(value.tolist())
    if isinstance(value, np.generic):
        return to_jsonable(value.item())
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_jsonable(v) for v in value]
    return value


def print_json(value: Any) -> None:
    """Write ``value`` as JSON to stdout, followed by a newline."""
    sys.stdout.write(json.dumps(to_jsonable(value), indent=2) + "\n")


#: Longest JSON value accepted on the command line, in characters.
MAX_JSON_ARGUMENT = 100_000


def parse_json_numbers(text: str, name: str, what: str) -> np.ndarray:
    """A JSON nested list of numbers from the command line -> float array.

    Raises:
        InputError: naming ``name`` for text that is too long, not JSON, nested too deeply, or
            not a (rectangular) list of numbers.
    """
    if len(text) > MAX_JSON_ARGUMENT:
        raise InputError(f"{name}: {len(text)} characters, more than {MAX_JSON_ARGUMENT}")
    try:
        value = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"{name}: not {what} ({exc.msg} at character {exc.pos})") from None
    except RecursionError:
        raise InputError(f"{name}: not {what} (JSON nested too deeply)") from None
    from lynxplan import guards

    return guards.float_array(name, value)


def parse_finite(text: str, name: str) -> float:
    """Parse a float command-line value; InputError naming ``name`` if not a finite number."""
    try:
        value = float(text)
    except ValueError:
        raise InputError(f"{name}: {text!r} is not a number") from None
    if not math.isfinite(value):
        raise InputError(f"{name}: {text!r} is not a finite number")
    return value


def parse_pose(text: str, length_unit: str) -> np.ndarray:
    """JSON 4x4 or 3x4 nested list -> (4, 4) pose in [m], checked by :func:`guards.poses`.

    Args:
        text: The ``--pose`` value.
        length_unit: Unit of its translation (``m``, ``mm``, ``in``).
    """
    from lynxplan import guards
    from lynxplan.exceptions import ShapeError
    from lynxplan.units import length_factor

    pose = parse_json_numbers(text, "--pose", "a JSON 4x4 (or 3x4) nested list of numbers")
    if pose.shape == (3, 4):
        pose = np.vstack([pose, [0.0, 0.0, 0.0, 1.0]])
    if pose.shape != (4, 4):
        raise ShapeError("--pose", "(4, 4) or (3, 4)", pose.shape)
    guards.finite_array("--pose", pose)
    pose[:3, 3] *= length_factor(length_unit)
    return guards.poses("--pose", pose, batch=False)


def check_joint_limits(
    q: np.ndarray,
    names: tuple[str, ...],
    lower: np.ndarray,
    upper: np.ndarray,
    angle_unit: str,
) -> None:
    """Joint angles beyond a joint's limits are an error (``fk``: 90 taken as radians is a
    typo, not a pose), naming the joint, its value and limits in ``angle_unit``, and suggesting
    ``--deg`` where the values read as degrees would be within the limits.

    Args:
        q: Joint angles, shape (n,), in [rad].
        names: Joint names (the argument is ``q<i> (joint <name>)``).
        lower, upper: Position limits, shape (n,), in [rad]; a value this close to a limit
            (``LIMIT_SNAP_TOLERANCE``) counts as on it.
        angle_unit: Unit the user gave the angles in (``rad`` or ``deg``).

    Raises:
        OutOfRangeError: naming the first joint beyond its limits.
    """
    from lynxplan.constants import LIMIT_SNAP_TOLERANCE
    from lynxplan.exceptions import OutOfRangeError

    slack = LIMIT_SNAP_TOLERANCE
    outside = (q < lower - slack) | (q > upper + slack)
    if not outside.any():
        return
    scale = math.pi / 180.0 if angle_unit == "deg" else 1.0
    j = int(np.flatnonzero(outside)[0])
    given = q / scale
    hint = ""
    as_degrees = np.radians(given)
    if angle_unit == "rad" and bool(
        np.all((as_degrees >= lower - slack) & (as_degrees <= upper + slack))
    ):
        hint = "; the values look like degrees: add --deg"
    elif angle_unit == "rad" and float(np.abs(given).max()) > 2 * math.pi:
        hint = "; angles are in rad unless --deg is given"
    label = f"q{j + 1}" if names[j] == f"q{j + 1}" else f"q{j + 1} (joint {names[j]})"
    raise OutOfRangeError(
        label,
        float(given[j]),
        f"within the joint's limits [{lower[j] / scale:.6g}, {upper[j] / scale:.6g}] "
        f"{angle_unit}{hint} (--ignore-limits computes the pose anyway)",
    )
