"""What the IK solvers know of an arm: a plain kinematic description (chain, family, limits).

The solvers of :mod:`lynxplan.robots.ik` take this, never the :class:`lynxplan.robots.Robot`:
the Robot builds it once from its URDF and hands it to :mod:`lynxplan.robots.ik.dispatch`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from lynxplan.robots.chain import Chain
from lynxplan.robots.family import FamilyParameters


@dataclass(frozen=True)
class Kinematics:
    """An arm as the IK solvers see it.

    Attributes:
        chain: The serial chain (joint placements and axes) the solvers' FK evaluates.
        family: The yaw-pitch-pitch-pitch-roll parameters, or None (then IK is numerical).
        lower: Lower joint limits, shape (n,), in [rad] (read-only).
        upper: Upper joint limits, shape (n,), in [rad] (read-only).
    """

    chain: Chain
    family: FamilyParameters | None
    lower: np.ndarray
    upper: np.ndarray

    @property
    def nq(self) -> int:
        """Number of joints."""
        return int(self.lower.shape[0])

    @cached_property
    def solver_name(self) -> str:
        """Name of the IK solver of this arm (``Robot.ik_solver``; each result carries it)."""
        if self.family is None:
            return "numerical (Levenberg-Marquardt, multi-start)"
        name = "yaw-pitch3-roll closed form"
        if not self.family.tool_on_roll_axis:
            name += " + roll root search (off-axis tool; reachable poses: roll from orientation)"
        if not self.family.exact:
            name += f" + Newton polish (model off the family by {self.family.deviation:.2g} rad)"
        return name
