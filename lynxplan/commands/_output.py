"""Shared helpers for sub-commands: JSON output, number parsing and IK branch listings."""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Sequence
from typing import Any, Protocol

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


class _IkBranch(Protocol):
    """What an IK listing reads of one branch (arm and URDF-robot results alike)."""

    @property
    def q(self) -> np.ndarray: ...
    @property
    def branch(self) -> str: ...
    @property
    def within_limits(self) -> bool: ...
    @property
    def orientation_error(self) -> float: ...
    @property
    def position_error(self) -> float: ...


class _IkAnswer(Protocol):
    """What an IK listing reads of a result."""

    @property
    def solutions(self) -> Sequence[_IkBranch]: ...
    @property
    def selected(self) -> int | None: ...
    @property
    def orientation_residual(self) -> float: ...


def ik_branch_rows(
    result: _IkAnswer, *, show_all: bool, angle_scale: float, length_scale: float
) -> tuple[list[dict[str, Any]], int | None]:
    """The branches an ``ik`` command lists (every one, or those within the joint limits).

    Args:
        result: The IK result.
        show_all: List every branch, not only those within limits (``--all``).
        angle_scale: Size of the output angle unit, in [rad].
        length_scale: Size of the output length unit, in [m].

    Returns:
        One JSON-ready row per listed branch (``q`` in the angle unit, ``position_error`` in the
        length unit, ``orientation_error`` in [rad]) and the selected branch's index among the
        rows (None when it is not listed).
    """
    listed = [i for i, s in enumerate(result.solutions) if show_all or s.within_limits]
    rows = [
        {
            "q": (result.solutions[i].q / angle_scale).tolist(),
            "branch": result.solutions[i].branch,
            "within_limits": result.solutions[i].within_limits,
            "position_error": result.solutions[i].position_error / length_scale,
            "orientation_error": result.solutions[i].orientation_error,
        }
        for i in listed
    ]
    selected = listed.index(result.selected) if result.selected in listed else None
    return rows, selected


def print_ik_branches(
    result: _IkAnswer,
    rows: Sequence[dict[str, Any]],
    selected: int | None,
    angle_unit: str,
    branch_width: int,
) -> None:
    """Print the orientation residual and the rows of :func:`ik_branch_rows`, the selected one
    marked ``*``; ``branch_width`` is the width of the branch-name column, in characters."""
    print(f"orientation residual: {result.orientation_residual:.3g} rad")
    if not rows:
        print("no solution within the joint limits (use --all to list every branch)")
    for k, row in enumerate(rows):
        mark = "*" if k == selected else " "
        angles = "  ".join(f"{v:10.4f}" for v in row["q"])
        flag = "" if row["within_limits"] else "  (outside limits)"
        print(f"{mark} {row['branch']:<{branch_width}} {angles} {angle_unit}{flag}")
