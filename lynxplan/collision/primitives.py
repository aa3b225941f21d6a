"""The arm's collision primitives (boxes, cylinders) with their covering spheres and joint reach,
and the obstacles' arrays and signed distance for the vectorised lower bound (see
:mod:`lynxplan.collision.world`)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from lynxplan.collision import _kernels
from lynxplan.collision.obstacles import BoxObstacle, CylinderObstacle, Obstacle, SphereObstacle
from lynxplan.exceptions import CollisionModelError

_AXES = {"JointModelRX": 0, "JointModelRY": 1, "JointModelRZ": 2}


@dataclass(frozen=True)
class LinkPrimitive:
    """One collision primitive of the arm.

    Attributes:
        geometry: Name of the geometry object, e.g. ``"gripper_1"``.
        link: Name of the URDF link carrying it, e.g. ``"gripper"``.
        joint: Index of the Pinocchio joint that moves it (0: fixed to the base).
        placement: Pose in the joint frame, shape (4, 4), in [m].
        kind: ``"box"`` or ``"cylinder"``.
        half_extents: Box half sizes (3,), or (radius, half length, 0) of a cylinder, in [m].
        sphere_centres: Covering sphere centres in the primitive frame, shape (K, 3), in [m].
        sphere_radius: Radius of every covering sphere, in [m].
        reach: Upper bound of the distance of any point of the primitive from the axis of each
            joint (shape (nq,), in [m]; 0 for joints that do not move it).
    """

    geometry: str
    link: str
    joint: int
    placement: np.ndarray
    kind: str
    half_extents: np.ndarray
    sphere_centres: np.ndarray
    sphere_radius: float
    reach: np.ndarray


def joint_structure(model: Any) -> tuple[list[tuple[int, int]], list[np.ndarray]]:
    axes: list[tuple[int, int]] = [(-1, -1)]
    for j in range(1, model.njoints):
        joint = model.joints[j]
        if joint.shortname() not in _AXES:
            raise CollisionModelError(
                model.names[j], f"joint type {joint.shortname()} is not supported (revolute x/y/z)"
            )
        axes.append((_AXES[joint.shortname()], joint.idx_q))
    placements = [np.array(model.jointPlacements[j].homogeneous) for j in range(model.njoints)]
    return axes, placements


def link_primitive(
    model: Any, geometry_object: Any, joint_placements: list[np.ndarray]
) -> LinkPrimitive:
    shape = geometry_object.geometry
    kind = type(shape).__name__
    name = geometry_object.name
    if kind == "Box":
        half = np.array(shape.halfSide, dtype=float)
        longest = int(np.argmax(half))
        second = float(np.sort(half)[-2])
        pieces = max(1, math.ceil(half[longest] / second))
        bounding = float(np.linalg.norm(half))
    elif kind == "Cylinder":
        half = np.array([shape.radius, shape.halfLength, 0.0])
        longest = 2
        pieces = max(1, math.ceil(shape.halfLength / shape.radius))
        bounding = math.hypot(shape.radius, shape.halfLength)
    else:
        raise CollisionModelError(name, f"shape {kind} is not supported (box or cylinder)")
    length = half[longest] if kind == "Box" else shape.halfLength
    piece_half = length / pieces
    centres = np.zeros((pieces, 3))
    centres[:, longest] = -length + piece_half * (2 * np.arange(pieces) + 1)
    if kind == "Box":
        sub = half.copy()
        sub[longest] = piece_half
        radius = float(np.linalg.norm(sub))
    else:
        radius = math.hypot(shape.radius, piece_half)
    placement = np.array(geometry_object.placement.homogeneous)
    joint = int(geometry_object.parentJoint)
    reach = np.zeros(model.nq)
    # Distance of any point of the primitive from joint j's origin (on its axis), bounded by the
    # chain of joint offsets from j down to the primitive's joint plus the primitive's extent.
    chain = float(np.linalg.norm(placement[:3, 3])) + bounding
    current = joint
    while current > 0:
        reach[model.joints[current].idx_q] = chain
        chain += float(np.linalg.norm(joint_placements[current][:3, 3]))
        current = model.parents[current]
    for array in (placement, half, centres, reach):
        array.setflags(write=False)
    link = model.frames[geometry_object.parentFrame].name
    return LinkPrimitive(name, link, joint, placement, kind.lower(), half, centres, radius, reach)


def fcl_shape(primitive: LinkPrimitive) -> Any:
    import fcl

    if primitive.kind == "box":
        return fcl.Box(*(2.0 * primitive.half_extents).tolist())
    radius, half_length, _ = primitive.half_extents.tolist()
    return fcl.Cylinder(radius, 2.0 * half_length)


def obstacle_arrays(obstacles: tuple[Obstacle, ...]) -> tuple[np.ndarray, ...]:
    """Obstacle kinds, centres (O, 3), rotations (O, 3, 3), half sizes (O, 3) for the kernels."""
    kinds = np.zeros(len(obstacles), dtype=np.int64)
    sizes = np.zeros((len(obstacles), 3))
    for o, obstacle in enumerate(obstacles):
        if isinstance(obstacle, BoxObstacle):
            kinds[o], sizes[o] = _kernels.BOX, obstacle.size / 2.0
        elif isinstance(obstacle, SphereObstacle):
            kinds[o], sizes[o, 0] = _kernels.SPHERE, obstacle.radius
        else:
            kinds[o] = _kernels.CYLINDER
            sizes[o, :2] = obstacle.radius, obstacle.length / 2.0
    centres = np.array([o.centre for o in obstacles]).reshape(-1, 3)
    rotations = np.array([np.asarray(o.rotation) for o in obstacles]).reshape(-1, 3, 3)
    return kinds, centres, rotations, sizes


def signed_distance(obstacle: Obstacle, points: np.ndarray) -> np.ndarray:
    """Exact signed distance of points (..., 3) to an obstacle, in [m] (negative inside)."""
    local = (points - obstacle.centre) @ np.asarray(obstacle.rotation)
    if isinstance(obstacle, SphereObstacle):
        return np.asarray(np.linalg.norm(local, axis=-1) - obstacle.radius)
    if isinstance(obstacle, BoxObstacle):
        excess = np.abs(local) - obstacle.size / 2.0
    elif isinstance(obstacle, CylinderObstacle):
        excess = np.stack(
            (
                np.linalg.norm(local[..., :2], axis=-1) - obstacle.radius,
                np.abs(local[..., 2]) - obstacle.length / 2.0,
            ),
            axis=-1,
        )
    outside = np.linalg.norm(np.maximum(excess, 0.0), axis=-1)
    return np.asarray(outside + np.minimum(excess.max(axis=-1), 0.0))
