"""Scenario kind ``trajectory``: a list of segments, sampled and compared with ruckig and toppra.

Example (``scenarios/free_motion.yaml``)::

    kind: trajectory
    units: {length: in, angle: rad}
    robot: {}                             # the AL5 (default); {name: so101}; {urdf: .., tool: ..}
    start: [0, 0, 0, 0, 0]               # joint angles, in the file's angle unit
    limits: {acceleration: 8.0, jerk: 60.0}   # per joint (scalar or 5 values), angle unit/s^n
    sample_rate: 1000                     # [Hz]
    segments:
      - motion: free                      # or: line (with orientation: consistent|slerp|lerp|drive)
        to_q: [1.2, 0.9, -0.68, 1, 0]     # or to_pose: 3 or 4 rows of 4 (file's length unit)
        tt: 3.0                           # [s]; omit tt and ta for the shortest LSPB
        ta: 1.0
    plot: {segment: 0, joint: 2}          # the report's q2(t) figure: segment index, joint 1..5
    expect: {max_line_deviation: "<= 1e-9 m", joint_limits_respected: true}

Robots: as in ``task`` scenarios, the AL5 or any 5-joint yaw-pitch-pitch-pitch-roll arm from
URDF. Position and velocity limits come from the URDF.

Metrics: ``line_deviation`` [m] (largest tool-point distance from the lines),
``joint_limits_respected``, ``branch_switches`` (IK branch changes along lines), ``duration``
[s]. Artifacts: ``trajectory.csv`` (t, q, qd, qdd and the tool point x, y, z, SI) and, unless
quick, ``joint_profiles.png``, ``tool_xyz.png`` and ``durations.png``; the per-segment figures
and the comparison table are in ``report.json`` details.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, ClassVar, Literal

import numpy as np
from pydantic import Field, ValidationError, model_validator
from pydantic_core import InitErrorDetails, PydanticCustomError

from lynxplan.arm.geometry import JointLimits
from lynxplan.constants import LIMIT_SNAP_TOLERANCE
from lynxplan.scenarios.base import (
    SI_UNITS,
    Finite,
    KindOutput,
    Positive,
    Quantity,
    RobotRef,
    ScenarioModel,
    StrictModel,
    Units,
    scale_translation,
    scaled,
)
from lynxplan.trajectory.limits import DEFAULT_MAX_ACCELERATION, DEFAULT_MAX_JERK, MotionLimits
from lynxplan.trajectory.lspb import LspbTiming
from lynxplan.trajectory.plan import (
    DEFAULT_SAMPLE_RATE,
    Plan,
    PlanSamples,
    SegmentReport,
    SegmentSpec,
    build_plan,
    segment_reports,
)
from lynxplan.trajectory.retime import TOPPRA_LIMIT_SAFETY
from lynxplan.units import angle_factor, length_factor

#: A per-joint limit: one value for every joint, or one value per joint (5).
PerJoint = Positive | Annotated[list[Positive], Field(min_length=5, max_length=5)]

NAME = "trajectory"


class SegmentEntry(StrictModel):
    """One segment of the scenario."""

    motion: Literal["free", "line"] = Field(description="Joint-space or Cartesian straight line.")
    to_q: list[Finite] | None = Field(default=None, min_length=5, max_length=5)
    to_pose: list[list[Finite]] | None = Field(default=None, min_length=3, max_length=4)
    tt: Positive | None = Field(default=None, le=3600.0, description="Total time, in [s].")
    ta: Positive | None = Field(default=None, description="Blend time, in [s].")
    orientation: Literal["consistent", "slerp", "lerp", "drive"] = "consistent"

    @model_validator(mode="after")
    def _one_target_and_timing(self) -> SegmentEntry:
        if (self.to_q is None) == (self.to_pose is None):
            raise ValueError("give exactly one of to_q and to_pose")
        if (self.tt is None) != (self.ta is None):
            raise ValueError("give both tt and ta, or neither (shortest LSPB within the limits)")
        if self.to_pose is not None and any(len(row) != 4 for row in self.to_pose):
            raise ValueError("to_pose rows must have 4 values")
        if self.tt is not None and self.ta is not None:
            LspbTiming(self.tt, self.ta)  # TimingError (a ValueError) names the problem
        return self

    def spec(self, units: Units) -> SegmentSpec:
        """The plan's :class:`SegmentSpec`, in SI units."""
        timing = None if self.tt is None or self.ta is None else LspbTiming(self.tt, self.ta)
        target_q = target_pose = None
        if self.to_q is not None:
            target_q = np.array(self.to_q) * angle_factor(units.angle)
        else:
            target_pose = np.eye(4)
            target_pose[: len(self.to_pose or []), :] = np.array(self.to_pose)
            target_pose[:3, 3] *= length_factor(units.length)
        return SegmentSpec(self.motion, target_q, target_pose, timing, self.orientation)


class LimitsEntry(StrictModel):
    """Acceleration and jerk limits per joint, in the file's angle unit per s^2 / s^3."""

    acceleration: PerJoint | None = Field(
        default=None, description=f"Default {DEFAULT_MAX_ACCELERATION} rad/s^2."
    )
    jerk: PerJoint | None = Field(default=None, description=f"Default {DEFAULT_MAX_JERK} rad/s^3.")

    def build(self, units: Units, robot: Any = None) -> MotionLimits:
        """:class:`MotionLimits` in SI; position and velocity limits from the robot's URDF
        (default: the AL5's)."""
        factor = angle_factor(units.angle)
        acc = DEFAULT_MAX_ACCELERATION if self.acceleration is None else self.acceleration
        jerk = DEFAULT_MAX_JERK if self.jerk is None else self.jerk
        scale = 1.0 if self.acceleration is None else factor
        jerk_scale = 1.0 if self.jerk is None else factor
        urdf = {} if robot is None else {"position": robot.limits.position}
        if robot is not None:
            urdf["velocity"] = robot.limits.velocity
        return MotionLimits(
            acceleration=np.asarray(acc, dtype=float) * scale,
            jerk=np.asarray(jerk, dtype=float) * jerk_scale,
            **urdf,
        )


class PlotEntry(StrictModel):
    """Which segment and joint the joint-profile figure shows."""

    segment: int = Field(default=0, ge=0)
    joint: int = Field(default=2, ge=1, le=5, description="1-based joint number (q2 default).")


class Input(ScenarioModel):
    """A ``trajectory`` scenario."""

    metrics: ClassVar[dict[str, Quantity]] = {
        "line_deviation": "length",
        "joint_limits_respected": "bool",
        "branch_switches": "count",
        "duration": "time",
    }

    kind: Literal["trajectory"]
    units: Units = Units(length="m", angle="rad")
    robot: RobotRef = Field(default_factory=RobotRef)
    start: list[Finite] = Field(min_length=5, max_length=5)
    segments: list[SegmentEntry] = Field(min_length=1)
    limits: LimitsEntry = Field(default_factory=LimitsEntry)
    sample_rate: float = Field(default=DEFAULT_SAMPLE_RATE, gt=0, le=1e5, allow_inf_nan=False)
    compare: bool = Field(default=True, description="Run the ruckig and toppra comparisons.")
    plot: PlotEntry = Field(default_factory=PlotEntry)

    def si_inputs(self) -> dict[str, Any]:
        """Inputs in [m] and [rad] (limits in rad/s^2, rad/s^3)."""
        length, angle = length_factor(self.units.length), angle_factor(self.units.angle)
        data = super().si_inputs()
        data["units"] = dict(SI_UNITS)
        data["start"] = scaled(self.start, angle)
        for entry, seg in zip(data["segments"], self.segments, strict=True):
            entry["to_q"] = scaled(seg.to_q, angle)
            entry["to_pose"] = scale_translation(seg.to_pose, length)
        for key in ("acceleration", "jerk"):
            data["limits"][key] = scaled(getattr(self.limits, key), angle)
        return data

    @model_validator(mode="after")
    def _plot_segment_exists(self) -> Input:
        if self.plot.segment >= len(self.segments):
            raise ValueError(
                f"plot.segment {self.plot.segment} does not exist "
                f"(there are {len(self.segments)} segments)"
            )
        return self

    @model_validator(mode="after")
    def _configurations_within_joint_limits(self) -> Input:
        """Reject a start or ``to_q`` outside the AL5's joint limits, naming the key path (for
        another robot, the run checks its URDF limits the same way).

        The check needs the file's angle unit, so it runs on the whole scenario; the error
        carries the offending entry's own location (``start[1]``, ``segments[2].to_q[1]``).
        """
        if self.robot != RobotRef():
            return self
        for loc, message, value in self.outside_limits(JointLimits().position):
            error = PydanticCustomError("joint_limit", message)
            raise ValidationError.from_exception_data(
                type(self).__name__, [InitErrorDetails(type=error, loc=loc, input=value)]
            )
        return self

    def outside_limits(
        self, position: np.ndarray
    ) -> list[tuple[tuple[int | str, ...], str, float]]:
        """``(key path, message, value)`` of each start or ``to_q`` angle outside ``position``
        (n, 2) [rad]."""
        factor = angle_factor(self.units.angle)
        entries: list[tuple[tuple[int | str, ...], list[float]]] = [(("start",), self.start)]
        entries += [
            (("segments", i, "to_q"), entry.to_q)
            for i, entry in enumerate(self.segments)
            if entry.to_q is not None
        ]
        found = []
        for loc, values in entries:
            q = np.array(values) * factor
            outside = (q < position[:, 0] - LIMIT_SNAP_TOLERANCE) | (
                q > position[:, 1] + LIMIT_SNAP_TOLERANCE
            )
            for j in np.flatnonzero(outside):
                low, high = position[j] / factor
                message = (
                    f"q{j + 1} = {values[j]:g} {self.units.angle} is outside its joint limits "
                    f"[{low:g}, {high:g}] {self.units.angle}"
                )
                found.append(((*loc, int(j)), message, values[j]))
        return found


Scenario = Input


def build(scenario: Input) -> Plan:
    """The scenario's plan (SI units) for its robot.

    Raises:
        ScenarioValueError: the robot cannot be used, or a start / ``to_q`` angle is outside
            its joint limits (named by key path).
    """
    from lynxplan.exceptions import ScenarioValueError
    from lynxplan.scenarios.robot import load_path_robot

    robot, kinematics = load_path_robot(scenario.robot)
    for loc, message, value in scenario.outside_limits(robot.limits.position):
        raise ScenarioValueError(loc, message, value)
    start = np.array(scenario.start) * angle_factor(scenario.units.angle)
    specs = [entry.spec(scenario.units) for entry in scenario.segments]
    return build_plan(start, specs, scenario.limits.build(scenario.units, robot), kinematics)


def _report_json(
    scenario: Input, plan: Plan, reports: list[SegmentReport], comparison: Any
) -> dict[str, Any]:
    limits = plan.limits
    segments = []
    for report in reports:
        entry: dict[str, Any] = report._asdict()
        if comparison is not None:
            entry["comparison"] = {
                name: {
                    "duration_s": s.duration,
                    "peak_velocity_rad_s": s.peak_velocity.tolist(),
                    "peak_acceleration_rad_s2": s.peak_acceleration.tolist(),
                    "peak_jerk_rad_s3": s.peak_jerk.tolist(),
                    "velocity_ratio": s.velocity_ratio,
                    "acceleration_ratio": s.acceleration_ratio,
                    "violations": list(s.violations),
                    "time_scale": s.time_scale,
                    "duration_matched": s.duration_matched,
                }
                for name, s in comparison.segments[report.segment].stats.items()
            }
        segments.append(entry)
    out: dict[str, Any] = {
        "name": scenario.name,
        "sample_rate_hz": scenario.sample_rate,
        "duration_s": plan.duration,
        "limits": {
            "position_rad": limits.position.tolist(),
            "velocity_rad_s": limits.velocity.tolist(),
            "acceleration_rad_s2": limits.acceleration.tolist(),
            "jerk_rad_s3": limits.jerk.tolist(),
        },
        "segments": segments,
    }
    if comparison is not None:
        out["plan_comparison"] = {
            name: {
                "total_duration_s": comparison.total_duration[name],
                "segments_covered": comparison.segments_covered[name],
                "peak_velocity_rad_s": comparison.peak_velocity[name].tolist(),
                "peak_acceleration_rad_s2": comparison.peak_acceleration[name].tolist(),
                "segments_with_violations": comparison.violation_count[name],
            }
            for name in comparison.total_duration
        }
        out["notes"] = [
            "ruckig applies to free segments only (it does not follow a Cartesian line).",
            "LSPB and toppra accelerations are piecewise constant: their sampled jerk is the "
            "acceleration step over the sample period (impulsive), not a limit violation.",
            f"toppra is given the limits times {TOPPRA_LIMIT_SAFETY} (it enforces them on its "
            "grid points only); its samples are verified and, if still over a limit, time is "
            "stretched uniformly by time_scale (velocity / k, acceleration / k^2).",
            "ruckig_lspb_duration asks ruckig for the LSPB's duration; when that is shorter "
            "than ruckig's jerk-limited minimum, ruckig takes longer (duration_matched false).",
        ]
    return out


def _metrics(plan: Plan, reports: list[SegmentReport]) -> dict[str, Any]:
    deviations = [r.max_line_deviation for r in reports if r.max_line_deviation is not None]
    return {
        "line_deviation": max(deviations) if deviations else 0.0,
        "joint_limits_respected": not any(r.limit_violation_samples for r in reports),
        "branch_switches": sum(r.branch_switches for r in reports),
        "duration": plan.duration,
    }


def run(scenario: Input, *, quick: bool = False) -> KindOutput:
    """Build, sample and compare the plan (no files)."""
    plan = build(scenario)
    samples = plan.sample(scenario.sample_rate)
    reports = segment_reports(plan, samples)
    comparison = None
    if scenario.compare and not quick:
        from lynxplan.trajectory.retime import compare_plan

        comparison = compare_plan(plan, scenario.sample_rate)
    details = _report_json(scenario, plan, reports, comparison)
    text = _summary(scenario, plan, reports, comparison)
    notes = {
        "joint_limits_respected": "; ".join(
            f"segments[{r.segment}]: {r.limit_violation_samples} samples outside the joint limits "
            f"({', '.join(f'q{j + 1}' for j in r.limit_violation_joints)})"
            for r in reports
            if r.limit_violation_samples
        ),
        "branch_switches": "; ".join(
            f"segments[{r.segment}]: {r.branch_switches} IK branch switches"
            for r in reports
            if r.branch_switches
        ),
    }
    return KindOutput(
        _metrics(plan, reports), text, details, payload=(plan, samples, comparison), notes=notes
    )


def write_outputs(scenario: Input, output: KindOutput, out_dir: Path, *, quick: bool) -> list[str]:
    """``trajectory.csv`` and, unless quick, the plots."""
    from lynxplan.scenarios.outputs import write_samples_csv

    plan, samples, comparison = output.payload
    write_samples_csv(out_dir / "trajectory.csv", samples)
    if quick:
        return ["trajectory.csv"]
    return ["trajectory.csv", *_write_plots(scenario, plan, samples, comparison, out_dir)]


def _write_plots(
    scenario: Input, plan: Plan, samples: PlanSamples, comparison: Any, out_dir: Path
) -> list[str]:
    from lynxplan.trajectory import plots

    written = []
    index, joint = scenario.plot.segment, scenario.plot.joint - 1
    if comparison is not None:
        plots.plot_joint_profiles(comparison.segments[index], joint, out_dir / "joint_profiles.png")
        plots.plot_durations(comparison, out_dir / "durations.png")
        written += ["joint_profiles.png", "durations.png"]
    lines = [i for i, seg in enumerate(plan.segments) if seg.kind == "line"]
    if lines:
        plots.plot_tool_xyz(plan, samples, lines[0], out_dir / "tool_xyz.png")
        written.append("tool_xyz.png")
    return written


def _summary(scenario: Input, plan: Plan, reports: list[SegmentReport], comparison: Any) -> str:
    lines = [r for r in reports if r.max_line_deviation is not None]
    text = (
        f"trajectory {scenario.name or ''}: {len(plan.segments)} segments, "
        f"{plan.duration:.3f} s planned"
    )
    if lines:
        deviation = max(r.max_line_deviation or 0.0 for r in lines)
        text += f"; largest line deviation {deviation:.2e} m"
    violations = sum(r.limit_violation_samples for r in reports)
    text += f"; {violations} samples outside joint limits"
    if comparison is not None:
        totals = ", ".join(f"{k} {v:.3f} s" for k, v in comparison.total_duration.items())
        text += f"; durations: {totals}"
    start = plan.kinematics.tool_poses(
        np.array(scenario.start)[None] * angle_factor(scenario.units.angle)
    )[0]
    text += f"; start tool point {np.round(start[:3, 3], 4).tolist()} m"
    return text
