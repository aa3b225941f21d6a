"""A resolved task sampled, checked against its joint limits and obstacles, and retimed.

:func:`execute` is the computation behind the scenario kind ``task``
(:mod:`lynxplan.scenarios.task`); it writes no file.
"""

from __future__ import annotations

import re
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from lynxplan.constants import LIMIT_CHECK_RELATIVE_TOLERANCE, LIMIT_SNAP_TOLERANCE
from lynxplan.task.setup import TaskSetup, resolve

if TYPE_CHECKING:
    from lynxplan.task.schema import Scenario

__all__ = ["LimitCheck", "TaskResult", "execute", "html_name"]


@dataclass(frozen=True)
class LimitCheck:
    """Joint-limit check of one segment, on every sample.

    Attributes:
        position_violation_samples: Samples with a joint outside its position limits.
        position_violation_joints: Joints (0-based) that leave their limits.
        peak_velocity_ratio: Largest |qd| / velocity limit over joints and samples.
        peak_acceleration_ratio: Largest |qdd| / acceleration limit over joints and samples.
    """

    position_violation_samples: int
    position_violation_joints: tuple[int, ...]
    peak_velocity_ratio: float
    peak_acceleration_ratio: float

    @property
    def velocity_ok(self) -> bool:
        """Velocity within its limit (up to floating-point noise)."""
        return self.peak_velocity_ratio <= 1.0 + LIMIT_CHECK_RELATIVE_TOLERANCE

    @property
    def acceleration_ok(self) -> bool:
        """Acceleration within its limit (up to floating-point noise)."""
        return self.peak_acceleration_ratio <= 1.0 + LIMIT_CHECK_RELATIVE_TOLERANCE

    @property
    def within_limits(self) -> bool:
        """Position, velocity and acceleration limits all hold."""
        return self.position_violation_samples == 0 and self.velocity_ok and self.acceleration_ok


@dataclass(frozen=True)
class TaskResult:
    """Everything a task run measured.

    Attributes:
        setup: The resolved scenario.
        samples: The plan sampled at the scenario's rate (``lynxplan.trajectory.PlanSamples``).
        segments: Per-segment figures from the samples (``SegmentReport``).
        limits: Per-segment joint-limit checks.
        collision: The collision report (``lynxplan.collision.MotionReport``).
        world: The collision world (arm primitives + obstacles).
        comparison: The ruckig/toppra comparison (``PlanComparison``), or None.
        stage_seconds: Wall time of each stage, in [s].
    """

    setup: TaskSetup
    samples: Any
    segments: list[Any]
    limits: list[LimitCheck]
    collision: Any
    world: Any
    comparison: Any
    stage_seconds: dict[str, float]

    @property
    def within_limits(self) -> bool:
        """Every segment within its joint limits."""
        return all(check.within_limits for check in self.limits)


def _limit_checks(setup: TaskSetup, samples: Any) -> list[LimitCheck]:
    limits = setup.limits
    lower, upper = limits.position[:, 0], limits.position[:, 1]
    checks = []
    for i in range(len(setup.plan.segments)):
        mask = samples.segment == i
        q, qd, qdd = samples.q[mask], samples.qd[mask], samples.qdd[mask]
        outside = (q < lower - LIMIT_SNAP_TOLERANCE) | (q > upper + LIMIT_SNAP_TOLERANCE)
        checks.append(
            LimitCheck(
                int(np.count_nonzero(outside.any(axis=1))),
                tuple(int(j) for j in np.flatnonzero(outside.any(axis=0))),
                float(np.max(np.abs(qd) / limits.velocity, initial=0.0)),
                float(np.max(np.abs(qdd) / limits.acceleration, initial=0.0)),
            )
        )
    return checks


def execute(
    scenario: Scenario,
    setup: TaskSetup | None = None,
    progress: Any = None,
    *,
    compare: bool | None = None,
) -> TaskResult:
    """Sample the plan, check limits and collisions, compare timings (no files written).

    Args:
        scenario: The validated scenario.
        setup: Its resolution (default: resolved again).
        progress: ``callback(done, total)`` for a progress bar, or None.
        compare: Run the ruckig/toppra comparison (default: the scenario's ``compare``).
    """
    from lynxplan.collision import CollisionWorld, check_trajectory
    from lynxplan.trajectory.plan import segment_reports

    report = progress or (lambda done, total: None)
    setup = setup or resolve(scenario)
    seconds: dict[str, float] = {}
    clock = time.perf_counter()

    def lap(name: str, step: int) -> None:
        nonlocal clock
        now = time.perf_counter()
        seconds[name] = now - clock
        clock = now
        report(step, 5)

    samples = setup.plan.sample(scenario.sample_rate)
    lap("sample", 1)
    segments = segment_reports(setup.plan, samples)
    checks = _limit_checks(setup, samples)
    lap("limits", 2)
    world = CollisionWorld(setup.arm, setup.obstacles, self_collision=scenario.self_collision)
    bound = np.abs(samples.qdd).max(axis=0)
    collision = check_trajectory(
        world, samples.q, samples.t, samples.segment, acceleration_bound=bound
    )
    lap("collision", 3)
    comparison = None
    if scenario.compare if compare is None else compare:
        from lynxplan.trajectory.retime import compare_plan

        comparison = compare_plan(setup.plan, scenario.sample_rate)
    lap("comparison", 4)
    return TaskResult(setup, samples, segments, checks, collision, world, comparison, seconds)


def html_name(scenario: Scenario) -> str:
    """File name of the HTML export: the scenario name as a slug, e.g. ``ok_task.html``."""
    slug = re.sub(r"[^a-z0-9]+", "_", scenario.name.lower()).strip("_")
    return f"{slug or 'task'}.html"
