"""Joint limits of an arm: a position range and a largest speed per joint, in SI units.

Every arm's limits (:attr:`lynxplan.robots.Robot.limits`, :class:`lynxplan.arm.Arm`'s); the
defaults are the AL5's (SPEC Part 1), for the code that has no arm at hand.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


def _limits(*degrees: tuple[float, float]) -> np.ndarray:
    """Read-only (n, 2) array of (lower, upper) pairs given in [deg], in [rad]."""
    array: np.ndarray = np.radians(np.array(degrees, dtype=float))
    array.setflags(write=False)
    return array


@dataclass(frozen=True)
class JointLimits:
    """Joint position and velocity limits.

    Attributes:
        position: Lower and upper limit per joint, shape (n, 2), in [rad] (default: the AL5's
            five joints).
        velocity: Largest speed per joint, shape (n,), in [rad/s].
    """

    position: np.ndarray = field(
        default_factory=lambda: _limits((0, 180), (0, 150), (-150, 0), (0, 180), (0, 180))
    )
    velocity: np.ndarray = field(default_factory=lambda: np.full(5, 3.0))

    @property
    def lower(self) -> np.ndarray:
        """Lower position limits, shape (n,), in [rad]."""
        return self.position[:, 0]

    @property
    def upper(self) -> np.ndarray:
        """Upper position limits, shape (n,), in [rad]."""
        return self.position[:, 1]
