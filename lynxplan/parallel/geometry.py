"""Dimensions of the planar 3-RRR parallel robot (SPEC Part 4), in SI units.

Unit decision: like the rest of lynxplan, everything inside is SI (lengths in [m], angles in
[rad]). The report, the CLI and the scenario files state this robot in mm and degrees; they are
converted at those edges only (:func:`pose_from_mm_deg`, the CLI and scenario modules).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from lynxplan.exceptions import InputError

#: Phases of the platform joints: joint i sits at ``c - rp (cos phi_i, sin phi_i)`` with
#: ``phi_i = alpha + PLATFORM_PHASES[i]`` (SPEC Part 4: 30, 150, 270 deg).
PLATFORM_PHASES = (math.radians(30.0), math.radians(150.0), math.radians(270.0))

#: Names of the legs, in order (base joints PA, PB, PC).
LEG_NAMES = ("A", "B", "C")


@dataclass(frozen=True)
class ParallelGeometry:
    """Dimensions of the 3-RRR (three identical legs: actuated base joint, passive elbow, passive
    platform joint).

    Attributes:
        base_circumradius: Circumradius ``rb`` of the equilateral base-joint triangle, in [m].
        platform_circumradius: Circumradius ``rp`` of the platform-joint triangle, in [m].
        proximal: Length ``S`` of each proximal (actuated) link, in [m].
        distal: Length ``L`` of each distal link, in [m].
    """

    base_circumradius: float = 0.290
    platform_circumradius: float = 0.130
    proximal: float = 0.170
    distal: float = 0.130

    def __post_init__(self) -> None:
        for name in ("base_circumradius", "platform_circumradius", "proximal", "distal"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise InputError(f"ParallelGeometry.{name} must be a positive length. Got: {value}")

    @property
    def base_joints(self) -> np.ndarray:
        """Base joints PA, PB, PC, shape (3, 2), in [m] (a fresh array)."""
        rb = self.base_circumradius
        return np.array(
            [[0.0, 0.0], [math.sqrt(3.0) * rb, 0.0], [math.sqrt(3.0) / 2 * rb, 1.5 * rb]]
        )

    @property
    def base_centre(self) -> np.ndarray:
        """Centroid of the base triangle, shape (2,), in [m]."""
        return np.asarray(self.base_joints.mean(axis=0))

    @property
    def leg_reach(self) -> tuple[float, float]:
        """Smallest and largest base-joint-to-platform-joint distance ``|S - L|, S + L``, in [m]."""
        return abs(self.proximal - self.distal), self.proximal + self.distal


def pose_from_mm_deg(xc: float, yc: float, alpha: float) -> np.ndarray:
    """Pose given in the report's units (mm, mm, deg) -> ``(xc, yc, alpha)`` in [m, m, rad]."""
    return np.array([xc * 1e-3, yc * 1e-3, math.radians(alpha)])


def pose_to_mm_deg(pose: np.ndarray) -> np.ndarray:
    """Pose(s) ``(..., 3)`` in [m, m, rad] -> the report's units (mm, mm, deg)."""
    pose = np.asarray(pose, dtype=float)
    return np.concatenate([pose[..., :2] * 1e3, np.degrees(pose[..., 2:3])], axis=-1)
