"""Errors of kinematics: unreachable poses, IK without a solution, the parallel robot's legs and
assembly modes, robot models and targets.
"""

from __future__ import annotations

import math

from lynxplan.exceptions.base import InputError, LynxplanError


class KinematicsError(LynxplanError):
    """A kinematics problem has no acceptable solution."""


class UnreachablePoseError(KinematicsError):
    """The tool position cannot be reached with the requested approach direction.

    Attributes:
        distance: By how much the wrist centre misses the reachable annulus, in [m].
    """

    def __init__(self, distance: float, detail: str = "") -> None:
        self.distance = distance
        extra = f" ({detail})" if detail else ""
        super().__init__(
            f"pose is out of reach: the wrist centre misses the arm's reach by "
            f"{distance * 1000:.4g} mm{extra}"
        )


class OrientationNotReachableError(KinematicsError):
    """Strict IK: the orientation cannot be reached by the 5-DOF arm within tolerance.

    Attributes:
        residual: Angle between the target and the nearest reachable orientation, in [rad].
        tolerance: The accepted residual, in [rad].
    """

    def __init__(self, residual: float, tolerance: float) -> None:
        self.residual = residual
        self.tolerance = tolerance
        super().__init__(
            f"orientation not reachable by the 5-DOF arm: residual {residual:.6g} rad exceeds "
            f"the strict tolerance {tolerance:.3g} rad"
        )


class NoSolutionWithinLimitsError(KinematicsError):
    """IK found solutions, but none within the joint limits."""


class PathNotFollowableError(KinematicsError):
    """A Cartesian path leaves the arm's reach: some sample has no IK solution.

    Attributes:
        s: Path parameter in [0, 1] of the first failing sample.
        reach_miss: By how much that sample misses the reach, in [m].
    """

    def __init__(self, s: float, reach_miss: float, what: str = "straight line") -> None:
        self.s = s
        self.reach_miss = reach_miss
        super().__init__(
            f"{what} leaves the arm's reach at s = {s:.4f} (missed by {reach_miss * 1000:.4g} mm)"
        )


class LegUnreachableError(KinematicsError):
    """A leg of the 3-RRR parallel robot cannot reach its platform joint.

    Attributes:
        leg: Name of the leg (``"A"``, ``"B"`` or ``"C"``).
        distance: Base-joint-to-platform-joint distance the pose needs, in [m].
        min_distance: Smallest distance the leg spans ``|S - L|``, in [m].
        max_distance: Largest distance the leg spans ``S + L``, in [m].
    """

    def __init__(self, leg: str, distance: float, min_distance: float, max_distance: float) -> None:
        self.leg = leg
        self.distance = distance
        self.min_distance = min_distance
        self.max_distance = max_distance
        super().__init__(
            f"parallel robot: {leg_unreachable_reason(leg, distance, min_distance, max_distance)}"
        )


def leg_unreachable_reason(
    leg: str, distance: float, min_distance: float, max_distance: float
) -> str:
    """One-line reason why leg ``leg`` cannot span ``distance`` (lengths in [m], printed in mm)."""
    return (
        f"leg {leg} cannot reach its platform joint: it needs a base-to-platform-joint distance of "
        f"{distance * 1e3:.4f} mm, outside the range [{min_distance * 1e3:.4f}, "
        f"{max_distance * 1e3:.4f}] mm it spans"
    )


def _degrees(theta: tuple[float, ...]) -> str:
    """Angles in [rad] as a comma-separated list in degrees, for messages."""
    return ", ".join(f"{math.degrees(t):.4f}" for t in theta)


class _ActuatedAnglesError(KinematicsError):
    """A 3-RRR forward-kinematics problem with given actuated angles.

    Attributes:
        theta: The actuated angles, shape (3,), in [rad].
    """

    _problem = ""

    def __init__(self, theta: tuple[float, float, float]) -> None:
        self.theta = theta
        super().__init__(
            f"parallel robot: the actuated angles ({_degrees(theta)}) deg {self._problem}"
        )


class DegenerateForwardKinematicsError(_ActuatedAnglesError):
    """Forward kinematics of the 3-RRR has a continuum of solutions (architecture singularity)."""

    _problem = (
        "leave the platform free to move (the closure polynomial vanishes identically); "
        "forward kinematics is not finite"
    )


class NoAssemblyModeError(_ActuatedAnglesError):
    """The actuated angles of the 3-RRR admit no real assembly mode."""

    _problem = "admit no assembly mode (the distal links cannot all meet the platform)"


class RobotError(LynxplanError):
    """A robot cannot be loaded or used as asked."""


class UnknownRobotError(RobotError, InputError):
    """A robot name that is neither a built-in robot nor an existing URDF file.

    Attributes:
        name: The name or path given.
        valid: The built-in robot names.
    """

    def __init__(self, name: str, valid: tuple[str, ...]) -> None:
        self.name = name
        self.valid = valid
        super().__init__(
            f"unknown robot {name!r}: not a built-in robot ({', '.join(valid)}) nor a URDF file"
        )


class TargetError(RobotError, InputError):
    """An IK target is malformed (wrong kind, zero approach vector, missing field).

    Attributes:
        reason: What is wrong.
    """

    def __init__(self, reason: str) -> None:
        self.reason = reason
        super().__init__(f"IK target: {reason}")


class IkFailedError(RobotError, KinematicsError):
    """No verified IK solution for a target (the numerical solver did not converge).

    Attributes:
        position_error: The smallest position error reached, in [m].
    """

    def __init__(self, position_error: float, detail: str = "") -> None:
        self.position_error = position_error
        suffix = f"; {detail}" if detail else ""
        super().__init__(f"IK failed: best position error {position_error:.3g} m{suffix}")


__all__ = [
    "DegenerateForwardKinematicsError",
    "IkFailedError",
    "KinematicsError",
    "LegUnreachableError",
    "NoAssemblyModeError",
    "NoSolutionWithinLimitsError",
    "OrientationNotReachableError",
    "PathNotFollowableError",
    "RobotError",
    "TargetError",
    "UnknownRobotError",
    "UnreachablePoseError",
    "leg_unreachable_reason",
]
