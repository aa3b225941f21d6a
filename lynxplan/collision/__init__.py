"""Collision checking: the arm's URDF collision geometry against obstacles, and the exact verifier.

- :mod:`~lynxplan.collision.world`: the arm's primitives and the obstacles, exact distances;
- :mod:`~lynxplan.collision.verify`: the exact verifier (conservative advancement), the one
  place that decides "collision free";
- :mod:`~lynxplan.collision.report`: its one report type, :class:`MotionReport`;
- :mod:`~lynxplan.collision.check`: sampled trajectories (task checks, the service's ``/check``).
"""

from lynxplan.collision.check import check_trajectory, clearance_profile
from lynxplan.collision.obstacles import (
    BoxObstacle,
    CylinderObstacle,
    Obstacle,
    SphereObstacle,
    axis_aligned_box,
    rotation_from_axis,
)
from lynxplan.collision.report import ClearanceRecord, CollisionReport, Contact, MotionReport
from lynxplan.collision.verify import MAX_BISECTION_DEPTH
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
    "MotionReport",
    "Obstacle",
    "SphereObstacle",
    "axis_aligned_box",
    "check_trajectory",
    "clearance_profile",
    "rotation_from_axis",
]
