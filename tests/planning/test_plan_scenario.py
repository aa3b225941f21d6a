"""Scenario kind ``plan``: outputs of a solved run, an unsolvable run, bad starts as errors."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from lynxplan.exceptions import ScenarioError
from lynxplan.scenarios import load_scenario, run_scenario

WALL = {"name": "wall", "type": "box", "centre": [0.0, 0.285, 0.18], "size": [0.02, 0.33, 0.54]}


def _scenario(**changes: object) -> dict[str, object]:
    scenario: dict[str, object] = {
        "kind": "plan",
        "name": "wall test",
        "units": {"length": "mm", "angle": "deg"},
        "obstacles": [
            {**WALL, "centre": [0.0, 285.0, 180.0], "size": [20.0, 330.0, 540.0]},
        ],
        "start": [45, 30, -30, 60, 0],
        "goal": {"q": [135, 30, -30, 60, 0]},
        "planner": {"seed": 4, "clearance": 3.0, "time_limit": 30.0},  # solves in ms; the
        # budget only covers a cold process (numba compilation) on a loaded machine
        "expect": {"solved": True, "collision_free": True, "min_clearance": ">= 3 mm"},
    }
    scenario.update(changes)
    return scenario


def test_solved_run_writes_csv_plot_and_html(tmp_path: Path) -> None:
    result = run_scenario(_scenario(), tmp_path / "out")
    assert result.ok, result.failed_expectations
    assert set(result.artifacts) == {
        "report.json",
        "trajectory.csv",
        "clearance.png",
        "wall_test.html",
    }
    table = np.loadtxt(tmp_path / "out" / "trajectory.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(np.degrees(table[0, 1:6]), [45, 30, -30, 60, 0], atol=1e-9)
    np.testing.assert_allclose(np.degrees(table[-1, 1:6]), [135, 30, -30, 60, 0], atol=1e-9)
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["metrics"]["min_clearance"] >= 0.003
    assert report["inputs"]["planner"]["clearance"] == pytest.approx(0.003)


def test_unsolvable_run_reports_solved_false(tmp_path: Path) -> None:
    suite = Path(__file__).resolve().parents[2] / "scenarios" / "planning"
    result = run_scenario(suite / "u01_goal_in_jar.yaml", tmp_path / "out")
    assert result.ok
    assert result.metrics["solved"] is False
    assert result.metrics["nodes"] > 10
    assert result.artifacts == ("report.json",)


def test_start_in_collision_is_an_error_naming_the_obstacle(tmp_path: Path) -> None:
    # The gripper and the wrist both pass through the 25 mm wall (equal depths): either is named.
    with pytest.raises(ScenarioError, match=r"in collision: link (gripper|wrist) with wall, pen"):
        run_scenario(_scenario(start=[90, 30, -30, 60, 0]), tmp_path / "out")


def test_goal_needs_exactly_one_form() -> None:
    with pytest.raises(Exception, match="give exactly one of q, pose, position"):
        load_scenario(_scenario(goal={"q": [0, 0, 0, 0, 0], "position": [0, 0, 0]}))


def test_planner_block_sets_the_shortcut_patience() -> None:
    from lynxplan.scenarios.plan import planner_options

    scenario = load_scenario(_scenario(planner={"seed": 1, "shortcut_patience": 3}))
    assert planner_options(scenario.scenario).shortcut_patience == 3
    with pytest.raises(ScenarioError, match="shortcut_patience"):
        load_scenario(_scenario(planner={"shortcut_patience": 0}))
