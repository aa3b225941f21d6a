"""Typed results of the AL5's IK (one pose); its branches and the selected-branch rule are every
arm's (:mod:`lynxplan.branches`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lynxplan.branches import Branch, IkSolution, selected_q

__all__ = ["Branch", "IkResult", "IkSolution", "selected_q"]


@dataclass(frozen=True)
class IkResult:
    """IK of one pose.

    Attributes:
        solutions: Every branch (four), in :data:`lynxplan.arm.ik.BRANCH_NAMES` order.
        selected: Index of the chosen solution, or None if none is within limits.
        orientation_residual: Angle between target and nearest reachable orientation, [rad].
    """

    solutions: tuple[IkSolution, ...]
    selected: int | None
    orientation_residual: float

    @property
    def q(self) -> np.ndarray:
        """The selected solution, shape (5,), in [rad].

        Raises:
            NoSolutionWithinLimitsError: if no branch is within the joint limits.
        """
        return selected_q(self.solutions, self.selected)
