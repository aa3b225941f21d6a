"""Decoding of request fields into validated values (Problem 422/413 naming the field)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from lynxplan.service.problems import Problem
from lynxplan.service.wire import as_array

#: Default robot when a request names none.
DEFAULT_ROBOT = "al5"


def robot_name(body: dict[str, Any]) -> str:
    """The ``robot`` field (default ``al5``)."""
    name = body.get("robot", DEFAULT_ROBOT)
    if not isinstance(name, str):
        raise Problem(422, f"robot must be a string. Got: {type(name).__name__}", "robot")
    return name


def flag(body: dict[str, Any], name: str, default: bool = False) -> bool:
    """A boolean field."""
    value = body.get(name, default)
    if not isinstance(value, bool):
        raise Problem(422, f"{name} must be true or false. Got: {value!r}"[:120], name)
    return value


def query_flag(params: Mapping[str, str], name: str, default: bool) -> bool:
    """A boolean query parameter (``true``/``false``/``1``/``0``)."""
    value = params.get(name)
    if value is None:
        return default
    if value.lower() in ("true", "1", "yes"):
        return True
    if value.lower() in ("false", "0", "no"):
        return False
    raise Problem(422, f"{name} must be true or false. Got: {value!r}"[:120], name)


def choice(body: dict[str, Any], name: str, options: tuple[str, ...]) -> str:
    """A string field among ``options`` (default: the first)."""
    value = body.get(name, options[0])
    if value not in options:
        raise Problem(
            422, f"{name} must be one of {', '.join(options)}. Got: {value!r}"[:160], name
        )
    return str(value)


def number(body: dict[str, Any], name: str, default: float, low: float, high: float) -> float:
    """A finite number field within [low, high]."""
    value = body.get(name, default)
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise Problem(422, f"{name} must be a number. Got: {value!r}"[:120], name)
    if not low <= value <= high:
        raise Problem(422, f"{name} must be within [{low:g}, {high:g}]. Got: {value:g}", name)
    return float(value)


def reference(
    body: dict[str, Any], count: int | None, dof: int = 5, robot: str = "al5"
) -> np.ndarray | None:
    """``q_reference``: (dof,) or, for a batch of ``count`` poses, (count, dof), in [rad]."""
    if body.get("q_reference") is None:
        return None
    owner = f"{robot} ({dof} joints)"
    array = as_array(
        body["q_reference"], "q_reference", (dof,), batch=count is not None, owner=owner
    )
    if array.ndim == 2 and array.shape[0] != count:
        raise Problem(
            422,
            f"q_reference must have shape ({dof},) or ({count}, {dof}) for {owner}. "
            f"Got: {array.shape}",
            "q_reference",
        )
    return array


def pose_from_position_approach(position: np.ndarray, approach: np.ndarray) -> np.ndarray:
    """Poses (N, 4, 4) whose third rotation column is the unit ``approach`` (N, 3) at
    ``position`` (N, 3) [m] (a 5-D target: the other two columns are any orthonormal pair)."""
    norm = np.linalg.norm(approach, axis=1)
    if (norm == 0).any():
        raise Problem(422, "approach must not be a zero vector", "approach")
    z = approach / norm[:, None]
    helper = np.where((np.abs(z[:, 0]) < 0.9)[:, None], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x, axis=1)[:, None]
    T = np.zeros((len(z), 4, 4))
    T[:, :3, 0], T[:, :3, 1], T[:, :3, 2] = x, np.cross(z, x), z
    T[:, :3, 3], T[:, 3, 3] = position, 1.0
    return T


def ik_target(body: dict[str, Any], limit: int) -> tuple[np.ndarray, bool, bool]:
    """Target poses of an /ik JSON body: ``T`` (4, 4) / (N, 4, 4), or ``position`` + ``approach``
    ((3,) / (N, 3), a 5-D target). Returns (poses, batch?, approach_only?)."""
    if "T" in body:
        T = as_array(body["T"], "T", (4, 4), limit=limit)
        return T, T.ndim == 3, flag(body, "approach_only")
    if "position" in body and "approach" in body:
        position = as_array(body["position"], "position", (3,), limit=limit)
        approach = as_array(body["approach"], "approach", (3,), limit=limit)
        if position.shape != approach.shape:
            raise Problem(
                422,
                f"approach must have the shape of position {position.shape}. Got: {approach.shape}",
                "approach",
            )
        poses = pose_from_position_approach(position.reshape(-1, 3), approach.reshape(-1, 3))
        return (poses, True, True) if position.ndim == 2 else (poses[0], False, True)
    raise Problem(422, "give the target as T (4x4 pose) or as position and approach", "T")


def obstacle_specs(body: dict[str, Any]) -> list[dict[str, Any]]:
    """The ``obstacles`` list of objects."""
    specs = body.get("obstacles", [])
    if not isinstance(specs, list) or not all(isinstance(s, dict) for s in specs):
        raise Problem(422, "obstacles must be a list of objects", "obstacles")
    return specs


def motion_limits(body: dict[str, Any], arm: Any) -> Any:
    """``limits: {velocity, acceleration, jerk}`` (each a number or 5 numbers, SI) over the
    robot's URDF limits and the library defaults."""
    from lynxplan.trajectory import MotionLimits

    given = body.get("limits") or {}
    if not isinstance(given, dict):
        raise Problem(422, "limits must be an object", "limits")
    unknown = set(given) - {"velocity", "acceleration", "jerk"}
    if unknown:
        raise Problem(
            422,
            f"unknown limit {sorted(unknown)[0]!r}; limits: velocity, acceleration, jerk",
            f"limits.{sorted(unknown)[0]}",
        )
    values: dict[str, Any] = {}
    for name, value in given.items():
        array = (
            as_array(value, f"limits.{name}", (5,))
            if isinstance(value, list)
            else as_array(value, f"limits.{name}", ())
        )
        if (array <= 0).any():
            raise Problem(422, f"limits.{name} must be positive", f"limits.{name}")
        values[name] = array
    base = MotionLimits.from_joint_limits(arm.limits)
    velocity = values.get("velocity", base.velocity)
    return MotionLimits(
        base.position,
        velocity,
        values.get("acceleration", base.acceleration),
        values.get("jerk", base.jerk),
    )


#: Ranges of the numeric /plan options a request may set (PlannerOptions fields): bounded so
#: that no option alone makes the planner allocate without bound (the node budget, the step
#: that sizes the trees' blocks) or sample without bound (the rate).
PLAN_OPTION_RANGES: dict[str, tuple[float, float]] = {
    "clearance": (0.0, 1.0),
    "step": (1e-4, 10.0),
    "goal_bias": (0.0, 0.99),
    "max_nodes": (2, 1_000_000),
    "shortcut_iterations": (0, 100_000),
    "shortcut_patience": (1, 100_000),
    "sample_rate": (1.0, 10_000.0),
}
#: /plan options given as a number or one number per joint, > 0.
PLAN_PER_JOINT_OPTIONS = ("max_acceleration", "max_jerk")
_INTEGER_OPTIONS = ("max_nodes", "shortcut_iterations", "shortcut_patience")


def plan_options(body: dict[str, Any], dof: int) -> dict[str, Any]:
    """The ``options`` object of /plan, checked (422 naming ``options.<name>``): known names,
    numbers within :data:`PLAN_OPTION_RANGES`, per-joint limits as a number or ``dof``
    positive numbers, ``timing`` one of ruckig, lspb, toppra."""
    given = body.get("options") or {}
    if not isinstance(given, dict):
        raise Problem(422, "options must be an object", "options")
    known = (*PLAN_OPTION_RANGES, *PLAN_PER_JOINT_OPTIONS, "timing")
    options: dict[str, Any] = {}
    for name, value in given.items():
        field = f"options.{name}"
        if name not in known:
            raise Problem(
                422, f"unknown option {str(name)[:40]!r}; options: {', '.join(known)}", "options"
            )
        if name == "timing":
            options[name] = choice({field: value}, field, ("ruckig", "lspb", "toppra"))
        elif name in PLAN_PER_JOINT_OPTIONS:
            shape = (dof,) if isinstance(value, list) else ()
            array = as_array(value, field, shape, batch=False)
            if (array <= 0).any():
                raise Problem(422, f"{field} must be positive", field)
            # as_array makes a 0-d value (1,): a number stays a number
            options[name] = float(array.ravel()[0]) if shape == () else tuple(array.tolist())
        else:
            low, high = PLAN_OPTION_RANGES[name]
            number_value = number({field: value}, field, low, low, high)
            if name in _INTEGER_OPTIONS and not isinstance(value, int):
                raise Problem(422, f"{field} must be an integer. Got: {value!r}"[:120], field)
            options[name] = int(number_value) if name in _INTEGER_OPTIONS else number_value
    return options
