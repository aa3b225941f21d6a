"""Collision checking with python-fcl: the arm's URDF collision geometry against obstacles."""

from lynxplan.collision.check import (
    MAX_BISECTION_DEPTH,
    ClearanceRecord,
    CollisionReport,
    Contact,
    check_trajectory,
    clearance_profile,
)
from lynxplan.collision.obstacles import (
    BoxObstacle,
    CylinderObstacle,
    Obstacle,
    SphereObstacle,
    axis_aligned_box,
    rotation_from_axis,
)
from lynxplan.collision.world import CollisionWorld, LinkPrimitive

__all__ = [
    "MAX_BISECTION_DEPTH",
    "BoxObstacle",
    "ClearanceRecord",
    "CollisionReport",
    "CollisionWorld",
    "Contact",
    "CylinderObstacle",
    "LinkPrimitive",
    "Obstacle",
    "SphereObstacle",
    "axis_aligned_box",
    "check_trajectory",
    "clearance_profile",
    "rotation_from_axis",
]
