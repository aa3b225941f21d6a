"""Which IK solver runs for a target: the one place that chooses.

==========================  ============================  =====================================
arm                         target                        solver
==========================  ============================  =====================================
no family (any chain)       pose or approach              ``numerical_solver`` (LM multi-start)
family                      one full pose, roll free      ``family_solver.solve_pose_one``
                                                          (``Robot.ik``; None: the batch path)
family                      every target of a batch       ``family_solver.solve_family``
==========================  ============================  =====================================

The solver modules load their numba kernels, so they are imported on first use.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lynxplan.robots.ik.description import Kinematics
from lynxplan.robots.results import RobotIkBatch, RobotIkResult
from lynxplan.robots.targets import Target


def solve(kinematics: Kinematics, target: Target, reference: np.ndarray) -> RobotIkBatch:
    """Every IK branch of each target; ``reference`` (1, n) or (N, n) [rad]."""
    if kinematics.family is None:
        from lynxplan.robots.ik.numerical_solver import solve_numerical

        return solve_numerical(kinematics, target, reference)
    from lynxplan.robots.ik.family_solver import solve_family

    return solve_family(kinematics, target, reference)


def solve_pose_one(
    kinematics: Kinematics, pose: Any, reference: np.ndarray
) -> RobotIkResult | None:
    """One full pose (4, 4) with the roll free, the lean way, for a family arm; None where the
    pose needs the batch path (:func:`solve`) or the arm has no family. ``reference`` (n,)."""
    if kinematics.family is None:
        return None
    from lynxplan.robots.ik.family_solver import solve_pose_one as family_pose_one

    return family_pose_one(kinematics, pose, reference)
