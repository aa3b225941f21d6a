"""Where the exact verification of a path must query distances: a schedule, compiled with numba.

The exact verifier (:mod:`lynxplan.planning.verify`) certifies each straight joint segment
``q(s) = q_a + s (q_b - q_a)``, ``s`` in [0, 1], pair by pair. With ``L`` the pair's motion
bound per unit ``s`` (:func:`lynxplan.planning.kernel_model.pair_rates`: no point of the pair's
geometry moves, relative to the other side, more than ``L |s1 - s0|`` between ``s0`` and
``s1``), lower bounds ``d0``, ``d1`` of the pair's distance at ``s0`` and ``s1`` prove it apart
on the whole interval when ``d0 + d1 > L (s1 - s0)`` (proof in :mod:`lynxplan.collision.verify`:
at any ``s`` in between every point is at least ``max(d0 - a, d1 - b)`` away with ``a + b = L
(s1 - s0)``).

This module only *chooses* the parameters ``s`` at which the verifier asks coal for exact
distances; it proves nothing itself (the exact verifier, :mod:`lynxplan.collision.verify`,
decides):

- a pair whose sphere gaps prove it apart on the segment needs no exact query there (the
  point distance of one primitive's covering spheres, a few along its longest axis, from the
  other's box, less their radius: :mod:`lynxplan.planning.sphere_gaps`, a plain, independent
  lower bound): either
  the gaps at both ends satisfy the inequality with the static bound ``L``, or the gaps on a
  uniform grid of the segment (all pairs at once) or a short chain of sphere gaps do with the
  lever-arm motion bounds of :func:`lynxplan.planning.motion.span_motion` (tested against
  the real motion);
- any other pair gets a chain ``0 = s_0 < s_1 < ... < s_n = 1`` such that the planner's tight
  separating-axis bounds ``b`` satisfy ``b_i + b_i+1 > L (s_i+1 - s_i)``. Exact distances are at
  least those bounds, so the verifier's exact test of the same inequality (with the motion bound
  the schedule hands it for each pair of consecutive rows) passes with few queries (about ``L /
  2d`` on a segment that stays ``d`` from an obstacle). Where the bounds give no guidance (a
  bound <= 0, or steps below :data:`MIN_STEP`) the chain jumps to ``s = 1``
  and the verifier bisects that interval with exact distances.
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

from lynxplan.planning.bounds import joint_poses_upto, primitive_pose, primitive_poses
from lynxplan.planning.kernel_model import (
    njit_no_refcount,
    njit_refcounted,
)
from lynxplan.planning.motion import (
    copy_row,
    pair_bound_at,
    pose_pair_at,
    reach_step,
    span_motion,
    two_sided_step,
)
from lynxplan.planning.pair_bound import all_pair_bounds
from lynxplan.planning.sphere_gaps import (
    SPHERE_GRID,
    grid_clear,
    poses_at,
    sphere_chain,
    sphere_gap,
    sphere_grid,
)

#: Smallest chain step, in units of the segment parameter s; below it the verifier bisects.
MIN_STEP = 1e-4


@njit_refcounted()
def segment_rates(path: np.ndarray, model: Any) -> np.ndarray:
    """Motion bound of every pair per unit s on every segment: (M, nq) -> (M - 1, P), in [m]."""
    rates = model.rates
    out = np.zeros((path.shape[0] - 1, rates.shape[0]))
    for k in range(path.shape[0] - 1):
        for p in range(rates.shape[0]):
            total = 0.0
            for j in range(path.shape[1]):
                total += rates[p, j] * abs(path[k + 1, j] - path[k, j])
            out[k, p] = total
    return out


@njit_no_refcount()
def _end_bounds(
    q_a: np.ndarray, q_b: np.ndarray, end: float, model: Any, scratch: Any, out: np.ndarray
) -> None:
    """Sphere gaps out[0] and tight bounds out[1] of every pair at s = end: out (2, P)."""
    poses_at(q_a, q_b, end, model, scratch)
    for p in range(model.pairs.shape[0]):
        out[0, p] = sphere_gap(p, model, scratch)
    all_pair_bounds(model, scratch.prim_poses, out[1])


@njit_no_refcount()
def _chain(
    q_a: np.ndarray,
    q_b: np.ndarray,
    p: int,
    ends: tuple[float, float],
    model: Any,
    scratch: Any,
    rows: Any,
    count: int,
) -> int:
    """Append the chain of pair p on one segment to rows (segment column already set by the
    caller); returns the new row count, -1 when full. ends: the bounds at s = 0 and 1. The
    motion column holds, for each row but the last of the chain, the bound of the pair's motion
    until the next row (the verifier's test); a jump to s = 1 gets the static bound."""
    parameter, pair, motion = rows[1], rows[2], rows[3]
    arms = scratch.arms
    static = 0.0
    for j in range(q_a.shape[0]):
        static += model.rates[p, j] * scratch.dq[j]
    s, b, trend = 0.0, ends[0], 0.0  # trend: the bound's change per unit s at the last step
    pose_pair_at(q_a, q_b, 0.0, p, model, scratch, np.int64(0))  # lever arms (not a literal)
    while True:
        if count >= pair.shape[0]:
            return -1
        parameter[count], pair[count], motion[count] = s, p, -1.0
        count += 1
        if s >= 1.0:
            return count
        if b <= 0.0:
            motion[count - 1] = static * (1.0 - s)
            s, b = 1.0, ends[1]
            continue
        # the walk's step: longer while the bound grows, one-sided steps as it closes in
        one = reach_step(b, p, arms, 0, model, scratch)
        t = min(1.0, s + two_sided_step(b, one, trend))
        while True:  # halve the step until the two-sided test passes (one inlined bound)
            bt = pair_bound_at(q_a, q_b, t, p, model, scratch, np.int64(1))
            span = span_motion(p, t - s, model, scratch)
            if b + bt > span or t - s < MIN_STEP:
                break
            t = s + 0.5 * (t - s)
        if t - s < MIN_STEP:
            motion[count - 1] = static * (1.0 - s)
            s, b = 1.0, ends[1]
            continue
        motion[count - 1] = span
        trend = (bt - b) / (t - s)
        s, b = t, bt
        copy_row(arms, 0, arms, 1)


@numba.njit(cache=True)
def _segment_ends(
    path: np.ndarray,
    k: int,
    model: Any,
    scratch: Any,
    start: np.ndarray,
    end: np.ndarray,
    waypoints: Any,
) -> None:
    """Sphere gaps and tight bounds of every pair at both ends of segment k (start, end: (2, P),
    see :func:`_end_bounds`; start is the previous segment's end), |path[k+1] - path[k]| ->
    scratch.dq; the waypoints' bounds and poses (waypoints: (M, P), (M, G, 4, 4)) filled."""
    bounds, poses = waypoints
    for j in range(path.shape[1]):
        scratch.dq[j] = abs(path[k + 1, j] - path[k, j])
    if k == 0:
        _end_bounds(path[k], path[k + 1], 0.0, model, scratch, start)
        poses[k] = scratch.prim_poses  # (k, not a literal 0: numba cannot assign an array there)
        bounds[k] = start[1]
    else:
        start[:] = end
    _end_bounds(path[k], path[k + 1], 1.0, model, scratch, end)
    poses[k + 1] = scratch.prim_poses
    bounds[k + 1] = end[1]


@numba.njit(cache=True)
def schedule(path: np.ndarray, model: Any, scratch: Any, rows: Any, waypoints: Any) -> int:
    """The exact queries that certify a path: rows (segment, s, pair, motion, source), chains in
    order.

    path: (M, nq), in [rad]. rows: output columns (segment int64, s float, pair int64, motion
    float [m]: the bound of the pair's motion until the next row of the chain, -1 on a chain's
    last row; source int64: -1 for a row to query, else the index of an earlier row at the same
    configuration of the pair, whose distance it is), each of shape (capacity,). Returns the
    number of rows, or -1 when the capacity is too small. waypoints: outputs (bounds (M, P),
    in [m], poses (M, G, 4, 4)): every pair's tight bound and the primitive poses at each
    waypoint (a segment's end is the next one's start: computed once).

    A pair whose relative pose does not change on a segment gets one row at s = 0 (unless its
    sphere gap is positive there), and none when its distance there is already a row's (it was
    static on the previous segment too, or a chain ended at the shared waypoint). A chain that
    starts where the pair's previous segment left a row (the shared waypoint) copies that row's
    distance (about one query per pair near an obstacle and inner waypoint).
    """
    segment, parameter, pair, motion, source = rows
    count_pairs = model.pairs.shape[0]
    rates = segment_rates(path, model)
    start, end = np.empty((2, count_pairs)), np.empty((2, count_pairs))
    todo = np.empty(count_pairs, dtype=np.bool_)
    gaps = np.empty((SPHERE_GRID + 1, count_pairs))
    arms = np.empty(((SPHERE_GRID + 1) * count_pairs, path.shape[1]))
    # per pair: the row holding its distance at the current waypoint (segment k's s = 0), or -1
    at_waypoint = np.full(count_pairs, -1, dtype=np.int64)
    count = np.int64(0)  # not a literal 0: numba would compile _chain for it as well
    for k in range(path.shape[0] - 1):
        _segment_ends(path, k, model, scratch, start, end, waypoints)
        for p in range(count_pairs):
            todo[p] = rates[k, p] > 0.0 and start[0, p] + end[0, p] <= rates[k, p]
        sphere_grid(path[k], path[k + 1], todo, model, scratch, gaps, arms)
        for p in range(count_pairs):
            rate = rates[k, p]
            first = count
            if rate == 0.0:
                if start[0, p] > 0.0:
                    at_waypoint[p] = -1
                    continue
                if at_waypoint[p] >= 0:
                    continue  # the same distance as that row's, on the whole segment
                if count >= pair.shape[0]:
                    return -1
                parameter[count], pair[count], motion[count], source[count] = 0.0, p, -1.0, -1
                at_waypoint[p] = count
                count += 1
            elif not todo[p] or (
                grid_clear(gaps, p)
                and sphere_chain(path[k], path[k + 1], p, start[0, p], model, scratch)
            ):
                at_waypoint[p] = -1
                continue  # the sphere gaps prove it apart: no exact query
            else:
                ends = (start[1, p], end[1, p])
                count = _chain(path[k], path[k + 1], p, ends, model, scratch, rows, count)
                if count < 0:
                    return -1
                source[first:count] = -1
                source[first] = at_waypoint[p]
                at_waypoint[p] = count - 1  # the chain ends at s = 1: the next waypoint
            segment[first:count] = k
    return int(count)


@numba.njit(cache=True)
def configuration_poses(
    path: np.ndarray,
    segment: np.ndarray,
    parameter: np.ndarray,
    model: Any,
    scratch: Any,
    out: np.ndarray,
) -> None:
    """Primitive poses at each row's configuration: out (R, G, 4, 4)."""
    for r in range(segment.shape[0]):
        k = segment[r]
        poses_at(path[k], path[k + 1], parameter[r], model, scratch)
        out[r] = scratch.prim_poses


@numba.njit(cache=True)
def row_transforms(
    path: np.ndarray,
    segment: np.ndarray,
    parameter: np.ndarray,
    pair: np.ndarray,
    model: Any,
    scratch: Any,
    rotation: np.ndarray,
    translation: np.ndarray,
) -> None:
    """World poses of each row's two primitives at its configuration (the second only for a
    self pair): rotation (R, 2, 3, 3), translation (R, 2, 3), in [m] (contiguous, ready for
    coal). Only the joints up to the pair's primitives are posed."""
    q, pairs, joint_of, poses = scratch.q, model.pairs, model.prim_joints, scratch.prim_poses
    for r in range(segment.shape[0]):
        k, s, p = segment[r], parameter[r], pair[r]
        for j in range(path.shape[1]):
            q[j] = path[k, j] + s * (path[k + 1, j] - path[k, j])
        a, b, is_self = pairs[p, 0], pairs[p, 1], pairs[p, 2]
        last = max(joint_of[a], joint_of[b]) if is_self == 1 else joint_of[a]
        joint_poses_upto(q, model, scratch, last)
        primitive_pose(a, model, scratch)
        if is_self == 1:
            primitive_pose(b, model, scratch)
        for side in range(1 + is_self):
            g = a if side == 0 else b
            for i in range(3):
                for j in range(3):
                    rotation[r, side, i, j] = poses[g, i, j]
                translation[r, side, i] = poses[g, i, 3]


@numba.njit(cache=True)
def waypoint_bounds(
    path: np.ndarray, model: Any, scratch: Any, bounds: np.ndarray, poses: np.ndarray
) -> None:
    """Tight bounds of every pair (N, P), in [m], and primitive poses (N, G, 4, 4) at every
    waypoint of path (N, nq), in one call."""
    for n in range(path.shape[0]):
        primitive_poses(path[n], model, scratch)
        poses[n] = scratch.prim_poses
        all_pair_bounds(model, scratch.prim_poses, bounds[n])


@numba.njit(cache=True)
def verification_rows(
    path: np.ndarray, model: Any, scratch: Any, rows: Any, transforms: Any, waypoints: Any
) -> tuple[int, int]:
    """:func:`schedule` of path (N, nq), and the primitives' poses of the rows to query, in one
    call (the model and scratch tuples cross into compiled code once: about 4 us a crossing).

    rows: columns (segment, s, pair, motion, source, query pair), each (capacity,); the first
    four as in :func:`schedule`; source becomes each row's index among the queries (a row at a
    configuration an earlier row has gets that row's), and the queries' pairs are the last
    column. transforms: the queries' :func:`row_transforms` (rotation (capacity, 2, 3, 3),
    translation (capacity, 2, 3), in [m]). waypoints: bounds (N, P), in [m], and poses
    (N, G, 4, 4) at the waypoints. Returns (rows, queries), or (-1, 0) when the capacity is too
    small.
    """
    count = schedule(path, model, scratch, rows[:5], waypoints)
    if count < 0:
        return count, 0
    segment, parameter, pair, lookup, query_pair = rows[0], rows[1], rows[2], rows[4], rows[5]
    queried = np.empty(count, dtype=np.int64)
    queries = 0
    for r in range(count):
        if lookup[r] < 0:
            queried[queries] = r
            query_pair[queries] = pair[r]
            lookup[r] = queries
            queries += 1
        else:
            lookup[r] = lookup[lookup[r]]
    which = queried[:queries]
    rotation, translation = transforms
    row_transforms(
        path, segment[which], parameter[which], pair[which], model, scratch, rotation, translation
    )
    return count, queries
