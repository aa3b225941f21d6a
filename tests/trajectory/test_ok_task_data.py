"""The OK task's data has one home (trajectory/ok_task.py); the shipped scenario must agree."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml

from lynxplan.trajectory.ok_task import OK_TASK_WALLS, OK_TASK_WAYPOINTS, REPORT_TIMING

SCENARIO = Path(__file__).resolve().parents[2] / "scenarios" / "ok_task.yaml"


def _scenario() -> dict:
    return yaml.safe_load(SCENARIO.read_text())


def test_scenario_waypoints_and_route_are_the_module_table() -> None:
    data = _scenario()
    names = [name for name, _, _ in OK_TASK_WAYPOINTS]
    route = [data["segments"][0]["from"]] + [seg["to"] for seg in data["segments"]]
    assert route == names
    assert [seg["motion"] for seg in data["segments"]] == [k for _, _, k in OK_TASK_WAYPOINTS[:-1]]
    for name, q_deg, _ in OK_TASK_WAYPOINTS:
        np.testing.assert_array_equal(data["waypoints"][name]["q"], q_deg)


def test_scenario_walls_and_timing_are_the_module_table() -> None:
    data = _scenario()
    assert data["units"]["length"] == "in"
    walls = [(o["name"], tuple(o["min_corner"]), tuple(o["size"])) for o in data["obstacles"]]
    assert walls == [(n, tuple(c), tuple(s)) for n, c, s in OK_TASK_WALLS]
    assert (data["timing"]["tt"], data["timing"]["ta"]) == (REPORT_TIMING.tt, REPORT_TIMING.ta)
