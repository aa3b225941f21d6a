"""``report.json``: the one JSON writer, and the published JSON Schema of a run's report.

JSON has no NaN or infinity. The rule, applied here and nowhere else: a non-finite number is
written as ``null`` (a metric that could not be measured, e.g. the clearance of a world without
obstacles). Every file lynxplan writes as JSON goes through :func:`dumps`, so strict parsers
(``json.loads(text, parse_constant=...)`` raising) read all of them.
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from lynxplan.scenarios.base import SCHEMA_VERSION, ExpectationResult, Result


def to_jsonable(value: Any) -> Any:
    """``value`` as plain JSON types: numpy arrays and scalars, tuples, dataclasses, mappings.

    Non-finite floats become None (see the module docstring).
    """
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        number = float(value)
        return number if math.isfinite(number) else None
    if isinstance(value, np.ndarray):
        return to_jsonable(value.tolist())
    if isinstance(value, Mapping):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: to_jsonable(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if hasattr(value, "_asdict"):
        return to_jsonable(value._asdict())
    if isinstance(value, (list, tuple, set, frozenset)):
        return [to_jsonable(v) for v in value]
    if isinstance(value, Path):
        return str(value)
    return value


def dumps(value: Any) -> str:
    """Strict JSON text of ``value`` (indented, NaN/infinity as null, trailing newline)."""
    return json.dumps(to_jsonable(value), indent=2, allow_nan=False) + "\n"


def write_json(path: Path, value: Any) -> None:
    """Write ``value`` as strict JSON to ``path``."""
    path.write_text(dumps(value), encoding="utf-8")


def result_dict(result: Result) -> dict[str, Any]:
    """``report.json`` content of a result (the summary is for stdout, not the report)."""
    data = to_jsonable(result)
    data.pop("summary", None)
    data["passed"] = result.ok
    return data  # type: ignore[no-any-return]


class _ExpectationModel(BaseModel):
    model_config = ConfigDict(extra="forbid")

    name: str = Field(description="The key as written in expect:.")
    wanted: Any = Field(description="The expectation as written, e.g. '>= 0.2 in'.")
    got: Any = Field(description="The measured value, SI units (null: not measurable).")
    passed: bool
    message: str


#: What ``min_clearance`` is, for every kind that reports it (``task``, ``plan``): one quantity,
#: computed once per run, the same in the metrics, the summary, ``details.min_clearance`` and
#: the plots.
MIN_CLEARANCE_DEFINITION = (
    "Smallest exact distance (coal) between the robot's collision geometry and the obstacles "
    "(and the robot's own links, for self pairs) over every sample of the run's trajectory (the "
    "rows of trajectory.csv), in [m]; negative for a penetration; null when there is nothing "
    "to collide with. details.min_clearance names the link, the obstacle and the time of that "
    "sample."
)


class _MetricsModel(BaseModel):
    """Measured values in SI units (m, rad, s); null where not measurable. The scenario's own
    units are in ``units``, each metric's quantity in ``metric_quantities``."""

    model_config = ConfigDict(extra="allow", title="Metrics")

    min_clearance: float | None = Field(None, description=MIN_CLEARANCE_DEFINITION)


class ReportModel(BaseModel):
    """Layout of ``report.json`` (published by ``lynxplan schema report``)."""

    model_config = ConfigDict(extra="forbid", title="lynxplan report")

    kind: str = Field(description="Scenario kind.")
    schema_version: int = Field(ge=1, le=SCHEMA_VERSION, description="Version of this layout.")
    name: str = Field(description="Scenario name.")
    inputs: dict[str, Any] = Field(description="The scenario echoed, normalised to SI units.")
    metrics: _MetricsModel = Field(
        description="Measured values in SI units (m, rad, s); null where not measurable."
    )
    expectations: list[_ExpectationModel]
    artifacts: list[str] = Field(description="Files written next to report.json (relative).")
    timing: dict[str, float] = Field(description="Wall time of each stage and 'total', in [s].")
    details: dict[str, Any] = Field(description="Kind-specific tables, SI units.")
    passed: bool = Field(description="Every expectation held.")
    units: dict[str, str] = Field(
        default_factory=lambda: {"length": "m", "angle": "rad"},
        description="The scenario's own units (its units: block). Inputs, metrics and details "
        "are SI regardless; lynxplan.Result.metric(name, units='scenario') converts.",
    )
    metric_quantities: dict[str, str] = Field(
        default_factory=dict,
        description="Metric name -> its quantity (length, angle, time, volume, bool, ...): "
        "the SI unit of each metric.",
    )


def report_schema() -> dict[str, Any]:
    """The JSON Schema of ``report.json``."""
    return ReportModel.model_json_schema()


__all__ = [
    "MIN_CLEARANCE_DEFINITION",
    "ExpectationResult",
    "ReportModel",
    "dumps",
    "report_schema",
    "result_dict",
    "to_jsonable",
    "write_json",
]
