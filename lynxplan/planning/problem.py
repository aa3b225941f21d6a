"""Planning problems: a start configuration and a goal (configuration, tool pose, or position +
approach direction), turned into the set of goal configurations the planner may reach.

- :class:`JointGoal`: one configuration.
- :class:`PoseGoal`: a tool pose; every IK branch within the joint limits is a goal (the planner
  grows its goal tree from all of them, so a goal that needs a branch change is found).
- :class:`ApproachGoal`: a tool position and approach direction (the tool z axis); the roll
  about the approach axis is free: IK branches at ``roll_samples`` rolls are all goals.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lynxplan.exceptions import (
    GoalUnreachableError,
    KinematicsError,
    NonFiniteInputError,
    OrientationNotReachableError,
    ShapeError,
    UnreachablePoseError,
)
from lynxplan.planning.space import JointSpace

#: Rolls about the approach axis tried for an :class:`ApproachGoal`.
DEFAULT_ROLL_SAMPLES = 8


@dataclass(frozen=True)
class JointGoal:
    """A goal configuration.

    Attributes:
        q: Joint angles, shape (nq,), in [rad].
    """

    q: np.ndarray

    def __post_init__(self) -> None:
        array = np.array(self.q, dtype=float)
        array.setflags(write=False)
        object.__setattr__(self, "q", array)


@dataclass(frozen=True)
class PoseGoal:
    """A tool pose; any IK branch is a valid goal.

    Attributes:
        pose: Tool pose in the base frame, shape (4, 4), translation in [m].
    """

    pose: np.ndarray

    def __post_init__(self) -> None:
        array = np.array(self.pose, dtype=float)
        if array.shape != (4, 4):
            raise ShapeError("goal pose", "(4, 4)", array.shape)
        if not np.isfinite(array).all():
            raise NonFiniteInputError("goal pose")
        array.setflags(write=False)
        object.__setattr__(self, "pose", array)


@dataclass(frozen=True)
class ApproachGoal:
    """A tool position and approach direction (tool z axis); the roll about it is free.

    Attributes:
        position: Tool point, shape (3,), in [m].
        approach: Approach direction, shape (3,) (normalised here).
        roll_samples: Number of rolls about the approach axis turned into IK goals.
    """

    position: np.ndarray
    approach: np.ndarray
    roll_samples: int = DEFAULT_ROLL_SAMPLES

    def __post_init__(self) -> None:
        for name in ("position", "approach"):
            array = np.array(getattr(self, name), dtype=float)
            if array.shape != (3,):
                raise ShapeError(f"goal {name}", "(3,)", array.shape)
            if not np.isfinite(array).all():
                raise NonFiniteInputError(f"goal {name}")
            if name == "approach":
                norm = float(np.linalg.norm(array))
                if norm == 0.0:
                    raise ShapeError("goal approach", "a non-zero vector", array.shape)
                array = array / norm
            array.setflags(write=False)
            object.__setattr__(self, name, array)

    def pose_at(self, angle: float) -> np.ndarray:
        """The tool pose rolled by ``angle`` [rad] about the approach axis, shape (4, 4)."""
        z = self.approach
        helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        x0 = _cross(helper, z)
        x0 /= np.linalg.norm(x0)
        y0 = _cross(z, x0)
        x = np.cos(angle) * x0 + np.sin(angle) * y0
        pose = np.zeros((4, 4))
        pose[:3, :3] = np.column_stack((x, _cross(z, x), z))
        pose[:3, 3] = self.position
        pose[3, 3] = 1.0
        return pose

    def poses(self) -> np.ndarray:
        """Tool poses at ``roll_samples`` rolls about the approach axis, shape (R, 4, 4)."""
        angles = np.linspace(0.0, 2 * np.pi, self.roll_samples, endpoint=False)
        return np.array([self.pose_at(float(angle)) for angle in angles]).reshape(-1, 4, 4)


Goal = JointGoal | PoseGoal | ApproachGoal


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b of two 3-vectors (np.cross's general broadcasting costs ~10 us a call)."""
    (a0, a1, a2), (b0, b1, b2) = a.tolist(), b.tolist()
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


@dataclass(frozen=True)
class GoalSet:
    """The goal configurations of a goal, with where each came from.

    Attributes:
        configurations: Shape (K, nq), in [rad], within the joint limits.
        labels: One label per configuration (IK branch name, roll), for reports.
    """

    configurations: np.ndarray
    labels: tuple[str, ...] = field(default=())


#: A goal branch must reach the target position to this, in [m] ...
GOAL_POSITION_TOLERANCE = 1e-9
#: ... and the orientation (or the approach axis) to this, in [rad]: a URDF robot's IK polishes
#: off-family models (the SO-101's axes are 3.7e-6 rad off parallel) to ~6e-6 rad; the AL5's
#: closed form reaches a reachable orientation to rounding.
ROBOT_GOAL_ORIENTATION_TOLERANCE = 1e-5
#: The last joint is a free roll of an approach goal when turning it moves the tool point and
#: the approach axis by less than this, in [m] and [rad].
_FREE_ROLL_TOLERANCE = 1e-9


def _exact_solutions(
    robot: Any, pose: np.ndarray, approach_only: bool, reference: np.ndarray | None
) -> tuple[Any, ...]:
    """The IK branches that reach ``pose`` (4, 4): the position to
    :data:`GOAL_POSITION_TOLERANCE` and the orientation (or, ``approach_only``, the approach
    axis) to :data:`ROBOT_GOAL_ORIENTATION_TOLERANCE`. Any robot whose ``ik(pose,
    approach_only=..., q_reference=...)`` answers branches with ``position_error`` and
    ``orientation_error``.

    Raises:
        KinematicsError: the pose is out of reach, or its orientation.
    """
    result = robot.ik(pose, approach_only=approach_only, q_reference=reference)
    exact = tuple(
        s
        for s in result.solutions
        if s.position_error <= GOAL_POSITION_TOLERANCE
        and s.orientation_error <= ROBOT_GOAL_ORIENTATION_TOLERANCE
    )
    if exact:
        return exact
    miss = min((float(s.position_error) for s in result.solutions), default=np.inf)
    if miss > GOAL_POSITION_TOLERANCE:
        raise UnreachablePoseError(miss, "nearest solution of the robot's IK")
    raise OrientationNotReachableError(
        result.orientation_residual, ROBOT_GOAL_ORIENTATION_TOLERANCE
    )


def _roll_is_free(robot: Any, space: JointSpace) -> bool:
    """Whether turning the last joint moves neither the tool point nor the approach axis (the
    tool z axis), from the robot's ``fk`` at a configuration inside the limits: then the roll of
    an approach goal is that joint's angle alone (the AL5)."""
    q = 0.5 * (space.lower + space.upper)
    turned = q.copy()
    turned[-1] = space.lower[-1] + 0.25 * (space.upper[-1] - space.lower[-1])
    if turned[-1] == q[-1]:
        return False
    before, after = np.asarray(robot.fk(q)), np.asarray(robot.fk(turned))
    moved = np.abs(before[:3, 2:4] - after[:3, 2:4]).max()
    return bool(moved <= _FREE_ROLL_TOLERANCE)


def goal_configurations(robot: Any, space: JointSpace, goal: Goal | Any) -> GoalSet:
    """Every configuration reaching ``goal`` within the joint limits (IK: every branch).

    A bare array is taken as a joint goal (shape (nq,)) or a pose goal (shape (4, 4)).

    Raises:
        ShapeError, NonFiniteInputError, ConfigurationOutsideLimitsError: bad goal.
        GoalUnreachableError: a pose/approach goal with no IK branch within the limits.
    """
    if not isinstance(goal, JointGoal | PoseGoal | ApproachGoal):
        array = np.asarray(goal, dtype=float)
        goal = PoseGoal(array) if array.shape == (4, 4) else JointGoal(array)
    if isinstance(goal, JointGoal):
        return GoalSet(space.check(goal.q, "goal")[None, :], ("joint goal",))
    approach_only = isinstance(goal, ApproachGoal)
    pose = goal.pose if isinstance(goal, PoseGoal) else goal.pose_at(0.0)
    rolls: np.ndarray | None = None
    reference = None
    if isinstance(goal, ApproachGoal) and _roll_is_free(robot, space):
        # The approach axis is the last joint's axis, with the tool point on it (the AL5): the
        # roll moves neither, so each sampled roll of that joint has the same branches in the
        # other joints (the IK sets it to the reference's). One IK, the roll set to each sample.
        # (Otherwise the IK leaves the roll free for an approach goal: every root, exactly.)
        rolls = np.linspace(space.lower[-1], space.upper[-1], goal.roll_samples)
        reference = np.zeros(space.dimension)
        reference[-1] = rolls[0]
    try:
        solutions = _exact_solutions(robot, pose, approach_only, reference)
    except KinematicsError as exc:
        raise GoalUnreachableError(str(exc)) from None
    found: list[np.ndarray] = []
    labels: list[str] = []
    nq = space.dimension
    for roll in [None] if rolls is None else rolls.tolist():
        for solution in solutions:
            q = np.array(solution.q, dtype=float)
            if roll is not None:
                q[-1] = roll
            if not solution.within_limits or not np.isfinite(q).all():
                continue
            if found and (np.abs(np.reshape(found, (-1, nq)) - q).max(axis=1) <= 1e-9).any():
                continue  # (a branch found before, to 1e-9 rad in every joint)
            found.append(np.clip(q, space.lower, space.upper))
            suffix = f" roll {np.degrees(q[-1]):.0f} deg" if approach_only else ""
            labels.append(f"{solution.branch}{suffix}")
    if not found:
        raise GoalUnreachableError("no IK branch within the limits")
    return GoalSet(np.array(found), tuple(labels))
