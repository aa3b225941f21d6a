"""The arm kinematics a trajectory needs: tool poses of configurations, and IK along a sampled
path on the branch continuous with the previous sample.

Two implementations of :class:`PathKinematics`:

- :class:`Al5Kinematics` (the default): the AL5's closed-form kernels (:mod:`lynxplan.arm`).
- :class:`RobotKinematics`: any robot of :func:`lynxplan.load_robot` whose chain is a
  yaw-pitch-pitch-pitch-roll arm (SO-100, SO-101, the AL5 from its URDF): its closed-form /
  root-search IK (:meth:`lynxplan.robots.Robot.ik_batch`), every branch verified by FK.

The ``consistent`` orientation of a line needs the approach *pitch* of a pose: the angle of the
approach axis from straight down, towards the outward direction of the arm's vertical plane. For
the AL5 that plane contains the base axis and the tool point; for a robot with a lateral offset
it is the plane of the pitch joints, turned by the yaw joint.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple, Protocol

import numpy as np

from lynxplan.constants import REACH_TOLERANCE
from lynxplan.exceptions import InputError, PathNotFollowableError
from lynxplan.trajectory.limits import MotionLimits


class PathIk(NamedTuple):
    """IK along a path: one configuration per sample, continuous with the previous one."""

    q: np.ndarray
    """Joint angles, shape (m, n), in [rad]."""
    branch: np.ndarray
    """Branch index per sample, shape (m,)."""
    residual: np.ndarray
    """Angle between the interpolated and the reached orientation (or approach), (m,), [rad]."""


class PathTargets(NamedTuple):
    """Tool targets along a path: full poses, or tool points with an approach pitch and a roll."""

    poses: np.ndarray
    """Target poses, shape (m, 4, 4), in [m] (only the translation when ``pitch`` is given)."""
    pitch: np.ndarray | None = None
    """Approach pitch, shape (m,), in [rad] (0: straight down), or None for full poses."""
    roll: np.ndarray | None = None
    """Roll joint angle, shape (m,), in [rad] (with ``pitch``)."""


class PathKinematics(Protocol):
    """What the free and straight-line segments need from an arm."""

    nq: int

    def tool_poses(self, q: np.ndarray) -> np.ndarray:
        """Tool poses of ``q`` (N, n) [rad] -> (N, 4, 4), translations in [m]."""
        ...

    def pitch(self, pose: np.ndarray, q: np.ndarray) -> float:
        """Approach pitch of configuration ``q`` (n,) reaching ``pose`` (4, 4), in [rad]
        (0: straight down)."""
        ...

    def solve(
        self, targets: PathTargets, q_before: np.ndarray, limits: MotionLimits, s: np.ndarray
    ) -> PathIk:
        """IK of the targets along a path from ``q_before`` (n,); ``s`` (m,) is the path
        parameter of each target (named in errors).

        Raises:
            PathNotFollowableError: a target is out of reach.
        """
        ...

    def nearest(self, pose: np.ndarray, q_near: np.ndarray, limits: MotionLimits) -> np.ndarray:
        """The IK branch of ``pose`` (4, 4) nearest ``q_near`` (n,), within limits if any; (n,).

        Raises:
            PathNotFollowableError: the pose is out of reach.
        """
        ...


def _not_followable(s: np.ndarray, failed: np.ndarray, miss: np.ndarray) -> PathNotFollowableError:
    first = int(failed[0])
    return PathNotFollowableError(float(s[first]), float(miss[first]))


class Al5Kinematics:
    """The AL5's closed-form FK and four-branch IK kernels (SPEC Part 1).

    Args:
        geometry: The arm's dimensions (``lynxplan.arm.ArmGeometry``; default: the shipped AL5).
    """

    nq = 5

    def __init__(self, geometry: Any = None) -> None:
        from lynxplan.arm.geometry import ArmGeometry

        self.geometry = geometry if geometry is not None else ArmGeometry()

    def tool_poses(self, q: np.ndarray) -> np.ndarray:
        from lynxplan.arm.kinematics import forward_kinematics

        # Always a writable array: read-only and writable inputs are two signatures of the
        # compiled kernel, each one more load from numba's cache in a fresh process (~4 ms).
        return forward_kinematics(np.array(q, dtype=float), self.geometry)

    def pitch(self, pose: np.ndarray, q: np.ndarray) -> float:
        """The approach's angle in the vertical plane through the tool point of ``pose``."""
        T = pose
        radial = T[:2, 3] / max(math.hypot(T[0, 3], T[1, 3]), 1e-300)
        return math.atan2(float(radial @ T[:2, 2]), -float(T[2, 2]))

    def _solve(
        self,
        poses: np.ndarray,
        reference: np.ndarray | None,
        q_before: np.ndarray,
        limits: MotionLimits,
        s: np.ndarray,
    ) -> PathIk:
        from lynxplan.arm.ik import select_continuous, solve_ik_batch

        ik = solve_ik_batch(
            poses,
            q_reference=reference,
            approach_only=reference is not None,
            limits=limits.joint_limits,
            geometry=self.geometry,
        )
        failed = np.flatnonzero(ik.status != 0)
        if failed.size:
            raise _not_followable(s, failed, ik.reach_miss)
        q, branch = select_continuous(ik.q, ik.within_limits, np.asarray(q_before, dtype=float))
        return PathIk(q, branch, np.asarray(ik.orientation_error))

    def solve(
        self, targets: PathTargets, q_before: np.ndarray, limits: MotionLimits, s: np.ndarray
    ) -> PathIk:
        if targets.pitch is None:
            return self._solve(targets.poses, None, q_before, limits, s)
        # The approach axis in the vertical plane through the tool point; the roll is q5 of
        # the reference (only the approach column of the pose is used: approach_only).
        poses = targets.poses.copy()
        azimuth = np.arctan2(poses[:, 1, 3], poses[:, 0, 3])
        poses[:, 0, 2] = np.cos(azimuth) * np.sin(targets.pitch)
        poses[:, 1, 2] = np.sin(azimuth) * np.sin(targets.pitch)
        poses[:, 2, 2] = -np.cos(targets.pitch)
        reference = np.zeros((len(poses), 5))
        reference[:, 4] = targets.roll
        return self._solve(poses, reference, q_before, limits, s)

    def nearest(self, pose: np.ndarray, q_near: np.ndarray, limits: MotionLimits) -> np.ndarray:
        from lynxplan.arm.ik import select_continuous, solve_ik_batch

        ik = solve_ik_batch(pose[None], limits=limits.joint_limits, geometry=self.geometry)
        if ik.status[0] != 0:
            raise PathNotFollowableError(1.0, float(ik.reach_miss[0]))
        return np.asarray(select_continuous(ik.q, ik.within_limits, q_near)[0][0])


class RobotKinematics:
    """A yaw-pitch-pitch-pitch-roll robot of :func:`lynxplan.load_robot`.

    Args:
        robot: The robot (``lynxplan.robots.Robot``) with a recognised family.

    Raises:
        InputError: the robot's chain is not in the family (its IK is numerical: no continuous
            closed-form branches to follow along a line).
    """

    def __init__(self, robot: Any) -> None:
        family = robot.info().family_parameters
        if family is None:
            raise InputError(
                f"robot {robot.name}: straight-line and task motions need a yaw-pitch-pitch-"
                f"pitch-roll arm ({robot.info().family})"
            )
        self.robot = robot
        self.nq = int(robot.nq)
        self._yaw = np.asarray(family.yaw_axis, dtype=float)
        self._outward = np.cross(self._yaw, np.asarray(family.pitch_axis, dtype=float))
        self._yaw_sign = float(family.signs[0])
        self._approach = np.asarray(robot.approach_in_tool, dtype=float)

    def tool_poses(self, q: np.ndarray) -> np.ndarray:
        poses: np.ndarray = self.robot.fk(np.asarray(q, dtype=float).reshape(-1, self.nq))
        return poses

    def pitch(self, pose: np.ndarray, q: np.ndarray) -> float:
        """``atan2(a . h, -a . k)``: ``a`` the approach axis, ``k`` the yaw axis, ``h`` the
        outward direction of the pitch plane turned by the yaw joint."""
        q = np.asarray(q, dtype=float)
        approach = self.tool_poses(q)[0, :3, :3] @ self._approach
        angle = self._yaw_sign * float(q[0])
        k, h = self._yaw, self._outward
        # Rodrigues: h turned by `angle` about k (h is perpendicular to k).
        turned = math.cos(angle) * h + math.sin(angle) * np.cross(k, h)
        return math.atan2(float(approach @ turned), -float(approach @ k))

    def _follow(self, batch: Any, q_before: np.ndarray, s: np.ndarray) -> PathIk:

        ok = (
            batch.valid
            & (batch.position_error <= REACH_TOLERANCE + batch.distance[:, None])
            & batch.reachable[:, None]
        )
        failed = np.flatnonzero(~ok.any(axis=1))
        if failed.size:
            raise _not_followable(s, failed, batch.distance)
        m = len(batch.q)
        q = np.empty((m, self.nq))
        branch = np.empty(m, dtype=np.int64)
        residual = np.empty(m)
        previous = np.asarray(q_before, dtype=float)
        for k in range(m):
            cost = np.where(ok[k], ((batch.q[k] - previous) ** 2).sum(axis=1), np.inf)
            cost = np.where(batch.within_limits[k], cost, cost + 1e6)  # within limits first
            b = int(np.argmin(cost))
            q[k], branch[k], residual[k] = batch.q[k, b], b, batch.orientation_error[k, b]
            previous = q[k]
        return PathIk(q, branch, residual)

    def solve(
        self, targets: PathTargets, q_before: np.ndarray, limits: MotionLimits, s: np.ndarray
    ) -> PathIk:
        if targets.pitch is None:
            batch = self.robot.ik_batch(targets.poses, q_reference=q_before)
        else:
            batch = self.robot.ik_batch(
                positions=targets.poses[:, :3, 3],
                pitches=targets.pitch,
                rolls=targets.roll,
                q_reference=q_before,
            )
        return self._follow(batch, q_before, s)

    def nearest(self, pose: np.ndarray, q_near: np.ndarray, limits: MotionLimits) -> np.ndarray:
        q: np.ndarray = self.solve(PathTargets(pose[None]), q_near, limits, np.ones(1)).q[0]
        return q
