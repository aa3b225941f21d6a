"""The AL5 as a Robot: full poses and approach targets go to the kernels of :mod:`lynxplan.arm`
(same numbers as ``Arm.ik_batch``); each branch's errors are measured on its FK (numba).

Angles in [rad], lengths in [m].
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numba
import numpy as np

from lynxplan.robots.ik.family_geometry import MODE_APPROACH
from lynxplan.robots.ik.family_polish import axis_angle, rotation_angle

if TYPE_CHECKING:
    from lynxplan.robots.ik.description import Kinematics
    from lynxplan.robots.results import BranchSlots, RobotIkResult
    from lynxplan.robots.targets import Target


@numba.njit(cache=True, nogil=True)
def branch_errors(
    reached: np.ndarray,
    goals: np.ndarray,
    approach_only: bool,
    position_error: np.ndarray,
    orientation_error: np.ndarray,
) -> None:
    """Errors of each branch's FK pose reached (N, B, 4, 4) against goals (N, 4, 4) into
    (N, B): the position distance [m]; the rotation angle of goal^T reached, or the angle
    between the approach axes (column 2) when ``approach_only`` [rad]."""
    for n in range(reached.shape[0]):
        goal = goals[n]
        for b in range(reached.shape[1]):
            pose = reached[n, b]
            d0 = pose[0, 3] - goal[0, 3]
            d1 = pose[1, 3] - goal[1, 3]
            d2 = pose[2, 3] - goal[2, 3]
            position_error[n, b] = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            if approach_only:
                orientation_error[n, b] = axis_angle(
                    pose[0, 2], pose[1, 2], pose[2, 2], goal[0, 2], goal[1, 2], goal[2, 2]
                )
            else:
                orientation_error[n, b] = rotation_angle(goal, pose)


def al5_fill(
    kinematics: Kinematics, target: Target, reference: np.ndarray, out: BranchSlots
) -> np.ndarray:
    """Targets the AL5 kernels of lynxplan.arm solve, into the batch arrays (N, 4, ...);
    returns which (the others need the general kernel)."""
    from lynxplan.arm.ik import IkStatus

    ref = np.broadcast_to(reference, (target.poses.shape[0], 5)).copy()
    given = ~np.isnan(target.roll)
    ref[given, 4] = target.roll[given]
    arm = kinematics.arm
    approach_only = target.kind == MODE_APPROACH
    batch = arm.ik_batch(target.poses, q_reference=ref, approach_only=approach_only)
    ok: np.ndarray = np.asarray(np.asarray(batch.status) == IkStatus.OK)
    if not ok.any():
        return ok
    q, valid, within, perr, oerr = out
    valid[ok] = True
    q_arm = np.asarray(batch.q)[ok]
    reached = np.asarray(arm.fk(q_arm.reshape(-1, 5))).reshape(-1, 4, 4, 4)
    q[ok] = q_arm
    within[ok] = np.asarray(batch.within_limits)[ok]
    p_err, o_err = np.empty(q_arm.shape[:2]), np.empty(q_arm.shape[:2])
    branch_errors(reached, np.ascontiguousarray(target.poses[ok]), approach_only, p_err, o_err)
    perr[ok] = p_err
    oerr[ok] = o_err
    return ok


def solve_al5_pose_one(
    kinematics: Kinematics, pose: np.ndarray, reference: np.ndarray
) -> RobotIkResult | None:
    """One full pose (4, 4) through ``Arm.ik`` (the lean single-pose kernel): the result, or
    None where the pose needs the general path (out of reach, not rigid, not finite).
    ``reference`` (5,) [rad]."""
    from lynxplan.exceptions import (
        NonFiniteInputError,
        NotRigidTransformError,
        UnreachablePoseError,
    )
    from lynxplan.robots.selection import finish_result

    try:
        result = kinematics.arm.ik(pose, q_reference=reference)
    except (UnreachablePoseError, NotRigidTransformError, NonFiniteInputError):
        return None
    solutions = list(result.solutions)  # the AL5's branch type is the Robot's
    distance = min(s.position_error for s in solutions)
    rows = [s.q.tolist() for s in solutions]
    return finish_result(solutions, rows, True, distance, reference, kinematics.solver_name)
