"""The report's "OK" writing task (SPEC Part 3): 14 waypoints, 13 segments, home at the end."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from lynxplan.trajectory.limits import MotionLimits
from lynxplan.trajectory.lspb import LspbTiming
from lynxplan.trajectory.plan import Plan, SegmentSpec, build_plan

if TYPE_CHECKING:
    from lynxplan.collision.obstacles import Obstacle

#: Waypoint names, joint angles in [deg] and the motion to the next waypoint (SPEC Part 3).
OK_TASK_WAYPOINTS: tuple[tuple[str, tuple[float, float, float, float, float], str], ...] = (
    ("O1", (104, 57, -59, 40, 0), "line"),
    ("O2", (109, 79, -93, 25, 0), "line"),
    ("O3", (97, 83, -97, 26, 0), "line"),
    ("O4", (95, 60, -63, 40, 0), "line"),
    ("O1", (104, 57, -59, 40, 0), "free"),
    ("I1", (90, 90, -30, 0, 0), "free"),
    ("K1", (81, 60, -63, 40, 0), "line"),
    ("K2", (77.7, 83, -97.5, 26, 0), "free"),
    ("I2", (77.7, 100, -60, 26, 0), "free"),
    ("K3", (75.5, 57, -59, 41, 0), "line"),
    ("K4", (79, 70, -77, 29, 0), "line"),
    ("K5", (64.7, 72.7, -84.7, 19.4, 0), "free"),
    ("I3", (30, 90, -30, 30, 0), "free"),
    ("I", (0, 0, 0, 0, 0), ""),
)

#: The report's two walls (SPEC Part 3): name, minimum corner and size, each (3,), in [in].
OK_TASK_WALLS: tuple[tuple[str, tuple[float, float, float], tuple[float, float, float]], ...] = (
    ("wall_letters", (-0.2, 8, -2), (0.4, 10, 3.5)),
    ("wall_home", (5, 4.5, -2), (10, 1, 8)),
)

#: The report's timing of every segment: tt = 2 s, ta = 0.5 s (26 s in all).
REPORT_TIMING = LspbTiming(2.0, 0.5)


def ok_task_configurations() -> np.ndarray:
    """The 14 waypoints' joint angles, shape (14, 5), in [rad]."""
    degrees = np.array([row[1] for row in OK_TASK_WAYPOINTS], dtype=float)
    return np.asarray(np.radians(degrees))


def ok_task_walls() -> list[Obstacle]:
    """The two walls as axis-aligned boxes, in [m]."""
    from lynxplan.collision.obstacles import axis_aligned_box
    from lynxplan.units import INCH

    return [
        axis_aligned_box(name, np.array(corner) * INCH, np.array(size) * INCH)
        for name, corner, size in OK_TASK_WALLS
    ]


def ok_task_specs(
    timing: LspbTiming | None = REPORT_TIMING, mode: str = "consistent"
) -> list[SegmentSpec]:
    """The 13 segments of the task (``timing=None``: auto-timed), as joint-angle targets."""
    q = ok_task_configurations()
    return [
        SegmentSpec(kind, target_q=q[i + 1], timing=timing, mode=mode)  # type: ignore[arg-type]
        for i, (_, _, kind) in enumerate(OK_TASK_WAYPOINTS[:-1])
    ]


def ok_task_plan(
    timing: LspbTiming | None = REPORT_TIMING,
    mode: str = "consistent",
    limits: MotionLimits | None = None,
) -> Plan:
    """The OK task as a plan from O1 (the report's timing by default)."""
    return build_plan(ok_task_configurations()[0], ok_task_specs(timing, mode), limits)
