"""A multi-segment plan (free and straight-line segments) sampled at any rate.

Each segment starts where the previous one ended. Sampling gives per sample the time, q, qd, qdd,
the tool pose, the segment index, the IK branch and the orientation residual; per-segment
reports (line deviation, residual, branch switches, joint-limit violations, peak speed) are
computed from the samples, not predicted.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal, NamedTuple

import numpy as np

from lynxplan import guards
from lynxplan.constants import LIMIT_SNAP_TOLERANCE
from lynxplan.exceptions import InputError, PathNotFollowableError
from lynxplan.trajectory.free import (
    FreeSegment,
    JointSamples,
    as_configuration,
    check_timing,
    free_segment,
)
from lynxplan.trajectory.kinematics import Al5Kinematics, PathKinematics
from lynxplan.trajectory.limits import MotionLimits
from lynxplan.trajectory.line import LineSegment, line_segment_from_checked_poses
from lynxplan.trajectory.lspb import LspbTiming

Segment = FreeSegment | LineSegment

#: The report's sampling period is 0.1 s; lynxplan samples at 1 kHz by default.
DEFAULT_SAMPLE_RATE = 1000.0


class PlanSamples(NamedTuple):
    """A plan sampled at a fixed rate (N samples, first at 0, last at the plan's end)."""

    t: np.ndarray
    """Time since the plan start, shape (N,), in [s]."""
    q: np.ndarray
    """Joint angles, shape (N, 5), in [rad]."""
    qd: np.ndarray
    """Joint velocities, shape (N, 5), in [rad/s]."""
    qdd: np.ndarray
    """Joint accelerations, shape (N, 5), in [rad/s^2]."""
    tool: np.ndarray
    """Tool poses (FK of q), shape (N, 4, 4), in [m]."""
    segment: np.ndarray
    """Index of the segment each sample belongs to, shape (N,)."""
    branch: np.ndarray
    """IK branch per sample, shape (N,) (-1 on free segments)."""
    orientation_residual: np.ndarray
    """Interpolated-vs-reached orientation angle, shape (N,), in [rad] (0 on free segments)."""


@dataclass(frozen=True)
class SegmentSpec:
    """What a user asks for: a segment to a target, with a timing (None = auto).

    Attributes:
        kind: ``"free"`` (joint space) or ``"line"`` (Cartesian straight line).
        target_q: Target configuration, shape (5,), in [rad], or None.
        target_pose: Target tool pose, shape (4, 4), in [m], or None (exactly one is given).
        timing: LSPB timing, or None for the shortest within the limits.
        mode: Orientation mode of a line segment.
    """

    kind: Literal["free", "line"]
    target_q: np.ndarray | None = None
    target_pose: np.ndarray | None = None
    timing: LspbTiming | None = None
    mode: str = "consistent"


@dataclass(frozen=True)
class Plan:
    """Consecutive segments; segment ``i`` starts at ``start_times[i]``.

    Attributes:
        segments: The segments, in order.
        limits: The joint limits the plan was built with.
        kinematics: The arm (FK of the samples; default: the AL5's closed form).
    """

    segments: tuple[Segment, ...]
    limits: MotionLimits
    kinematics: PathKinematics = field(default_factory=Al5Kinematics)

    @property
    def start_times(self) -> np.ndarray:
        """Start time of each segment, shape (n,), in [s]."""
        durations = [seg.duration for seg in self.segments]
        return np.concatenate([[0.0], np.cumsum(durations)[:-1]])

    @property
    def duration(self) -> float:
        """Total duration, in [s]."""
        return float(sum(seg.duration for seg in self.segments))

    def sample(self, rate: float = DEFAULT_SAMPLE_RATE) -> PlanSamples:
        """Sample the plan every ``1/rate`` seconds from 0 to the end (end included).

        Args:
            rate: Samples per second, in [Hz] (the report used 10 Hz).
        """
        rate = guards.sample_rate("sample rate", rate)
        # t, q, qd, qdd, tool pose, segment, branch, residual: about 300 bytes per sample.
        guards.check_size(
            f"trajectory samples ({self.duration:.6g} s at {rate:g} Hz)",
            self.duration * rate + 2,
            300.0,
        )
        count = math.floor(self.duration * rate + 1e-9) + 1
        t = np.arange(count) / rate
        if t[-1] < self.duration - 1e-12:
            t = np.append(t, self.duration)
        starts = self.start_times
        index = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(self.segments) - 1)
        parts: list[JointSamples] = []
        for i, seg in enumerate(self.segments):
            local = t[index == i] - starts[i]
            parts.append(seg.sample(np.minimum(local, seg.duration)))
        q = np.concatenate([p.q for p in parts])
        return PlanSamples(
            t,
            q,
            np.concatenate([p.qd for p in parts]),
            np.concatenate([p.qdd for p in parts]),
            self.kinematics.tool_poses(q),
            index,
            np.concatenate([p.branch for p in parts]),
            np.concatenate([p.orientation_residual for p in parts]),
        )


def _ik_nearest(
    T: np.ndarray, q_near: np.ndarray, limits: MotionLimits, kinematics: PathKinematics
) -> np.ndarray:
    try:
        return kinematics.nearest(T, q_near, limits)
    except PathNotFollowableError as exc:
        raise PathNotFollowableError(1.0, exc.reach_miss, "target pose") from exc


def _build_segment(
    i: int, spec: SegmentSpec, q: np.ndarray, lim: MotionLimits, kinematics: PathKinematics
) -> Segment:
    if (spec.target_q is None) == (spec.target_pose is None):
        raise InputError(f"segment {i}: give exactly one of target_q and target_pose")
    pose = np.eye(4)  # replaced below when the target is a pose
    if spec.target_pose is not None:
        pose = guards.poses(f"segments[{i}].target_pose", spec.target_pose, batch=False)
    if spec.kind in ("free", "line"):
        check_timing(spec.timing, f"segments[{i}].timing")
    if spec.kind == "free":
        target = (
            as_configuration(spec.target_q, f"segments[{i}].target_q")
            if spec.target_q is not None
            else _ik_nearest(pose, q, lim, kinematics)
        )
        return free_segment(q, target, spec.timing, limits=lim)
    if spec.kind == "line":
        if spec.target_q is not None:
            target_q = as_configuration(spec.target_q, f"segments[{i}].target_q")
            pose = kinematics.tool_poses(target_q[None])[0]
        T_start = kinematics.tool_poses(q[None])[0]
        # Both poses are FK results or were checked above: not checked again (numba kernel).
        return line_segment_from_checked_poses(
            T_start, pose, q, spec.timing, mode=spec.mode, limits=lim, kinematics=kinematics
        )
    raise InputError(f"segment {i}: unknown kind {spec.kind!r}; valid kinds: free, line")


def build_plan(
    q_start: np.ndarray | list[float],
    specs: list[SegmentSpec] | tuple[SegmentSpec, ...],
    limits: MotionLimits | None = None,
    kinematics: PathKinematics | None = None,
) -> Plan:
    """Chain segments from ``q_start``; each starts at the previous one's end configuration.

    Args:
        q_start: Start configuration, shape (5,), in [rad].
        specs: The segments.
        limits: Joint limits for auto-timing and IK (default: URDF + documented defaults).
        kinematics: The arm (default: the AL5's closed-form kernels).

    Raises:
        InputError: a spec gives neither or both targets, or there is no segment.
        PathNotFollowableError: a line leaves the reach, or a target pose is unreachable.
    """
    lim = limits or MotionLimits()
    if not isinstance(lim, MotionLimits):
        raise InputError(f"limits must be MotionLimits or None. Got: {type(lim).__name__}")
    if isinstance(specs, (str, bytes)) or not hasattr(specs, "__len__"):
        raise InputError(f"specs must be a list of SegmentSpec. Got: {type(specs).__name__}")
    if not specs:
        raise InputError("a plan needs at least one segment")
    for i, spec in enumerate(specs):
        if not isinstance(spec, SegmentSpec):
            raise InputError(f"specs[{i}] must be a SegmentSpec. Got: {type(spec).__name__}")
    guards.check_size("plan segments", len(specs))
    kin = kinematics or Al5Kinematics()
    q = as_configuration(q_start, "q_start")
    segments: list[Segment] = []
    for i, spec in enumerate(specs):
        try:
            segment = _build_segment(i, spec, q, lim, kin)
        except PathNotFollowableError as exc:
            what = f"segment {i} ({spec.kind})"
            raise PathNotFollowableError(exc.s, exc.reach_miss, what) from exc
        segments.append(segment)
        q = segment.q_end
    return Plan(tuple(segments), lim, kin)


class SegmentReport(NamedTuple):
    """What the samples of one segment show."""

    segment: int
    """Segment index in the plan."""
    kind: str
    """``"free"`` or ``"line"``."""
    mode: str | None
    """Orientation mode of a line, None for free motion."""
    tt: float
    """Total time, in [s]."""
    ta: float
    """Blend time, in [s]."""
    max_line_deviation: float | None
    """Largest distance of the tool point from the segment, in [m] (lines only)."""
    max_orientation_residual: float
    """Largest interpolated-vs-reached orientation angle, in [rad]."""
    branch_switches: int
    """How often the IK branch changes between consecutive samples."""
    limit_violation_samples: int
    """Samples with a joint outside its position limits (beyond the snap tolerance)."""
    limit_violation_joints: tuple[int, ...]
    """Joints (0-based) that leave their limits."""
    max_joint_speed: float
    """Largest |qd| over joints and samples, in [rad/s]."""
    max_joint_speed_joint: int
    """Joint (0-based) of that speed."""
    max_joint_speed_time: float
    """Plan time of that speed, in [s]."""


def _line_deviation(points: np.ndarray, p0: np.ndarray, p1: np.ndarray) -> float:
    """Largest distance of ``points`` (m, 3) from the segment ``p0``-``p1``, in [m]."""
    direction = p1 - p0
    length2 = float(direction @ direction)
    rel = points - p0
    u = np.zeros(len(points)) if length2 == 0 else np.clip(rel @ direction / length2, 0, 1)
    return float(np.max(np.linalg.norm(rel - np.outer(u, direction), axis=1)))


def segment_reports(plan: Plan, samples: PlanSamples) -> list[SegmentReport]:
    """Per-segment figures computed from the samples of ``plan``."""
    lower, upper = plan.limits.position[:, 0], plan.limits.position[:, 1]
    reports = []
    for i, seg in enumerate(plan.segments):
        mask = samples.segment == i
        q, qd = samples.q[mask], samples.qd[mask]
        outside = (q < lower - LIMIT_SNAP_TOLERANCE) | (q > upper + LIMIT_SNAP_TOLERANCE)
        deviation = None
        if isinstance(seg, LineSegment):
            deviation = _line_deviation(
                samples.tool[mask, :3, 3], seg.T_start[:3, 3], seg.T_end[:3, 3]
            )
        flat = int(np.argmax(np.abs(qd))) if qd.size else 0
        k, joint = divmod(flat, q.shape[1])
        reports.append(
            SegmentReport(
                i,
                seg.kind,
                seg.mode if isinstance(seg, LineSegment) else None,
                seg.timing.tt,
                seg.timing.ta,
                deviation,
                float(np.max(samples.orientation_residual[mask], initial=0.0)),
                int(np.count_nonzero(np.diff(samples.branch[mask]))),
                int(np.count_nonzero(outside.any(axis=1))),
                tuple(int(j) for j in np.flatnonzero(outside.any(axis=0))),
                float(np.abs(qd).max(initial=0.0)),
                joint,
                float(samples.t[mask][k]) if qd.size else 0.0,
            )
        )
    return reports
