"""The arm's collision primitives (boxes, cylinders, meshes) with their covering spheres and joint
reach, and the obstacles' arrays and signed distance for the vectorised lower bound (see
:mod:`lynxplan.collision.world`).

A mesh (a URDF ``<mesh>`` collision element, e.g. the SO-101's STL parts) is replaced by its
convex hull (coal's qhull), expressed in the frame of the hull's axis-aligned bounding box: exact
distances are taken to the hull, never more than the distance to the mesh itself (the safe side
for a clearance), and the covering spheres cover the bounding box like a box primitive's.
"""

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
        kind: ``"box"``, ``"cylinder"`` or ``"mesh"`` (its convex hull, inside the box of
            ``half_extents`` centred on the primitive frame).
        half_extents: Box (or a mesh's bounding box) half sizes (3,), or (radius, half length, 0)
            of a cylinder, in [m].
        sphere_centres: Covering sphere centres in the primitive frame, shape (K, 3), in [m].
        sphere_radius: Radius of every covering sphere, in [m].
        reach: Upper bound of the distance of any point of the primitive from the axis of each
            joint (shape (nq,), in [m]; 0 for joints that do not move it).
        shape: The coal geometry of exact distances, in the primitive frame.
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
    shape: Any = None


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


#: Centred hulls already built in this process, by the hash of their mesh's hull vertices: a
#: robot's worlds (one per scene, e.g. each problem of a benchmark) share them instead of
#: rebuilding each mesh's hull (the SO-101's 17 meshes: ~0.2 s a world).
_HULLS: dict[bytes, tuple[Any, np.ndarray, np.ndarray]] = {}
#: At most this many hulls are kept (a robot has tens of meshes).
_HULLS_KEPT = 512


def _mesh_hull(shape: Any, name: str) -> tuple[Any, np.ndarray, np.ndarray]:
    """Convex hull of a mesh (coal BVH or Convex) centred on its bounding box, the offset (4, 4)
    of that frame in the geometry frame, and the hull's vertices (K, 3) in it [m]."""
    import hashlib

    import coal

    if not type(shape).__name__.startswith("Convex"):
        if shape.convex is None:  # built once per mesh, kept by the robot's GeometryModel
            shape.buildConvexHull(True, "Qt")
        shape = shape.convex
    points = np.array(shape.points(), dtype=float).reshape(-1, 3)
    if points.shape[0] < 4 or not np.isfinite(points).all():
        raise CollisionModelError(name, "mesh has no usable vertices for a convex hull")
    key = hashlib.blake2b(points.tobytes(), digest_size=16).digest()
    known = _HULLS.get(key)
    if known is not None:
        return known
    centre = (points.min(axis=0) + points.max(axis=0)) / 2.0
    shifted = coal.StdVec_Vec3s()
    shifted.extend(list(points - centre))
    hull = coal.Convex.convexHull(shifted, False, "Qt")
    offset = np.eye(4)
    offset[:3, 3] = centre
    centred = points - centre
    for array in (offset, centred):
        array.setflags(write=False)
    if len(_HULLS) >= _HULLS_KEPT:
        _HULLS.clear()
    _HULLS[key] = (hull, offset, centred)
    return hull, offset, centred


def _cover(kind: str, half: np.ndarray) -> tuple[np.ndarray, float]:
    """Covering sphere centres (K, 3) and radius of a box ``half`` (3,) or a cylinder
    ``(radius, half length, 0)``, cut into pieces along the longest axis."""
    if kind == "cylinder":
        radius, half_length = float(half[0]), float(half[1])
        longest, length = 2, half_length
        pieces = max(1, math.ceil(half_length / radius))
    else:
        longest = int(np.argmax(half))
        length = float(half[longest])
        second = float(np.sort(half)[-2])
        pieces = max(1, math.ceil(length / second)) if second > 0 else 1
    piece_half = length / pieces
    centres = np.zeros((pieces, 3))
    centres[:, longest] = -length + piece_half * (2 * np.arange(pieces) + 1)
    if kind == "cylinder":
        return centres, math.hypot(float(half[0]), piece_half)
    sub = half.copy()
    sub[longest] = piece_half
    return centres, float(np.linalg.norm(sub))


def link_primitive(
    model: Any, geometry_object: Any, joint_placements: list[np.ndarray]
) -> LinkPrimitive:
    shape = geometry_object.geometry
    kind = type(shape).__name__
    name = geometry_object.name
    placement = np.array(geometry_object.placement.homogeneous)
    if kind == "Box":
        kind, half = "box", np.array(shape.halfSide, dtype=float)
    elif kind == "Cylinder":
        kind, half = "cylinder", np.array([shape.radius, shape.halfLength, 0.0])
    elif kind.startswith(("BVHModel", "Convex")):
        shape, offset, points = _mesh_hull(shape, name)
        placement = placement @ offset
        kind, half = "mesh", np.abs(points).max(axis=0)
    else:
        raise CollisionModelError(name, f"shape {kind} is not supported (box, cylinder, mesh)")
    centres, radius = _cover(kind, half)
    bounding = float(np.linalg.norm(half)) if kind != "cylinder" else math.hypot(half[0], half[1])
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
    return LinkPrimitive(name, link, joint, placement, kind, half, centres, radius, reach, shape)


def fcl_shape(primitive: LinkPrimitive) -> Any:
    import fcl

    if primitive.kind == "mesh":
        raise CollisionModelError(primitive.geometry, "the fcl engine takes boxes and cylinders")
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
