"""The robots the service knows, by name, and their public description."""

from __future__ import annotations

from typing import Any

from lynxplan.service.problems import Problem

#: Robot name -> family (the closed-form IK family of the AL5: base yaw, three pitches, roll).
ROBOT_FAMILIES = {"al5": "yaw-pitch3-roll"}


def robot_names() -> list[str]:
    """Names of the robots the service serves."""
    return sorted(ROBOT_FAMILIES)


def get_robot(name: str) -> Any:
    """The robot model (``lynxplan.arm.Arm``) named ``name``; Problem 404 if unknown."""
    if name not in ROBOT_FAMILIES:
        raise Problem(404, f"unknown robot {name!r}; robots: {', '.join(robot_names())}", "robot")
    from lynxplan.arm.model import load_arm

    return load_arm()


def describe_robot(name: str) -> dict[str, Any]:
    """Joints, limits (rad, rad/s), family, tool frame and DH lengths (m) of robot ``name``."""
    arm = get_robot(name)
    from lynxplan.arm.geometry import JOINT_NAMES, TOOL_FRAME

    limits = arm.limits
    return {
        "name": name,
        "family": ROBOT_FAMILIES[name],
        "dof": int(arm.model.nq),
        "tool": TOOL_FRAME,
        "urdf": arm.urdf_path.name,
        "joints": [
            {"name": joint, "lower": lower, "upper": upper, "velocity": velocity}
            for joint, lower, upper, velocity in zip(
                JOINT_NAMES,
                limits.lower.tolist(),
                limits.upper.tolist(),
                limits.velocity.tolist(),
                strict=True,
            )
        ],
        "geometry": {"a2": arm.geometry.a2, "a3": arm.geometry.a3, "d5": arm.geometry.d5},
    }
