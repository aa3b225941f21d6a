"""Every error lynxplan raises on purpose: one base class, specific subclasses.

Each subclass keeps the offending values as attributes, and its message is one line a user can act
on. The CLI prints that line and exits non-zero; it never shows a traceback for bad input.
"""

from __future__ import annotations


class LynxplanError(Exception):
    """Base class of every error raised by lynxplan on purpose."""


class InputError(LynxplanError, ValueError):
    """An argument has the wrong shape, type, value or unit."""


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

    def __init__(self, name: str) -> None:
        self.name = name
        super().__init__(f"{name} contains NaN or infinite values")


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
        super().__init__(
            f"{what} is not a rigid transform: rotation deviates from orthonormal by "
            f"{deviation:.3g} (at most {tolerance:.3g} is re-orthonormalised)"
        )


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


class ScenarioError(LynxplanError):
    """A scenario file is missing, unreadable or invalid.

    Attributes:
        file: Path of the scenario file.
        location: Key path inside the file, e.g. ``"segments[3].ta"``, or ``""``.
        reason: What is wrong.
    """

    def __init__(self, file: str, location: str, reason: str) -> None:
        self.file = file
        self.location = location
        self.reason = reason
        where = f"{file}, {location}" if location else file
        super().__init__(f"scenario {where}: {reason}")
