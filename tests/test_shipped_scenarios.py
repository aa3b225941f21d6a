"""Every shipped scenario runs the way ``pytest scenarios/`` runs it, so examples never go stale."""

from __future__ import annotations

from pathlib import Path

import pytest

from lynxplan.pytest_plugin import check_scenario_file, is_scenario_file

SCENARIOS = sorted((Path(__file__).resolve().parents[1] / "scenarios").glob("*.yaml"))


def test_scenarios_are_shipped():
    assert "ok_task.yaml" in [path.name for path in SCENARIOS]
    assert all(is_scenario_file(path) for path in SCENARIOS)


@pytest.mark.parametrize("path", SCENARIOS, ids=[path.stem for path in SCENARIOS])
def test_shipped_scenario_expectations_hold(path):
    outcome = check_scenario_file(path)
    assert outcome.summary
