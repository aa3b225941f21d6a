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
#: ... and a URDF robot's branch the orientation (approach axis) to this, in [rad]: its IK
#: polishes off-family models (the SO-101's axes are 3.7e-6 rad off parallel) to ~6e-6 rad.
ROBOT_GOAL_ORIENTATION_TOLERANCE = 1e-5


def _exact_solutions(
    robot: Any, pose: np.ndarray, approach_only: bool, reference: np.ndarray | None
) -> tuple[Any, ...]:
    """The IK branches that reach ``pose`` (4, 4): the position exactly, and the orientation (or,
    ``approach_only``, the approach axis) within the AL5's
    :data:`~lynxplan.constants.STRICT_ORIENTATION_TOLERANCE` or a URDF robot's
    :data:`ROBOT_GOAL_ORIENTATION_TOLERANCE`.

    Raises:
        KinematicsError: the pose is out of reach (the AL5's strict IK; a URDF robot's nearest
            solution misses it).
    """
    from lynxplan.arm.model import Arm

    if isinstance(robot, Arm):
        result = robot.ik(pose, approach_only=approach_only, strict=True, q_reference=reference)
        return tuple(result.solutions)
    result = robot.ik(pose, approach_only=approach_only, q_reference=reference)
    exact = tuple(
        s
        for s in result.solutions
        if s.position_error <= GOAL_POSITION_TOLERANCE
        and s.orientation_error <= ROBOT_GOAL_ORIENTATION_TOLERANCE
    )
    if not exact and result.distance > GOAL_POSITION_TOLERANCE:
        raise UnreachablePoseError(result.distance, "nearest solution of the robot's IK")
    if not exact:
        raise OrientationNotReachableError(
            result.orientation_residual, ROBOT_GOAL_ORIENTATION_TOLERANCE
        )
    return exact


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
    from lynxplan.arm.model import Arm

    approach_only = isinstance(goal, ApproachGoal)
    pose = goal.pose if isinstance(goal, PoseGoal) else goal.pose_at(0.0)
    rolls: np.ndarray | None = None
    reference = None
    if isinstance(goal, ApproachGoal) and isinstance(robot, Arm):
        # The AL5's approach axis is its roll axis, with the tool point on it: the roll moves
        # neither, so each sampled roll of the last joint has the same branches in the other
        # joints (the IK sets q5 to the reference's). One IK, the roll set to each sample.
        # (A URDF robot's IK leaves the roll free for an approach goal: every root, exactly.)
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
