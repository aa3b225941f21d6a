"""Scenario kind ``task``: the schema of an arm task (waypoints, segments, obstacles, expectations).

Example (``scenarios/ok_task.yaml`` is the full SPEC Part 3 task)::

    kind: task
    name: pick and place
    units: {length: in, angle: deg}          # lengths in|mm|m, angles deg|rad
    robot: {}                                # the shipped AL5; {name: so101}; {urdf: .., tool: ..}
    sample_rate: 1000                        # [Hz]
    timing: {tt: 2.0, ta: 0.5}               # default of every segment [s]; or: auto
    limits: {acceleration: 450, jerk: 3400}  # per joint (scalar or 5 values), angle unit / s^n
    obstacles:
      - {name: wall, type: box, min_corner: [-0.2, 8, -2], size: [0.4, 10, 3.5]}
      - {name: crate, type: box, centre: [5, 5, 0], size: [2, 2, 2], rpy: [0, 0, 30]}
      - {name: ball, type: sphere, centre: [0, 9, 6], radius: 1}
      - {name: post, type: cylinder, centre: [4, 8, 0], radius: 0.5, length: 6, axis: [0, 0, 1]}
    waypoints:
      A: {q: [104, 57, -59, 40, 0]}                     # joint angles
      B: {pose: [[-0.3196, 0.9455, -0.0621, -2.8966],   # 3 or 4 rows of a 4x4 pose (IK)
                 [0.9281, 0.3256, 0.1804, 8.4123],
                 [0.1908, 0, -0.9816, 0.5472]]}
      C: {position: [2, 10, 1.4], approach: [0, 0.34, -0.94]}   # 5-D target (IK)
    segments:
      - {from: A, to: B, motion: line, orientation: consistent}
      - {to: C, motion: free, timing: auto}   # from: defaults to the previous segment's end
      - {to: A, motion: plan}                 # planned around the obstacles (lynxplan.plan)
    writing_plane: {point: [0.5, 10.3, 1.26], tilt: 20, size: [10, 8]}   # drawn only
    outputs: {plots: true, html: true}
    expect:
      collision_free: true            # no contact at any sample nor between samples
      within_limits: true             # position, velocity and acceleration limits, every sample
      min_clearance: ">= 0.2 in"      # comparator, number, unit (default: the file's unit)
      max_duration: "<= 30 s"

Robots: the shipped AL5 (default; also any URDF of its joint structure, solved with its closed
form), ``{name: so100}`` / ``{name: so101}`` or ``{urdf: path, tool: frame}`` of any 5-joint
yaw-pitch-pitch-pitch-roll arm (closed-form / root-search IK of :func:`lynxplan.load_robot`, mesh
collision geometry as convex hulls). A waypoint's ``ik: report`` is the AL5's branch rule; other
robots take the branch nearest ``q_reference`` (default: zeros). ``scenarios/so101_writing.yaml``
is the SO-101 example.

Relative URDF paths are resolved from the current working directory.

Metrics: ``collision_free``, ``within_limits``, ``min_clearance`` [m], ``duration`` [s],
``path_deviation`` [m], ``joint_speed`` [rad/s] (peak), ``contacts``. Artifacts:
``trajectory.csv`` and, unless quick or switched off in ``outputs``, ``task_side.png``,
``task_top.png``, ``joints.png``, ``clearance.png`` and ``<name>.html``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, ClassVar, Literal

from pydantic import Discriminator, Field, Tag, model_validator
from typing_extensions import Self

from lynxplan.scenarios.base import (
    SI_UNITS,
    Finite,
    KindOutput,
    Matrix3,
    Positive,
    Quantity,
    RobotRef,
    ScenarioModel,
    StrictModel,
    TargetEntry,
    Units,
    Vector3,
    located_error,
    scale_translation,
    scaled,
)
from lynxplan.trajectory.lspb import LspbTiming
from lynxplan.units import angle_factor, length_factor

NAME = "task"

PerJoint = Positive | Annotated[list[Positive], Field(min_length=5, max_length=5)]


class _Oriented(StrictModel):
    """Orientation of an obstacle: roll-pitch-yaw angles or a rotation matrix (not both)."""

    rpy: Vector3 | None = Field(
        None, description="Fixed-axis roll, pitch, yaw (R = Rz Ry Rx), in the file's angle unit."
    )
    rotation: Matrix3 | None = Field(None, description="Rotation matrix (columns = body axes).")

    @model_validator(mode="after")
    def _one_orientation(self) -> Self:
        if self.rpy is not None and self.rotation is not None:
            raise ValueError("give rpy or rotation, not both")
        return self


class BoxEntry(_Oriented):
    """A cuboid: ``min_corner`` + ``size`` (axis-aligned) or ``centre`` + ``size`` (+ rotation)."""

    type: Literal["box"]
    name: str | None = None
    min_corner: Vector3 | None = Field(None, description="Minimum corner (axis-aligned box).")
    centre: Vector3 | None = None
    size: Annotated[list[Positive], Field(min_length=3, max_length=3)]

    @model_validator(mode="after")
    def _placement(self) -> Self:
        if (self.min_corner is None) == (self.centre is None):
            raise ValueError("give exactly one of min_corner and centre")
        if self.min_corner is not None and (self.rpy is not None or self.rotation is not None):
            raise ValueError("a box given by min_corner is axis-aligned: use centre with rpy")
        return self


class SphereEntry(StrictModel):
    """A ball."""

    type: Literal["sphere"]
    name: str | None = None
    centre: Vector3
    radius: Positive


class CylinderEntry(_Oriented):
    """A solid cylinder; its axis is ``axis`` (default +z) or the rotation's third column."""

    type: Literal["cylinder"]
    name: str | None = None
    centre: Vector3 = Field(description="Centre of the axis segment.")
    radius: Positive
    length: Positive
    axis: Vector3 | None = None

    @model_validator(mode="after")
    def _one_axis(self) -> Self:
        if self.axis is not None and (self.rpy is not None or self.rotation is not None):
            raise ValueError("give axis or an orientation (rpy, rotation), not both")
        if self.axis is not None and not any(self.axis):
            raise ValueError("axis must not be the zero vector")
        return self


ObstacleEntry = Annotated[BoxEntry | SphereEntry | CylinderEntry, Field(discriminator="type")]


class WaypointEntry(TargetEntry):
    """A waypoint: joint angles, a 4x4 pose, or a position with an approach direction."""

    q: Annotated[list[Finite], Field(min_length=5, max_length=5)] | None = Field(
        None, description="Joint angles q1..q5, in the file's angle unit."
    )
    ik: Literal["report", "nearest"] = Field(
        "report",
        description="IK branch: the report's rule (first within limits with q2 >= 0, q3 <= 0) "
        "or the one nearest to q_reference.",
    )
    q_reference: Annotated[list[Finite], Field(min_length=5, max_length=5)] | None = Field(
        None, description="For ik: nearest and for q5 of a position + approach target."
    )


class TimingEntry(StrictModel):
    """LSPB timing of a segment, in [s]."""

    tt: Positive = Field(description="Total time, in [s].")
    ta: Positive = Field(description="Blend time, in [s] (at most tt / 2).")

    @model_validator(mode="after")
    def _valid_lspb(self) -> Self:
        LspbTiming(self.tt, self.ta)  # TimingError (a ValueError) says what is wrong
        return self


def _timing_tag(value: Any) -> str:
    return "auto" if isinstance(value, str) else "fixed"


#: ``{tt, ta}`` or ``"auto"``; error paths read ``timing.fixed.ta`` / ``timing.auto``.
Timing = Annotated[
    Annotated[TimingEntry, Tag("fixed")] | Annotated[Literal["auto"], Tag("auto")],
    Discriminator(_timing_tag),
]


class SegmentEntry(StrictModel):
    """One motion between two named waypoints."""

    from_: str | None = Field(
        None, alias="from", description="Start waypoint (default: the previous segment's end)."
    )
    to: str = Field(description="Target waypoint name.")
    motion: Literal["free", "line", "plan"] = Field(
        description="Joint-space or Cartesian straight line, or plan: a collision-free motion "
        "found by lynxplan.plan (straight joint pieces through planned via points)."
    )
    timing: Timing | None = Field(
        None, description="{tt, ta} or auto (shortest within limits); default: the file's timing."
    )
    orientation: Literal["consistent", "slerp", "lerp", "drive"] = Field(
        "consistent", description="Orientation mode of a line (see lynxplan.trajectory.line)."
    )


class LimitsEntry(StrictModel):
    """Joint limits beyond the URDF's position limits; per joint (scalar or 5 values)."""

    velocity: PerJoint | None = Field(
        None, description="Angle unit/s; default: the URDF's velocity limits."
    )
    acceleration: PerJoint | None = Field(None, description="Angle unit/s^2; default 8 rad/s^2.")
    jerk: PerJoint | None = Field(None, description="Angle unit/s^3 (ruckig); default 60 rad/s^3.")


class WritingPlaneEntry(StrictModel):
    """The writing surface, drawn in plots and HTML (not an obstacle)."""

    point: Vector3 = Field(description="A point of the plane, in the file's length unit.")
    tilt: Finite = Field(description="Tilt about x, rising along +y, in the file's angle unit.")
    size: Annotated[list[Positive], Field(min_length=2, max_length=2)] = Field(
        description="Extent along x and along the rising direction, in the file's length unit."
    )


class OutputsEntry(StrictModel):
    """Which outputs a full (not ``--quick``) run writes; report.json is always written."""

    plots: bool = True
    html: bool = True


class Input(ScenarioModel):
    """A ``task`` scenario: an arm moving through named waypoints among obstacles."""

    metrics: ClassVar[dict[str, Quantity]] = {
        "collision_free": "bool",
        "within_limits": "bool",
        "min_clearance": "length",
        "duration": "time",
        "path_deviation": "length",
        "joint_speed": "angular_speed",
        "contacts": "count",
    }

    kind: Literal["task"]
    units: Units = Units(length="m", angle="rad")
    robot: RobotRef = Field(default_factory=RobotRef)
    sample_rate: Positive = Field(1000.0, le=1e5, description="Samples per second, in [Hz].")
    timing: Timing = Field("auto", description="Default timing of every segment.")
    limits: LimitsEntry = Field(default_factory=LimitsEntry)
    obstacles: list[ObstacleEntry] = Field(default_factory=list, max_length=1000)
    waypoints: dict[str, WaypointEntry] = Field(min_length=1, max_length=10_000)
    segments: list[SegmentEntry] = Field(min_length=1, max_length=10_000)
    writing_plane: WritingPlaneEntry | None = None
    self_collision: bool = Field(False, description="Also check non-adjacent link pairs.")
    compare: bool = Field(True, description="Run the ruckig and toppra comparisons.")
    outputs: OutputsEntry = Field(default_factory=OutputsEntry)

    def si_inputs(self) -> dict[str, Any]:
        """Inputs in [m] and [rad] (limits in rad/s^n)."""
        length, angle = length_factor(self.units.length), angle_factor(self.units.angle)
        data = super().si_inputs()
        data["units"] = dict(SI_UNITS)
        for entry in data["obstacles"]:
            for key in ("min_corner", "centre", "size", "radius", "length"):
                entry[key] = scaled(entry.get(key), length)
            entry["rpy"] = scaled(entry.get("rpy"), angle)
        for entry in data["waypoints"].values():
            entry["q"] = scaled(entry["q"], angle)
            entry["q_reference"] = scaled(entry["q_reference"], angle)
            entry["position"] = scaled(entry["position"], length)
            entry["pose"] = scale_translation(entry["pose"], length)
        for key in ("velocity", "acceleration", "jerk"):
            data["limits"][key] = scaled(data["limits"][key], angle)
        if data["writing_plane"] is not None:
            plane = data["writing_plane"]
            plane.update(
                point=scaled(plane["point"], length),
                size=scaled(plane["size"], length),
                tilt=scaled(plane["tilt"], angle),
            )
        return data

    @model_validator(mode="after")
    def _route_names_exist(self) -> Self:
        from lynxplan.exceptions import ScenarioValueError
        from lynxplan.task.setup import route

        try:
            route(self)
        except ScenarioValueError as exc:
            raise located_error(exc.loc, exc.reason, exc.value) from None
        return self


Scenario = Input


def run(scenario: Input, *, quick: bool = False) -> KindOutput:
    """Resolve the scenario (IK of the waypoints, the plan), sample, check, compare (no files)."""
    from lynxplan.progress import progress_bar
    from lynxplan.task.report import summary, task_details, task_metrics, task_notes
    from lynxplan.task.run import execute
    from lynxplan.task.setup import resolve

    with progress_bar(f"task {scenario.name}".strip()) as progress:
        setup = resolve(scenario)
        result = execute(scenario, setup, progress, compare=scenario.compare and not quick)
        progress(5, 5)
    return KindOutput(
        task_metrics(result),
        summary(scenario, result),
        task_details(scenario, result),
        payload=result,
        stage_seconds=result.stage_seconds,
        notes=task_notes(result),
    )


def write_outputs(scenario: Input, output: KindOutput, out_dir: Path, *, quick: bool) -> list[str]:
    """``trajectory.csv`` and, unless quick, the plots and the meshcat HTML."""
    from lynxplan.scenarios.outputs import write_samples_csv
    from lynxplan.task.run import html_name

    result = output.payload
    samples = result.samples
    write_samples_csv(out_dir / "trajectory.csv", samples)
    written = ["trajectory.csv"]
    if quick:
        return written
    if scenario.outputs.plots:
        from lynxplan.scenarios.expect import parse_expectation
        from lynxplan.task.plots import write_plots

        required = None
        if "min_clearance" in scenario.expect:
            required = parse_expectation(
                "min_clearance", scenario.expect["min_clearance"], Input.metrics, scenario.units
            )
        written += write_plots(scenario, result, out_dir, required)
    if scenario.outputs.html:
        from lynxplan.task.html import write_html

        write_html(scenario, result, out_dir / html_name(scenario))
        written.append(html_name(scenario))
    return written
