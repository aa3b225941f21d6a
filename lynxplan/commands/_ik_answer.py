"""The answer of ``lynxplan ik`` for the AL5 and for any robot: the branches it lists, the one
selected, and, when there is no solution, why (a contract that scripts read).

Top-level JSON fields built here:

- ``status``: ``"ok"`` (a branch within the joint limits reaches the target: ``selected``),
  ``"unreachable"`` (the target is out of reach; the branches listed miss it by ``distance``) or
  ``"no_solution_within_limits"`` (every branch breaks a joint limit; each row's
  ``violations`` names the joints, their values and the limits).
- ``message``: one line saying why when ``status`` is not ``"ok"``, else null.
- ``selected``: index in ``solutions`` of the chosen branch; null unless ``status`` is ``"ok"``.
- ``nearest``: index of the branch that comes nearest when there is no solution (the nearest
  within the limits, else the one breaking them least); null when ``status`` is ``"ok"``.
- ``orientation_residual`` [rad], ``position_error`` [length unit]: of the selected branch
  (null when none is selected): every top-level figure describes the selected branch.
- ``reachable``, ``distance``: whether the target position is reached, and by how much the
  nearest branch misses it [length unit].

With ``--strict`` a status other than ``"ok"``, or a selected branch whose orientation error
exceeds the tolerance, is an error (exit 2, one line naming why).
"""

from __future__ import annotations

import math
import sys
from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np

from lynxplan.branches import IkResult
from lynxplan.units import angle_factor, length_factor


class JointTable(NamedTuple):
    """The joints an answer names in its limit violations."""

    names: tuple[str, ...]
    """Joint names, in q order."""
    lower: np.ndarray
    """Lower position limits, shape (n,), in [rad]."""
    upper: np.ndarray
    """Upper position limits, shape (n,), in [rad]."""


class Units(NamedTuple):
    """The units an answer is written in."""

    angle: str
    """``rad`` or ``deg``."""
    length: str
    """``m``, ``mm`` or ``in``."""


def violations(q: np.ndarray, joints: JointTable, angle_unit: str) -> list[dict[str, Any]]:
    """The joint limits q (n,) [rad] breaks: joint, value, the limit broken and its side
    (``lower``/``upper``), values in ``angle_unit``."""
    scale = angle_factor(angle_unit)
    found = []
    for name, value, low, high in zip(
        joints.names, q.tolist(), joints.lower.tolist(), joints.upper.tolist(), strict=True
    ):
        if value < low or value > high:
            side, limit = ("lower", low) if value < low else ("upper", high)
            found.append(
                {"joint": name, "value": value / scale, "limit": limit / scale, "side": side}
            )
    return found


def describe_violations(found: Sequence[dict[str, Any]], angle_unit: str) -> str:
    """``wrist_flex = 99.17 deg > upper limit 95 deg`` for each violation, comma-separated."""

    def text(value: float) -> str:
        if angle_unit == "deg":
            return f"{value:.4g} deg"
        return f"{value:.4g} rad ({math.degrees(value):.4g} deg)"

    return ", ".join(
        f"{v['joint']} = {text(v['value'])} "
        f"{'>' if v['side'] == 'upper' else '<'} {v['side']} limit {text(v['limit'])}"
        for v in found
    )


def _excess(q: np.ndarray, joints: JointTable) -> float:
    """Sum over the joints of how far q (n,) [rad] is outside its limits, in [rad]."""
    return float((np.maximum(joints.lower - q, 0.0) + np.maximum(q - joints.upper, 0.0)).sum())


def ik_answer(
    result: IkResult,
    joints: JointTable,
    units: Units,
    *,
    show_all: bool,
    reachable: bool = True,
    distance: float = 0.0,
) -> dict[str, Any]:
    """The JSON-ready answer of an IK result (see the module docstring).

    Args:
        result: The IK result (``lynxplan.arm.IkResult`` or ``lynxplan.robots.RobotIkResult``).
        joints: Names and limits of the joints (for the violations).
        units: Units of the answer (``q`` and limits in the angle unit, position errors and
            ``distance`` in the length unit; orientation errors always in [rad]).
        show_all: List every branch (``--all``); otherwise those within the limits, or every
            branch when none is within them.
        reachable: Whether the target position is reached.
        distance: By how much the nearest branch misses the target, in [m].
    """
    scale, length = angle_factor(units.angle), length_factor(units.length)
    branches = result.solutions
    any_within = any(s.within_limits for s in branches)
    listed = [i for i, s in enumerate(branches) if show_all or s.within_limits or not any_within]
    rows = [
        {
            "q": (branches[i].q / scale).tolist(),
            "branch": branches[i].branch,
            "within_limits": branches[i].within_limits,
            "violations": []
            if branches[i].within_limits
            else violations(branches[i].q, joints, units.angle),
            "position_error": branches[i].position_error / length,
            "orientation_error": branches[i].orientation_error,
        }
        for i in listed
    ]
    ok = reachable and result.selected is not None and result.selected in listed
    selected = listed.index(result.selected) if ok and result.selected is not None else None
    nearest = None if ok else _nearest(result, listed, joints)
    status, message = _status(rows, nearest, units, reachable, distance / length)
    chosen = rows[selected] if selected is not None else None
    return {
        "status": status,
        "message": message,
        "reachable": reachable,
        "distance": (chosen["position_error"] if chosen else distance / length),
        "solutions": rows,
        "selected": selected,
        "nearest": nearest,
        # branches not listed (outside the joint limits; --all lists them)
        "outside_limits_not_listed": len(branches) - len(rows),
        "orientation_residual": chosen["orientation_error"] if chosen else None,
        "position_error": chosen["position_error"] if chosen else None,
    }


def _nearest(result: IkResult, listed: list[int], joints: JointTable) -> int | None:
    """Row index of the branch that comes nearest: the result's pick (within the limits,
    nearest the target), else the listed branch breaking the limits least."""
    if not listed:
        return None
    if result.selected is not None and result.selected in listed:
        return listed.index(result.selected)
    excess = [_excess(result.solutions[i].q, joints) for i in listed]
    return int(np.argmin(excess))


def _status(
    rows: list[dict[str, Any]],
    nearest: int | None,
    units: Units,
    reachable: bool,
    distance: float,
) -> tuple[str, str | None]:
    """The answer's status and its one-line message (None when ``ok``); ``distance`` in the
    length unit."""
    if not reachable:
        return "unreachable", (
            f"target out of reach: the nearest IK branch misses it by {distance:.4g} {units.length}"
        )
    if nearest is None:
        return "ok", None
    row = rows[nearest]
    return "no_solution_within_limits", (
        f"no IK branch within the joint limits ({len(rows)} branches); the nearest, "
        f"{row['branch']}, breaks {describe_violations(row['violations'], units.angle)}"
    )


def check_strict(answer: dict[str, Any], tolerance: float, units: Units) -> None:
    """``--strict``: raise unless a branch within the limits reaches the target and its
    orientation error is within ``tolerance`` [rad].

    Raises:
        UnreachablePoseError: the target is out of reach.
        NoSolutionWithinLimitsError: every branch breaks a joint limit.
        OrientationNotReachableError: the selected branch misses the orientation.
    """
    from lynxplan.exceptions import (
        NoSolutionWithinLimitsError,
        OrientationNotReachableError,
        UnreachablePoseError,
    )

    if answer["status"] == "unreachable":
        raise UnreachablePoseError(
            answer["distance"] * length_factor(units.length), "nearest IK branch"
        )
    if answer["status"] != "ok":
        raise NoSolutionWithinLimitsError(answer["message"])
    if answer["orientation_residual"] > tolerance:
        raise OrientationNotReachableError(answer["orientation_residual"], tolerance)


def emit(
    answer: dict[str, Any],
    units: Units,
    *,
    as_json: bool,
    header: dict[str, Any],
    footer: dict[str, Any],
    branch_width: int,
) -> None:
    """Print an answer: JSON (``header`` fields first, ``footer`` fields last; the message also
    as one line on stderr, for whoever reads the terminal), or text."""
    from lynxplan.commands._output import print_json

    if not as_json:
        print_answer(answer, units, branch_width)
        return
    if answer["message"] is not None:
        print(f"lynxplan: warning: ik: {answer['message']}", file=sys.stderr)
    print_json({**header, **answer, **footer})


def print_answer(answer: dict[str, Any], units: Units, branch_width: int) -> None:
    """Print an answer as text: why there is no solution (if so), the selected branch's
    orientation residual, and the branches (the selected one marked ``*``, the nearest ``~``)."""
    if answer["message"] is not None:
        print(f"no solution: {answer['message']}")
    if answer["orientation_residual"] is not None:
        print(f"orientation residual (selected branch): {answer['orientation_residual']:.3g} rad")
    if not answer["solutions"]:
        print("no branch to list")
    for k, row in enumerate(answer["solutions"]):
        mark = "*" if k == answer["selected"] else ("~" if k == answer["nearest"] else " ")
        angles = "  ".join(f"{v:10.4f}" for v in row["q"])
        flag = ""
        if not row["within_limits"]:
            flag = f"  (outside limits: {describe_violations(row['violations'], units.angle)})"
        print(f"{mark} {row['branch']:<{branch_width}} {angles} {units.angle}{flag}")
