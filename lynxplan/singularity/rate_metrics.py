"""Figures of a resolved-rate run: speeds against the limits, tracking, completion."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from lynxplan.arm.geometry import JointLimits
from lynxplan.constants import COMPLETION_TOLERANCE, LIMIT_CHECK_RELATIVE_TOLERANCE
from lynxplan.singularity.rate_problem import STRATEGY_NAMES, ResolvedRateProblem, ResolvedRateRun

_DEFAULT_LIMITS = JointLimits()


class RunMetrics(NamedTuple):
    """Figures of one strategy's run.

    Attributes:
        strategy: Strategy name.
        peak_joint_speed: Largest |qdot_i| over the run, in [rad/s].
        peak_speed_ratio: Largest |qdot_i| / limit_i (> 1: a limit is exceeded).
        speed_limit_exceeded: Whether a joint exceeded its speed limit.
        max_tracking_error: Largest tool-point distance from the reference, in [m].
        rms_tracking_error: RMS of that distance over the run, in [m].
        max_pitch_error: Largest |pitch - pitch_ref|, in [rad] (0 when pitch is not a task row).
        min_manipulability: Smallest m(q) reached (task units).
        completion_time: First time the reference has reached its end and the tool is within
            ``COMPLETION_TOLERANCE`` of it, in [s]; None if it never is.
        joint_limit_violation: Largest excursion outside the joint position limits, in [rad].
    """

    strategy: str
    peak_joint_speed: float
    peak_speed_ratio: float
    speed_limit_exceeded: bool
    max_tracking_error: float
    rms_tracking_error: float
    max_pitch_error: float
    min_manipulability: float
    completion_time: float | None
    joint_limit_violation: float


def run_metrics(
    run: ResolvedRateRun, problem: ResolvedRateProblem, limits: JointLimits = _DEFAULT_LIMITS
) -> RunMetrics:
    """Metrics of a run against the problem's speed limits and ``limits``' position limits."""
    ratio = float(np.max(np.abs(run.qd) / problem.velocity_limits))
    error = run.position_error
    pitch_error = (
        float(np.max(np.abs(run.x[:, 3] - run.x_ref[:, 3]))) if 6 in run.task.rows else 0.0
    )
    arrived = (run.path_time >= problem.path.duration - 1e-12) & (error <= COMPLETION_TOLERANCE)
    completion = float(run.t[np.argmax(arrived)]) if arrived.any() else None
    violation = np.maximum(limits.lower - run.q, run.q - limits.upper).max()
    return RunMetrics(
        strategy=STRATEGY_NAMES[run.strategy],
        peak_joint_speed=float(np.max(np.abs(run.qd))),
        peak_speed_ratio=ratio,
        speed_limit_exceeded=ratio > 1.0 + LIMIT_CHECK_RELATIVE_TOLERANCE,
        max_tracking_error=float(error.max()),
        rms_tracking_error=float(np.sqrt(np.mean(error**2))),
        max_pitch_error=pitch_error,
        min_manipulability=float(run.m.min()),
        completion_time=completion,
        joint_limit_violation=max(float(violation), 0.0),
    )
