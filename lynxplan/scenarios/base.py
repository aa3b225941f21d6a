"""The scenario contract: the input base model, a kind's output, and the frozen run result.

A scenario kind is one module of :mod:`lynxplan.scenarios` registered in
:data:`lynxplan.scenarios.registry.KIND_MODULES`. It defines

- ``Input``: a :class:`ScenarioModel` subclass (validation only, never computation) whose
  ``metrics`` class variable declares the metrics ``run`` measures and their quantities;
- ``run(scenario, *, quick) -> KindOutput``: the computation, pure (writes no file); ``quick``
  skips work no expectation needs (the comparisons with peer time laws);
- ``write_outputs(scenario, output, out_dir, *, quick) -> list[str]``: the artifacts (CSV, PNG,
  HTML) written into ``out_dir``, returned as paths relative to it.

The runner (:mod:`lynxplan.scenarios.runner`) evaluates the ``expect:`` block against the metrics
with one parser (:mod:`lynxplan.scenarios.expect`) and writes ``report.json``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any, ClassVar, Protocol

from pydantic import Field, model_validator

from lynxplan.scenarios.expect import ExpectationResult, parse_expectations
from lynxplan.scenarios.quantities import Quantity, StrictModel, Units

__all__ = [
    "SCHEMA_VERSION",
    "SI_UNITS",
    "ExpectationResult",
    "Finite",
    "KindOutput",
    "Matrix3",
    "Positive",
    "Quantity",
    "Result",
    "RobotRef",
    "ScenarioKind",
    "ScenarioModel",
    "StrictModel",
    "TargetEntry",
    "Units",
    "Vector3",
    "check_target_form",
    "located_error",
    "scale_translation",
    "scaled",
]

#: Version of the ``report.json`` layout (:class:`Result`); bumped on incompatible changes.
SCHEMA_VERSION = 1

#: Field types shared by the kinds' input models.
Finite = Annotated[float, Field(allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
Vector3 = Annotated[list[Finite], Field(min_length=3, max_length=3)]
Matrix3 = Annotated[list[Vector3], Field(min_length=3, max_length=3)]


def located_error(loc: tuple[int | str, ...], message: str, value: Any = None) -> Exception:
    """A pydantic ValidationError at key path ``loc`` (raised from a model validator)."""
    from pydantic import ValidationError
    from pydantic_core import InitErrorDetails, PydanticCustomError

    error = PydanticCustomError("scenario", message.replace("{", "{{").replace("}", "}}"))
    return ValidationError.from_exception_data(
        "scenario", [InitErrorDetails(type=error, loc=loc, input=value)]
    )


def check_target_form(entry: Any) -> None:
    """A waypoint or goal gives exactly one of ``q``, ``pose`` (3 or 4 rows of 4) or
    ``position`` + ``approach`` (non-zero); ValueError naming what is wrong otherwise."""
    given = [name for name in ("q", "pose", "position") if getattr(entry, name) is not None]
    if len(given) != 1:
        raise ValueError(f"give exactly one of q, pose, position (got: {given or 'none'})")
    if (entry.position is None) != (entry.approach is None):
        raise ValueError("position and approach go together")
    if entry.approach is not None and not any(entry.approach):
        raise ValueError("approach must not be the zero vector")
    if entry.pose is not None:
        if any(len(row) != 4 for row in entry.pose):
            raise ValueError("pose rows must have 4 values")
        if len(entry.pose) == 4 and entry.pose[3] != [0, 0, 0, 1]:
            raise ValueError("the 4th pose row must be [0, 0, 0, 1]")


class RobotRef(StrictModel):
    """Which robot: a built-in name, or a URDF file with its tool frame."""

    name: str | None = Field(None, description="Built-in robot name (default: al5).")
    urdf: str | None = Field(None, description="URDF path (relative to the working directory).")
    tool: str | None = Field(None, description="Tool frame name of the URDF.")

    @model_validator(mode="after")
    def _name_or_urdf(self) -> RobotRef:
        if self.name is not None and self.urdf is not None:
            raise ValueError("give name or urdf, not both")
        if self.tool is not None and self.urdf is None and self.name is None:
            raise ValueError("tool needs name or urdf")
        return self


class TargetEntry(StrictModel):
    """A target of the arm: joint angles, a 4x4 tool pose, or a tool point with an approach
    direction (exactly one form; see :func:`check_target_form`)."""

    q: Annotated[list[Finite], Field(min_length=1, max_length=12)] | None = Field(
        None, description="Joint angles, in the file's angle unit."
    )
    pose: Annotated[list[list[Finite]], Field(min_length=3, max_length=4)] | None = Field(
        None, description="Tool pose: 3 or 4 rows of 4 (translation in the file's length unit)."
    )
    position: Vector3 | None = Field(None, description="Tool point (with approach).")
    approach: Vector3 | None = Field(None, description="Tool approach axis (z) direction.")

    @model_validator(mode="after")
    def _one_form(self) -> TargetEntry:
        check_target_form(self)
        return self


class ScenarioModel(StrictModel):
    """Base of every kind's input model.

    Class variables:
        metrics: Metric name -> quantity, for every metric the kind's ``run`` reports. The
            ``expect:`` block may only name these (``name``, or ``max_name`` / ``min_name``).
        default_expect: Expectations checked even when the file does not name them.
    """

    metrics: ClassVar[Mapping[str, Quantity]] = {}
    default_expect: ClassVar[Mapping[str, Any]] = {}

    kind: str
    name: str = Field("", description="Free-form name, used in summaries and file names.")
    description: str = ""
    units: Units = Field(default_factory=Units)
    expect: dict[str, Any] = Field(
        default_factory=dict,
        description="Checks on the metrics: true/false, '<op> <number> [unit]', a bare number "
        "for max_*/min_* keys, a list of names (each flag true), or {equals, tolerance}.",
    )

    @model_validator(mode="after")
    def _expectations_parse(self) -> ScenarioModel:
        parse_expectations(self.expect, type(self).metrics, self.units)
        return self

    def si_inputs(self) -> dict[str, Any]:
        """The inputs echoed in ``report.json``, normalised to SI (m, rad, s).

        The default echoes the file's values with its ``units``; kinds whose inputs carry
        lengths or angles override it.
        """
        return self.model_dump(mode="json", by_alias=True, exclude={"expect"})


def scaled(value: Any, factor: float) -> Any:
    """``value`` (a number or nested lists of numbers; None passes) times ``factor``."""
    if value is None or isinstance(value, bool):
        return value
    if isinstance(value, (list, tuple)):
        return [scaled(v, factor) for v in value]
    if isinstance(value, (int, float)):
        return value * factor
    return value


def scale_obstacles(entries: list[dict[str, Any]], length: float, angle: float) -> None:
    """Obstacle entries (dumped ``ObstacleEntry`` mappings) to [m] and [rad], in place: their
    lengths times ``length``, their ``rpy`` times ``angle`` (the factors to SI)."""
    for entry in entries:
        for key in ("min_corner", "centre", "size", "radius", "length"):
            entry[key] = scaled(entry.get(key), length)
        entry["rpy"] = scaled(entry.get("rpy"), angle)


def scale_translation(pose: Any, factor: float) -> Any:
    """Rows of a 3x4 / 4x4 pose with the translation column times ``factor``."""
    if pose is None:
        return None
    return [[*row[:3], row[3] * factor] if i < 3 else list(row) for i, row in enumerate(pose)]


SI_UNITS = {"length": "m", "angle": "rad"}


@dataclass(frozen=True)
class KindOutput:
    """What a kind's ``run`` computed.

    Attributes:
        metrics: Metric name -> value in SI units (float, bool, int, a list of floats, or for
            ``flags`` a mapping name -> bool). Names must be declared in ``Input.metrics``.
        summary: One paragraph for stdout.
        details: Kind-specific tables for ``report.json`` (JSON-able, SI units).
        payload: In-memory results ``write_outputs`` needs (not serialised).
        stage_seconds: Wall time of each stage of the run, in [s].
        notes: Metric name -> a line explaining its value (appended to a failed expectation's
            message, e.g. where the first contact happened).
    """

    metrics: Mapping[str, Any]
    summary: str
    details: Mapping[str, Any] = field(default_factory=dict)
    payload: Any = None
    stage_seconds: Mapping[str, float] = field(default_factory=dict)
    notes: Mapping[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class Result:
    """The result of one scenario run: what ``report.json`` holds.

    Attributes:
        kind: The scenario kind.
        schema_version: :data:`SCHEMA_VERSION`.
        name: The scenario's name.
        inputs: The scenario echoed, normalised to SI.
        metrics: Measured values, SI units.
        expectations: Each ``expect:`` entry, checked.
        artifacts: Files written next to ``report.json``, relative paths.
        timing: Wall time of each stage and in total, in [s].
        details: Kind-specific tables (SI units).
        summary: One paragraph for stdout.
        units: The scenario's own units (its ``units:`` block, e.g. ``{"length": "in",
            "angle": "deg"}``); the metrics stay SI, :meth:`metric` and :meth:`metrics_in`
            convert.
        metric_quantities: Metric name -> its quantity (``length``, ``volume``, ``bool``...).

    Reading a metric in the scenario's units: ``result.metric("min_clearance",
    units="scenario")`` (e.g. inches for an inch file), or in any unit of its quantity:
    ``result.metric("min_clearance", units="mm")``; every metric at once:
    ``result.metrics_in("scenario")``; the unit a value is in: ``result.unit_of(name)``.
    """

    kind: str
    schema_version: int
    name: str
    inputs: Mapping[str, Any]
    metrics: Mapping[str, Any]
    expectations: tuple[ExpectationResult, ...]
    artifacts: tuple[str, ...]
    timing: Mapping[str, float]
    details: Mapping[str, Any]
    summary: str
    units: Mapping[str, str] = field(default_factory=lambda: dict(SI_UNITS))
    metric_quantities: Mapping[str, str] = field(default_factory=dict)

    def unit_of(self, name: str, units: str = "scenario") -> str:
        """The unit :meth:`metric` gives ``name`` in: ``units`` is ``"si"``, ``"scenario"`` or
        a unit of the metric's quantity (returned as is once checked); "" for a number without
        a unit (counts, ratios, booleans).

        Raises:
            InputError: an unknown metric (naming the valid ones) or a unit that is not one of
                the metric's quantity (naming the valid ones).
        """
        from lynxplan.exceptions import InputError
        from lynxplan.scenarios.quantities import QUANTITY_UNITS, default_unit

        if name not in self.metrics:
            raise InputError(
                f"metric {name!r}: not a metric of this {self.kind} run; valid: "
                + ", ".join(sorted(self.metrics))
            )
        quantity = self.metric_quantities.get(name, "")
        table = QUANTITY_UNITS.get(quantity, {"": 1.0})
        if units in ("si", "scenario"):
            frame = Units(**self.units) if units == "scenario" else Units(length="m", angle="rad")
            return default_unit(quantity, frame)
        if units not in table:
            valid = ", ".join(repr(u) for u in ("si", "scenario", *table) if u)
            raise InputError(
                f"metric {name!r} ({quantity or 'no unit'}): unknown unit {units!r}; valid: {valid}"
            )
        return units

    def metric(self, name: str, units: str = "si") -> Any:
        """A metric's value in ``units``.

        Args:
            name: The metric (a key of :attr:`metrics`).
            units: ``"si"`` (m, rad, s: the value in :attr:`metrics`), ``"scenario"`` (the
                scenario's ``units:`` block: ``in`` for a length of an inch file, ``in^3`` for
                a volume, ``deg/s`` for an angular speed; seconds for times) or a unit of the
                metric's quantity (``"mm"``, ``"deg"``, ``"in^3"``, ``"ms"``...).

        Returns:
            The value (a number, or nested lists for array metrics) in that unit; booleans,
            counts, flags and unmeasured values (None, NaN) as they are.

        Raises:
            InputError: an unknown metric or unit (see :meth:`unit_of`).
        """
        from lynxplan.scenarios.quantities import QUANTITY_UNITS

        unit = self.unit_of(name, units)
        factor = QUANTITY_UNITS.get(self.metric_quantities.get(name, ""), {}).get(unit, 1.0)
        return _divided(self.metrics[name], factor)

    def metrics_in(self, units: str = "scenario") -> dict[str, Any]:
        """Every metric in ``units`` (``"si"`` or ``"scenario"``; see :meth:`metric`)."""
        if units not in ("si", "scenario"):
            from lynxplan.exceptions import InputError

            raise InputError(f"metrics_in: units must be 'si' or 'scenario'. Got: {units!r}")
        return {name: self.metric(name, units) for name in self.metrics}

    @property
    def ok(self) -> bool:
        """True when every expectation held."""
        return all(e.passed for e in self.expectations)

    @property
    def failed_expectations(self) -> tuple[str, ...]:
        """Messages of the expectations that did not hold."""
        return tuple(e.message for e in self.expectations if not e.passed)


def _divided(value: Any, factor: float) -> Any:
    """``value`` (a number or nested lists/tuples of numbers) divided by ``factor``; booleans,
    None, mappings and strings pass unchanged."""
    if factor == 1.0 or value is None or isinstance(value, (bool, str, Mapping)):
        return value
    if isinstance(value, (list, tuple)):
        return [_divided(v, factor) for v in value]
    if hasattr(value, "tolist"):  # a numpy array or scalar
        return _divided(value.tolist(), factor)
    if isinstance(value, (int, float)):
        return value / factor
    return value


class ScenarioKind(Protocol):
    """Interface of a scenario-kind module."""

    NAME: str
    Input: type[ScenarioModel]

    def run(self, scenario: Any, *, quick: bool = False) -> KindOutput: ...

    def write_outputs(
        self, scenario: Any, output: KindOutput, out_dir: Path, *, quick: bool
    ) -> list[str]: ...
