"""Continuous IK of a stream of tool targets (teleoperation, a scripted path) in LeRobot units.

Each frame is solved by :meth:`Robot.ik_track <lynxplan.robots.Robot.ik_track>` from the
configuration last commanded, so the branch is the one continuous with what the arm does. Then:

- each joint's step from the previous frame is bounded (``max_step``, by default the servo speed
  bound of :mod:`lynxplan.lerobot.servo` over one frame): a branch change or a far first target
  becomes a ramp over several frames, never a jump; such frames are marked ``held``;
- a target out of reach gives the solver's nearest solution (the tool as near the target as the
  arm gets) with ``reachable`` False when that pose is within one step of the arm; when it is
  not (the nearest pose of an unreachable pitch can be another configuration altogether) or
  there is none within the limits, the frame goes to the farthest point the arm reaches on the
  way from the last reached target towards it (bisection), still ``reachable`` False.

Every commanded configuration lies within the robot's limits (each frame moves from a
configuration within them towards another, inside a box).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from lynxplan.exceptions import InputError
from lynxplan.lerobot.servo import DEFAULT_FPS, DEFAULT_MAX_VELOCITY
from lynxplan.lerobot.units import LeRobotUnits

if TYPE_CHECKING:
    from lynxplan.robots.robot import Robot

#: A target counts as reached when the commanded tool point is this close to it, in [m]
#: (the IK is exact to ~1e-12 m where the target is reachable).
REACHED_TOLERANCE = 1e-6
#: Bisection steps towards a target out of reach (to 1/4096 of the way).
FALLBACK_BISECTIONS = 12
_KINDS = ("poses", "positions", "approaches", "pitches", "rolls")


class LeRobotTrack(NamedTuple):
    """The frames of a tracked stream of N targets."""

    q: np.ndarray
    """Commanded joint angles, shape (N, n), in [rad] (read-only)."""
    values: np.ndarray
    """The same in LeRobot units, shape (N, n) (degrees or -100..100; read-only)."""
    gripper: np.ndarray
    """Gripper channel, shape (N,), 0..100; NaN where none was given."""
    reachable: np.ndarray
    """Whether the target itself can be reached, shape (N,), bool."""
    held: np.ndarray
    """Whether the step bound held the frame short of the IK solution, shape (N,), bool."""
    distance: np.ndarray
    """Distance from the commanded tool point to the target point, shape (N,), in [m]."""
    max_step: float
    """Largest joint change of a frame (the first from the start), in [rad]."""
    units: LeRobotUnits
    """The units of ``values``."""

    def frames(self) -> list[dict[str, float]]:
        """The LeRobot action dicts (with ``gripper.pos`` where the gripper was given)."""
        rows = []
        for i in range(len(self.q)):
            grip = None if np.isnan(self.gripper[i]) else float(self.gripper[i])
            frame = self.units.to_action(self.q[i], grip)
            assert isinstance(frame, dict)
            rows.append(frame)
        return rows


def _targets(robot: Robot, given: dict[str, Any]) -> tuple[dict[str, np.ndarray], int]:
    arrays = {k: np.asarray(v, dtype=float) for k, v in given.items() if v is not None}
    if "poses" not in arrays and "positions" not in arrays:
        raise InputError("track_targets needs poses (N, 4, 4) or positions (N, 3) [m]")
    lead = arrays.get("poses", arrays.get("positions"))
    assert lead is not None
    n = int(lead.shape[0]) if lead.ndim > 1 else 0
    if "approaches" in arrays and arrays["approaches"].shape == (3,):  # one for every target
        arrays["approaches"] = np.broadcast_to(arrays["approaches"], (n, 3))
    for name, array in arrays.items():
        if array.ndim == 0 or array.shape[0] != n:
            raise InputError(f"{name}: {n} targets expected (the first axis). Got: {array.shape}")
    return arrays, n


def _point(target: dict[str, np.ndarray]) -> np.ndarray:
    return target["poses"][0, :3, 3] if "poses" in target else target["positions"][0]


def _between(a: dict[str, np.ndarray], b: dict[str, np.ndarray], t: float) -> dict[str, Any]:
    """Target a + t (b - a) (a pose keeps b's orientation, moving its point)."""
    out: dict[str, Any] = {}
    for name, end in b.items():
        if name == "poses":
            pose = end.copy()
            pose[0, :3, 3] = a[name][0, :3, 3] + t * (end[0, :3, 3] - a[name][0, :3, 3])
            out[name] = pose
        else:
            out[name] = a[name] + t * (end - a[name])
    return out


def _solve(robot: Robot, target: dict[str, Any], previous: np.ndarray) -> np.ndarray:
    """The IK branch of one target continuous with ``previous`` (n,) [rad]; NaN if none."""
    return np.asarray(robot.ik_track(q0=previous, **target).q[0])


def _start(robot: Robot, units: LeRobotUnits, start: Any) -> np.ndarray:
    lower, upper = robot.limits.lower, robot.limits.upper
    if start is None:
        return np.clip(np.zeros(robot.nq), lower, upper)
    q = units.to_joints(start).q if isinstance(start, Mapping) else np.asarray(start, dtype=float)
    if q.shape != (robot.nq,) or not np.all(np.isfinite(q)):
        raise InputError(f"start must be a LeRobot observation or shape ({robot.nq},) [rad]")
    if np.any(q < lower - 1e-9) or np.any(q > upper + 1e-9):
        raise InputError("start is outside the robot's joint limits (load_calibrated?)")
    return q


def track_targets(
    robot: Robot,
    units: LeRobotUnits,
    *,
    poses: Any = None,
    positions: Any = None,
    approaches: Any = None,
    pitches: Any = None,
    rolls: Any = None,
    gripper: Any = None,
    start: Any = None,
    fps: float = DEFAULT_FPS,
    max_velocity: float = DEFAULT_MAX_VELOCITY,
) -> LeRobotTrack:
    """Frames that follow N tool targets, one per frame, continuously (module docstring).

    Args:
        robot: The model (:func:`~lynxplan.lerobot.load_calibrated` for the arm's own limits).
        units: Its LeRobot units (:func:`~lynxplan.lerobot.lerobot_units`).
        poses / positions + approaches / pitches, rolls: N targets as in ``Robot.ik_batch``
            (positions [m], pitches and rolls [rad]); one approach, shape (3,), applies to
            every target.
        gripper: Gripper channel per target, shape (N,) or scalar, 0..100.
        start: The arm's configuration before the first frame: a LeRobot observation dict or
            shape (n,) [rad]. Default: zeros within the limits.
        fps: Frame rate [frames/s]; with ``max_velocity`` [rad/s] it bounds each joint's step
            per frame to ``max_velocity / fps`` [rad].

    Raises:
        InputError: no targets, targets of different counts, a start outside the limits, a
            non-positive fps or velocity.
    """
    if not (fps > 0 and max_velocity > 0 and np.isfinite(fps) and np.isfinite(max_velocity)):
        raise InputError(f"fps = {fps}, max_velocity = {max_velocity}: must be finite and > 0")
    given = dict(zip(_KINDS, (poses, positions, approaches, pitches, rolls), strict=True))
    targets, n = _targets(robot, given)
    bound = max_velocity / fps
    previous = _start(robot, units, start)
    q = np.empty((n, robot.nq))
    reachable = np.zeros(n, dtype=bool)
    held = np.zeros(n, dtype=bool)
    distance = np.empty(n)
    last_reached: dict[str, np.ndarray] | None = None
    for k in range(n):
        target = {name: a[k : k + 1] for name, a in targets.items()}
        goal = _point(target)
        solution = _solve(robot, target, previous)
        reachable[k] = _reaches(robot, solution, goal)
        if reachable[k]:
            last_reached = target
        elif last_reached is not None and not _within_step(solution, previous, bound):
            # the solver's nearest pose is far from the arm (or there is none): the farthest
            # reachable point towards the target instead, continuous with the frames before
            boundary = _boundary(robot, last_reached, target, previous)
            solution = solution if np.isnan(boundary).any() else boundary
        if np.isnan(solution).any():
            solution = previous
        step = solution - previous
        held[k] = bool(np.any(np.abs(step) > bound))
        previous = previous + np.clip(step, -bound, bound)
        q[k] = previous
        distance[k] = float(np.linalg.norm(robot.fk(previous)[:3, 3] - goal))
    return _result(robot, units, q, gripper, reachable, held, distance, start)


def _reaches(robot: Robot, solution: np.ndarray, goal: np.ndarray) -> bool:
    """Whether ``solution`` (n,) [rad] puts the tool on ``goal`` (3,) [m] (False for NaN)."""
    if np.isnan(solution).any():
        return False
    return bool(np.linalg.norm(robot.fk(solution)[:3, 3] - goal) <= REACHED_TOLERANCE)


def _within_step(solution: np.ndarray, previous: np.ndarray, bound: float) -> bool:
    return bool(np.all(np.abs(solution - previous) <= bound))


def _boundary(
    robot: Robot, reached: dict[str, np.ndarray], target: dict[str, Any], previous: np.ndarray
) -> np.ndarray:
    """The solution of the farthest target from ``reached`` towards ``target`` that the arm
    reaches (bisection; NaN when none is found)."""
    low, high, best = 0.0, 1.0, np.full(robot.nq, np.nan)
    for _ in range(FALLBACK_BISECTIONS):
        middle = 0.5 * (low + high)
        between = _between(reached, target, middle)
        solution = _solve(robot, between, previous)
        if _reaches(robot, solution, _point(between)):
            low, best = middle, solution
        else:
            high = middle
    return best


def _result(
    robot: Robot,
    units: LeRobotUnits,
    q: np.ndarray,
    gripper: Any,
    reachable: np.ndarray,
    held: np.ndarray,
    distance: np.ndarray,
    start: Any,
) -> LeRobotTrack:
    n = len(q)
    grip = np.full(n, np.nan) if gripper is None else np.broadcast_to(gripper, (n,)).astype(float)
    first = _start(robot, units, start)
    steps = np.abs(np.diff(np.vstack((first, q)), axis=0)) if n else np.zeros((0, robot.nq))
    values = units.to_values(q)
    for array in (q, values, grip, reachable, held, distance):
        array.setflags(write=False)
    max_step = float(steps.max()) if n else 0.0
    return LeRobotTrack(q, values, grip, reachable, held, distance, max_step, units)
