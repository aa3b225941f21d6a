"""Robots from URDF: built-ins (AL5, SO-100, SO-101) and any revolute arm, one surface for all.

``load_robot("so101")`` gives a :class:`Robot` with ``fk``, ``ik``, ``ik_batch``, ``jacobian``,
``ik_track``, ``limits``, ``collision_model``, ``workspace`` and ``info()``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from lynxplan.robots.family import FamilyParameters
from lynxplan.robots.results import (
    JointInfo,
    RobotIkBatch,
    RobotIkResult,
    RobotIkSolution,
    RobotInfo,
    TrackJump,
    TrackResult,
)
from lynxplan.robots.robot import Robot

__all__ = [
    "FamilyParameters",
    "JointInfo",
    "Robot",
    "RobotIkBatch",
    "RobotIkResult",
    "RobotIkSolution",
    "RobotInfo",
    "TrackJump",
    "TrackResult",
    "builtin_robot_names",
    "load_robot",
]

_CACHE: dict[str, Robot] = {}


def builtin_robot_names() -> tuple[str, ...]:
    """Names accepted by :func:`load_robot` besides URDF paths."""
    from lynxplan.robots.loading import builtin_robots

    return tuple(builtin_robots())


def load_robot(
    name_or_urdf: str | Path,
    *,
    tool: str | None = None,
    base: Any = None,
    package_dirs: list[str] | tuple[str, ...] | None = None,
    srdf: str | Path | None = None,
    calibration: str | Path | None = None,
) -> Robot:
    """A robot by built-in name (``al5``, ``so100``, ``so101``, ``ur5``, ``ur10``, ``panda``) or
    URDF path.

    Args:
        name_or_urdf: Built-in name or path of a URDF file.
        tool: Tool frame name (default: the built-in's tool; for a URDF, its last frame).
        base: Placement of the robot base in the world, shape (4, 4), [m]. Default: identity.
        package_dirs: Folders searched first for ``package://`` and relative mesh paths (then
            ROS_PACKAGE_PATH, AMENT_PREFIX_PATH, the URDF's folder and its parents and
            example-robot-data; see :mod:`lynxplan.mesh_paths`).
        srdf: SRDF whose ``disable_collisions`` pairs are not checked for self-collision.
            Default: ``<stem>.srdf`` next to the URDF or in ``../srdf/``, if there is one.
        calibration: A LeRobot calibration file of the arm (SO-100/SO-101): joint limits from
            its calibrated ranges (see :func:`lynxplan.lerobot.load_calibrated`).

    Raises:
        UnknownRobotError: neither a built-in name nor an existing file.
        ModelError: unreadable URDF or SRDF, missing tool frame, non-revolute joint on the
            chain, a package folder that does not exist.
    """
    from lynxplan.robots.loading import load_model

    if calibration is not None:
        from lynxplan.lerobot.calibration import load_calibrated

        return load_calibrated(
            name_or_urdf, calibration, tool=tool, base=base, package_dirs=package_dirs, srdf=srdf
        )
    key = str(name_or_urdf)
    plain = tool is None and base is None and package_dirs is None and srdf is None
    if plain and key in _CACHE:
        return _CACHE[key]
    loaded, builtin = load_model(name_or_urdf, tool, base, package_dirs, srdf)
    robot = Robot(loaded, builtin)
    if plain and builtin is not None:
        _CACHE[key] = robot
    return robot
