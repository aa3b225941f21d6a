"""The schema of a ``task`` scenario (waypoints, segments, obstacles, limits, outputs) and its
route; the file format with an example: :mod:`lynxplan.scenarios.task`."""

from __future__ import annotations

from typing import Annotated, Any, ClassVar, Literal

from pydantic import Discriminator, Field, Tag, model_validator
from typing_extensions import Self

from lynxplan.exceptions import ScenarioValueError
from lynxplan.scenarios.base import (
    SI_UNITS,
    Finite,
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
    scale_obstacles,
    scale_translation,
    scaled,
)
from lynxplan.trajectory.lspb import LspbTiming
from lynxplan.units import angle_factor, length_factor

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
        scale_obstacles(data["obstacles"], length, angle)
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
        try:
            route(self)
        except ScenarioValueError as exc:
            raise located_error(exc.loc, exc.reason, exc.value) from None
        return self


Scenario = Input


def route(scenario: Input) -> tuple[tuple[str, str], ...]:
    """The (from, to) waypoint names of every segment (``from`` defaults to the previous end).

    Raises:
        ScenarioValueError: an unknown waypoint name or a segment that does not chain.
    """
    names = list(scenario.waypoints)
    valid = ", ".join(names)
    route: list[tuple[str, str]] = []
    previous: str | None = None
    for i, entry in enumerate(scenario.segments):
        for key, value in (("from", entry.from_), ("to", entry.to)):
            if value is not None and value not in scenario.waypoints:
                raise ScenarioValueError(
                    ("segments", i, key), f"unknown waypoint {value!r}; waypoints: {valid}", value
                )
        start = entry.from_ if entry.from_ is not None else previous
        if start is None:
            raise ScenarioValueError(
                ("segments", 0, "from"), "the first segment needs a 'from' waypoint"
            )
        if previous is not None and start != previous:
            raise ScenarioValueError(
                ("segments", i, "from"),
                f"{start!r} but segment {i - 1} ends at {previous!r} (segments are chained)",
                start,
            )
        route.append((start, entry.to))
        previous = entry.to
    return tuple(route)
