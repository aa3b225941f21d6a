"""One IK branch of an arm, checked by forward kinematics, and the rule that selects one.

Shared by the AL5's results (:mod:`lynxplan.arm.ik_result`) and every Robot's
(:mod:`lynxplan.robots.results`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple, Protocol

import numpy as np

from lynxplan.exceptions import NoSolutionWithinLimitsError


class Branch(Protocol):
    """What the selection rule reads of a branch."""

    @property
    def q(self) -> np.ndarray: ...
    @property
    def branch(self) -> str: ...


def selected_q(solutions: Sequence[Branch], selected: int | None) -> np.ndarray:
    """q of the selected branch.

    Raises:
        NoSolutionWithinLimitsError: if no branch is selected (none within the joint limits).
    """
    if selected is None:
        raise NoSolutionWithinLimitsError(
            "IK: no branch is within the joint limits: "
            + "; ".join(f"{s.branch} {np.degrees(s.q).round(3).tolist()} deg" for s in solutions)
        )
    return solutions[selected].q


class IkSolution(NamedTuple):
    """One IK branch, checked by forward kinematics (the AL5's, and every Robot's as
    ``lynxplan.robots.RobotIkSolution``).

    Attributes:
        q: Joint angles, shape (5,) (a Robot's: (n,)), in [rad] (read-only).
        branch: Branch name, e.g. ``"front/elbow-up"`` or ``"front/roll-1/elbow-up"``.
        within_limits: Whether q is within the joint limits (after snapping).
        position_error: ``|p_fk(q) - p_target|``, in [m] (the miss when unreachable).
        orientation_error: Angle between the FK rotation and the target (full pose), or between
            the target and reached approach axes (approach, pitch targets), in [rad].
    """

    q: np.ndarray
    branch: str
    within_limits: bool
    position_error: float
    orientation_error: float


@dataclass(frozen=True)
class IkResult:
    """IK of one target: every branch found, each verified; one selected (the AL5's
    ``Arm.ik`` and every ``Robot.ik``; ``lynxplan.robots.RobotIkResult`` is this type).

    Attributes:
        solutions: The branches (verified by FK), solver order (the AL5's: four, in
            ``lynxplan.arm.ik.BRANCH_NAMES`` order).
        selected: Index of the chosen one (within limits and reachable, by the selection rule),
            or None when no branch is within the limits.
        reachable: Whether the target position is reached (position error within tolerance).
        distance: Smallest position error over the branches, in [m] (0 up to rounding when
            reachable): how far the nearest reachable solution is from the target.
        orientation_residual: Orientation error of the selected (else best) branch, in [rad].
        solver: ``"AL5 closed form"``, ``"yaw-pitch3-roll closed form"``, ``"... + roll root
            search"``, ``"numerical"``.
    """

    solutions: tuple[IkSolution, ...]
    selected: int | None
    reachable: bool
    distance: float
    orientation_residual: float
    solver: str

    @property
    def q(self) -> np.ndarray:
        """The selected solution, shape (n,), in [rad].

        Raises:
            NoSolutionWithinLimitsError: if no branch is within the joint limits.
        """
        return selected_q(self.solutions, self.selected)
