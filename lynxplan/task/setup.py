"""A validated task scenario resolved into SI values: robot, obstacles, waypoint angles, the plan.

Every problem found here is raised as a :class:`~lynxplan.exceptions.ScenarioValueError` located
at its key path (``segments[3].to``, ``waypoints.O2.pose``); the scenario runner reports it like a
schema error: file, key path (line), reason. This runs at run time, never during validation.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from lynxplan.constants import LIMIT_SNAP_TOLERANCE
from lynxplan.exceptions import LynxplanError, ScenarioValueError
from lynxplan.scenarios.robot import load_path_robot
from lynxplan.task.schema import route
from lynxplan.units import angle_factor, length_factor
from lynxplan.viz import WritingPlane

if TYPE_CHECKING:
    from lynxplan.arm.model import Arm
    from lynxplan.collision.obstacles import Obstacle
    from lynxplan.robots import Robot
    from lynxplan.task.schema import (
        BoxEntry,
        CylinderEntry,
        Scenario,
        SphereEntry,
        WaypointEntry,
    )
    from lynxplan.trajectory.kinematics import PathKinematics
    from lynxplan.trajectory.limits import MotionLimits
    from lynxplan.trajectory.plan import Plan


@dataclass(frozen=True)
class TaskSetup:
    """A task scenario in SI units, ready to run.

    Attributes:
        arm: The robot: the AL5 (``lynxplan.arm.Arm``) or a URDF robot (``lynxplan.Robot``).
        kinematics: Its FK and path IK for the trajectory layer.
        obstacles: The obstacles, in [m].
        waypoints: Joint angles of each named waypoint, shape (5,), in [rad].
        route: ``(from, to)`` waypoint names of each segment.
        limits: Joint limits used for timing, IK and the limit check.
        plan: The planned motion (segment ``i`` goes ``route[i]``).
        writing_plane: The writing surface, or None.
    """

    arm: Arm | Robot
    kinematics: PathKinematics
    obstacles: tuple[Obstacle, ...]
    waypoints: dict[str, np.ndarray]
    route: tuple[tuple[str, str], ...]
    limits: MotionLimits
    plan: Plan
    writing_plane: WritingPlane | None


_InvalidError = ScenarioValueError


def resolve(scenario: Scenario) -> TaskSetup:
    """Resolve a valid scenario into SI values, solving waypoint IK and planning the segments.

    Raises:
        ScenarioValueError: naming the key path of the value that cannot be used.
    """
    return _resolve(scenario)


def _resolve(scenario: Scenario) -> TaskSetup:
    from lynxplan.trajectory.plan import Plan

    length = length_factor(scenario.units.length)
    angle = angle_factor(scenario.units.angle)
    arm, kinematics = load_path_robot(scenario.robot)
    limits = _limits(scenario, arm, angle)
    obstacles = tuple(_obstacles(scenario, length, angle))
    _warn_implausible(scenario, arm)
    waypoints = {
        name: _waypoint(name, entry, arm, length, angle)
        for name, entry in scenario.waypoints.items()
    }
    path = route(scenario)
    q = waypoints[path[0][0]]
    segments = []
    expanded: list[tuple[str, str]] = []  # a planned motion adds its via points to the route
    for i, ((start, target), entry) in enumerate(zip(path, scenario.segments, strict=True)):
        if entry.motion == "plan":
            vias = _planned_vias(i, entry, q, waypoints[target], arm, obstacles)
            names = [start, *(f"{start}->{target}#{k}" for k in range(1, len(vias) - 1)), target]
            waypoints.update(zip(names[1:-1], vias[1:-1], strict=True))
            for k in range(len(vias) - 1):
                piece = _segment(
                    i, entry, vias[k + 1], vias[k], scenario, limits, kinematics, "free"
                )
                segments.append(piece)
                expanded.append((names[k], names[k + 1]))
            q = segments[-1].q_end
            continue
        segment = _segment(i, entry, waypoints[target], q, scenario, limits, kinematics)
        segments.append(segment)
        expanded.append((start, target))
        q = segment.q_end
    path = tuple(expanded)
    plane = None
    if scenario.writing_plane is not None:
        wp = scenario.writing_plane
        plane = WritingPlane.tilted(
            np.array(wp.point) * length,
            float(wp.tilt) * angle,
            (wp.size[0] * length, wp.size[1] * length),
        )
    plan = Plan(tuple(segments), limits, kinematics)
    return TaskSetup(arm, kinematics, obstacles, waypoints, path, limits, plan, plane)


def _limits(scenario: Scenario, arm: Arm | Robot, angle: float) -> MotionLimits:
    from lynxplan.trajectory.limits import DEFAULT_MAX_ACCELERATION, DEFAULT_MAX_JERK, MotionLimits

    entry = scenario.limits

    def scaled(value: Any, default: Any) -> np.ndarray:
        return np.asarray(default if value is None else np.asarray(value) * angle, dtype=float)

    return MotionLimits(
        arm.limits.position,
        scaled(entry.velocity, arm.limits.velocity),
        scaled(entry.acceleration, DEFAULT_MAX_ACCELERATION),
        scaled(entry.jerk, DEFAULT_MAX_JERK),
    )


def rpy_matrix(rpy: np.ndarray) -> np.ndarray:
    """Fixed-axis roll-pitch-yaw (rad) -> rotation ``Rz(yaw) Ry(pitch) Rx(roll)``, shape (3, 3)."""
    r, p, y = rpy
    rx = np.array([[1, 0, 0], [0, np.cos(r), -np.sin(r)], [0, np.sin(r), np.cos(r)]])
    ry = np.array([[np.cos(p), 0, np.sin(p)], [0, 1, 0], [-np.sin(p), 0, np.cos(p)]])
    rz = np.array([[np.cos(y), -np.sin(y), 0], [np.sin(y), np.cos(y), 0], [0, 0, 1]])
    rotation: np.ndarray = rz @ ry @ rx
    return rotation


def _rotation(entry: BoxEntry | CylinderEntry, angle: float) -> np.ndarray | None:
    if entry.rpy is not None:
        return rpy_matrix(np.array(entry.rpy) * angle)
    if entry.rotation is not None:
        return np.array(entry.rotation, dtype=float)
    return None


def _warn_implausible(scenario: Scenario, arm: Any) -> None:
    """One warning when an obstacle or a waypoint's tool point is implausibly far for the arm
    (a file in mm read as metres), as for ``plan`` scenarios."""
    from lynxplan.scenarios.plausible import warn_implausible_lengths

    targets = []
    for name, entry in scenario.waypoints.items():
        point = entry.position if entry.pose is None else [row[3] for row in entry.pose[:3]]
        if point is not None:
            targets.append((f"waypoints.{name}", point))
    warn_implausible_lengths(arm, scenario.units.length, scenario.obstacles, targets)


def _obstacles(scenario: Scenario, length: float, angle: float) -> list[Obstacle]:
    built: list[Obstacle] = []
    for i, entry in enumerate(scenario.obstacles):
        name = entry.name or f"obstacle_{i}"
        if name in [o.name for o in built]:
            raise _InvalidError(("obstacles", i, "name"), f"duplicate obstacle name {name!r}", name)
        try:
            built.append(_obstacle(entry, name, length, angle))
        except LynxplanError as exc:
            raise _InvalidError(("obstacles", i), str(exc)) from exc
    return built


def _obstacle(
    entry: BoxEntry | SphereEntry | CylinderEntry, name: str, length: float, angle: float
) -> Obstacle:
    from lynxplan.collision.obstacles import (
        BoxObstacle,
        CylinderObstacle,
        SphereObstacle,
        axis_aligned_box,
        rotation_from_axis,
    )

    if entry.type == "sphere":
        return SphereObstacle(name, np.array(entry.centre) * length, entry.radius * length)
    rotation = _rotation(entry, angle)
    if entry.type == "box":
        size = np.array(entry.size) * length
        if entry.min_corner is not None:
            return axis_aligned_box(name, np.array(entry.min_corner) * length, size)
        centre = np.array(entry.centre) * length
        return BoxObstacle(name, centre, size, np.eye(3) if rotation is None else rotation)
    if entry.axis is not None:
        rotation = rotation_from_axis(entry.axis)
    return CylinderObstacle(
        name,
        np.array(entry.centre) * length,
        entry.radius * length,
        entry.length * length,
        np.eye(3) if rotation is None else rotation,
    )


def _waypoint(
    name: str, entry: WaypointEntry, arm: Arm | Robot, length: float, angle: float
) -> np.ndarray:
    loc: tuple[str | int, ...] = ("waypoints", name)
    if entry.q is not None:
        q = np.array(entry.q) * angle
        _check_within_limits(q, arm, (*loc, "q"), angle)
        return q
    reference = None if entry.q_reference is None else np.array(entry.q_reference) * angle
    if entry.pose is not None:
        pose = np.eye(4)
        pose[: len(entry.pose)] = np.array(entry.pose)
        pose[:3, 3] *= length
        key = "pose"
    else:
        pose = _approach_pose(np.array(entry.position) * length, np.array(entry.approach))
        key = "position"
    # The AL5 (its package or its Robot) has the report's branch rule; any other robot takes
    # the branch nearest q_reference.
    report_rule = entry.ik == "report" and "report" in arm.selection_rules
    try:
        result = arm.ik(
            pose,
            q_reference=reference,
            select="report" if report_rule else "nearest",
            approach_only=entry.pose is None,
        )
        q = np.array(result.q)
    except LynxplanError as exc:
        raise _InvalidError((*loc, key), f"unreachable waypoint: {exc}") from exc
    if not getattr(result, "reachable", True):  # a URDF robot answers with the nearest solution
        miss = float(getattr(result, "distance", np.nan))
        raise _InvalidError(
            (*loc, key),
            f"unreachable waypoint: the nearest solution misses it by "
            f"{miss / length:.6g} (file's length unit)",
        )
    return q


def _approach_pose(position: np.ndarray, approach: np.ndarray) -> np.ndarray:
    """A pose whose z axis is ``approach`` (the IK only uses that axis: approach_only)."""
    from lynxplan.collision.obstacles import rotation_from_axis

    pose = np.eye(4)
    pose[:3, :3] = rotation_from_axis(approach)
    pose[:3, 3] = position
    return pose


def _check_within_limits(
    q: np.ndarray, arm: Arm | Robot, loc: tuple[str | int, ...], angle: float
) -> None:
    lower, upper = arm.limits.lower, arm.limits.upper
    for j in range(len(q)):
        if not lower[j] - LIMIT_SNAP_TOLERANCE <= q[j] <= upper[j] + LIMIT_SNAP_TOLERANCE:
            raise _InvalidError(
                (*loc, j),
                f"q{j + 1} = {q[j] / angle:.6g} is outside the joint limits "
                f"[{lower[j] / angle:.6g}, {upper[j] / angle:.6g}] (file's angle unit)",
                q[j] / angle,
            )


def _planned_vias(
    i: int, entry: Any, q: np.ndarray, target: np.ndarray, arm: Arm | Robot, obstacles: Any
) -> np.ndarray:
    """``motion: plan``: the waypoints of a collision-free path planned by
    :func:`lynxplan.plan` (RRT-Connect, shortcut, verified exactly), shape (M, 5), in [rad]."""
    from lynxplan.planning import Planner

    try:
        return np.asarray(Planner(arm, obstacles).solve(q, target, seed=0).waypoints)
    except LynxplanError as exc:
        raise _InvalidError(("segments", i), f"planned motion to {entry.to!r}: {exc}") from exc


def _segment(
    i: int,
    entry: Any,
    target: np.ndarray,
    q: np.ndarray,
    scenario: Scenario,
    limits: MotionLimits,
    kinematics: PathKinematics,
    motion: Literal["free", "line"] | None = None,
) -> Any:
    from lynxplan.trajectory.lspb import LspbTiming
    from lynxplan.trajectory.plan import SegmentSpec, build_plan

    timing_entry = entry.timing if entry.timing is not None else scenario.timing
    timing = None if timing_entry == "auto" else LspbTiming(timing_entry.tt, timing_entry.ta)
    kind: Literal["free", "line"] = motion or entry.motion
    if entry.motion == "plan":
        timing = None  # the pieces of a planned motion: shortest LSPB each, rest at the vias
    spec = SegmentSpec(kind, target_q=target, timing=timing, mode=entry.orientation)
    try:
        return build_plan(q, [spec], limits, kinematics).segments[0]
    except LynxplanError as exc:
        raise _InvalidError(
            ("segments", i), f"{entry.motion} motion to {entry.to!r}: {exc}"
        ) from exc
