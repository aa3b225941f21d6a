"""One pair's distance bound at several points of an edge at once: a vectorised numba kernel.

:func:`pair_along` computes, for one checked pair and :data:`LANES` parameters ``s_i`` of the
straight joint edge ``q(s) = q_a + s (q_b - q_a)``, the same quantities as one step of the
scalar edge walk (:func:`lynxplan.planning.motion.pose_pair_at` and
:func:`lynxplan.planning.pair_bound.pair_bound`): the pair's lower bound of the distance and its
lever arms about each joint; :func:`spheres_along` the exact verification's sphere gap
(:func:`lynxplan.planning.sphere_gaps.sphere_gap`) with the same lever arms. The lanes are the
innermost loop of every computation, stored as rows of a constant-width scratch array
(structure of arrays, one row a quantity), with selects instead of branches, so LLVM turns each
loop into SIMD instructions (several configurations for about the price of one).

The bound is :mod:`lynxplan.planning.pair_bound`'s (its :func:`obb_gap` and
:func:`point_box_gap` in every lane).

The walk (:func:`lynxplan.planning.edge_walk.edge_walk`) uses the lanes as a speculative run of
two-sided steps of one pair: every interval between consecutive lanes is certified by the same
test as a scalar two-sided step, the first that fails ends the run.
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np

from lynxplan._fastmath import sincos
from lynxplan.planning.kernel_model import (
    LANES,
    OBSTACLE_SPHERE,
    njit_no_refcount,
    stack_array,
)
from lynxplan.planning.pair_bound import ALL_AXES, obb_gap, point_box_gap

#: Joints (frames) a kernel model may have for the lanes (the scalar walk serves larger ones).
MAX_JOINTS = 12
#: IEEE-safe fast-math flags (fused multiply-add, reciprocal division; see ik_kernel).
_FAST = {"contract", "arcp"}

# Scratch rows: 12 per joint frame (rotation row-major, then translation); then constant rows
# that every vectorised loop reads and writes (a loop between rows at run-time offsets would
# need aliasing checks, and LLVM gives up on many): the input pose P, the new pose N, the two
# primitives of the pair A and B, the parameters S, a result T and the bound.
_P = 12 * MAX_JOINTS
_N = _P + 12
_A = _N + 12
_B = _A + 12
_S = _B + 12
_T = _S + 1
_BOUND = _T + 1
_ROWS = _BOUND + 1
#: The work rows of :func:`pair_along` and :func:`spheres_along`, on their stack.
_lane_rows = stack_array(_ROWS, LANES)
#: Rows of the output of :func:`pair_along` and :func:`spheres_along`: 0 the bound [m], 1 the
#: parameter s (input), 2 the covering-sphere gap of the exact verification [m], 3 + j the lever
#: arm about configuration index j [m].
OUT_BOUND, OUT_S, OUT_SPHERE, OUT_ARMS = 0, 1, 2, 3


@numba.njit(cache=True, inline="always", fastmath=_FAST)
def _copy_rows(w: np.ndarray, dst: int, src: int, count: int) -> None:
    """Rows src..src+count-1 of w -> rows dst..dst+count-1."""
    for r in range(count):
        for i in range(LANES):
            w[dst + r, i] = w[src + r, i]


@numba.njit(cache=True, inline="always", fastmath=_FAST)
def _joint_rows(w: np.ndarray, j: int, model: Any, q_a: np.ndarray, q_b: np.ndarray) -> None:
    """World pose of joint frame j in every lane (its parent's rows ready): the parent's pose,
    the joint placement, then the rotation about the joint axis (it turns two columns)."""
    axes, index_q, parents, pl = model.axes, model.index_q, model.parents, model.joint_placements
    a = axes[j]
    i1, i2 = (a + 1) % 3, (a + 2) % 3
    qa, dq = q_a[index_q[j]], q_b[index_q[j]] - q_a[index_q[j]]
    p00, p01, p02, p03 = pl[j, 0, 0], pl[j, 0, 1], pl[j, 0, 2], pl[j, 0, 3]
    p10, p11, p12, p13 = pl[j, 1, 0], pl[j, 1, 1], pl[j, 1, 2], pl[j, 1, 3]
    p20, p21, p22, p23 = pl[j, 2, 0], pl[j, 2, 1], pl[j, 2, 2], pl[j, 2, 3]
    # column k of the new rotation: M_k (k = a), c M_i1 + s M_i2 (k = i1), c M_i2 - s M_i1
    _copy_rows(w, _P, 12 * parents[j], 12)
    for i in range(LANES):
        s, c = sincos(qa + w[_S, i] * dq)
        for r in range(3):
            u0, u1, u2 = w[_P + 3 * r, i], w[_P + 3 * r + 1, i], w[_P + 3 * r + 2, i]
            m0 = u0 * p00 + u1 * p10 + u2 * p20
            m1 = u0 * p01 + u1 * p11 + u2 * p21
            m2 = u0 * p02 + u1 * p12 + u2 * p22
            w[_N + 9 + r, i] = u0 * p03 + u1 * p13 + u2 * p23 + w[_P + 9 + r, i]
            mi1 = m1 if i1 == 1 else (m2 if i1 == 2 else m0)
            mi2 = m1 if i2 == 1 else (m2 if i2 == 2 else m0)
            first = c * mi1 + s * mi2
            second = c * mi2 - s * mi1
            w[_N + 3 * r, i] = m0 if a == 0 else (first if i1 == 0 else second)
            w[_N + 3 * r + 1, i] = m1 if a == 1 else (first if i1 == 1 else second)
            w[_N + 3 * r + 2, i] = m2 if a == 2 else (first if i1 == 2 else second)
    _copy_rows(w, 12 * j, _N, 12)


@numba.njit(cache=True, inline="always", fastmath=_FAST)
def _primitive_rows(w: np.ndarray, out: int, g: int, model: Any) -> None:
    """World pose of primitive g in every lane -> rows out..out+11."""
    pl = model.prim_placements
    p00, p01, p02, p03 = pl[g, 0, 0], pl[g, 0, 1], pl[g, 0, 2], pl[g, 0, 3]
    p10, p11, p12, p13 = pl[g, 1, 0], pl[g, 1, 1], pl[g, 1, 2], pl[g, 1, 3]
    p20, p21, p22, p23 = pl[g, 2, 0], pl[g, 2, 1], pl[g, 2, 2], pl[g, 2, 3]
    _copy_rows(w, _P, 12 * model.prim_joints[g], 12)
    for i in range(LANES):
        for r in range(3):
            u0, u1, u2 = w[_P + 3 * r, i], w[_P + 3 * r + 1, i], w[_P + 3 * r + 2, i]
            w[out + 3 * r, i] = u0 * p00 + u1 * p10 + u2 * p20
            w[out + 3 * r + 1, i] = u0 * p01 + u1 * p11 + u2 * p21
            w[out + 3 * r + 2, i] = u0 * p02 + u1 * p12 + u2 * p22
            w[out + 9 + r, i] = u0 * p03 + u1 * p13 + u2 * p23 + w[_P + 9 + r, i]


@numba.njit(cache=True, inline="always", fastmath=_FAST)
def _fixed_rows(w: np.ndarray, out: int, poses: np.ndarray, b: int) -> None:
    """The fixed pose poses[b] (4, 4) in every lane -> rows out..out+11."""
    for r in range(3):
        for c in range(3):
            value = poses[b, r, c]
            for i in range(LANES):
                w[out + 3 * r + c, i] = value
        value = poses[b, r, 3]
        for i in range(LANES):
            w[out + 9 + r, i] = value


@numba.njit(cache=True, inline="always", fastmath=_FAST)
def _box_bounds(
    w: np.ndarray, half_a: np.ndarray, a: int, half_b: np.ndarray, b: int, rab: float
) -> None:
    """Lower bound of the distance of box A (rows _A, half sizes half_a[a]) and box B (rows
    _B, half sizes half_b[b]), every lane -> row _BOUND (:func:`obb_gap`; rab: the two
    bounding radii)."""
    ha0, ha1, ha2 = half_a[a, 0], half_a[a, 1], half_a[a, 2]
    hb0, hb1, hb2 = half_b[b, 0], half_b[b, 1], half_b[b, 2]
    for i in range(LANES):
        w[_BOUND, i] = obb_gap(
            (
                w[_B + 9, i] - w[_A + 9, i],
                w[_B + 10, i] - w[_A + 10, i],
                w[_B + 11, i] - w[_A + 11, i],
            ),
            (
                (w[_A, i], w[_A + 1, i], w[_A + 2, i]),
                (w[_A + 3, i], w[_A + 4, i], w[_A + 5, i]),
                (w[_A + 6, i], w[_A + 7, i], w[_A + 8, i]),
            ),
            (
                (w[_B, i], w[_B + 1, i], w[_B + 2, i]),
                (w[_B + 3, i], w[_B + 4, i], w[_B + 5, i]),
                (w[_B + 6, i], w[_B + 7, i], w[_B + 8, i]),
            ),
            (ha0, ha1, ha2),
            (hb0, hb1, hb2),
            rab,
            ALL_AXES,
        )


@numba.njit(cache=True, inline="always", fastmath=_FAST)
def _sphere_bounds(w: np.ndarray, half: np.ndarray, a: int, model: Any, b: int) -> None:
    """Distance of box A (rows _A, half sizes half[a]) to sphere obstacle b, every lane -> row
    _BOUND (exact: point-box distance minus the radius)."""
    c0, c1, c2 = (
        model.obstacle_centres[b, 0],
        model.obstacle_centres[b, 1],
        model.obstacle_centres[b, 2],
    )
    radius = model.obstacle_half[b, 0]
    ha = (half[a, 0], half[a, 1], half[a, 2])
    for i in range(LANES):
        d = (c0 - w[_A + 9, i], c1 - w[_A + 10, i], c2 - w[_A + 11, i])
        rows = (
            (w[_A, i], w[_A + 1, i], w[_A + 2, i]),
            (w[_A + 3, i], w[_A + 4, i], w[_A + 5, i]),
            (w[_A + 6, i], w[_A + 7, i], w[_A + 8, i]),
        )
        w[_BOUND, i] = point_box_gap(d, rows, ha) - radius


@numba.njit(cache=True, inline="always", fastmath=_FAST)
def _arm_row(w: np.ndarray, rows: int, extra: float) -> None:
    """Lever arm about the axis in rows _P (direction) and _P + 3 (a point on it) of the
    primitive in rows ``rows`` (its centre), plus ``extra`` [m], every lane -> row _T."""
    for i in range(LANES):
        w0, w1, w2 = w[_P, i], w[_P + 1, i], w[_P + 2, i]
        d0 = w[rows + 9, i] - w[_P + 3, i]
        d1 = w[rows + 10, i] - w[_P + 4, i]
        d2 = w[rows + 11, i] - w[_P + 5, i]
        c0, c1, c2 = w1 * d2 - w2 * d1, w2 * d0 - w0 * d2, w0 * d1 - w1 * d0
        w[_T, i] = math.sqrt(c0 * c0 + c1 * c1 + c2 * c2) + extra


@numba.njit(cache=True, inline="always", fastmath=_FAST)
def _arm_rows(w: np.ndarray, p: int, model: Any, out: np.ndarray) -> None:
    """Lever arms of pair p about each configuration index, every lane -> out[OUT_ARMS + j]
    (as :func:`lynxplan.planning.motion.lever_arms`)."""
    axes, radius, owners, joints, pairs = (
        model.axes,
        model.prim_radius,
        model.owners,
        model.joint_of_q,
        model.pairs,
    )
    for j in range(owners.shape[1]):
        g = owners[p, j]
        joint = joints[j]
        if g < 0 or joint < 0:
            for i in range(LANES):
                out[OUT_ARMS + j, i] = 0.0
            continue
        base, a = 12 * joint, axes[joint]
        for k in range(3):  # the axis (rotation column a), then the origin
            _copy_rows(w, _P + k, base + 3 * k + a, 1)
        _copy_rows(w, _P + 3, base + 9, 3)
        if g == pairs[p, 0]:
            _arm_row(w, _A, radius[g])
        else:
            _arm_row(w, _B, radius[g])
        for i in range(LANES):
            out[OUT_ARMS + j, i] = w[_T, i]


@numba.njit(cache=True, inline="always", fastmath=_FAST)
def _pose_pair_rows(
    q_a: np.ndarray, q_b: np.ndarray, p: int, model: Any, out: np.ndarray, w: np.ndarray
) -> None:
    """Pair p's robot primitives posed at the LANES points s_i = out[OUT_S, i] of the edge from
    q_a to q_b (nq,): rows _A (and _B for a self pair)."""
    pairs, prim_joints = model.pairs, model.prim_joints
    for i in range(LANES):
        w[_S, i] = out[OUT_S, i]
    for r in range(12):  # the universe frame: identity
        value = 1.0 if r % 4 == 0 else 0.0
        for i in range(LANES):
            w[r, i] = value
    a, b, is_self = pairs[p, 0], pairs[p, 1], pairs[p, 2]
    last = prim_joints[a]
    if is_self == 1:
        last = max(last, prim_joints[b])
    for j in range(1, last + 1):
        _joint_rows(w, j, model, q_a, q_b)
    _primitive_rows(w, _A, a, model)
    if is_self == 1:
        _primitive_rows(w, _B, b, model)


@njit_no_refcount(error_model="numpy", fastmath=_FAST)
def pair_along(q_a: np.ndarray, q_b: np.ndarray, p: int, model: Any, out: np.ndarray) -> None:
    """Pair p at the LANES points s_i = out[OUT_S, i] of the edge from q_a to q_b (nq,), in
    [rad]: out[OUT_BOUND] its distance lower bound [m], out[OUT_ARMS + j] its lever arm about
    configuration index j [m]; out: (3 + nq, LANES).

    The model has at most :data:`MAX_JOINTS` joint frames and configuration indices.
    """
    w = _lane_rows()
    _pose_pair_rows(q_a, q_b, p, model, out, w)
    a, b, is_self = model.pairs[p, 0], model.pairs[p, 1], model.pairs[p, 2]
    half, radius = model.prim_half, model.prim_radius
    if is_self == 1:
        _box_bounds(w, half, a, half, b, radius[a] + radius[b])
    elif model.obstacle_kinds[b] == OBSTACLE_SPHERE:
        _sphere_bounds(w, half, a, model, b)
    else:
        _fixed_rows(w, _B, model.obstacle_poses, b)
        _box_bounds(w, half, a, model.obstacle_half, b, radius[a] + model.obstacle_radius[b])
    for i in range(LANES):
        out[OUT_BOUND, i] = w[_BOUND, i]
    _arm_rows(w, p, model, out)


@njit_no_refcount(error_model="numpy", fastmath=_FAST)
def spheres_along(q_a: np.ndarray, q_b: np.ndarray, p: int, model: Any, out: np.ndarray) -> None:
    """Pair p at the LANES points s_i = out[OUT_S, i] of the edge from q_a to q_b (nq,), in
    [rad]: out[OUT_SPHERE] its covering-sphere gap (the exact verification's independent bound,
    :func:`lynxplan.planning.sphere_gaps.sphere_gap`) [m], out[OUT_ARMS + j] its lever arm about
    configuration index j [m]; out: (3 + nq, LANES).

    The model has at most :data:`MAX_JOINTS` joint frames and configuration indices.
    """
    w = _lane_rows()
    _pose_pair_rows(q_a, q_b, p, model, out, w)
    _sphere_gap_rows(w, p, model)
    for i in range(LANES):
        out[OUT_SPHERE, i] = w[_BOUND, i]
    _arm_rows(w, p, model, out)


@numba.njit(cache=True, inline="always", fastmath=_FAST)
def _cover_rows(w: np.ndarray, rows: int, c: np.ndarray, out: int) -> None:
    """World position of the point c (3,) of the primitive posed in rows ``rows``, every lane ->
    rows out..out+2."""
    for r in range(3):
        m0, m1, m2, t = rows + 3 * r, rows + 3 * r + 1, rows + 3 * r + 2, rows + 9 + r
        for i in range(LANES):
            w[out + r, i] = w[t, i] + w[m0, i] * c[0] + w[m1, i] * c[1] + w[m2, i] * c[2]


@numba.njit(cache=True, inline="always", fastmath=_FAST)
def _sphere_gap_rows(w: np.ndarray, p: int, model: Any) -> None:
    """The covering-sphere gap of pair p (:func:`lynxplan.planning.sphere_gaps.sphere_gap`) from
    rows _A (and _B), every lane -> row _BOUND, in [m]. Rows _P.._P+5 (the joint axis rows, free
    once the primitives are posed) hold sphere centres, row _T the other way round's distance."""
    pairs, centres, counts, radii, half = (
        model.pairs,
        model.cover_centres,
        model.cover_counts,
        model.cover_radii,
        model.prim_half,
    )
    a, b = pairs[p, 0], pairs[p, 1]
    for i in range(LANES):
        w[_BOUND, i] = np.inf  # the smallest squared distance of a centre of a
        w[_T, i] = np.inf  # ... of a centre of b (a self pair)
    if pairs[p, 2] == 1:
        for m in range(counts[a]):
            _cover_rows(w, _A, centres[a, m], _P)
            _nearest_box(w, _B, half[b], _BOUND)
        for m in range(counts[b]):
            _cover_rows(w, _B, centres[b, m], _P)
            _nearest_box(w, _A, half[a], _T)
        ra, rb = radii[a], radii[b]
        for i in range(LANES):
            w[_BOUND, i] = max(math.sqrt(w[_BOUND, i]) - ra, math.sqrt(w[_T, i]) - rb)
        return
    if model.obstacle_kinds[b] == OBSTACLE_SPHERE:  # the centres' distance less both radii
        for r in range(3):
            for i in range(LANES):
                w[_P + 3 + r, i] = model.obstacle_poses[b, r, 3]
        for m in range(counts[a]):
            _cover_rows(w, _A, centres[a, m], _P)
            _nearest_point(w)
        other = radii[a] + model.obstacle_half[b, 0]
    else:
        _fixed_rows(w, _B, model.obstacle_poses, b)
        for m in range(counts[a]):
            _cover_rows(w, _A, centres[a, m], _P)
            _nearest_box(w, _B, model.obstacle_half[b], _BOUND)
        other = radii[a]
    for i in range(LANES):
        w[_BOUND, i] = math.sqrt(w[_BOUND, i]) - other


@numba.njit(cache=True, inline="always", fastmath=_FAST)
def _nearest_point(w: np.ndarray) -> None:
    """Row _BOUND lowered to the squared distance of the points in rows _P.._P+2 and
    _P+3.._P+5, every lane."""
    for i in range(LANES):
        d0 = w[_P + 3, i] - w[_P, i]
        d1 = w[_P + 4, i] - w[_P + 1, i]
        d2 = w[_P + 5, i] - w[_P + 2, i]
        w[_BOUND, i] = min(w[_BOUND, i], d0 * d0 + d1 * d1 + d2 * d2)


@numba.njit(cache=True, inline="always", fastmath=_FAST)
def _nearest_box(w: np.ndarray, rows: int, half: np.ndarray, out: int) -> None:
    """Row ``out`` lowered to the squared distance of the point in rows _P.._P+2 from the box
    posed in rows ``rows`` with half sizes half (3,), every lane."""
    h0, h1, h2 = half[0], half[1], half[2]
    for i in range(LANES):
        d0 = w[_P, i] - w[rows + 9, i]
        d1 = w[_P + 1, i] - w[rows + 10, i]
        d2 = w[_P + 2, i] - w[rows + 11, i]
        x = w[rows, i] * d0 + w[rows + 3, i] * d1 + w[rows + 6, i] * d2
        y = w[rows + 1, i] * d0 + w[rows + 4, i] * d1 + w[rows + 7, i] * d2
        z = w[rows + 2, i] * d0 + w[rows + 5, i] * d1 + w[rows + 8, i] * d2
        e0 = max(abs(x) - h0, 0.0)
        e1 = max(abs(y) - h1, 0.0)
        e2 = max(abs(z) - h2, 0.0)
        w[out, i] = min(w[out, i], e0 * e0 + e1 * e1 + e2 * e2)
