"""One SmallArmBench problem: a robot among boxes, a start and a goal configuration."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from lynxplan.collision import BoxObstacle

#: SRDFs of the suite's robots that the built-in loader does not find by the URDF's name
#: (example-robot-data's ``ur5_robot.urdf`` has ``srdf/ur5.srdf``: without it, base/upper arm
#: and forearm/wrist pairs 13-14 mm apart in every pose are self-checked, and the planner's
#: conservative checker certifies no UR5 start).
SUITE_SRDF = {"ur5": "ur5.srdf"}

_ROBOTS: dict[str, Any] = {}


def suite_robot(name: str) -> Any:
    """The built-in robot ``name`` as the suite plans it (with :data:`SUITE_SRDF`'s SRDF when
    the built-in has no disabled collision pairs), loaded once per process."""
    if name not in _ROBOTS:
        from lynxplan.robots import load_robot

        robot = load_robot(name)
        srdf = robot.urdf_path.parent.parent / "srdf" / SUITE_SRDF.get(name, "")
        if name in SUITE_SRDF and not robot.disabled_collisions and srdf.is_file():
            robot = load_robot(name, srdf=srdf)
        _ROBOTS[name] = robot
    return _ROBOTS[name]


def yaw_rotation(yaw: float) -> np.ndarray:
    """Rotation about the base z axis by ``yaw`` [rad], shape (3, 3)."""
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


@dataclass(frozen=True, eq=False)
class Problem:
    """A planning problem of the suite.

    Attributes:
        robot: Built-in robot name (``al5``, ``so101``, ``ur5``).
        family: Scene family (:data:`lynxplan.benchsuite.families.FAMILIES`).
        index: Index of the problem within its robot's family (0, 1, ...).
        attempt: The generator's attempt number that produced it (regenerates it alone).
        names: Obstacle names, K of them.
        centres: Box centres, shape (K, 3), in [m].
        sizes: Box edge lengths, shape (K, 3), in [m].
        yaws: Box rotations about the base z axis, shape (K,), in [rad].
        start: Start configuration, shape (nq,), in [rad].
        goal: Goal configuration, shape (nq,), in [rad].
    """

    robot: str
    family: str
    index: int
    attempt: int
    names: tuple[str, ...]
    centres: np.ndarray
    sizes: np.ndarray
    yaws: np.ndarray
    start: np.ndarray
    goal: np.ndarray

    @property
    def name(self) -> str:
        """``<robot>_<family>_<index>``, e.g. ``so101_shelf_007``."""
        return f"{self.robot}_{self.family}_{self.index:03d}"

    def obstacles(self) -> tuple[BoxObstacle, ...]:
        """The boxes as lynxplan obstacles."""
        return tuple(
            BoxObstacle(n, c, s, yaw_rotation(float(y)))
            for n, c, s, y in zip(self.names, self.centres, self.sizes, self.yaws, strict=True)
        )

    def same_as(self, other: Problem) -> bool:
        """Whether both problems are bit for bit the same."""
        arrays = ("centres", "sizes", "yaws", "start", "goal")
        return (self.robot, self.family, self.index, self.attempt, self.names) == (
            other.robot,
            other.family,
            other.index,
            other.attempt,
            other.names,
        ) and all(
            getattr(self, a).shape == getattr(other, a).shape
            and getattr(self, a).tobytes() == getattr(other, a).tobytes()
            for a in arrays
        )
