"""IK along a sequence of targets, each step on the branch continuous with the previous one."""

from __future__ import annotations

import numpy as np

from lynxplan.constants import REACH_TOLERANCE
from lynxplan.robots.ik.description import Kinematics
from lynxplan.robots.ik.dispatch import solve
from lynxplan.robots.results import TrackJump, TrackResult
from lynxplan.robots.targets import Target

#: ik_track flags a step whose largest joint change exceeds this [rad].
TRACK_JUMP_THRESHOLD = 0.5


def track(
    kinematics: Kinematics,
    target: Target,
    start: np.ndarray,
    start_given: bool,
    jump_threshold: float,
) -> TrackResult:
    """IK along N targets, each step on the branch nearest the previous step (see
    ``Robot.ik_track``); start (n,) [rad]; the first step counts as a jump only if given."""
    n = target.poses.shape[0]
    q = np.full((n, kinematics.nq), np.nan)
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
        batch = solve(kinematics, one, previous.reshape(1, -1))
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
