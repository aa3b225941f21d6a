"""Metrics that cannot mislead (issue 34, section 4): ``min_clearance`` is one quantity,
reported the same in the metrics, the summary, the details and computed over the samples of
``trajectory.csv``; a result reads its metrics in the scenario's units."""

from __future__ import annotations

import json
import re
from pathlib import Path

import jsonschema
import numpy as np
import pytest
import yaml

import lynxplan
from lynxplan.exceptions import InputError
from lynxplan.scenarios.report import MIN_CLEARANCE_DEFINITION, report_schema

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
INCH = 0.0254  # [m], by definition


def _in_inches(source: Path) -> dict[str, object]:
    """A metre plan scenario rewritten with every length in inches."""
    data = yaml.safe_load(source.read_text())
    data["units"] = {**data["units"], "length": "in"}
    for obstacle in data["obstacles"]:
        for key in ("centre", "size", "min_corner"):
            if key in obstacle:
                obstacle[key] = [v / INCH for v in obstacle[key]]
    data["expect"] = {"solved": True, "min_clearance": ">= 0.08 in"}
    return data


@pytest.fixture(scope="module")
def window_in_inches(tmp_path_factory: pytest.TempPathFactory) -> tuple[object, Path]:
    out = tmp_path_factory.mktemp("window") / "out"
    scenario = _in_inches(SCENARIOS / "planning" / "p04_window.yaml")
    return lynxplan.run_scenario(scenario, out, quick=True), out


def test_min_clearance_is_one_quantity_everywhere(window_in_inches: tuple[object, Path]) -> None:
    result, out = window_in_inches
    metric = result.metrics["min_clearance"]  # type: ignore[attr-defined]
    details = result.details["min_clearance"]  # type: ignore[attr-defined]
    assert details["clearance"] == metric
    shown = re.search(
        r"min clearance ([0-9.]+) in \((\S+) to (\S+) at t = ([0-9.]+) s\)", result.summary
    )  # type: ignore[attr-defined]
    assert shown is not None, result.summary  # type: ignore[attr-defined]
    assert float(shown[1]) == pytest.approx(metric / INCH, rel=1e-3)
    assert (shown[2], shown[3]) == (details["link"], details["obstacle"])
    # independent of the run's own arrays: the exact distances at the rows of trajectory.csv
    from lynxplan.planning import Planner
    from lynxplan.planning.verify import sample_clearances
    from lynxplan.scenarios.plan import Input, plan_inputs

    rows = np.loadtxt(out / "trajectory.csv", delimiter=",", skiprows=1)
    scenario = Input.model_validate(_in_inches(SCENARIOS / "planning" / "p04_window.yaml"))
    inputs = plan_inputs(scenario)
    world = Planner(inputs.robot, inputs.obstacles, inputs.options).world
    nq = inputs.start.shape[0]
    distances = sample_clearances(world, rows[:, 1 : 1 + nq])
    worst = int(np.argmin(distances))
    assert float(distances[worst]) == pytest.approx(metric, rel=1e-6, abs=1e-9)
    assert rows[worst, 0] == pytest.approx(details["time"], abs=1e-6)


def test_report_defines_min_clearance_and_carries_the_units(
    window_in_inches: tuple[object, Path],
) -> None:
    _, out = window_in_inches
    report = json.loads((out / "report.json").read_text())
    schema = report_schema()
    jsonschema.validate(report, schema)
    assert report["units"] == {"length": "in", "angle": "deg"}
    assert report["metric_quantities"]["min_clearance"] == "length"
    metrics = schema["$defs"][schema["properties"]["metrics"]["$ref"].rsplit("/", 1)[1]]
    assert metrics["properties"]["min_clearance"]["description"] == MIN_CLEARANCE_DEFINITION


def test_a_metric_in_the_scenario_units(window_in_inches: tuple[object, Path]) -> None:
    result: object = window_in_inches[0]
    si = result.metrics["min_clearance"]  # type: ignore[attr-defined]
    assert result.metric("min_clearance") == si  # type: ignore[attr-defined]
    assert result.metric("min_clearance", units="scenario") == pytest.approx(si / INCH, rel=1e-15)  # type: ignore[attr-defined]
    assert result.metric("min_clearance", units="mm") == pytest.approx(si * 1e3, rel=1e-15)  # type: ignore[attr-defined]
    assert result.unit_of("min_clearance") == "in"  # type: ignore[attr-defined]
    assert result.metric("path_length", units="scenario") == pytest.approx(  # type: ignore[attr-defined]
        np.degrees(result.metrics["path_length"]),
        rel=1e-12,  # type: ignore[attr-defined]
    )
    assert result.metric("solved", units="scenario") is True  # type: ignore[attr-defined]
    converted = result.metrics_in("scenario")  # type: ignore[attr-defined]
    assert converted["duration"] == result.metrics["duration"]  # seconds either way  # type: ignore[attr-defined]
    with pytest.raises(InputError, match=r"unknown unit 'deg'; valid: 'si', 'scenario', 'm'"):
        result.metric("min_clearance", units="deg")  # type: ignore[attr-defined]
    with pytest.raises(InputError, match="'clearance': not a metric of this plan run; valid: "):
        result.metric("clearance")  # type: ignore[attr-defined]


def test_workspace_volume_in_the_scenario_units() -> None:
    result = lynxplan.run_scenario(
        {"kind": "workspace", "samples": 20000, "cell": 0.4, "units": {"length": "in"}}
    )
    assert result.unit_of("volume") == "in^3"
    assert result.metric("volume", "scenario") == pytest.approx(
        result.metrics["volume"] / INCH**3, rel=1e-12
    )
    assert result.metric("reach", "scenario") == pytest.approx(
        result.metrics["reach"] / INCH, rel=1e-12
    )
