"""The closed-form tool pose of the 5-DOF arm (SPEC Part 1), written once: plain arithmetic on the
joints' sines and cosines, compiled into the batch kernel of :mod:`lynxplan.arm.kinematics` and
evaluated directly in Python for one configuration (no numba import: light commands start fast).
"""

from __future__ import annotations

import math

import numpy as np

from lynxplan.arm.configuration import as_configurations
from lynxplan.arm.geometry import ArmGeometry

_DEFAULT_GEOMETRY = ArmGeometry()


def tool_pose_from_sines(
    sines: tuple[float, float, float, float, float],
    cosines: tuple[float, float, float, float, float],
    a2: float,
    a3: float,
    d5: float,
    t: np.ndarray,
) -> None:
    """Write the tool transform (4, 4) into ``t`` from the joints' ``sines`` and ``cosines``
    (q1..q5) and the DH lengths in [m]."""
    s1, s2, s3, s4, s5 = sines
    c1, c2, c3, c4, c5 = cosines
    # Angle sums by the addition theorems: 5 sine/cosine pairs instead of 6.
    s23, c23 = s2 * c3 + c2 * s3, c2 * c3 - s2 * s3
    s234, c234 = s23 * c4 + c23 * s4, c23 * c4 - s23 * s4
    r = d5 * s234 + a3 * c23 + a2 * c2
    # Frame-4 axes x4 = (c1 c234, s1 c234, s234), y4 = (s1, -c1, 0); n = c5 x4 + s5 y4,
    # o = -s5 x4 + c5 y4, a = z4 = (c1 s234, s1 s234, -c234)  (SPEC Part 1, closed form).
    t[0, 0] = c5 * c1 * c234 + s5 * s1
    t[1, 0] = c5 * s1 * c234 - s5 * c1
    t[2, 0] = c5 * s234
    t[0, 1] = -s5 * c1 * c234 + c5 * s1
    t[1, 1] = -s5 * s1 * c234 - c5 * c1
    t[2, 1] = -s5 * s234
    t[0, 2] = c1 * s234
    t[1, 2] = s1 * s234
    t[2, 2] = -c234
    t[0, 3] = c1 * r
    t[1, 3] = s1 * r
    t[2, 3] = a3 * s23 + a2 * s2 - d5 * c234
    t[3, 0] = 0.0
    t[3, 1] = 0.0
    t[3, 2] = 0.0
    t[3, 3] = 1.0


def tool_pose(q: np.ndarray, geometry: ArmGeometry = _DEFAULT_GEOMETRY) -> np.ndarray:
    """Tool pose of one configuration ``q`` (5,) in [rad] -> (4, 4), translation in [m], in plain
    Python (libm sines; the batch kernel agrees to an ulp)."""
    config = as_configurations(q)[0]
    pose = np.empty((4, 4))
    sines = tuple(math.sin(x) for x in config)
    cosines = tuple(math.cos(x) for x in config)
    tool_pose_from_sines(sines, cosines, geometry.a2, geometry.a3, geometry.d5, pose)  # type: ignore[arg-type]
    return pose
