"""Every error lynxplan raises on purpose: one base class, specific subclasses.

Each subclass keeps the offending values as attributes, and its message is one line a user can act
on. The CLI prints that line and exits non-zero; it never shows a traceback for bad input.
"""

from __future__ import annotations

import math


class LynxplanError(Exception):
    """Base class of every error raised by lynxplan on purpose."""


class LynxplanInputError(LynxplanError, ValueError):
    """Bad input: a value, array, file or option lynxplan refuses (the CLI exits 2).

    Every error caused by what the user gave (as opposed to a problem without a solution, such
    as an unreachable pose) is a subclass of this one.
    """


class InputError(LynxplanInputError):
    """An argument has the wrong shape, type, value or unit."""


class OutOfRangeError(InputError):
    """A value lies outside the documented valid range of its quantity (see lynxplan.guards).

    Attributes:
        name: Name of the value (argument, option or scenario key).
        value: The value given.
        requirement: The valid range, e.g. ``"finite, |q| <= 100 rad"``.
    """

    def __init__(self, name: str, value: object, requirement: str) -> None:
        self.name = name
        self.value = value
        self.requirement = requirement
        super().__init__(f"{name} = {_short(value)} is out of range: must be {requirement}")


class ResourceLimitError(InputError):
    """A request would exceed a resource limit (memory or time) and is refused before it starts.

    Attributes:
        quantity: What is counted, e.g. ``"workspace grid cells"``.
        requested: The size the input implies.
        limit: The largest size allowed.
        how_to_raise: How the user can raise the limit (an option or a scenario ``limits:`` key).
    """

    def __init__(self, quantity: str, requested: float, limit: float, how_to_raise: str) -> None:
        self.quantity = quantity
        self.requested = requested
        self.limit = limit
        self.how_to_raise = how_to_raise
        super().__init__(
            f"{quantity}: {requested:.4g} requested, more than the limit of {limit:.4g}; "
            f"{how_to_raise}"
        )


def _short(value: object, width: int = 60) -> str:
    """``repr`` of a value cut to ``width`` characters, for one-line messages."""
    text = f"{value:.6g}" if isinstance(value, float) else repr(value)
    return text if len(text) <= width else text[: width - 3] + "..."


class ShapeError(InputError):
    """An array does not have the expected shape.

    Attributes:
        name: Name of the argument.
        expected: Description of the expected shape, e.g. ``"(5,) or (N, 5)"``.
        got: The shape received.
    """

    def __init__(self, name: str, expected: str, got: tuple[int, ...]) -> None:
        self.name = name
        self.expected = expected
        self.got = got
        super().__init__(f"{name} must have shape {expected}. Got: {got}")


class NonFiniteInputError(InputError):
    """An input contains NaN or infinity.

    Attributes:
        name: Name of the argument.
    """

    def __init__(self, name: str, detail: str = "") -> None:
        self.name = name
        extra = f" ({detail})" if detail else ""
        super().__init__(f"{name} contains NaN or infinite values{extra}")


class UnknownUnitError(InputError):
    """A unit name is not one lynxplan knows.

    Attributes:
        unit: The unit given.
        valid: The accepted unit names.
    """

    def __init__(self, unit: str, valid: tuple[str, ...], quantity: str) -> None:
        self.unit = unit
        self.valid = valid
        super().__init__(f"unknown {quantity} unit {unit!r}; valid units: {', '.join(valid)}")


class NotRigidTransformError(InputError):
    """A 4x4 matrix is not a rigid transform (rotation part too far from orthonormal).

    Attributes:
        deviation: ``max |R^T R - I|`` or the bottom-row error of the matrix.
        tolerance: The largest deviation that would have been repaired.
    """

    def __init__(self, deviation: float, tolerance: float, what: str = "pose") -> None:
        self.deviation = deviation
        self.tolerance = tolerance
        if tolerance > 0:
            detail = (
                f"rotation deviates from orthonormal by {deviation:.3g} (at most "
                f"{tolerance:.3g} is re-orthonormalised)"
            )
        else:
            detail = f"off by {deviation:.3g}"
        super().__init__(f"{what} is not a rigid transform: {detail}")


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


class ScenarioError(LynxplanInputError):
    """A scenario file is missing, unreadable or invalid.

    Attributes:
        file: Path of the scenario file.
        location: Key path inside the file, e.g. ``"segments[3].ta"``, or ``""``.
        reason: What is wrong.
        line: 1-based line of the key in the file, when known.
    """

    def __init__(self, file: str, location: str, reason: str, line: int | None = None) -> None:
        self.file = file
        self.location = location
        self.reason = reason
        self.line = line
        where = f"{file}, {location}" if location else file
        at = f" (line {line})" if line is not None else ""
        super().__init__(f"scenario {where}: {reason}{at}")


class ScenarioValueError(LynxplanError):
    """A scenario value found unusable while running it (e.g. an unreachable waypoint).

    The scenario runner turns it into a :class:`ScenarioError` naming the file and the line.

    Attributes:
        loc: Key path inside the scenario, e.g. ``("waypoints", "O2", "pose")``.
        reason: What is wrong.
        value: The offending value, or None.
    """

    def __init__(self, loc: tuple[str | int, ...], reason: str, value: object = None) -> None:
        self.loc = loc
        self.reason = reason
        self.value = value
        super().__init__(reason)


class TimingError(InputError):
    """An LSPB time law is impossible: durations not positive, or blends that would overlap.

    Attributes:
        tt: Total segment time, in [s].
        ta: Blend time, in [s].
    """

    def __init__(self, tt: float, ta: float, reason: str) -> None:
        self.tt = tt
        self.ta = ta
        super().__init__(f"invalid LSPB timing tt = {tt:.6g} s, ta = {ta:.6g} s: {reason}")


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


class ModelError(LynxplanInputError):
    """A robot model (URDF) cannot be loaded or does not have the expected structure."""


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


class RetimingError(LynxplanError):
    """A time-parameterisation library (ruckig, toppra) found no trajectory.

    Attributes:
        method: ``"ruckig"`` or ``"toppra"``.
        reason: What the library reported.
    """

    def __init__(self, method: str, reason: str) -> None:
        self.method = method
        self.reason = reason
        super().__init__(f"{method} found no trajectory: {reason}")


class InvalidObstacleError(InputError):
    """An obstacle has a non-positive size or an improper rotation.

    Attributes:
        obstacle: Name of the obstacle.
        reason: What is wrong.
    """

    def __init__(self, obstacle: str, reason: str) -> None:
        self.obstacle = obstacle
        self.reason = reason
        super().__init__(f"obstacle {obstacle!r}: {reason}")


class CollisionModelError(LynxplanError):
    """The robot's collision geometry has a shape or joint the collision checker cannot handle.

    Attributes:
        geometry: Name of the offending geometry object or joint.
    """

    def __init__(self, geometry: str, reason: str) -> None:
        self.geometry = geometry
        super().__init__(f"collision model, {geometry}: {reason}")


class TrajectoryCheckError(InputError):
    """A trajectory handed to the collision or limit check is malformed (e.g. times not
    strictly increasing)."""


# -- motion planning (lynxplan.planning) ---------------------------------------------------------


class PlanningError(LynxplanError):
    """Base class of the motion planner's errors."""


class ConfigurationOutsideLimitsError(InputError, PlanningError):
    """A start or goal configuration has a joint outside its position limits.

    Attributes:
        what: ``"start"`` or ``"goal"``.
        joint: Joint name.
        value: The joint's value, in [rad].
        lower: Lower limit, in [rad].
        upper: Upper limit, in [rad].
    """

    def __init__(self, what: str, joint: str, value: float, lower: float, upper: float) -> None:
        self.what, self.joint, self.value = what, joint, value
        self.lower, self.upper = lower, upper
        super().__init__(
            f"{what}: joint {joint} = {value:.6g} rad is outside its limits "
            f"[{lower:.6g}, {upper:.6g}] rad"
        )


class StateInCollisionError(InputError, PlanningError):
    """The start or goal configuration collides (or is closer than the required clearance).

    Attributes:
        what: ``"start"`` or ``"goal"`` (``"goal (every IK branch)"`` for a pose goal).
        link: URDF link of the colliding primitive.
        obstacle: Obstacle name (``"self:<geometry>"`` for a self-collision).
        penetration_depth: Penetration depth (exact, coal), in [m]; negative: the distance by
            which a collision-free state misses the required clearance.
        clearance: The required clearance, in [m].
    """

    def __init__(
        self, what: str, link: str, obstacle: str, penetration_depth: float, clearance: float
    ) -> None:
        self.what, self.link, self.obstacle = what, link, obstacle
        self.penetration_depth, self.clearance = penetration_depth, clearance
        if penetration_depth >= 0:
            detail = f"penetration depth {penetration_depth * 1e3:.3f} mm"
        else:
            detail = (
                f"distance {-penetration_depth * 1e3:.3f} mm is below the required clearance "
                f"{clearance * 1e3:.3f} mm"
            )
        super().__init__(f"{what} is in collision: link {link} with {obstacle}, {detail}")


class GoalUnreachableError(PlanningError):
    """No IK branch of a pose goal is within the joint limits.

    Attributes:
        reason: What IK reported.
    """

    def __init__(self, reason: str) -> None:
        self.reason = reason
        super().__init__(f"goal: no configuration reaches it: {reason}")


class PlanningFailed(PlanningError):  # noqa: N818 (the name the issue gives)
    """The planner found no collision-free path within its time and node budgets.

    Attributes:
        nodes: Number of tree nodes created (both trees).
        iterations: Number of sampling iterations.
        elapsed: Planning time spent, in [s].
        reason: Why the search stopped: ``"time limit 1 s reached"``, ``"node limit 20000
            reached"``, or a start/goal the conservative checker cannot certify.
    """

    def __init__(self, nodes: int, iterations: int, elapsed: float, reason: str) -> None:
        self.nodes, self.iterations, self.elapsed, self.reason = nodes, iterations, elapsed, reason
        super().__init__(
            f"no collision-free path found after {nodes} nodes "
            f"({iterations} iterations, {elapsed * 1e3:.1f} ms): {reason}"
        )


class PathVerificationError(PlanningError):
    """The exact collision check rejected a planned path (a planner bug: never expected).

    Attributes:
        detail: The contact or uncertified interval found.
    """

    def __init__(self, detail: str) -> None:
        self.detail = detail
        super().__init__(f"planned path failed the exact collision check: {detail}")


class TaskError(InputError):
    """A singularity task (selection of tool-Jacobian rows) is unknown or unusable.

    Attributes:
        task: The task name or row given.
        reason: What is wrong, with the valid choices.
    """

    def __init__(self, task: str, reason: str) -> None:
        self.task = task
        self.reason = reason
        super().__init__(f"task {task!r}: {reason}")


class SingularityParameterError(InputError):
    """A parameter of a singularity-handling strategy is out of range.

    Attributes:
        name: Parameter name, e.g. ``"sigma"``.
        value: The value given.
        requirement: What the value must satisfy, e.g. ``"> 0"``.
    """

    def __init__(self, name: str, value: float, requirement: str) -> None:
        self.name = name
        self.value = value
        self.requirement = requirement
        super().__init__(f"singularity parameter {name} = {value!r} must be {requirement}")


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
