"""Python side of the numerical solver: starts, packing, results (one slot per target)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from lynxplan.robots.ik import numerical as num
from lynxplan.robots.results import RobotIkBatch

if TYPE_CHECKING:
    from lynxplan.robots.ik.description import Kinematics
    from lynxplan.robots.targets import Target

#: Seed of the deterministic multi-start configurations.
START_SEED = 20240613


def solve_numerical(
    kinematics: Kinematics, target: Target, reference: np.ndarray, starts: int = num.DEFAULT_STARTS
) -> RobotIkBatch:
    """Levenberg-Marquardt multi-start IK of each target (position + orientation or approach)."""
    from lynxplan.exceptions import TargetError

    if target.kind == 2:
        raise TargetError("pitch targets need a yaw-pitch-pitch-pitch-roll arm")
    n = target.poses.shape[0]
    lower, upper = kinematics.lower.copy(), kinematics.upper.copy()
    finite_lower = np.where(np.isfinite(lower), lower, -np.pi)
    finite_upper = np.where(np.isfinite(upper), upper, np.pi)
    rng = np.random.default_rng(START_SEED)
    seeds = rng.uniform(finite_lower, finite_upper, size=(starts, kinematics.nq))
    result = num.NumericalResult.empty(n, kinematics.nq)
    chain = kinematics.chain
    arm = num.NumericalArm(chain.placements, chain.axes, lower, upper, np.array([0.0, 0.0, 1.0]))
    num.numerical_ik_kernel(
        arm,
        target.poses,
        target.kind == 1,
        np.ascontiguousarray(reference, dtype=float),
        seeds,
        result,
    )
    q, success, perr, oerr, _ = result
    within = success.copy()
    arrays = (
        q[:, None, :],
        success[:, None],
        within[:, None],
        perr[:, None],
        oerr[:, None],
        success,
        np.where(success, perr, perr),
    )
    for array in arrays:
        array.setflags(write=False)
    return RobotIkBatch(*arrays, ("numerical",))
