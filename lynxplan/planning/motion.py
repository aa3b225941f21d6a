"""How far a checked pair may move along an edge of joint space: the motion bounds of
conservative advancement, shared by the edge walk (:mod:`lynxplan.planning.edge_walk`) and the
verification schedule (:mod:`lynxplan.planning.certify`).

Between two states ``q_a`` and ``q_b`` the joints move linearly. A point at distance ``rho_j`` from
joint j's axis moves at ``sum_j rho_j |dq_j|`` per unit of the edge parameter ``s`` (proof in
:mod:`lynxplan.collision.verify`, with ``rho_j`` bounded by the static reach ``R_gj``). The
bounds use the lever arms at the configuration itself (:func:`lever_arms`: the distance of the
primitive's centre from each axis plus its bounding radius), which grow at most at the point's own
speed relative to that joint (:func:`reach_step`, :func:`span_motion`). For a self pair only the
joints that move one body and not the other count (the distance depends on the relative pose only;
common ancestors move both rigidly), and a fixed cylinder coaxial with the first joint (the base)
makes that joint irrelevant (:func:`lynxplan.planning.kernel_model.pair_rates`). A pair with slack
``sigma`` above the clearance at ``s`` is certified one-sided up to ``s + ds`` (its motion bound
reaches ``sigma``), and two-sided on ``[s, t]`` when ``sigma_s + sigma_t`` exceeds the motion bound
over it.
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np

from lynxplan.planning.bounds import joint_poses_upto, primitive_pose
from lynxplan.planning.kernel_model import LANES, njit_no_refcount
from lynxplan.planning.lanes import OUT_ARMS, OUT_S
from lynxplan.planning.pair_bound import pair_bound


@numba.njit(cache=True, inline="always")
def copy_row(dst: np.ndarray, i: int, src: np.ndarray, k: int) -> None:
    """dst[i, :] = src[k, :] for 2-D arrays, indexed rather than sliced (a slice costs two
    atomic reference counts in compiled code)."""
    for j in range(dst.shape[1]):
        dst[i, j] = src[k, j]


@numba.njit(cache=True, inline="always")
def lever_arms(
    p: int, world: np.ndarray, poses: np.ndarray, model: Any, out: np.ndarray, row: int
) -> None:
    """Lever arm of pair p about each joint at joint poses ``world`` (J, 4, 4) and primitive
    poses ``poses`` (G, 4, 4) -> out[row] (nq,), in [m]: the largest distance of a point of the
    primitive that joint j moves (relative to the other side) from joint j's axis, bounded by
    the distance of its centre from the axis plus its bounding radius; 0 when j moves neither.
    (Rows are indexed, not sliced: no reference counting in the compiled hot loops.)
    """
    axes, radius, owners, joints = model.axes, model.prim_radius, model.owners, model.joint_of_q
    for j in range(out.shape[1]):
        g = owners[p, j]
        joint = joints[j]
        if g < 0 or joint < 0:
            out[row, j] = 0.0
            continue
        a = axes[joint]
        w0, w1, w2 = world[joint, 0, a], world[joint, 1, a], world[joint, 2, a]
        d0 = poses[g, 0, 3] - world[joint, 0, 3]
        d1 = poses[g, 1, 3] - world[joint, 1, 3]
        d2 = poses[g, 2, 3] - world[joint, 2, 3]
        c0, c1, c2 = w1 * d2 - w2 * d1, w2 * d0 - w0 * d2, w0 * d1 - w1 * d0
        out[row, j] = math.sqrt(c0 * c0 + c1 * c1 + c2 * c2) + radius[g]


@numba.njit(cache=True, inline="always")
def reach_step(slack: float, p: int, arms: np.ndarray, row: int, model: Any, scratch: Any) -> float:
    """Largest ds such that pair p, with ``slack`` [m] above the clearance at s and lever arms
    ``arms[row]`` (nq,) there, provably keeps the clearance on [s, s + ds] (one-sided).

    A point of the moving primitive moves at most ``sum_j |dq_j| rho_j`` per unit s, rho_j its
    distance from joint j's axis; rho_j at s is at most ``arms[j]``, never more than the static
    reach ``R_j`` (``model.rates``), and grows at most at the speed of the point relative to joint
    j's frame, ``L = sum_i R_i |dq_i|`` (only joints between j and the primitive move it there).
    So the motion over ds is at most ``min(L ds, V ds + L D ds^2 / 2)`` with ``V = sum_j |dq_j|
    min(R_j, arms_j)`` and ``D = sum_j |dq_j|`` over the pair's joints.
    """
    rates, dq = model.rates, scratch.dq
    static = lever = spread = 0.0
    for j in range(dq.shape[0]):
        if rates[p, j] > 0.0:
            static += rates[p, j] * dq[j]
            lever += min(rates[p, j], arms[row, j]) * dq[j]
            spread += dq[j]
    if static <= 0.0:
        return np.inf
    quadratic = 2.0 * slack / (lever + math.sqrt(lever * lever + 2.0 * static * spread * slack))
    return max(slack / static, quadratic)


@numba.njit(cache=True, inline="always")
def span_motion(p: int, ds: float, model: Any, scratch: Any) -> float:
    """Bound of pair p's motion over an interval of length ds (of s) between two points whose
    lever arms are scratch.arms[0] and scratch.arms[1], in [m].

    In between, rho_j is at most the smaller of ``rho_j(s) + L (u - s)`` and ``rho_j(t) +
    L (t - u)``, hence at most their mean ``(rho_j(s) + rho_j(t) + L ds) / 2``, and at most R_j.
    """
    rates, dq, arms = model.rates, scratch.dq, scratch.arms
    static = 0.0
    for j in range(dq.shape[0]):
        static += rates[p, j] * dq[j]
    total = 0.0
    for j in range(dq.shape[0]):
        if rates[p, j] > 0.0:
            rho = 0.5 * (min(rates[p, j], arms[0, j]) + min(rates[p, j], arms[1, j]) + static * ds)
            total += min(rates[p, j], rho) * dq[j]
    return total * ds


@njit_no_refcount()
def pose_pair_at(
    q_a: np.ndarray, q_b: np.ndarray, s: float, p: int, model: Any, scratch: Any, side: int
) -> None:
    """Pair p's primitives posed at q_a + s (q_b - q_a) (joints beyond them left alone: they
    move neither); its lever arms -> scratch.arms[side]."""
    q, pairs, joint_of = scratch.q, model.pairs, model.prim_joints
    for j in range(q_a.shape[0]):
        q[j] = q_a[j] + s * (q_b[j] - q_a[j])
    last = joint_of[pairs[p, 0]]
    if pairs[p, 2] == 1:
        last = max(last, joint_of[pairs[p, 1]])
    joint_poses_upto(q, model, scratch, last)
    primitive_pose(pairs[p, 0], model, scratch)
    if pairs[p, 2] == 1:
        primitive_pose(pairs[p, 1], model, scratch)
    lever_arms(p, scratch.joint_poses, scratch.prim_poses, model, scratch.arms, side)


@njit_no_refcount()
def pair_bound_at(
    q_a: np.ndarray, q_b: np.ndarray, s: float, p: int, model: Any, scratch: Any, side: int
) -> float:
    """Pair p's bound at q_a + s (q_b - q_a), in [m] (:func:`lynxplan.planning.pair_bound.
    pair_bound`); its lever arms -> scratch.arms[side]."""
    pose_pair_at(q_a, q_b, s, p, model, scratch, side)
    return float(pair_bound(p, model, scratch))


#: A walk tries a two-sided step of this many one-sided steps (the two-sided test allows < 2).
STEP_GROWTH = 1.9
#: ... and never more than this many.
MAX_GROWTH = 4.0
#: The points of a vectorised run are this many predicted one-sided steps apart (below
#: STEP_GROWTH: a run skips points that prove too close, but stops at one too far).
LANE_GROWTH = 1.2
#: ... predicting a slack never below this fraction of the slack at the run's start.
LANE_FLOOR = 0.05


@numba.njit(cache=True, inline="always")
def two_sided_step(slack: float, one: float, trend: float) -> float:
    """The length of s to try for a two-sided step from a point with ``slack`` [m] above the
    clearance, one-sided step ``one`` and slack trend [m per unit s] (its change at the last
    step): the bound's speed V ~ slack / one; the two ends' slacks sum to about 2 slack +
    trend t, enough while t < 2 slack / (V - trend). Approaching (trend ~ -V): one-sided
    steps; at most :data:`MAX_GROWTH` of them."""
    speed = slack / one
    closing = speed - min(max(trend, -speed), speed)
    span = STEP_GROWTH * slack / closing if closing > 0.0 else MAX_GROWTH * one
    return min(span, MAX_GROWTH * one)


@numba.njit(cache=True, inline="always")
def place_lanes(s: float, sigma: float, one: float, trend: float, out: np.ndarray) -> bool:
    """The points of a run (:func:`_lane_run`) from s, slack sigma [m], one-sided step ``one``
    and slack trend [m per unit s] -> out[OUT_S]; False when there is no step to take."""
    if one <= 0.0 or sigma <= 0.0:
        return False
    speed = sigma / one
    rate = min(max(trend, -speed), speed)
    closing = speed - rate
    u, predicted = s, sigma
    for i in range(LANES):
        step = MAX_GROWTH * predicted / speed
        if closing > 0.0:
            step = min(step, LANE_GROWTH * predicted / closing)
        u = min(1.0, u + step)
        predicted = max(predicted + rate * step, LANE_FLOOR * sigma)
        out[OUT_S, i] = u
    return True


@numba.njit(cache=True, inline="always")
def farthest_lane(
    i: int,
    start: tuple[float, float, float],
    p: int,
    model: Any,
    scratch: Any,
    level: tuple[int, float, float],
) -> int:
    """The farthest lane k >= i of a vectorised run (scratch.lanes) certified from start = (s,
    slack [m], one-sided step own) (lever arms scratch.arms[0], one-sided reach s + own): the
    lane's slack ``scratch.lanes[row, k] - offset`` above ``floor`` (level = (row, offset,
    floor)), and k within the reach or passing the two-sided test (:func:`span_motion`);
    scanning forward until a lane fails after one passed. -1: none; -2 - k: lane k, the first
    lane after s, has its slack at or below ``floor`` (a wall for the edge walk; the sphere
    chains stop there too)."""
    s, slack, own = start
    row, offset, floor = level
    out, arms = scratch.lanes, scratch.arms
    best = -1
    for k in range(i, LANES):
        t = out[OUT_S, k]
        slack_t = out[row, k] - offset
        if t <= s:
            continue
        if slack_t <= floor:
            return -2 - k if best < 0 else best
        ok = t <= s + own
        if not ok:
            for j in range(arms.shape[1]):
                arms[1, j] = out[OUT_ARMS + j, k]
            ok = slack + slack_t > span_motion(p, t - s, model, scratch)
        if ok:
            best = k
        elif best >= 0:
            break
    return best
