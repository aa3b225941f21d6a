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

#: Before the exact check, each path segment is split so that no point of the robot moves more
#: than this between two checked configurations, in [m]: pairs farther apart than that are then
#: certified by the collision world's sphere bounds alone, and the exact (coal) queries go to the
#: close pairs (2 cm halves the check's time on the suite against checking bare waypoints).
VERIFY_MOTION_STEP = 0.02


@dataclass(frozen=True)
class VerificationReport:
    """Exact verification of a path.

    Attributes:
        collision_free: No contact anywhere along the path, every interval certified.
        min_clearance: Smallest exact distance found at the waypoints and at the points the
            certification probed between them (link, obstacle, where), in [m]; its ``time`` is
            the path parameter (waypoint index, fractional between waypoints). In between, the
            path is certified collision-free, and the planner's own certificate guarantees at
            least ``required_clearance`` everywhere.
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
        waypoints: Shape (N, nq), in [rad]; the path is the straight joint segments between them
            (split every :data:`VERIFY_MOTION_STEP` of robot motion before the check).
        clearance: The required clearance the planner guaranteed, in [m] (reported).

    Raises:
        PathVerificationError: a contact or an uncertified interval (never expected: the
            planner's checker is conservative).
    """
    given = np.asarray(waypoints, dtype=float)
    if len(given) == 1:  # a single configuration: checked as a motion that does not move
        path, parameter = np.vstack([given, given]), np.array([0.0, 1.0])
    else:
        path = densify(world, given, VERIFY_MOTION_STEP)
        parameter = _segment_parameter(world, given)
    report = check_trajectory(world, path, parameter)
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


def _steps(world: CollisionWorld, waypoints: np.ndarray, step: float) -> np.ndarray:
    """Pieces of each segment so that no point of the robot moves more than ``step`` [m]."""
    reach = np.stack([p.reach for p in world.links]).max(axis=0)  # (nq,)
    motion = np.abs(np.diff(waypoints, axis=0)) @ reach
    pieces: np.ndarray = np.maximum(1, np.ceil(motion / step)).astype(int)
    return pieces


def densify(world: CollisionWorld, waypoints: np.ndarray, step: float) -> np.ndarray:
    """The path's straight segments split so that no robot point moves more than ``step`` [m].

    waypoints: shape (N, nq), in [rad] -> shape (M, nq), every waypoint kept.
    """
    if len(waypoints) < 2:
        single: np.ndarray = waypoints.copy()
        return single
    pieces = [waypoints[:1]]
    for k, count in enumerate(_steps(world, waypoints, step).tolist()):
        s = np.arange(1, count + 1)[:, None] / count
        pieces.append(waypoints[k] + s * (waypoints[k + 1] - waypoints[k]))
    dense: np.ndarray = np.vstack(pieces)
    return dense


def _segment_parameter(world: CollisionWorld, waypoints: np.ndarray) -> np.ndarray:
    """The path parameter (waypoint index, fractional in between) of every densified point."""
    values = [np.zeros(1)]
    for k, count in enumerate(_steps(world, waypoints, VERIFY_MOTION_STEP).tolist()):
        values.append(k + np.arange(1, count + 1) / count)
    parameter: np.ndarray = np.concatenate(values)
    return parameter


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


def sample_clearances(world: CollisionWorld, q: np.ndarray) -> np.ndarray:
    """Exact smallest distance over every pair at each sample (branch and bound).

    Pairs whose lower bound (:meth:`CollisionWorld.lower_bounds`) is not below the best exact
    distance found so far cannot be the minimum and are skipped.

    q: shape (N, nq), in [rad] -> shape (N,), in [m] (inf without pairs).
    """
    config = np.atleast_2d(np.asarray(q, dtype=float))
    poses = world.primitive_poses(config)
    bounds = world.lower_bounds(poses)
    result = np.full(len(config), np.inf)
    for n in range(len(config)):
        best = np.inf
        for pair in np.argsort(bounds[n]).tolist():
            if bounds[n, pair] >= best and bounds[n, pair] > 0:
                break
            best = min(best, world.distance(poses[n], pair))
        result[n] = best
    return result
