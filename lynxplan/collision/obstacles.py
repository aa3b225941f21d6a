"""Obstacles of the collision world: oriented boxes, spheres and cylinders, in SI units.

Every obstacle is a frozen value with a name, a pose (``centre`` + ``rotation``) and its size.
:func:`axis_aligned_box` builds a box from its minimum corner and size, the way SPEC Part 3 gives
the two walls of the "OK" task.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lynxplan import guards
from lynxplan.exceptions import InvalidObstacleError, NonFiniteInputError, ShapeError

#: ``max |R^T R - I|`` accepted for an obstacle's rotation matrix.
_ROTATION_TOLERANCE = 1e-9


def _vector(name: str, value: Any, length: int = 3) -> np.ndarray:
    array = np.array(guards.float_array(name, value))
    if array.shape != (length,):
        raise ShapeError(name, f"({length},)", array.shape)
    if not np.isfinite(array).all():
        raise NonFiniteInputError(name)
    guards.length(name, float(np.abs(array).max()))
    array.setflags(write=False)
    return array


def _rotation(name: str, value: Any) -> np.ndarray:
    if value is None:
        value = np.eye(3)
    array = np.array(guards.float_array(f"{name}.rotation", value))
    if array.shape != (3, 3):
        raise ShapeError(f"{name}.rotation", "(3, 3)", array.shape)
    if not np.isfinite(array).all():
        raise NonFiniteInputError(f"{name}.rotation")
    deviation = float(np.abs(array.T @ array - np.eye(3)).max())
    if deviation > _ROTATION_TOLERANCE or np.linalg.det(array) < 0:
        raise InvalidObstacleError(
            name, f"rotation is not a proper rotation (|RᵀR - I| = {deviation:.3g})"
        )
    array.setflags(write=False)
    return array


def _positive(obstacle: str, what: str, value: float) -> float:
    value = guards.real(f"obstacle {obstacle!r} {what}", value)
    if value > guards.MAX_ABS_LENGTH:
        raise InvalidObstacleError(
            obstacle, f"{what} = {value:g} m is larger than {guards.MAX_ABS_LENGTH:g} m"
        )
    if not np.isfinite(value) or value <= 0:
        raise InvalidObstacleError(obstacle, f"{what} must be positive and finite. Got: {value!r}")
    return float(value)


@dataclass(frozen=True)
class BoxObstacle:
    """A cuboid.

    Attributes:
        name: Name used in reports.
        centre: Centre, shape (3,), in [m].
        size: Edge lengths along the box's own x, y, z axes, shape (3,), in [m].
        rotation: Box axes in the world frame (columns), shape (3, 3).
    """

    name: str
    centre: np.ndarray
    size: np.ndarray
    rotation: np.ndarray = field(default_factory=lambda: np.eye(3))

    def __post_init__(self) -> None:
        object.__setattr__(self, "centre", _vector(f"{self.name}.centre", self.centre))
        object.__setattr__(self, "size", _vector(f"{self.name}.size", self.size))
        for axis, edge in zip("xyz", self.size.tolist(), strict=True):
            _positive(self.name, f"size along {axis}", edge)
        object.__setattr__(self, "rotation", _rotation(self.name, self.rotation))

    def fcl_geometry(self) -> Any:
        """The python-fcl shape (centred at its origin)."""
        import fcl

        return fcl.Box(*self.size.tolist())

    def coal_geometry(self) -> Any:
        """The coal shape (centred at its origin)."""
        import coal

        return coal.Box(*self.size.tolist())


@dataclass(frozen=True)
class SphereObstacle:
    """A ball.

    Attributes:
        name: Name used in reports.
        centre: Centre, shape (3,), in [m].
        radius: Radius, in [m].
    """

    name: str
    centre: np.ndarray
    radius: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "centre", _vector(f"{self.name}.centre", self.centre))
        object.__setattr__(self, "radius", _positive(self.name, "radius", self.radius))

    @property
    def rotation(self) -> np.ndarray:
        """Identity, shape (3, 3)."""
        return np.eye(3)

    def fcl_geometry(self) -> Any:
        """The python-fcl shape (centred at its origin)."""
        import fcl

        return fcl.Sphere(self.radius)

    def coal_geometry(self) -> Any:
        """The coal shape (centred at its origin)."""
        import coal

        return coal.Sphere(self.radius)


@dataclass(frozen=True)
class CylinderObstacle:
    """A solid circular cylinder.

    Attributes:
        name: Name used in reports.
        centre: Centre of the axis segment, shape (3,), in [m].
        radius: Radius, in [m].
        length: Length along the axis, in [m].
        rotation: Orientation, shape (3, 3); its third column is the cylinder axis.
    """

    name: str
    centre: np.ndarray
    radius: float
    length: float
    rotation: np.ndarray = field(default_factory=lambda: np.eye(3))

    def __post_init__(self) -> None:
        object.__setattr__(self, "centre", _vector(f"{self.name}.centre", self.centre))
        object.__setattr__(self, "radius", _positive(self.name, "radius", self.radius))
        object.__setattr__(self, "length", _positive(self.name, "length", self.length))
        object.__setattr__(self, "rotation", _rotation(self.name, self.rotation))

    def fcl_geometry(self) -> Any:
        """The python-fcl shape (axis along its local z, centred at its origin)."""
        import fcl

        return fcl.Cylinder(self.radius, self.length)

    def coal_geometry(self) -> Any:
        """The coal shape (axis along its local z, centred at its origin)."""
        import coal

        return coal.Cylinder(self.radius, self.length)


Obstacle = BoxObstacle | SphereObstacle | CylinderObstacle


def axis_aligned_box(name: str, min_corner: Any, size: Any) -> BoxObstacle:
    """An axis-aligned box from its minimum corner, shape (3,), and size, shape (3,), in [m]."""
    corner = _vector(f"{name}.min_corner", min_corner)
    extent = _vector(f"{name}.size", size)
    return BoxObstacle(name, corner + extent / 2.0, extent)


def rotation_from_axis(axis: Any) -> np.ndarray:
    """A rotation, shape (3, 3), whose third column is the unit vector along ``axis`` (3,)."""
    direction = _vector("axis", axis)
    norm = float(np.linalg.norm(direction))
    if norm == 0.0:
        raise InvalidObstacleError("axis", "the axis vector must not be zero")
    z = direction / norm
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    return np.column_stack((x, np.cross(z, x), z))
