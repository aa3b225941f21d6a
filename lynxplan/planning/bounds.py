"""The compiled kernels of the planner's validity checker: the robot's joint and primitive poses,
each pair's lower bound of the distance, a state's bounds and the clearance probes of an edge.

What the bounds are and how the checker uses them: :mod:`lynxplan.planning.validity` (the
checker, over these kernels) and :mod:`lynxplan.planning.edge_walk` (edges).
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np

from lynxplan.planning.kernel_model import njit_no_refcount
from lynxplan.planning.pair_bound import all_pair_bounds, pair_bound_below

#: An edge walk stops when a pair's bound is within this of the required clearance, in [m]:
#: every step then advances by at least this over the pair's motion rate (no endless creeping).
STALL_DISTANCE = 2e-4


# -- compiled kernels ---------------------------------------------------------------------------


@numba.njit(cache=True, inline="always")
def _compose_into(a: np.ndarray, i: int, b: np.ndarray, j: int, out: np.ndarray, k: int) -> None:
    """out[k] = a[i] @ b[j] for 4x4 rigid transforms (bottom row 0 0 0 1); a, b, out: (n, 4, 4)
    stacks, indexed here rather than sliced (a slice of an array costs two atomic reference
    counts in compiled code: the hot loops take none)."""
    for r in range(3):
        a0, a1, a2 = a[i, r, 0], a[i, r, 1], a[i, r, 2]
        for c in range(4):
            out[k, r, c] = a0 * b[j, 0, c] + a1 * b[j, 1, c] + a2 * b[j, 2, c]
        out[k, r, 3] += a[i, r, 3]
    out[k, 3, 0] = 0.0
    out[k, 3, 1] = 0.0
    out[k, 3, 2] = 0.0
    out[k, 3, 3] = 1.0


@numba.njit(cache=True, inline="always")
def joint_poses(q: np.ndarray, model: Any, scratch: Any) -> None:
    """World pose of every joint frame at one configuration q (nq,) -> scratch.joint_poses."""
    joint_poses_upto(q, model, scratch, model.joint_placements.shape[0] - 1)


@numba.njit(cache=True, inline="always")
def joint_poses_upto(q: np.ndarray, model: Any, scratch: Any, last: int) -> None:
    """World poses of joint frames 0..last at one configuration q (nq,) -> scratch.joint_poses (a
    parent's index is below its child's, so those need no other joint).

    The joint rotation is applied to the placement's columns directly (a rotation about one
    axis mixes two columns), then composed with the parent's pose.
    """
    axes, index_q, parents, placement = (
        model.axes,
        model.index_q,
        model.parents,
        model.joint_placements,
    )
    world, local = scratch.joint_poses, scratch.local
    for i in range(4):
        for j in range(4):
            world[0, i, j] = 1.0 if i == j else 0.0
    for j in range(1, last + 1):
        angle = q[index_q[j]]
        c, s = math.cos(angle), math.sin(angle)
        a = axes[j]
        i1, i2 = (a + 1) % 3, (a + 2) % 3
        for r in range(3):
            first, second = placement[j, r, i1], placement[j, r, i2]
            local[0, r, i1] = c * first + s * second
            local[0, r, i2] = c * second - s * first
            local[0, r, a] = placement[j, r, a]
            local[0, r, 3] = placement[j, r, 3]
        _compose_into(world, parents[j], local, 0, world, j)


@numba.njit(cache=True, inline="always")
def primitive_pose(g: int, model: Any, scratch: Any) -> None:
    """World pose of primitive g from scratch.joint_poses -> scratch.prim_poses[g]."""
    _compose_into(
        scratch.joint_poses, model.prim_joints[g], model.prim_placements, g, scratch.prim_poses, g
    )


@njit_no_refcount()
def primitive_poses(q: np.ndarray, model: Any, scratch: Any) -> None:
    """World poses of every primitive at one configuration q (nq,) -> scratch.prim_poses."""
    joint_poses(q, model, scratch)
    for g in range(model.prim_joints.shape[0]):
        primitive_pose(g, model, scratch)


@njit_no_refcount()
def state_bounds(q: np.ndarray, model: Any, scratch: Any, out: np.ndarray) -> None:
    """Lower bound of the distance of every pair at q (nq,) -> out (P,), in [m] (all pairs at
    once: :func:`lynxplan.planning.pair_bound.all_pair_bounds`)."""
    primitive_poses(q, model, scratch)
    all_pair_bounds(model, scratch.prim_poses, out)


@njit_no_refcount()
def first_below(q: np.ndarray, model: Any, scratch: Any, threshold: float, out: np.ndarray) -> int:
    """Every pair's bound at q (nq,) -> out (P,), in [m], and the first pair whose bound is at
    most ``threshold`` [m] (-1: none). The pair that failed last (scratch.counters[3]) is tried
    alone first (a blocked region usually blocks the same pair): when it fails, -2 - that pair
    is returned and out is not filled."""
    primitive_poses(q, model, scratch)
    count, last = model.pairs.shape[0], scratch.counters[3]
    if last < count and pair_bound_below(last, model, scratch, threshold) <= threshold:
        return int(-2 - last)
    all_pair_bounds(model, scratch.prim_poses, out)
    for p in range(count):
        if out[p] <= threshold:
            scratch.counters[3] = p
            return p
    return -1


@njit_no_refcount()
def point_is_clear(
    q_a: np.ndarray,
    q_b: np.ndarray,
    s: float,
    model: Any,
    scratch: Any,
    clearance: float,
    row: int,
) -> bool:
    """Whether every pair's bound exceeds clearance + STALL_DISTANCE at q_a + s (q_b - q_a).

    A quick rejection before an edge walk (a blocked edge usually has a blocked point there):
    it stops at the first failing pair, trying first the pair that failed last
    (scratch.counters[3]).
    When it passes, the edge walk may use its bounds: they are in grid row ``row``
    (scratch.grid[row], (P,), in [m]; the point's parameter s in scratch.grid_at[row]).
    """
    q = scratch.q
    for j in range(q_a.shape[0]):
        q[j] = q_a[j] + s * (q_b[j] - q_a[j])
    scratch.grid_at[row] = s
    return first_below(q, model, scratch, clearance + STALL_DISTANCE, scratch.grid[row]) == -1


@numba.njit(cache=True, inline="always")
def probes_are_clear(
    q_a: np.ndarray, q_b: np.ndarray, model: Any, scratch: Any, clearance: float
) -> bool:
    """:func:`point_is_clear` at s = 1/4, 3/4, then 1/2 of the edge (their bounds are then grid
    rows 0, 2 and 1: the walk's grid of :data:`PROBES` points, for
    :func:`lynxplan.planning.edge_walk.edge_is_free_after_probes`).

    Before an edge walk whose only use is a whole certified edge (a shortcut, the straight
    edge to a goal): a blocked edge is usually blocked at one of these points, and a test
    there costs one configuration's bounds, where the walk would advance to the obstacle
    first. A pair far enough from everything is then certified by the grid alone."""
    return (
        point_is_clear(q_a, q_b, 0.25, model, scratch, clearance, np.int64(0))
        and point_is_clear(q_a, q_b, 0.75, model, scratch, clearance, np.int64(2))
        and point_is_clear(q_a, q_b, 0.5, model, scratch, clearance, np.int64(1))
    )


#: Grid points that :func:`probes_are_clear` leaves for the edge walk.
PROBES = 3
