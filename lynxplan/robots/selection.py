"""Choosing among IK branches: the one nearest a reference for one target, and the branch
continuous with the previous step along a track."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from lynxplan.robots.results import (
    RobotIkBatch,
    RobotIkResult,
    RobotIkSolution,
    TrackJump,
    TrackResult,
)
from lynxplan.robots.targets import Target

if TYPE_CHECKING:
    from lynxplan.robots.robot import Robot

#: A branch reaches its target when FK puts the tool this close to the target position [m].
REACH_TOLERANCE = 1e-9
#: ik_track flags a step whose largest joint change exceeds this [rad].
TRACK_JUMP_THRESHOLD = 0.5


def select_one(
    robot: Robot, batch: RobotIkBatch, reference: np.ndarray, verify: bool
) -> RobotIkResult:
    """The branches of the single target of ``batch``, the one nearest ``reference`` (n,) [rad]
    selected among those within the limits that reach the target (or come nearest)."""
    slots = np.flatnonzero(batch.valid[0])
    names = batch.branch_names
    return assemble_result(
        robot,
        batch.q[0, slots],
        [names[b] for b in slots.tolist()],
        batch.within_limits[0, slots].tolist(),
        batch.position_error[0, slots].tolist(),
        batch.orientation_error[0, slots].tolist(),
        bool(batch.reachable[0]),
        float(batch.distance[0]),
        reference,
        verify,
    )


def assemble_result(
    robot: Robot,
    q: np.ndarray,
    names: list[str],
    within: list[bool],
    position_error: list[float],
    orientation_error: list[float],
    reachable: bool,
    distance: float,
    reference: np.ndarray,
    verify: bool,
) -> RobotIkResult:
    """One target's result from its branches q (k, n) [rad] (a fresh array; made read-only)
    and per-branch lists: the one nearest ``reference`` (n,) [rad] selected among those within
    the limits that reach the target (or come nearest)."""
    q.setflags(write=False)
    solutions = [
        RobotIkSolution(q[i], names[i], within[i], position_error[i], orientation_error[i])
        for i in range(len(names))
    ]
    return finish_result(robot, solutions, q.tolist(), reachable, distance, reference, verify)


def finish_result(
    robot: Robot,
    solutions: list[RobotIkSolution],
    rows: list[list[float]],
    reachable: bool,
    distance: float,
    reference: np.ndarray,
    verify: bool,
) -> RobotIkResult:
    """The result of one target's branches (``rows``: their q as lists): verified by Pinocchio
    when asked, the one nearest ``reference`` (n,) [rad] selected among those within the limits
    that reach the target (or come nearest)."""
    if verify:
        verify_branches(robot, solutions)
    limit = distance + REACH_TOLERANCE
    ref = reference.tolist()
    # plain Python on the few branches: cheaper than numpy calls on arrays this small
    best, best_cost = None, math.inf
    for i, s in enumerate(solutions):
        if not s.within_limits or s.position_error > limit:
            continue
        cost = sum((a - r) ** 2 for a, r in zip(rows[i], ref, strict=True))
        if cost < best_cost:
            best, best_cost = i, cost
    ranked = (
        best
        if best is not None
        else (int(np.argmin([s.orientation_error for s in solutions])) if solutions else None)
    )
    residual = float(solutions[ranked].orientation_error) if ranked is not None else np.nan
    return RobotIkResult(tuple(solutions), best, reachable, distance, residual, robot.ik_solver)


def verify_branches(robot: Robot, solutions: list[RobotIkSolution]) -> None:
    """Pinocchio FK of each branch must agree with the solver's own FK (1e-12 m)."""
    from lynxplan.exceptions import IkFailedError

    for s in solutions:
        placement = robot.frame_placement(s.q)
        own = robot.fk(s.q)
        gap = float(np.abs(placement[:3] - own[:3]).max())
        if gap > 1e-12:
            raise IkFailedError(s.position_error, f"Pinocchio FK disagrees by {gap:.3g} m")


def track(
    robot: Robot, target: Target, start: np.ndarray, start_given: bool, jump_threshold: float
) -> TrackResult:
    """IK along N targets, each step on the branch nearest the previous step (see
    ``Robot.ik_track``); start (n,) [rad]; the first step counts as a jump only if given."""
    n = target.poses.shape[0]
    q = np.full((n, robot.nq), np.nan)
    branch = np.full(n, -1, dtype=np.int64)
    jumps: list[TrackJump] = []
    unsolved: list[int] = []
    previous = start.copy()
    max_step = 0.0
    for k in range(n):
        one = Target(
            target.poses[k : k + 1],
            target.kind,
            target.pitch[k : k + 1],
            target.roll[k : k + 1],
        )
        batch = robot._solve(one, previous.reshape(1, -1))
        ok = (
            batch.valid[0]
            & batch.within_limits[0]
            & (batch.position_error[0] <= batch.distance[0] + REACH_TOLERANCE)
        )
        if not ok.any():
            unsolved.append(k)
            continue
        steps = np.abs(batch.q[0] - previous).max(axis=1)
        steps[~ok] = np.inf
        b = int(np.argmin(steps))
        q[k], branch[k] = batch.q[0, b], b
        size = float(steps[b])
        if k > 0 or start_given:
            max_step = max(max_step, size)
            if size > jump_threshold:
                jumps.append(TrackJump(k, size))
        previous = q[k].copy()
    q.setflags(write=False)
    branch.setflags(write=False)
    return TrackResult(q, branch, tuple(jumps), tuple(unsolved), max_step)
