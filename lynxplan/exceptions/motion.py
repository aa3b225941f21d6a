"""Errors of motion: retiming, obstacles and collision models, trajectory checks and planning."""

from __future__ import annotations

from lynxplan.exceptions.base import InputError, LynxplanError


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


__all__ = [
    "CollisionModelError",
    "ConfigurationOutsideLimitsError",
    "GoalUnreachableError",
    "InvalidObstacleError",
    "PathVerificationError",
    "PlanningError",
    "PlanningFailed",
    "RetimingError",
    "StateInCollisionError",
    "TrajectoryCheckError",
]
