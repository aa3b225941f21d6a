"""Dimensions and joint limits of the 5-DOF arm (standard DH, SPEC Part 1), in SI units."""

from __future__ import annotations

from dataclasses import dataclass

from lynxplan.joint_limits import JointLimits
from lynxplan.units import INCH

__all__ = ["DH_FRAMES", "JOINT_NAMES", "TOOL_FRAME", "ArmGeometry", "JointLimits"]


@dataclass(frozen=True)
class ArmGeometry:
    """Lengths of the DH model (a1 = d1..d4 = a4 = a5 = 0, alpha1 = alpha4 = +90 deg).

    Attributes:
        a2: Shoulder-to-elbow length, in [m].
        a3: Elbow-to-wrist length, in [m].
        d5: Wrist-centre-to-tool (pen tip) length along the approach axis, in [m].
    """

    a2: float = 5.75 * INCH
    a3: float = 7.375 * INCH
    d5: float = 3.375 * INCH

    @property
    def max_wrist_reach(self) -> float:
        """Largest shoulder-to-wrist-centre distance, in [m] (elbow stretched)."""
        return self.a2 + self.a3

    @property
    def min_wrist_reach(self) -> float:
        """Smallest shoulder-to-wrist-centre distance, in [m] (elbow folded)."""
        return abs(self.a2 - self.a3)

    @property
    def max_reach(self) -> float:
        """Largest shoulder-to-tool distance, in [m] (16.5 in for the AL5)."""
        return self.a2 + self.a3 + self.d5


#: Joint names, in order, as in the URDF.
JOINT_NAMES = ("q1", "q2", "q3", "q4", "q5")
#: Tool frame name in the URDF (DH frame 5, the pen tip).
TOOL_FRAME = "tool"
#: Names of DH frames 1-4 in the URDF.
DH_FRAMES = ("dh_frame_1", "dh_frame_2", "dh_frame_3", "dh_frame_4")
