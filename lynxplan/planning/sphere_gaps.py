"""The exact verification's independent bound: covering-sphere gaps (numba).

A robot primitive lies inside the union of its covering spheres and inside its box: the point
distance of one primitive's sphere centres from the other's box, less the spheres' radius, is a
lower bound of the pair's distance (:func:`sphere_gap`), independent of the planner's
separating-axis bound. The verification schedule (:mod:`lynxplan.planning.certify`) asks coal
for no exact distance of a pair on a segment where these gaps prove it apart: at both ends with
the static motion bound, on a uniform grid of the segment (:func:`sphere_grid`, all pairs at
once) or along a short chain (:func:`sphere_chain`) with the motion bounds of
:mod:`lynxplan.planning.motion`.
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np

from lynxplan.planning.bounds import primitive_poses
from lynxplan.planning.kernel_model import LANES, OBSTACLE_SPHERE, njit_no_refcount
from lynxplan.planning.lanes import MAX_JOINTS, OUT_ARMS, OUT_S, OUT_SPHERE, spheres_along
from lynxplan.planning.motion import (
    copy_row,
    farthest_lane,
    lever_arms,
    place_lanes,
    pose_pair_at,
    reach_step,
    span_motion,
)

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


@njit_no_refcount()
def sphere_gap(p: int, model: Any, scratch: Any) -> float:
    """Covering-sphere lower bound of pair p's distance at the poses in scratch.prim_poses, in [m].

    A robot primitive lies inside the union of its covering spheres (model.cover_centres and
    cover_radii) and inside its box (model.prim_half: a cylinder's or a mesh hull's bounding
    box): the bound is the exact point distance of one primitive's sphere centres from the
    other's box, less the spheres' radius (for a self pair the larger of the two ways round),
    from a box obstacle the same (a cylinder obstacle is stored as its bounding box, which
    contains it), from a sphere obstacle the centres' distance less both radii.
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
def poses_at(q_a: np.ndarray, q_b: np.ndarray, s: float, model: Any, scratch: Any) -> None:
    q = scratch.q
    for j in range(q_a.shape[0]):
        q[j] = q_a[j] + s * (q_b[j] - q_a[j])
    primitive_poses(q, model, scratch)


@njit_no_refcount()
def sphere_chain(
    q_a: np.ndarray, q_b: np.ndarray, p: int, gap: float, model: Any, scratch: Any
) -> bool:
    """Whether pair p's sphere gaps alone prove it apart on the whole segment: a chain of
    points, from at most :data:`SPHERE_STEPS` evaluated (LANES at a time, by
    :func:`lynxplan.planning.lanes.spheres_along`), whose consecutive gaps exceed the motion bound
    between them (:func:`lynxplan.planning.motion.span_motion`) or that lie within the
    previous point's one-sided reach (:func:`lynxplan.planning.motion.reach_step`)."""
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
def sphere_grid(
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
    (:func:`lynxplan.planning.motion.span_motion` between consecutive points) are cleared.

    gaps: (n + 1, P) and arms: ((n + 1) P, nq) work arrays (row i P + p: pair p at point i);
    n = gaps.shape[0] - 1.
    """
    intervals, count = gaps.shape[0] - 1, gaps.shape[1]
    for i in range(intervals + 1):
        poses_at(q_a, q_b, i / intervals, model, scratch)
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
def grid_clear(gaps: np.ndarray, p: int) -> bool:
    """Whether pair p's sphere gaps on the grid of :func:`sphere_grid` (gaps (n + 1, P), in
    [m]) are all positive. A sphere chain cannot prove a pair apart on a segment where its
    covering spheres touch the obstacle at a grid point (the chain's interval over that point
    would prove the sphere apart there): such a pair goes to the exact chain at once."""
    smallest: float = gaps[:, p].min()
    return smallest > 0.0
