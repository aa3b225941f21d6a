"""Every shipped scenario runs through the registry with its expectations holding, and writes a
report.json that is strict JSON and valid against the published schema (``lynxplan schema
report``), so examples never go stale and the contract holds for every kind."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest

from lynxplan.pytest_plugin import is_scenario_file
from lynxplan.scenarios import run_scenario
from lynxplan.scenarios.report import report_schema

SCENARIOS = sorted((Path(__file__).resolve().parents[1] / "scenarios").rglob("*.yaml"))


def _no_constants(name: str) -> None:
    raise ValueError(f"non-standard JSON constant {name}")


def test_scenarios_are_shipped():
    assert "ok_task.yaml" in [path.name for path in SCENARIOS]
    assert all(is_scenario_file(path) for path in SCENARIOS)


@pytest.mark.parametrize("path", SCENARIOS, ids=[path.stem for path in SCENARIOS])
def test_shipped_scenario_runs_and_its_report_follows_the_contract(path, tmp_path):
    out = tmp_path / "out"
    result = run_scenario(path, out, quick=True)
    assert result.ok, result.failed_expectations
    assert result.summary
    for file in out.rglob("*.json"):
        json.loads(file.read_text(), parse_constant=_no_constants)
    report = json.loads((out / "report.json").read_text(), parse_constant=_no_constants)
    jsonschema.validate(report, report_schema())
    assert report["kind"] == result.kind
    assert report["passed"] is True
    assert sorted(report["artifacts"]) == sorted(
        str(p.relative_to(out)) for p in out.rglob("*") if p.is_file() and p.name[0] != "."
    )
    assert [e["name"] for e in report["expectations"]] == [e.name for e in result.expectations]
    assert report["expectations"], "every shipped scenario states what it expects"
