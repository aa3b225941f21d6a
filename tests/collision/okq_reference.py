"""SPEC Part 3 data for the collision tests: waypoints, obstacles, a joint-space trajectory."""

from __future__ import annotations

import numpy as np

from lynxplan.trajectory.ok_task import ok_task_configurations, ok_task_walls

#: SPEC Part 3 waypoints, shape (14, 5), in [deg] (the package's table, not a copy).
WAYPOINTS_DEG = np.degrees(ok_task_configurations())


def spec_obstacles() -> list:
    """The two walls of SPEC Part 3 (inches there), in [m] (the package's table)."""
    return ok_task_walls()


def joint_space_task(rate: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The 13 segments as linear joint interpolation, 2 s each, sampled at ``rate`` [Hz].

    Returns q (N, 5) [rad], t (N,) [s], segment index (N,).
    """
    q = np.radians(WAYPOINTS_DEG)
    per = round(2.0 * rate)
    s = np.arange(per) / per
    rows = [q[i] + s[:, None] * (q[i + 1] - q[i]) for i in range(len(q) - 1)]
    samples = np.vstack([*rows, q[-1:]])
    times = np.arange(len(samples)) / rate
    segment = np.minimum(np.arange(len(samples)) // per, len(q) - 2)
    return samples, times, segment
