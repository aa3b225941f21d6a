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
  other's box, less their radius: :func:`sphere_gap`, a plain, independent lower bound): either
  the gaps at both ends satisfy the inequality with the static bound ``L``, or the gaps on a
  uniform grid of the segment (all pairs at once) or a short chain of sphere gaps do with the
  lever-arm motion bounds of :func:`lynxplan.planning.validity.span_motion` (tested against
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

import math
from typing import Any

import numba
import numpy as np

from lynxplan.planning.edge_walk import (
    copy_row,
    farthest_lane,
    lever_arms,
    place_lanes,
    pose_pair_at,
    reach_step,
    span_motion,
    two_sided_step,
)
from lynxplan.planning.kernel_model import (
    LANES,
    OBSTACLE_SPHERE,
    njit_no_refcount,
    njit_refcounted,
)
from lynxplan.planning.lanes import (
    MAX_JOINTS,
    OUT_ARMS,
    OUT_S,
    OUT_SPHERE,
    spheres_along,
)
from lynxplan.planning.pair_bound import all_pair_bounds, pair_bound
from lynxplan.planning.validity import (
    joint_poses,
    joint_poses_upto,
    primitive_pose,
    primitive_poses,
)

#: Smallest chain step, in units of the segment parameter s; below it the verifier bisects.
MIN_STEP = 1e-4
#: Sphere gaps evaluated for one pair on a segment (LANES at a time) before the exact chain is
#: scheduled instead.
SPHERE_STEPS = 48
#: Intervals of the uniform grid of sphere gaps tried first, all pairs at once.
SPHERE_GRID = 8


@numba.njit(cache=True, inline="always")
def _cover_centre(poses: np.ndarray, g: int, c: np.ndarray) -> tuple[float, float, float]:
    """World position of the point c (3,) of primitive g's frame (poses (G, 4, 4)), in [m]."""
    return (
        poses[g, 0, 3] + poses[g, 0, 0] * c[0] + poses[g, 0, 1] * c[1] + poses[g, 0, 2] * c[2],
        poses[g, 1, 3] + poses[g, 1, 0] * c[0] + poses[g, 1, 1] * c[1] + poses[g, 1, 2] * c[2],
        poses[g, 2, 3] + poses[g, 2, 0] * c[0] + poses[g, 2, 1] * c[1] + poses[g, 2, 2] * c[2],
    )


@numba.njit(cache=True, inline="always")
def _spheres_to_box(
    poses: np.ndarray, a: int, boxes: np.ndarray, b: int, half: np.ndarray, model: Any
) -> float:
    """Lower bound of the distance of robot primitive a (poses (G, 4, 4)) from the box b of
    poses boxes (N, 4, 4) and half sizes half (N, 3): the exact point distance of each of a's
    covering sphere centres from the box, less the spheres' radius, in [m]."""
    centres, counts, radii = model.cover_centres, model.cover_counts, model.cover_radii
    best = np.inf  # the smallest squared distance of a centre
    for i in range(counts[a]):
        x0, x1, x2 = _cover_centre(poses, a, centres[a, i])
        dx, dy, dz = x0 - boxes[b, 0, 3], x1 - boxes[b, 1, 3], x2 - boxes[b, 2, 3]
        total = 0.0
        for k in range(3):
            excess = (
                abs(boxes[b, 0, k] * dx + boxes[b, 1, k] * dy + boxes[b, 2, k] * dz) - half[b, k]
            )
            if excess > 0.0:
                total += excess * excess
        best = min(best, total)
    gap: float = math.sqrt(best) - radii[a]
    return gap


@numba.njit(cache=True, inline="always")
def sphere_gap(p: int, model: Any, scratch: Any) -> float:
    """Covering-sphere lower bound of pair p's distance at the poses in scratch.prim_poses, in [m].

    A robot primitive lies inside the union of its covering spheres (model[17..19]) and inside
    its box (model.prim_half: a cylinder's or a mesh hull's bounding box): the bound is the exact
    point distance of one primitive's sphere centres from the other's box, less the spheres'
    radius (for a self pair the larger of the two ways round), from a box obstacle the same (a
    cylinder obstacle is stored as its bounding box, which contains it), from a sphere obstacle
    the centres' distance less both radii.
    """
    pairs, kinds, poses_b, obstacle_half = (
        model.pairs,
        model.obstacle_kinds,
        model.obstacle_poses,
        model.obstacle_half,
    )
    poses = scratch.prim_poses
    a, b = pairs[p, 0], pairs[p, 1]
    if pairs[p, 2] == 1:
        half = model.prim_half
        return max(
            _spheres_to_box(poses, a, poses, b, half, model),
            _spheres_to_box(poses, b, poses, a, half, model),
        )
    if kinds[b] != OBSTACLE_SPHERE:
        return _spheres_to_box(poses, a, poses_b, b, obstacle_half, model)
    centres, counts, radii = model.cover_centres, model.cover_counts, model.cover_radii
    c0, c1, c2 = poses_b[b, 0, 3], poses_b[b, 1, 3], poses_b[b, 2, 3]
    best = np.inf
    for i in range(counts[a]):
        x0, x1, x2 = _cover_centre(poses, a, centres[a, i])
        best = min(best, (x0 - c0) ** 2 + (x1 - c1) ** 2 + (x2 - c2) ** 2)
    ball_gap: float = math.sqrt(best) - radii[a] - obstacle_half[b, 0]
    return ball_gap


@numba.njit(cache=True, inline="always")
def _poses_at(q_a: np.ndarray, q_b: np.ndarray, s: float, model: Any, scratch: Any) -> None:
    q = scratch.q
    for j in range(q_a.shape[0]):
        q[j] = q_a[j] + s * (q_b[j] - q_a[j])
    joint_poses(q, model, scratch)
    for g in range(model.prim_joints.shape[0]):
        primitive_pose(g, model, scratch)


@numba.njit(cache=True, inline="always")
def _bound_at(
    q_a: np.ndarray, q_b: np.ndarray, s: float, p: int, model: Any, scratch: Any, side: int
) -> float:
    """Pair p's tight bound at q_a + s (q_b - q_a), in [m]; its lever arms -> scratch.arms[side]."""
    pose_pair_at(q_a, q_b, s, p, model, scratch, side)
    return float(pair_bound(p, model, scratch))


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
    _poses_at(q_a, q_b, end, model, scratch)
    for p in range(model.pairs.shape[0]):
        out[0, p] = sphere_gap(p, model, scratch)
    all_pair_bounds(model, scratch.prim_poses, out[1])


@njit_no_refcount()
def _sphere_chain(
    q_a: np.ndarray, q_b: np.ndarray, p: int, gap: float, model: Any, scratch: Any
) -> bool:
    """Whether pair p's sphere gaps alone prove it apart on the whole segment: a chain of
    points, from at most :data:`SPHERE_STEPS` evaluated (LANES at a time, by
    :func:`lynxplan.planning.lanes.spheres_along`), whose consecutive gaps exceed the motion bound
    between them (:func:`lynxplan.planning.validity.span_motion`) or that lie within the
    previous point's one-sided reach (:func:`lynxplan.planning.edge_walk.reach_step`)."""
    arms = scratch.arms
    if gap <= 0.0:
        return False
    for side in range(2):  # lever arms at both ends (one inlined copy of the pose code)
        pose_pair_at(q_a, q_b, float(side), p, model, scratch, side)
    gap_end = float(sphere_gap(p, model, scratch))  # at s = 1 (gap at 0: the caller's)
    if gap_end > 0.0 and gap + gap_end > span_motion(p, 1.0, model, scratch):
        return True  # one two-sided interval: the whole segment
    if model.axes.shape[0] > MAX_JOINTS:  # too many joints for the lanes: the exact chain
        return False
    s, trend = 0.0, 0.0
    out = scratch.lanes
    one = reach_step(gap, p, arms, 0, model, scratch)
    for _ in range(SPHERE_STEPS // LANES):
        if s + one >= 1.0 or not place_lanes(s, gap, one, trend, out):
            break
        spheres_along(q_a, q_b, p, model, out)
        progressed, i = False, 0
        while i < LANES and s + one < 1.0:
            best = farthest_lane(i, (s, gap, one), p, model, scratch, (OUT_SPHERE, 0.0, 0.0))
            if best < 0:
                break
            t, gap_t = out[OUT_S, best], out[OUT_SPHERE, best]
            trend = (gap_t - gap) / (t - s)
            s, gap = t, gap_t
            for j in range(arms.shape[1]):
                arms[0, j] = out[OUT_ARMS + j, best]
            one = reach_step(gap, p, arms, 0, model, scratch)
            progressed, i = True, best + 1
        if not progressed:
            break
    return s + one >= 1.0  # certified one-sided from the last point to the end


@njit_no_refcount()
def _sphere_grid(
    q_a: np.ndarray,
    q_b: np.ndarray,
    todo: np.ndarray,
    model: Any,
    scratch: Any,
    gaps: np.ndarray,
    arms: np.ndarray,
) -> None:
    """Sphere gaps on a uniform grid of the segment, all pairs at once (one pose computation per
    grid point): pairs flagged in todo (P,) that the grid proves apart on every interval
    (:func:`lynxplan.planning.validity.span_motion` between consecutive points) are cleared.

    gaps: (n + 1, P) and arms: ((n + 1) P, nq) work arrays (row i P + p: pair p at point i);
    n = gaps.shape[0] - 1.
    """
    intervals, count = gaps.shape[0] - 1, gaps.shape[1]
    for i in range(intervals + 1):
        _poses_at(q_a, q_b, i / intervals, model, scratch)
        for p in range(todo.shape[0]):
            if todo[p]:
                gaps[i, p] = sphere_gap(p, model, scratch)
                lever_arms(p, scratch.joint_poses, scratch.prim_poses, model, arms, i * count + p)
    side = scratch.arms
    for p in range(todo.shape[0]):
        if not todo[p]:
            continue
        proven = True
        for i in range(intervals):
            if gaps[i, p] <= 0.0 or gaps[i + 1, p] <= 0.0:
                proven = False
                break
            copy_row(side, 0, arms, i * count + p)
            copy_row(side, 1, arms, (i + 1) * count + p)
            if gaps[i, p] + gaps[i + 1, p] <= span_motion(p, 1.0 / intervals, model, scratch):
                proven = False
                break
        if proven:
            todo[p] = False


@numba.njit(cache=True, inline="always")
def _grid_clear(gaps: np.ndarray, p: int) -> bool:
    """Whether pair p's sphere gaps on the grid of :func:`_sphere_grid` (gaps (n + 1, P), in
    [m]) are all positive. A sphere chain cannot prove a pair apart on a segment where its
    covering spheres touch the obstacle at a grid point (the chain's interval over that point
    would prove the sphere apart there): such a pair goes to the exact chain at once."""
    smallest: float = gaps[:, p].min()
    return smallest > 0.0


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
    pose_pair_at(q_a, q_b, 0.0, p, model, scratch, 0)  # its lever arms (b: the caller's)
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
            bt = _bound_at(q_a, q_b, t, p, model, scratch, 1)
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
        _sphere_grid(path[k], path[k + 1], todo, model, scratch, gaps, arms)
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
                _grid_clear(gaps, p)
                and _sphere_chain(path[k], path[k + 1], p, start[0, p], model, scratch)
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
        _poses_at(path[k], path[k + 1], parameter[r], model, scratch)
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
