"""Which IK solver runs for a target: the one place that chooses (:func:`route`).

=====================  =======================  ==========  ===================================
arm                    target                   batch       solver (``route`` name: function)
=====================  =======================  ==========  ===================================
no family (any chain)  pose or approach         any         ``numerical``: Levenberg-Marquardt,
                                                            multi-start (``numerical_solver``)
family, one pose       full pose, roll free     1           ``scalar``: ``solve_pose_one``
(``Robot.ik``)                                              (closed form, one kernel call);
                                                            a pose it leaves: the rows below
family                 full pose, roll free     >= 32       ``block``: ``solve_poses`` by the
                                                            vectorised closed form
                                                            (``pose_block``)
family                 full pose, roll free     < 32        ``scalar``: ``solve_poses`` by the
                                                            scalar closed form (``pose_kernel``)
family                 approach, pitch, or a    any         ``roll search``:
                       given roll                           ``solve_roll_search``
                                                            (``family_kernel``)
=====================  =======================  ==========  ===================================

Within ``solve_poses`` the poses the closed form leaves (out of reach,
degenerate, a given roll) go to the roll search; after the roll search a model only close to
the family (SO-101) gets the near-axis rescue (``rescue_near_axis``: the numerical solver
started from the branches), where no exact branch was found. Solver functions are in
``family_solver`` unless named otherwise.

The solver modules load their numba kernels, so they are imported on first use.
"""

from __future__ import annotations

import functools
from types import ModuleType
from typing import Any

import numpy as np

from lynxplan.robots.ik.description import Kinematics
from lynxplan.robots.results import RobotIkBatch, RobotIkResult
from lynxplan.robots.targets import KIND_POSE, Target

#: Full-pose batches of this many poses on are solved by the vectorised closed form (one block
#: of ``block_layout.BLOCK`` poses: a test checks they agree).
BLOCK_FROM = 32

NUMERICAL, SCALAR, BLOCK, ROLL_SEARCH = "numerical", "scalar", "block", "roll search"


@functools.cache
def _solver(name: str) -> ModuleType:
    """A solver module, imported on first use (it loads the numba kernels); cached, so a
    single-pose call pays no import statement."""
    if name == "numerical_solver":
        from lynxplan.robots.ik import numerical_solver

        return numerical_solver
    from lynxplan.robots.ik import family_solver

    return family_solver


def route(kinematics: Kinematics, target: Target) -> str:
    """Name of the solver :func:`solve` runs for these targets (the table above)."""
    if kinematics.family is None:
        return NUMERICAL
    if target.kind == KIND_POSE:
        return BLOCK if target.poses.shape[0] >= BLOCK_FROM else SCALAR
    return ROLL_SEARCH


def solve(kinematics: Kinematics, target: Target, reference: np.ndarray) -> RobotIkBatch:
    """Every IK branch of each target; ``reference`` (1, n) or (N, n) [rad]."""
    chosen = route(kinematics, target)
    batch: RobotIkBatch
    if chosen == NUMERICAL:
        batch = _solver("numerical_solver").solve_numerical(kinematics, target, reference)
    elif chosen == ROLL_SEARCH:
        batch = _solver("family_solver").solve_roll_search(kinematics, target, reference)
    else:
        block = chosen == BLOCK
        batch = _solver("family_solver").solve_poses(kinematics, target, reference, block)
    return batch


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
