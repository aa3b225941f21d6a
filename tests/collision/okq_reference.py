"""SPEC Part 3 data for the collision tests: waypoints, obstacles, a joint-space trajectory."""

from __future__ import annotations

import numpy as np

from lynxplan.collision import axis_aligned_box
from lynxplan.units import INCH

WAYPOINTS_DEG = np.array(
    [
        [104, 57, -59, 40, 0],
        [109, 79, -93, 25, 0],
        [97, 83, -97, 26, 0],
        [95, 60, -63, 40, 0],
        [104, 57, -59, 40, 0],
        [90, 90, -30, 0, 0],
        [81, 60, -63, 40, 0],
        [77.7, 83, -97.5, 26, 0],
        [77.7, 100, -60, 26, 0],
        [75.5, 57, -59, 41, 0],
        [79, 70, -77, 29, 0],
        [64.7, 72.7, -84.7, 19.4, 0],
        [30, 90, -30, 30, 0],
        [0, 0, 0, 0, 0],
    ]
)


def spec_obstacles() -> list:
    """The two walls of SPEC Part 3 (inches there), in [m]."""
    return [
        axis_aligned_box(
            "wall_letters", np.array([-0.2, 8, -2]) * INCH, np.array([0.4, 10, 3.5]) * INCH
        ),
        axis_aligned_box("wall_home", np.array([5, 4.5, -2]) * INCH, np.array([10, 1, 8]) * INCH),
    ]


def joint_space_task(rate: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The 13 segments as linear joint interpolation, 2 s each, sampled at ``rate`` [Hz].

    Returns q (N, 5) [rad], t (N,) [s], segment index (N,).
    """
    q = np.radians(WAYPOINTS_DEG)
    per = int(round(2.0 * rate))
    s = np.arange(per) / per
    rows = [q[i] + s[:, None] * (q[i + 1] - q[i]) for i in range(len(q) - 1)]
    samples = np.vstack([*rows, q[-1:]])
    times = np.arange(len(samples)) / rate
    segment = np.minimum(np.arange(len(samples)) // per, len(q) - 2)
    return samples, times, segment
