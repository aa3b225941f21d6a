"""Exact verification of planned paths with coal, and the exact start/goal collision test.

The planner's own checker is conservative but approximate (bounding boxes, separating axes). A
returned path is therefore re-checked by :func:`lynxplan.collision.check_trajectory` — exact
coal distances between the URDF collision geometry and the obstacles, and between every pair of
primitives on non-adjacent links, with its certification between waypoints (conservative
advancement + bisection: a bound on the motion of any point of the robot between two checked
configurations is kept below the distances found there; proof in
:mod:`lynxplan.collision.check`).

Self-collision pairs ("allowed pairs" from the URDF adjacency): two primitives are *not*
checked when they hang on the same joint or on a parent/child pair of joints (they touch by
design at the joint); every other pair is, including the fixed base against the moving links.
This is :class:`lynxplan.collision.CollisionWorld`'s rule with ``self_collision=True``.

The time-parameterised trajectory follows the path's straight joint segments (rest-to-rest
profiles, see :mod:`lynxplan.planning.timing`), so the set of configurations it visits is the
path: verifying the path verifies the trajectory. The tests also check the sampled trajectory
itself, densely.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lynxplan.collision import ClearanceRecord, CollisionWorld, check_trajectory
from lynxplan.exceptions import PathVerificationError, StateInCollisionError


@dataclass(frozen=True)
class VerificationReport:
    """Exact verification of a path.

    Attributes:
        collision_free: No contact anywhere along the path, every interval certified.
        min_clearance: Smallest exact distance over the path (link, obstacle, where), in [m];
            its ``time`` is the path parameter (waypoint index, fractional between waypoints).
        required_clearance: The planner's required clearance, in [m].
        self_collision_pairs: Number of self-collision pairs checked.
        obstacle_pairs: Number of primitive/obstacle pairs checked.
        exact_queries: Exact (coal) distance queries made.
        refined_intervals: (interval, pair) cases certified by bisection.
    """

    collision_free: bool
    min_clearance: ClearanceRecord
    required_clearance: float
    self_collision_pairs: int
    obstacle_pairs: int
    exact_queries: int
    refined_intervals: int


def verify_path(
    world: CollisionWorld, waypoints: np.ndarray, clearance: float
) -> VerificationReport:
    """Verify a piecewise-linear joint path exactly.

    Args:
        world: Collision world built with ``self_collision=True``.
        waypoints: Shape (N, nq), in [rad]; the path is the straight joint segments between them.
        clearance: The required clearance the planner guaranteed, in [m] (reported).

    Raises:
        PathVerificationError: a contact or an uncertified interval (never expected: the
            planner's checker is conservative).
    """
    path = np.asarray(waypoints, dtype=float)
    if len(path) == 1:
        path = np.vstack([path, path + 1e-12])
    report = check_trajectory(world, path, np.arange(len(path), dtype=float))
    if report.contacts:
        c = report.contacts[0]
        raise PathVerificationError(
            f"{c.link} ({c.geometry}) touches {c.obstacle} at path parameter {c.time:.4f}, "
            f"penetration {c.penetration_depth * 1e3:.4f} mm"
        )
    if not report.certified:
        raise PathVerificationError("an interval could not be certified (grazing contact)")
    self_pairs = int(world.pair_is_self.sum())
    return VerificationReport(
        collision_free=report.collision_free,
        min_clearance=report.min_clearance,
        required_clearance=clearance,
        self_collision_pairs=self_pairs,
        obstacle_pairs=world.pair_count - self_pairs,
        exact_queries=report.exact_queries,
        refined_intervals=report.refined_intervals,
    )


def closest_contact(world: CollisionWorld, q: np.ndarray) -> tuple[float, str, str]:
    """Exact smallest signed distance at q (nq,), with its link and obstacle names, in [m]."""
    distances = world.distances(q)[0]
    if distances.size == 0:
        return float("inf"), "", ""
    pair = int(np.argmin(distances))
    link, _geometry, obstacle = world.pair_names(pair)
    return float(distances[pair]), link, obstacle


def require_clear(world: CollisionWorld, q: np.ndarray, what: str, clearance: float) -> float:
    """The exact clearance at q; raises StateInCollisionError below ``clearance`` [m]."""
    distance, link, obstacle = closest_contact(world, q)
    if distance < clearance:
        raise StateInCollisionError(what, link, obstacle, -distance, clearance)
    return distance
