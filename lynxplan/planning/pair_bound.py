"""The one conservative lower bound of a checked pair's distance, scalar and vectorised.

Every collision primitive of the robot (the URDF's boxes and cylinders, a mesh by its hull) is
replaced by its oriented bounding box (a cylinder by the box around it: it lies inside); a
cylinder obstacle by its bounding box too. For a pair of boxes the bound is the larger of

- the bounding-sphere gap ``|c_a - c_b| - r_a - r_b``, and
- the separating-axis gap: the largest separation of the two boxes' projections over the 15
  axes of the separating axis theorem (box faces and edge cross products). Projection on a
  unit vector is 1-Lipschitz, so every projected gap is a lower bound of the distance; it is
  positive if and only if the boxes are apart (SAT), and exact when the closest features are
  two faces or two edges.

A sphere obstacle is bounded exactly: the point-box distance of its centre, less its radius.

:func:`obb_gap` and :func:`point_box_gap` are the definition, on scalars. :func:`pair_bound`
applies them to one pair, :func:`all_pair_bounds` to every pair of a configuration (gathered
into rows, one branch-free loop), :mod:`lynxplan.planning.lanes` to one pair at several points
of an edge. An edge axis whose squared norm ``1 - (a_i . b_j)^2`` is below :data:`_PARALLEL`
(near-parallel edges) is left out: any subset of the axes gives a valid bound, and its
normalisation would amplify rounding.
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np

from lynxplan.planning.kernel_model import OBSTACLE_SPHERE, njit_refcounted

#: Pairs whose bounding-sphere gap exceeds the clearance by more than this skip the separating
#: axis test in :func:`pair_bound_below` (its bound cannot limit a step much), in [m].
SAT_SKIP_DISTANCE = 0.15
#: The scalar :func:`pair_bound` tries the 9 edge axes only below this face-axis gap, in [m].
EDGE_AXES_BELOW = 0.02
#: :func:`obb_gap`'s ``edges_below`` for every axis.
ALL_AXES = np.inf
#: Edge axes with squared norm below this are left out (near-parallel edges).
_PARALLEL = 1e-6
#: IEEE-safe fast-math flags (fused multiply-add, reciprocal division; see ik_kernel).
_FAST = {"contract", "arcp"}


@numba.njit(cache=True, inline="always", fastmath=_FAST)
def obb_gap(
    t: tuple[float, float, float],
    ra: tuple[tuple[float, float, float], ...],
    rb: tuple[tuple[float, float, float], ...],
    ha: tuple[float, float, float],
    hb: tuple[float, float, float],
    rab: float,
    edges_below: float,
) -> float:
    """Lower bound of the distance of two oriented boxes, in [m]: the larger of the sphere gap
    ``|t| - rab`` and the separating-axis gap over the 15 axes (the 9 edge axes only when the
    face axes leave a gap below ``edges_below`` [m]: any subset of the axes gives a valid bound;
    the vectorised loops pass :data:`ALL_AXES`, a compile-time constant, and have no branch).

    t: centre of B minus centre of A (world); ra, rb: the three rows of the boxes' rotations
    (columns: the box axes); ha, hb: half sizes; rab: the sum of their bounding radii. No
    branch: a select leaves out near-parallel edge axes.
    """
    t0, t1, t2 = t
    ra0, ra1, ra2 = ra
    rb0, rb1, rb2 = rb
    a00, a01, a02 = ra0
    a10, a11, a12 = ra1
    a20, a21, a22 = ra2
    b00, b01, b02 = rb0
    b10, b11, b12 = rb1
    b20, b21, b22 = rb2
    ha0, ha1, ha2 = ha
    hb0, hb1, hb2 = hb
    # m_kl = a_k . b_l
    m00 = a00 * b00 + a10 * b10 + a20 * b20
    m01 = a00 * b01 + a10 * b11 + a20 * b21
    m02 = a00 * b02 + a10 * b12 + a20 * b22
    m10 = a01 * b00 + a11 * b10 + a21 * b20
    m11 = a01 * b01 + a11 * b11 + a21 * b21
    m12 = a01 * b02 + a11 * b12 + a21 * b22
    m20 = a02 * b00 + a12 * b10 + a22 * b20
    m21 = a02 * b01 + a12 * b11 + a22 * b21
    m22 = a02 * b02 + a12 * b12 + a22 * b22
    r00, r01, r02 = abs(m00), abs(m01), abs(m02)
    r10, r11, r12 = abs(m10), abs(m11), abs(m12)
    r20, r21, r22 = abs(m20), abs(m21), abs(m22)
    # t in A's frame and in B's frame
    u0 = a00 * t0 + a10 * t1 + a20 * t2
    u1 = a01 * t0 + a11 * t1 + a21 * t2
    u2 = a02 * t0 + a12 * t1 + a22 * t2
    v0 = b00 * t0 + b10 * t1 + b20 * t2
    v1 = b01 * t0 + b11 * t1 + b21 * t2
    v2 = b02 * t0 + b12 * t1 + b22 * t2
    best = math.sqrt(t0 * t0 + t1 * t1 + t2 * t2) - rab
    best = max(best, abs(u0) - ha0 - hb0 * r00 - hb1 * r01 - hb2 * r02)
    best = max(best, abs(u1) - ha1 - hb0 * r10 - hb1 * r11 - hb2 * r12)
    best = max(best, abs(u2) - ha2 - hb0 * r20 - hb1 * r21 - hb2 * r22)
    best = max(best, abs(v0) - hb0 - ha0 * r00 - ha1 * r10 - ha2 * r20)
    best = max(best, abs(v1) - hb1 - ha0 * r01 - ha1 * r11 - ha2 * r21)
    best = max(best, abs(v2) - hb2 - ha0 * r02 - ha1 * r12 - ha2 * r22)
    if edges_below < ALL_AXES and best >= edges_below:
        return best
    # edge axes a_k x b_l, in A's frame e_k x (m_0l, m_1l, m_2l); squared norm 1 - m_kl^2
    best = _edge(best, u2 * m10 - u1 * m20, ha1 * r20 + ha2 * r10, hb1 * r02 + hb2 * r01, m00)
    best = _edge(best, u2 * m11 - u1 * m21, ha1 * r21 + ha2 * r11, hb0 * r02 + hb2 * r00, m01)
    best = _edge(best, u2 * m12 - u1 * m22, ha1 * r22 + ha2 * r12, hb0 * r01 + hb1 * r00, m02)
    best = _edge(best, u0 * m20 - u2 * m00, ha0 * r20 + ha2 * r00, hb1 * r12 + hb2 * r11, m10)
    best = _edge(best, u0 * m21 - u2 * m01, ha0 * r21 + ha2 * r01, hb0 * r12 + hb2 * r10, m11)
    best = _edge(best, u0 * m22 - u2 * m02, ha0 * r22 + ha2 * r02, hb0 * r11 + hb1 * r10, m12)
    best = _edge(best, u1 * m00 - u0 * m10, ha0 * r10 + ha1 * r00, hb1 * r22 + hb2 * r21, m20)
    best = _edge(best, u1 * m01 - u0 * m11, ha0 * r11 + ha1 * r01, hb0 * r22 + hb2 * r20, m21)
    best = _edge(best, u1 * m02 - u0 * m12, ha0 * r12 + ha1 * r02, hb0 * r21 + hb1 * r20, m22)
    return best


@numba.njit(cache=True, inline="always", fastmath=_FAST)
def _edge(best: float, along: float, radius_a: float, radius_b: float, m: float) -> float:
    """best, or the gap along edge axis L (projection of t on L: along; the boxes' radii on L:
    radius_a, radius_b; m the cosine of the two edges, |L|^2 = 1 - m^2) if larger."""
    norm2 = 1.0 - m * m
    gap = (abs(along) - radius_a - radius_b) / math.sqrt(max(norm2, _PARALLEL))
    return max(best, gap) if norm2 > _PARALLEL else best


@numba.njit(cache=True, inline="always", fastmath=_FAST)
def point_box_gap(
    d: tuple[float, float, float],
    r: tuple[tuple[float, float, float], ...],
    half: tuple[float, float, float],
) -> float:
    """Distance of a point from a solid box (0 inside), in [m]: d the point minus the box's
    centre (world), r the three rows of the box's rotation (columns: its axes), half its half
    sizes."""
    d0, d1, d2 = d
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = r
    e0 = max(abs(r00 * d0 + r10 * d1 + r20 * d2) - half[0], 0.0)
    e1 = max(abs(r01 * d0 + r11 * d1 + r21 * d2) - half[1], 0.0)
    e2 = max(abs(r02 * d0 + r12 * d1 + r22 * d2) - half[2], 0.0)
    return math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)


@numba.njit(cache=True, inline="always")
def rotation_rows(poses: np.ndarray, g: int) -> tuple[tuple[float, float, float], ...]:
    """The three rows of pose g's rotation (poses (N, 4, 4))."""
    return (
        (poses[g, 0, 0], poses[g, 0, 1], poses[g, 0, 2]),
        (poses[g, 1, 0], poses[g, 1, 1], poses[g, 1, 2]),
        (poses[g, 2, 0], poses[g, 2, 1], poses[g, 2, 2]),
    )


@numba.njit(cache=True, inline="always")
def pair_bound(p: int, model: Any, scratch: Any) -> float:
    """Lower bound of pair p's distance at the poses in scratch.prim_poses, in [m]."""
    return pair_bound_below(p, model, scratch, SAT_SKIP_DISTANCE)


@numba.njit(cache=True, inline="always")
def pair_bound_below(p: int, model: Any, scratch: Any, enough: float) -> float:
    """:func:`pair_bound` where only whether it reaches ``enough`` [m] matters above that: the
    bounding-sphere gap when it is at least ``min(enough, SAT_SKIP_DISTANCE)`` (no separating
    axis test), else :func:`obb_gap` (or, for a sphere obstacle, :func:`point_box_gap`). Either
    is a lower bound of the distance."""
    poses, pairs, radius = scratch.prim_poses, model.pairs, model.prim_radius
    a, b = pairs[p, 0], pairs[p, 1]
    ha = (model.prim_half[a, 0], model.prim_half[a, 1], model.prim_half[a, 2])
    if pairs[p, 2] == 1:
        other, half_b, rab = poses, model.prim_half, radius[a] + radius[b]
    else:
        other, half_b = model.obstacle_poses, model.obstacle_half
        rab = radius[a] + model.obstacle_radius[b]
    t = (
        other[b, 0, 3] - poses[a, 0, 3],
        other[b, 1, 3] - poses[a, 1, 3],
        other[b, 2, 3] - poses[a, 2, 3],
    )
    ra = rotation_rows(poses, a)
    if pairs[p, 2] == 0 and model.obstacle_kinds[b] == OBSTACLE_SPHERE:
        ball: float = point_box_gap(t, ra, ha) - half_b[b, 0]
        return ball
    gap: float = math.sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]) - rab
    if gap >= min(enough, SAT_SKIP_DISTANCE):
        return gap
    hb = (half_b[b, 0], half_b[b, 1], half_b[b, 2])
    return obb_gap(t, ra, rotation_rows(other, b), ha, hb, rab, EDGE_AXES_BELOW)


#: Pairs per block of :func:`all_pair_bounds` (a constant width: no run-time aliasing checks).
PAIR_BLOCK = 64
# Rows of a block: pose A (12), pose B (12), half sizes A (3), B (3), the two bounding radii,
# sphere obstacle flag and radius.
_HA, _HB = 24, 27
_RAB, _SPHERE, _SR = 30, 31, 32
_PAIR_ROWS = 33


@numba.njit(cache=True, inline="always")
def _gather_pose(w: np.ndarray, row: int, i: int, poses: np.ndarray, g: int) -> None:
    for r in range(3):
        for c in range(3):
            w[row + 3 * r + c, i] = poses[g, r, c]
        w[row + 9 + r, i] = poses[g, r, 3]


@njit_refcounted(error_model="numpy", fastmath=_FAST)
def all_pair_bounds(model: Any, poses: np.ndarray, out: np.ndarray) -> None:
    """Lower bound of every pair's distance at primitive poses (G, 4, 4) -> out (P,), in [m].

    The same bound as :func:`pair_along` (sphere gap, 15 separating axes, exact for a sphere
    obstacle), for all pairs of one configuration: the pairs' poses are gathered into rows of
    :data:`PAIR_BLOCK` pairs, then one branch-free loop computes every pair's bound.
    """
    pairs, half, radius = model.pairs, model.prim_half, model.prim_radius
    kinds, obstacle_poses = model.obstacle_kinds, model.obstacle_poses
    obstacle_half, obstacle_radius = model.obstacle_half, model.obstacle_radius
    # On the heap: measured a quarter faster than the same rows on the stack (stack_array).
    w = np.empty((_PAIR_ROWS, PAIR_BLOCK))
    count = pairs.shape[0]
    for start in range(0, count, PAIR_BLOCK):
        m = min(PAIR_BLOCK, count - start)
        for i in range(m):
            p = start + i
            a, b = pairs[p, 0], pairs[p, 1]
            _gather_pose(w, 0, i, poses, a)
            for k in range(3):
                w[_HA + k, i] = half[a, k]
            if pairs[p, 2] == 1:
                _gather_pose(w, 12, i, poses, b)
                for k in range(3):
                    w[_HB + k, i] = half[b, k]
                w[_RAB, i] = radius[a] + radius[b]
                w[_SPHERE, i] = 0.0
                w[_SR, i] = 0.0
            else:
                _gather_pose(w, 12, i, obstacle_poses, b)
                for k in range(3):
                    w[_HB + k, i] = obstacle_half[b, k]
                w[_RAB, i] = radius[a] + obstacle_radius[b]
                w[_SPHERE, i] = 1.0 if kinds[b] == OBSTACLE_SPHERE else 0.0
                w[_SR, i] = obstacle_half[b, 0]
        for i in range(m):
            t = (w[21, i] - w[9, i], w[22, i] - w[10, i], w[23, i] - w[11, i])
            rows_a = (
                (w[0, i], w[1, i], w[2, i]),
                (w[3, i], w[4, i], w[5, i]),
                (w[6, i], w[7, i], w[8, i]),
            )
            half_a = (w[_HA, i], w[_HA + 1, i], w[_HA + 2, i])
            box = obb_gap(
                t,
                rows_a,
                (
                    (w[12, i], w[13, i], w[14, i]),
                    (w[15, i], w[16, i], w[17, i]),
                    (w[18, i], w[19, i], w[20, i]),
                ),
                half_a,
                (w[_HB, i], w[_HB + 1, i], w[_HB + 2, i]),
                w[_RAB, i],
                ALL_AXES,
            )
            # sphere obstacle: the point-box distance of its centre minus its radius (exact)
            sphere = point_box_gap(t, rows_a, half_a) - w[_SR, i]
            w[_RAB, i] = sphere if w[_SPHERE, i] != 0.0 else box
        for i in range(m):
            out[start + i] = w[_RAB, i]
