"""Conservative advancement along an edge of joint space for the planner's checker (numba).

Each checked pair is walked along the edge with the motion bounds of
:mod:`lynxplan.planning.motion`: the pair certified least far advances next; the walk stops where
a bound comes within :data:`STALL_DISTANCE` of the clearance. Every certified part of an edge is
collision-free for the real geometry with distance >= ``clearance``: no sampling resolution,
nothing skipped between samples.

Most pairs are certified before any step, from every pair's bounds at the edge's start, its end
and the points where quick tests of it came first (a grid: its midpoint, or its quarters),
computed all pairs at once (:func:`lynxplan.planning.pair_bound.all_pair_bounds`), with the static
motion bound (:func:`_walk_start`); a pair that the grid certifies from some point to the end
stops walking there.
A pair that needs steps advances through several points per vectorised call
(:func:`lynxplan.planning.lanes.pair_along`, :func:`_lane_run`); each accepted point passes the
same one- or two-sided test as a single step.

Primitives fixed to the base (joint 0) do not move: their obstacle pairs are checked once,
exactly, by the problem set-up, and left out here.
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

from lynxplan.planning.bounds import (
    PROBES,
    STALL_DISTANCE,
    first_below,
    primitive_poses,
)
from lynxplan.planning.kernel_model import LANES, njit_no_refcount
from lynxplan.planning.lanes import (
    MAX_JOINTS,
    OUT_ARMS,
    OUT_BOUND,
    OUT_S,
    pair_along,
)
from lynxplan.planning.motion import (
    copy_row,
    farthest_lane,
    lever_arms,
    pair_bound_at,
    place_lanes,
    reach_step,
)
from lynxplan.planning.pair_bound import all_pair_bounds


@njit_no_refcount()
def state_slacks(
    q: np.ndarray, model: Any, scratch: Any, clearance: float, out: np.ndarray
) -> bool:
    """Every pair's bound minus the clearance at q (nq,) -> out (P,), in [m]; whether all exceed
    :data:`STALL_DISTANCE` (out is only complete when they do). The pair that failed last
    (scratch.counters[3]) is tried alone first (:func:`lynxplan.planning.bounds.first_below`)."""
    if first_below(q, model, scratch, clearance + STALL_DISTANCE, out) != -1:
        return False
    for p in range(out.shape[0]):
        out[p] -= clearance
    return True


@njit_no_refcount()
def edge_fraction(
    q_a: np.ndarray, q_b: np.ndarray, model: Any, scratch: Any, clearance: float
) -> float:
    """Conservative advancement from q_a towards q_b: the certified fraction s in [0, 1].

    Returns -1 if q_a itself is not valid (:func:`edge_walk`).
    """
    return edge_walk(
        q_a, q_b, model, scratch, clearance, np.bool_(False), np.int64(0), np.int64(ALL_JOINTS)
    )


@njit_no_refcount()
def edge_fraction_from(
    q_a: np.ndarray,
    q_b: np.ndarray,
    slacks: tuple[np.ndarray, np.ndarray],
    points: int,
    model: Any,
    scratch: Any,
    clearance: float,
    moved: int,
) -> float:
    """:func:`edge_fraction` with the pairs' slacks at q_a and q_b already known (slacks, two
    (P,) arrays, in [m], from :func:`state_slacks` at exactly q_a and q_b: tree nodes',
    computed once), and every pair's bound at ``points`` grid points of this edge (grid rows
    0..points-1: quick tests :func:`lynxplan.planning.bounds.point_is_clear` that passed
    just before, in increasing order of s).

    ``moved``: the joints (bit j: joint j) in which the edge may differ from a certified one
    (:func:`edge_walk`), or :data:`ALL_JOINTS`."""
    slack_a, slack_b = slacks
    start, end = scratch.slack, scratch.end
    for p in range(start.shape[0]):
        start[p] = slack_a[p]
        end[p] = slack_b[p]
    return edge_walk(
        q_a, q_b, model, scratch, clearance, np.bool_(True), END_KNOWN + points * POINT, moved
    )


@njit_no_refcount()
def edge_is_free_after_probes(
    q_a: np.ndarray, q_b: np.ndarray, model: Any, scratch: Any, clearance: float
) -> bool:
    """Whether the whole edge from q_a to q_b is certified, right after the quick tests
    :func:`lynxplan.planning.bounds.probes_are_clear` of this edge passed (their bounds are
    the grid)."""
    walked = edge_walk(
        q_a,
        q_b,
        model,
        scratch,
        clearance,
        np.bool_(False),
        np.int64(PROBES * POINT),
        np.int64(ALL_JOINTS),
    )
    return walked >= 1.0


#: :func:`edge_walk`'s ``moved`` when the edge is new in every joint.
ALL_JOINTS = -1
#: Joints with a bit of their own in ``moved``; any joint beyond them stands for all.
_JOINT_BITS = 62

#: Flags of :func:`edge_walk`'s ``grid``: the pairs' slacks at the edge's end are in
#: scratch.end (END_KNOWN); plus POINT times the number of grid points: every pair's bounds at
#: them are grid rows scratch.grid[i], (P,), at edge parameters scratch.grid_at[i], increasing.
END_KNOWN, POINT = 1, 2


@numba.njit(cache=True, inline="always")
def _grid_start(
    p: int, static: float, points: int, model: Any, scratch: Any, clearance: float
) -> None:
    """Where pair p's walk starts (scratch.where[p], its slack, lever arms and reach) and the grid
    point from which the grid certifies it to the edge's end (scratch.tail[p]), or nothing to
    walk (reach infinite), from the two-sided static test (motion bound ``static`` [m] per unit
    s) on the intervals i = 0..points between the grid points s_{i-1} and s_i (s_{-1} = 0,
    s_points = 1; :func:`_walk_start`)."""
    slack, reach, where, all_arms = scratch.slack, scratch.reach, scratch.where, scratch.all_arms
    end, bounds, at, tail = scratch.end, scratch.grid, scratch.grid_at, scratch.tail
    first = last = -1  # the first and the last interval not certified
    before, sigma = 0.0, slack[p]
    for i in range(points + 1):
        u = at[i] if i < points else 1.0
        sigma_u = bounds[i, p] - clearance if i < points else end[p]
        passed = sigma + sigma_u > static * (u - before) and (
            i == points or sigma_u > STALL_DISTANCE
        )
        if not passed:
            last = i
            if first < 0:
                first = i
        before, sigma = u, sigma_u
    if first < 0:
        return  # every interval certified
    tail[p] = at[last] if last < points else np.inf
    if first > 0:  # certified up to grid point first - 1: the walk starts there
        where[p], slack[p] = at[first - 1], bounds[first - 1, p] - clearance
        copy_row(all_arms, p, model.rates, p)  # lever arms at most the static reach
        reach[p] = where[p] + reach_step(slack[p], p, all_arms, p, model, scratch)
        return
    lever_arms(p, scratch.joint_poses, scratch.prim_poses, model, all_arms, p)
    reach[p] = reach_step(slack[p], p, all_arms, p, model, scratch)


@numba.njit(cache=True, inline="always")
def joint_bit(j: int) -> int:
    """Joint j as a bit set for ``moved`` (:func:`edge_walk`)."""
    bit: int = np.int64(1) << j if j < _JOINT_BITS else np.int64(ALL_JOINTS)
    return bit


@numba.njit(cache=True, inline="always")
def _moves(p: int, moved: int, rates: np.ndarray) -> bool:
    """Whether a joint of the bit set ``moved`` (not :data:`ALL_JOINTS`) changes pair p's
    distance (its motion rate about that joint, rates (P, nq), is not zero)."""
    for j in range(min(rates.shape[1], _JOINT_BITS)):
        if (moved >> j) & 1 and rates[p, j] > 0.0:
            return True
    return False


@numba.njit(cache=True, inline="always")
def _walk_start(
    q_a: np.ndarray,
    q_b: np.ndarray,
    model: Any,
    scratch: Any,
    clearance: float,
    known: bool | np.bool_,
    grid: int,
    moved: int,
) -> bool:
    """Set up an edge walk: joint steps, every pair's slack at q_a (unless ``known``) and at
    q_b (unless ``grid`` has END_KNOWN), first one-sided reach; False when a pair is within
    :data:`STALL_DISTANCE` at q_a.

    A pair is certified on the whole edge at once by the static motion bound L (its motion
    over any interval of length ds is at most L ds): one-sided when its slack at q_a is at
    least L, two-sided when the slacks at both ends sum to more than L, or interval by interval
    between the edge's ends and the grid points (``grid``)
    where its bounds are known: two-sided on [s, t] when the slacks at s and t sum to more
    than L (t - s) (the test of :func:`span_motion` with the static bound). A pair whose
    intervals pass up to a grid point starts its walk there (scratch.where); one whose intervals
    pass from a grid point to the end is certified to the end once its walk reaches that point
    (scratch.tail, infinite when not). A pair that no joint of ``moved`` moves (:func:`edge_walk`)
    is certified at once.
    """
    pairs, rates = model.pairs, model.rates
    count = pairs.shape[0]
    dq, counters, slack = scratch.dq, scratch.counters, scratch.slack
    end, reach, where, trend = scratch.end, scratch.reach, scratch.where, scratch.trend
    points = grid // POINT
    for j in range(q_a.shape[0]):
        dq[j] = abs(q_b[j] - q_a[j])
    counters[0] += 1
    counters[1] += 1
    counters[2] += count
    if grid & END_KNOWN == 0:
        primitive_poses(q_b, model, scratch)
        all_pair_bounds(model, scratch.prim_poses, end)
        for p in range(count):
            end[p] -= clearance
    primitive_poses(q_a, model, scratch)
    if not known:
        all_pair_bounds(model, scratch.prim_poses, slack)
        for p in range(count):
            slack[p] -= clearance
    for p in range(count):
        static = 0.0
        for j in range(dq.shape[0]):
            static += rates[p, j] * dq[j]
        if slack[p] <= STALL_DISTANCE:
            counters[3] = p
            return False
        where[p] = 0.0
        trend[p] = 0.0
        reach[p] = np.inf
        if slack[p] >= static or slack[p] + end[p] > static:
            continue  # certified to s = 1 by the static bound alone
        if moved != ALL_JOINTS and not _moves(p, moved, rates):
            continue  # the same motion as on the certified edge
        _grid_start(p, static, points, model, scratch, clearance)
    return True


@numba.njit(cache=True, inline="always")
def _lane_run(
    q_a: np.ndarray,
    q_b: np.ndarray,
    p: int,
    nearest: float,
    model: Any,
    scratch: Any,
    clearance: float,
) -> float:
    """Advance pair p through up to LANES points at once: its bounds and lever arms there come
    from one vectorised call (:func:`lynxplan.planning.lanes.pair_along`).

    The points follow the pair's slack trend: steps of :data:`LANE_GROWTH` times the predicted
    slack over the closing speed (the slack falling or rising linearly at its last rate), so
    they crowd where the pair approaches something. From the last accepted point, the farthest
    of the next points is accepted whose interval from it is certified — by the two-sided test
    (:func:`span_motion`) or because the point lies within the one-sided reach
    (:func:`reach_step`) — and whose slack exceeds :data:`STALL_DISTANCE`; a point with less
    slack is a wall the run does not pass. Updates the pair's state (where, slack, arms, trend,
    reach) as single steps would.

    Inlined into :func:`edge_walk` (a compiled call passing the model and scratch tuples costs
    an atomic reference count per array at its entry and exits, on every run).

    Returns 1 when a point was accepted; -t when the first point t lies within the pair's
    one-sided reach ``nearest`` (certified to t) and its slack is within STALL_DISTANCE (the
    walk stops there, as a single step would); 0 otherwise (the caller takes a single step)."""
    slack, reach, where, arms = scratch.slack, scratch.reach, scratch.where, scratch.arms
    all_arms, trend, out, counters = (
        scratch.all_arms,
        scratch.trend,
        scratch.lanes,
        scratch.counters,
    )
    s, sigma = where[p], slack[p]
    if not place_lanes(s, sigma, nearest - s, trend[p], out):
        return 0.0
    pair_along(q_a, q_b, p, model, out)
    counters[1] += LANES
    counters[2] += LANES
    nq = q_a.shape[0]
    accepted, i = 0, 0
    own = reach_step(sigma, p, arms, 0, model, scratch)
    while i < LANES:
        best = farthest_lane(
            i, (s, sigma, own), p, model, scratch, (OUT_BOUND, clearance, STALL_DISTANCE)
        )
        if best < -1:  # a wall at the first point
            t = float(out[OUT_S, -2 - best])
            if accepted == 0 and t <= nearest:
                return -t
            break
        if best < 0:
            break
        t = out[OUT_S, best]
        sigma_t = out[OUT_BOUND, best] - clearance
        trend[p] = (sigma_t - sigma) / (t - s)
        s, sigma = t, sigma_t
        for j in range(nq):
            arms[0, j] = out[OUT_ARMS + j, best]
        own = reach_step(sigma, p, arms, 0, model, scratch)
        accepted += 1
        i = best + 1
        if s >= 1.0:
            break
    if accepted == 0:
        return 0.0
    where[p], slack[p] = s, sigma
    copy_row(all_arms, p, arms, 0)
    reach[p] = s + own
    return 1.0


@njit_no_refcount()
def edge_walk(
    q_a: np.ndarray,
    q_b: np.ndarray,
    model: Any,
    scratch: Any,
    clearance: float,
    known: bool | np.bool_,
    grid: int,
    moved: int,
) -> float:
    """Conservative advancement from q_a towards q_b: the certified fraction s in [0, 1]; with
    ``known``, scratch.slack holds the pairs' slacks at q_a; ``grid``: what else is known
    (:data:`END_KNOWN`, grid points; :func:`_walk_start` certifies most pairs with them).

    ``moved``: :data:`ALL_JOINTS`, or a bit set of joints (bit j: joint j) when the caller
    knows that in every other joint the edge runs along a certified edge: its configurations,
    in those joints, are those of the certified edge (a piece of an edge of a valid path with
    only these joints changed, as a partial shortcut makes). A pair that none of these joints
    moves (its motion rate about each is zero: its distance depends on the other joints only)
    then has the distances it had there, all above the clearance: it is certified without a
    walk.

    Every pair keeps the last point s_p of the edge where its bound was evaluated, its slack
    sigma_p above the clearance there, and the point it is certified to. The pair certified
    least far is advanced next: it tries t = s_p + STEP_GROWTH ds (ds its one-sided step,
    :func:`reach_step`) and is certified to t when ``sigma_p + sigma_t`` exceeds its motion
    bound over [s_p, t] (:func:`span_motion`: at any u in between, one of the two ends is still
    far enough); otherwise it is evaluated at s_p + ds, where it was certified one-sided. The
    walk stops at the first point where a pair's slack is within :data:`STALL_DISTANCE`
    (returned), or when every pair is certified to s = 1. Returns -1 if q_a itself is not
    valid. Proof: module docstring.

    Callers pass ``known`` and ``grid`` as ``np.bool_``/``np.int64``: numba compiles a function
    once per literal argument value, and this walk takes about a minute to compile.
    """
    count = model.pairs.shape[0]
    counters, slack = scratch.counters, scratch.slack
    reach, where, arms, all_arms = scratch.reach, scratch.where, scratch.arms, scratch.all_arms
    trend, tail = scratch.trend, scratch.tail
    if not _walk_start(q_a, q_b, model, scratch, clearance, known, grid, moved):
        return -1.0
    lanes = model.axes.shape[0] <= MAX_JOINTS and q_a.shape[0] <= MAX_JOINTS
    while True:
        p, nearest = np.int64(0), np.inf  # (a literal 0 would compile pair_along twice)
        for k in range(count):
            if reach[k] < nearest:
                p, nearest = k, reach[k]
        if nearest >= 1.0:
            return 1.0
        if nearest >= tail[p]:  # the grid certifies the rest of the edge
            reach[p] = np.inf
            continue
        one = nearest - where[p]
        copy_row(arms, 0, all_arms, p)
        if lanes:
            run = _lane_run(q_a, q_b, p, nearest, model, scratch, clearance)
            if run > 0.0:
                continue
            if run < 0.0:  # blocked within the one-sided reach: the edge is certified to -run
                counters[3] = p
                return -run
        slack_t = pair_bound_at(q_a, q_b, nearest, p, model, scratch, np.int64(1)) - clearance
        counters[1] += 1
        counters[2] += 1
        if slack_t <= STALL_DISTANCE:
            counters[3] = p
            return nearest
        trend[p] = (slack_t - slack[p]) / one
        where[p], slack[p] = nearest, slack_t
        copy_row(all_arms, p, arms, 1)
        reach[p] = nearest + reach_step(slack_t, p, all_arms, p, model, scratch)
