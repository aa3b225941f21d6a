"""Per-joint motion limits used by auto-timing and the retiming comparisons."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from lynxplan.arm.geometry import JointLimits
from lynxplan.exceptions import InputError

#: Default joint acceleration limit, in [rad/s^2]: an operating value for AL5-class hobby servos
#: (no-load speed about 5 rad/s reached in roughly 0.3-0.5 s).
DEFAULT_MAX_ACCELERATION = 8.0
#: Default joint jerk limit, in [rad/s^3] (used by ruckig): the acceleration limit built up in
#: about 0.13 s.
DEFAULT_MAX_JERK = 60.0


def _per_joint(values: np.ndarray | float | list[float], name: str) -> np.ndarray:
    array = np.array(np.broadcast_to(np.asarray(values, dtype=float), (5,)))
    if not np.all(np.isfinite(array)) or np.any(array <= 0.0):
        raise InputError(f"{name} limits must be positive and finite. Got: {array.tolist()}")
    array.setflags(write=False)
    return array


@dataclass(frozen=True)
class MotionLimits:
    """Joint position, velocity, acceleration and jerk limits of the 5-DOF arm.

    Attributes:
        position: Lower and upper limit per joint, shape (5, 2), in [rad] (from the URDF).
        velocity: Speed limit per joint, shape (5,), in [rad/s] (from the URDF).
        acceleration: Acceleration limit per joint, shape (5,), in [rad/s^2].
        jerk: Jerk limit per joint, shape (5,), in [rad/s^3].
    """

    position: np.ndarray = field(default_factory=lambda: JointLimits().position)
    velocity: np.ndarray = field(default_factory=lambda: JointLimits().velocity)
    acceleration: np.ndarray = field(
        default_factory=lambda: _per_joint(DEFAULT_MAX_ACCELERATION, "")
    )
    jerk: np.ndarray = field(default_factory=lambda: _per_joint(DEFAULT_MAX_JERK, ""))

    def __post_init__(self) -> None:
        for name in ("velocity", "acceleration", "jerk"):
            object.__setattr__(self, name, _per_joint(getattr(self, name), name))

    @classmethod
    def from_joint_limits(
        cls,
        joint_limits: JointLimits,
        acceleration: np.ndarray | float = DEFAULT_MAX_ACCELERATION,
        jerk: np.ndarray | float = DEFAULT_MAX_JERK,
    ) -> MotionLimits:
        """Position and velocity limits from the URDF, acceleration and jerk given."""
        return cls(
            joint_limits.position,
            joint_limits.velocity,
            _per_joint(acceleration, "acceleration"),
            _per_joint(jerk, "jerk"),
        )

    @property
    def joint_limits(self) -> JointLimits:
        """The position and velocity part, as the arm's :class:`JointLimits`."""
        return JointLimits(self.position, self.velocity)
