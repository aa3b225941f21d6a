"""The robots the service knows, by built-in name only, and their public description.

Over HTTP a robot is one of lynxplan's built-in robots (``al5``, ``so100``, ``so101``, ``ur5``,
``ur10``, ``panda``), named in the request; no name is ever taken for a path. A URDF of the
caller's comes only with a run (:mod:`.uploads`), into that run's own folder. The AL5 is served
by ``lynxplan.arm`` (its closed-form kernels); the others by ``lynxplan.load_robot``.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from lynxplan.service.problems import Problem

#: Longest robot name quoted back in an error.
NAME_ECHO = 40


#: Joints of the robots served by /check, /trajectory, /plan and /view (their arrays are
#: (N, 5)); /fk, /ik, /robots and runs serve every built-in (ur5, ur10: 6 joints; panda: 7).
MOTION_DOF = 5


@functools.cache
def robot_names() -> tuple[str, ...]:
    """Names of the robots the service serves (lynxplan's built-ins)."""
    from lynxplan.robots import builtin_robot_names

    return tuple(sorted(builtin_robot_names()))


@functools.cache
def robot_dof(name: str) -> int:
    """Joints of the arm of built-in robot ``name`` (from its description, nothing loaded)."""
    from lynxplan.robots.loading import builtin_robots

    return int(builtin_robots()[name].arm_joints)


def motion_robot(name: str, path: str) -> str:
    """``name`` if it is a built-in robot of :data:`MOTION_DOF` joints, the robots ``path``
    serves; else Problem 404 (unknown) or 422 naming ``robot``, its joints and those robots."""
    check_robot_name(name)
    if robot_dof(name) != MOTION_DOF:
        served = ", ".join(n for n in robot_names() if robot_dof(n) == MOTION_DOF)
        raise Problem(
            422,
            f"robot: {name} has {robot_dof(name)} joints; {path} serves the {MOTION_DOF}-joint "
            f"robots ({served}); every robot: /fk, /ik and runs",
            "robot",
        )
    return name


def check_robot_name(name: object, field: str = "robot") -> str:
    """``name`` if it is a built-in robot; else Problem 404 naming ``field`` and the robots
    (never looked up on the disk: the answer is the same for any other string; 422 for a
    value that is not a string)."""
    if not isinstance(name, str):
        raise Problem(422, f"{field} must be a robot name. Got: {type(name).__name__}", field)
    if name not in robot_names():
        shown = name if len(name) <= NAME_ECHO else name[:NAME_ECHO] + "..."
        raise Problem(
            404, f"{field}: unknown robot {shown!r}; robots: {', '.join(robot_names())}", field
        )
    return name


#: The built-in robots loaded so far, by name (the hot routes look them up once a request).
_LOADED: dict[str, Any] = {}


def get_robot(name: str, field: str = "robot") -> Any:
    """The model of built-in robot ``name``: ``lynxplan.arm.Arm`` for the AL5, else a
    ``lynxplan.robots.Robot``; Problem 404 if ``name`` is not a built-in."""
    robot = _LOADED.get(name)
    if robot is not None:
        return robot
    check_robot_name(name, field)
    if name == "al5":
        from lynxplan.arm.model import load_arm

        robot = load_arm()
    else:
        from lynxplan.robots import load_robot

        robot = load_robot(name)
    _LOADED[name] = robot
    return robot


def is_numerical(robot: Any) -> bool:
    """Whether ``robot``'s IK is the numerical solver (outside the closed-form family): its
    cost per pose is milliseconds, not microseconds."""
    return not is_al5(robot) and robot.family is None


def ik_slots(robot: Any, approach_only: bool) -> int:
    """Branch slots per pose of ``robot``'s batch IK (``Robot.ik_batch``): 4 for the AL5 and
    arms whose tool is on the roll axis, 8 (24 for approach targets) for an off-axis tool, 1
    for the numerical solver."""
    if is_al5(robot):
        return 4
    if robot.family is None:
        return 1
    if robot.family.tool_on_roll_axis:
        return 4
    return 24 if approach_only else 8


def is_al5(robot: Any) -> bool:
    """Whether ``robot`` is the AL5 of ``lynxplan.arm`` (its own IK API)."""
    if robot is _LOADED.get("al5"):
        return True
    from lynxplan.arm.model import Arm

    return isinstance(robot, Arm)


def describe_robot(name: str) -> dict[str, Any]:
    """Joints, limits (rad, rad/s), family, tool frame (and the AL5's DH lengths, m) of a
    built-in robot; Problem 404 if ``name`` is not one."""
    robot = get_robot(name)
    limits = robot.limits
    if is_al5(robot):
        from lynxplan.arm.geometry import JOINT_NAMES, TOOL_FRAME

        joints, tool, family = JOINT_NAMES, TOOL_FRAME, "yaw-pitch3-roll"
    else:
        joints, tool = robot.joint_names, robot.tool_frame
        family = "yaw-pitch3-roll" if robot.family is not None else "numerical"
    described: dict[str, Any] = {
        "name": name,
        "family": family,
        "dof": int(robot.model.nq),
        "tool": tool,
        "urdf": robot.urdf_path.name,
        "joints": [
            {"name": joint, "lower": lower, "upper": upper, "velocity": velocity}
            for joint, lower, upper, velocity in zip(
                joints,
                limits.lower.tolist(),
                limits.upper.tolist(),
                limits.velocity.tolist(),
                strict=True,
            )
        ],
    }
    if is_al5(robot):
        described["geometry"] = {"a2": robot.geometry.a2, "a3": robot.geometry.a3,
                                 "d5": robot.geometry.d5}  # fmt: skip
    return described


def robot_ik_batch_arrays(
    robot: Any, T: np.ndarray, q_reference: np.ndarray | None, approach_only: bool
) -> tuple[dict[str, np.ndarray], list[str]]:
    """All-branch IK of (N, 4, 4) poses for a ``lynxplan.robots.Robot``: the arrays of its
    ``RobotIkBatch`` (``position_error``: the solver's FK check of each branch, in [m]) and the
    names of the branch slots. ``approach_only``: column 3 is the point, column 2 the approach."""
    if approach_only:
        batch = robot.ik_batch(
            positions=T[:, :3, 3], approaches=T[:, :3, 2], q_reference=q_reference
        )
    else:
        batch = robot.ik_batch(T, q_reference=q_reference)
    arrays = {name: np.asarray(getattr(batch, name)) for name in batch._fields[:-1]}
    return arrays, list(batch.branch_names)
