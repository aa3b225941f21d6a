"""Scenario kind ``task``: the schema of an arm task (waypoints, segments, obstacles, expectations).

Example (``scenarios/ok_task.yaml`` is the full SPEC Part 3 task)::

    kind: task
    name: pick and place
    units: {length: in, angle: deg}          # lengths in|mm|m, angles deg|rad
    robot: {}                                # the shipped AL5 URDF; or {urdf: path/to.urdf}
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
    writing_plane: {point: [0.5, 10.3, 1.26], tilt: 20, size: [10, 8]}   # drawn only
    outputs: {plots: true, html: true}
    expect:
      collision_free: true            # no contact at any sample nor between samples
      within_limits: true             # position, velocity and acceleration limits, every sample
      min_clearance: ">= 0.2 in"      # comparator, number, unit (default: the file's unit)
      max_duration: "<= 30 s"

Robots: task scenarios plan with the AL5's analytic IK, so the robot must have the AL5's joint
structure (the shipped URDF or a variant with other link lengths or collision shapes). A robot of
another structure (``example_robot_data: <name>``, or another URDF) is loaded and rejected with a
message saying so; use it with :mod:`lynxplan.viz` and :mod:`lynxplan.collision` directly.

Relative URDF paths are resolved from the current working directory.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import Discriminator, Field, PrivateAttr, Tag, field_validator, model_validator
from typing_extensions import Self

from lynxplan.scenario import StrictModel, Units
from lynxplan.task.expect import parse_comparison
from lynxplan.trajectory.lspb import LspbTiming

Finite = Annotated[float, Field(allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
Vector3 = Annotated[list[Finite], Field(min_length=3, max_length=3)]
Matrix3 = Annotated[list[Vector3], Field(min_length=3, max_length=3)]
PerJoint = Positive | Annotated[list[Positive], Field(min_length=5, max_length=5)]


class RobotEntry(StrictModel):
    """Which robot: the shipped AL5 URDF (default), another URDF, or example-robot-data."""

    urdf: str | None = Field(None, description="URDF path (relative to the working directory).")
    example_robot_data: str | None = Field(
        None, description="Robot name in example-robot-data (loaded; rejected unless AL5-like)."
    )

    @model_validator(mode="after")
    def _at_most_one(self) -> Self:
        if self.urdf is not None and self.example_robot_data is not None:
            raise ValueError("give urdf or example_robot_data, not both")
        return self


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


class WaypointEntry(StrictModel):
    """A waypoint: joint angles, a 4x4 pose, or a position with an approach direction."""

    q: Annotated[list[Finite], Field(min_length=5, max_length=5)] | None = Field(
        None, description="Joint angles q1..q5, in the file's angle unit."
    )
    pose: Annotated[list[list[Finite]], Field(min_length=3, max_length=4)] | None = Field(
        None, description="Tool pose: 3 or 4 rows of 4 (translation in the file's length unit)."
    )
    position: Vector3 | None = Field(None, description="Tool point (with approach).")
    approach: Vector3 | None = Field(None, description="Tool approach axis (z) direction.")
    ik: Literal["report", "nearest"] = Field(
        "report",
        description="IK branch: the report's rule (first within limits with q2 >= 0, q3 <= 0) "
        "or the one nearest to q_reference.",
    )
    q_reference: Annotated[list[Finite], Field(min_length=5, max_length=5)] | None = Field(
        None, description="For ik: nearest and for q5 of a position + approach target."
    )

    @model_validator(mode="after")
    def _one_form(self) -> Self:
        given = [name for name in ("q", "pose", "position") if getattr(self, name) is not None]
        if len(given) != 1:
            raise ValueError(f"give exactly one of q, pose, position (got: {given or 'none'})")
        if (self.position is None) != (self.approach is None):
            raise ValueError("position and approach go together")
        if self.approach is not None and not any(self.approach):
            raise ValueError("approach must not be the zero vector")
        if self.pose is not None:
            if any(len(row) != 4 for row in self.pose):
                raise ValueError("pose rows must have 4 values")
            if len(self.pose) == 4 and self.pose[3] != [0, 0, 0, 1]:
                raise ValueError("the 4th pose row must be [0, 0, 0, 1]")
        return self


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
    motion: Literal["free", "line"] = Field(description="Joint-space or Cartesian straight line.")
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


Expectation = str | Finite


def _checked(value: Expectation | None, quantity: str, default_op: str | None) -> Any:
    if value is not None:
        unit = {"length": "m", "time": "s", "angular_speed": "rad/s", "count": ""}[quantity]
        parse_comparison(value, quantity, unit, default_op)
    return value


class Expect(StrictModel):
    """What the run must measure. Comparisons are ``"<op> <number> [unit]"`` strings."""

    collision_free: bool | None = Field(
        None, description="No contact at any sample nor between samples (certified)."
    )
    within_limits: bool | None = Field(
        None, description="Position, velocity and acceleration limits hold on every sample."
    )
    min_clearance: Expectation | None = Field(
        None, description="Overall minimum clearance, e.g. '>= 0.2 in' (bare number: >=)."
    )
    max_duration: Expectation | None = Field(None, description="Planned duration (bare: <=).")
    max_path_deviation: Expectation | None = Field(
        None, description="Largest tool deviation from a straight line (bare number: <=)."
    )
    max_joint_speed: Expectation | None = Field(
        None, description="Peak |qd| over joints, e.g. '<= 90 deg/s' (bare number: <=)."
    )
    contacts: Expectation | None = Field(None, description="Number of contacts, e.g. '== 0'.")

    @field_validator("min_clearance")
    @classmethod
    def _length_min(cls, value: Expectation | None) -> Any:
        return _checked(value, "length", ">=")

    @field_validator("max_path_deviation")
    @classmethod
    def _length_max(cls, value: Expectation | None) -> Any:
        return _checked(value, "length", "<=")

    @field_validator("max_duration")
    @classmethod
    def _time(cls, value: Expectation | None) -> Any:
        return _checked(value, "time", "<=")

    @field_validator("max_joint_speed")
    @classmethod
    def _speed(cls, value: Expectation | None) -> Any:
        return _checked(value, "angular_speed", "<=")

    @field_validator("contacts")
    @classmethod
    def _count(cls, value: Expectation | None) -> Any:
        return _checked(value, "count", "<=")


class Scenario(StrictModel):
    """A ``task`` scenario: an arm moving through named waypoints among obstacles."""

    kind: Literal["task"]
    name: str = ""
    description: str = ""
    units: Units = Units(length="m", angle="rad")
    robot: RobotEntry = Field(default_factory=RobotEntry)
    sample_rate: Positive = Field(1000.0, le=1e5, description="Samples per second, in [Hz].")
    timing: Timing = Field("auto", description="Default timing of every segment.")
    limits: LimitsEntry = Field(default_factory=LimitsEntry)
    obstacles: list[ObstacleEntry] = Field(default_factory=list)
    waypoints: dict[str, WaypointEntry] = Field(min_length=1)
    segments: list[SegmentEntry] = Field(min_length=1)
    writing_plane: WritingPlaneEntry | None = None
    self_collision: bool = Field(False, description="Also check non-adjacent link pairs.")
    compare: bool = Field(True, description="Run the ruckig and toppra comparisons.")
    outputs: OutputsEntry = Field(default_factory=OutputsEntry)
    expect: Expect = Field(default_factory=Expect)

    _setup: Any = PrivateAttr(default=None)

    @classmethod
    def model_validate(cls, obj: Any, **kwargs: Any) -> Self:
        """Validate the schema, then resolve it: robot, obstacles, waypoints (IK), the plan.

        Problems found while resolving (unknown waypoint names, unreachable waypoints, a line
        leaving the reach, a non-AL5 robot) are raised as a ``ValidationError`` located at their
        key path, like schema errors.
        """
        scenario = super().model_validate(obj, **kwargs)
        from lynxplan.task.setup import resolve

        scenario._setup = resolve(scenario)
        return scenario
