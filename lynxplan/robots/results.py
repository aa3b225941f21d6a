"""Typed, read-only results of the robot IK solvers."""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from lynxplan.branches import IkResult, IkSolution

#: One IK branch of any robot, verified by FK on the exact model: the AL5's branch type (one
#: type for both; its ``q`` has shape (n,) here).
RobotIkSolution = IkSolution


#: IK of one target (every branch, one selected): the one result type of every arm.
RobotIkResult = IkResult


class BranchSlots(NamedTuple):
    """The arrays the IK kernels write for N targets and B branch slots (internal; the batch
    result is made of them): empty slots NaN / False."""

    q: np.ndarray
    """(N, B, n) [rad]."""
    valid: np.ndarray
    """(N, B) bool."""
    within: np.ndarray
    """(N, B) bool."""
    position_error: np.ndarray
    """(N, B) [m]."""
    orientation_error: np.ndarray
    """(N, B) [rad]."""

    @classmethod
    def empty(cls, n: int, slots: int, nq: int = 5) -> BranchSlots:
        """Uninitialised arrays (the kernels write every slot of the targets they solve)."""
        return cls(
            np.empty((n, slots, nq)),
            np.empty((n, slots), dtype=np.bool_),
            np.empty((n, slots), dtype=np.bool_),
            np.empty((n, slots)),
            np.empty((n, slots)),
        )

    def clear(self) -> None:
        """Every slot empty."""
        self.q.fill(np.nan)
        self.valid.fill(False)
        self.within.fill(False)
        self.position_error.fill(np.nan)
        self.orientation_error.fill(np.nan)

    def rows(self, mask: np.ndarray) -> BranchSlots:
        """A copy of the targets in ``mask`` (N,) bool."""
        return BranchSlots(*(np.ascontiguousarray(a[mask]) for a in self))

    def put(self, mask: np.ndarray, part: BranchSlots) -> None:
        """Write ``part`` (from :meth:`rows`) back to the targets in ``mask``."""
        for whole, piece in zip(self, part, strict=True):
            whole[mask] = piece


class RobotIkBatch(NamedTuple):
    """IK of N targets, every branch slot. Arrays are read-only; empty slots are NaN/False.

    B, the number of slots, depends on the target kind and the tool (``Robot.ik_batch``): 4, 8
    for full poses of an off-axis tool, 24 for its approach targets."""

    q: np.ndarray
    """Joint angles, shape (N, B, n), in [rad]; NaN in unused slots."""
    valid: np.ndarray
    """Whether a slot holds a verified branch, shape (N, B), bool."""
    within_limits: np.ndarray
    """Whether each branch is within the joint limits, shape (N, B), bool."""
    position_error: np.ndarray
    """FK position error of each branch, shape (N, B), in [m]."""
    orientation_error: np.ndarray
    """Orientation error of each branch, shape (N, B), in [rad] (see RobotIkSolution)."""
    reachable: np.ndarray
    """Whether some branch reaches the position, shape (N,), bool."""
    distance: np.ndarray
    """Smallest position error over the branches, shape (N,), in [m]."""
    branch_names: tuple[str, ...]
    """Name of each of the B slots."""


@dataclass(frozen=True)
class TrackJump:
    """A step of a track where no branch continues the previous configuration.

    Attributes:
        index: Index of the target (the jump is from ``index - 1`` to ``index``).
        size: Largest joint change of the step, in [rad].
    """

    index: int
    size: float


@dataclass(frozen=True)
class TrackResult:
    """IK along a sequence of targets, branch by branch continuity.

    Attributes:
        q: Joint angles, shape (N, n), in [rad]; NaN where no solution (read-only).
        branch: Branch slot per target, shape (N,), -1 where none (read-only).
        jumps: Steps larger than the continuity threshold: flagged, never silent.
        unsolved: Indices of targets with no solution within limits.
        max_step: Largest joint change between consecutive solved targets, in [rad].
    """

    q: np.ndarray
    branch: np.ndarray
    jumps: tuple[TrackJump, ...]
    unsolved: tuple[int, ...]
    max_step: float

    @property
    def continuous(self) -> bool:
        """Whether every target is solved with no jump."""
        return not self.jumps and not self.unsolved


@dataclass(frozen=True)
class JointInfo:
    """One joint of the arm chain.

    Attributes:
        name: URDF joint name.
        lower, upper: Position limits, in [rad].
        velocity: Velocity limit, in [rad/s].
    """

    name: str
    lower: float
    upper: float
    velocity: float


@dataclass(frozen=True)
class RobotInfo:
    """What ``lynxplan robot info`` prints.

    Attributes:
        name: Robot name.
        urdf: URDF path.
        tool_frame: Tool frame name.
        joints: The arm joints.
        locked_joints: Joints off the chain (a gripper jaw), with the value they are held at.
        family: ``"yaw-pitch-pitch-pitch-roll"`` or why not (the reason).
        family_parameters: Parameters of the recognised family (``FamilyParameters``), or None.
        ik_solver: The IK solver used.
    """

    name: str
    urdf: str
    tool_frame: str
    joints: tuple[JointInfo, ...]
    locked_joints: tuple[tuple[str, float], ...]
    family: str
    family_parameters: object | None
    ik_solver: str
