"""The base error classes and the errors of bad input (values, shapes, units, scenarios).

Each subclass keeps the offending values as attributes, and its message is one line a user can act
on.
"""

from __future__ import annotations


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


class ModelError(LynxplanInputError):
    """A robot model (URDF) cannot be loaded or does not have the expected structure."""


class MeshNotFoundError(ModelError):
    """A mesh a URDF names (``<mesh filename=...>``) is not found in any mesh search folder.

    Attributes:
        mesh: The ``filename`` as the URDF writes it.
        urdf: Name of the URDF.
        searched: The folders searched, in order.
    """

    def __init__(self, mesh: str, urdf: str, searched: tuple[str, ...], hint: str) -> None:
        self.mesh = mesh
        self.urdf = urdf
        self.searched = searched
        super().__init__(f"URDF {urdf}: mesh {mesh or '(empty filename)'} not found ({hint})")


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


__all__ = [
    "InputError",
    "LynxplanError",
    "LynxplanInputError",
    "ModelError",
    "NonFiniteInputError",
    "NotRigidTransformError",
    "OutOfRangeError",
    "ResourceLimitError",
    "ScenarioError",
    "ScenarioValueError",
    "ShapeError",
    "SingularityParameterError",
    "TaskError",
    "TimingError",
    "UnknownUnitError",
]
