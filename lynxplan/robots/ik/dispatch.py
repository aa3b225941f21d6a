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

import functools
from types import ModuleType
from typing import Any

import numpy as np

from lynxplan.robots.ik.description import Kinematics
from lynxplan.robots.results import RobotIkBatch, RobotIkResult
from lynxplan.robots.targets import Target


@functools.cache
def _solver(name: str) -> ModuleType:
    """A solver module, imported on first use (it loads the numba kernels); cached, so a
    single-pose call pays no import statement."""
    if name == "numerical_solver":
        from lynxplan.robots.ik import numerical_solver

        return numerical_solver
    from lynxplan.robots.ik import family_solver

    return family_solver


def solve(kinematics: Kinematics, target: Target, reference: np.ndarray) -> RobotIkBatch:
    """Every IK branch of each target; ``reference`` (1, n) or (N, n) [rad]."""
    if kinematics.family is None:
        batch: RobotIkBatch = _solver("numerical_solver").solve_numerical(
            kinematics, target, reference
        )
        return batch
    family_batch: RobotIkBatch = _solver("family_solver").solve_family(
        kinematics, target, reference
    )
    return family_batch


def solve_pose_one(
    kinematics: Kinematics, pose: Any, reference: np.ndarray
) -> RobotIkResult | None:
    """One full pose (4, 4) with the roll free, the lean way, for a family arm; None where the
    pose needs the batch path (:func:`solve`) or the arm has no family. ``reference`` (n,)."""
    if kinematics.family is None:
        return None
    result: RobotIkResult | None = _solver("family_solver").solve_pose_one(
        kinematics, pose, reference
    )
    return result
