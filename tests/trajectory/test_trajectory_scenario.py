"""Scenario kind ``trajectory``: the shipped files, outputs, expectations and errors."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from lynxplan.cli import main
from lynxplan.exceptions import PathNotFollowableError, ScenarioError
from lynxplan.scenarios import run_scenario

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
SHIPPED = ["free_motion.yaml", "straight_line.yaml"]


@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_scenarios_run_and_hold_their_expectations(name: str) -> None:
    outcome = run_scenario(SCENARIOS / name)  # not quick: with the ruckig/toppra comparison
    assert outcome.ok, outcome.failed_expectations
    segment = outcome.details["segments"][0]
    assert segment["tt"] == 3.0 and segment["ta"] == 1.0
    assert segment["limit_violation_samples"] == 0
    assert {"lspb", "lspb_auto", "toppra"} <= set(segment["comparison"])
    assert outcome.details["plan_comparison"]["lspb"]["total_duration_s"] == pytest.approx(3.0)


def test_quick_runs_skip_the_comparison_and_keep_the_metrics(tmp_path: Path) -> None:
    full = run_scenario(SCENARIOS / "straight_line.yaml")
    quick = run_scenario(SCENARIOS / "straight_line.yaml", tmp_path, quick=True)
    assert quick.metrics == full.metrics
    report = json.loads((tmp_path / "report.json").read_text())
    assert "comparison" not in report["details"]["segments"][0]
    assert "plan_comparison" not in report["details"]


def test_free_motion_report_matches_the_lspb_formulas() -> None:
    stats = run_scenario(SCENARIOS / "free_motion.yaml").details["segments"][0]["comparison"]
    # dA / T with T = tt - ta = 2 s and dA / (T ta) for the report's example.
    delta = [1.2, 0.9, 0.68, 1.0, 0.0]
    assert stats["lspb"]["peak_velocity_rad_s"] == pytest.approx([d / 2 for d in delta], abs=1e-9)
    assert stats["lspb"]["peak_acceleration_rad_s2"] == pytest.approx(
        [d / 2 for d in delta], abs=1e-9
    )
    assert stats["ruckig_lspb_duration"]["duration_s"] == pytest.approx(3.0)
    assert stats["ruckig"]["violations"] == []


def test_plots_are_written_unless_quick(tmp_path: Path) -> None:
    outcome = run_scenario(SCENARIOS / "straight_line.yaml", tmp_path)
    assert outcome.ok
    for png in ("joint_profiles.png", "tool_xyz.png", "durations.png"):
        assert (tmp_path / png).stat().st_size > 10_000, png


def _write(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "scenario.yaml"
    path.write_text("kind: trajectory\nstart: [0.0, 0.3, -0.5, 1.0, 0.2]\n" + body)
    return path


def test_failed_expectations_are_listed(tmp_path: Path) -> None:
    # The letter O's first stroke with a full-SO(3) slerp: the roll dips below its 0 deg limit.
    path = tmp_path / "o1_o2.yaml"
    path.write_text(
        "kind: trajectory\nunits: {angle: deg}\nstart: [104, 57, -59, 40, 0]\ncompare: false\n"
        "segments:\n  - {motion: line, to_q: [109, 79, -93, 25, 0], orientation: slerp,"
        " tt: 2, ta: 0.5}\nexpect: {joint_limits_respected: true}\n"
    )
    outcome = run_scenario(path, None)
    assert not outcome.ok
    assert "samples outside the joint limits (q5)" in outcome.failed_expectations[0]


Q0 = "to_q: [0, 0, 0, 0, 0]"
INVALID = [
    (f"segments: [{{motion: free, {Q0}, tt: 1.0}}]", "segments[0]", "both tt and ta"),
    (f"segments: [{{motion: free, {Q0}, tt: 1.0, ta: 0.6}}]", "segments[0]", "blends overlap"),
    (
        "segments: [{motion: free, tt: 1, ta: 0.2}]",
        "segments[0]",
        "exactly one of to_q and to_pose",
    ),
    (f"segments: [{{motion: jump, {Q0}}}]", "segments[0].motion", "Input should be"),
    (
        f"segments: [{{motion: line, {Q0}, orientation: spline}}]",
        "segments[0].orientation",
        "Input should be",
    ),
    (f"segments: [{{motion: free, {Q0}}}]\nplot: {{segment: 3}}", "", "plot.segment 3 does not"),
    ("segments: []", "segments", "at least 1 item"),
    (
        f"segments: [{{motion: free, {Q0}}}, {{motion: line, to_q: [0, 3, 0, 0, 0]}}]",
        "segments[1].to_q[1]",
        r"q2 = 3 rad is outside its joint limits \[0, 2.61799\] rad",
    ),
]


@pytest.mark.parametrize(("body", "location", "reason"), INVALID)
def test_invalid_scenarios_name_the_key(
    tmp_path: Path, body: str, location: str, reason: str
) -> None:
    with pytest.raises(ScenarioError, match=reason) as info:
        run_scenario(_write(tmp_path, body), None)
    assert info.value.location == location


def test_configurations_outside_the_joint_limits_are_rejected(tmp_path: Path) -> None:
    path = tmp_path / "deg.yaml"
    head = "kind: trajectory\nunits: {angle: deg}\n"
    path.write_text(
        head + "start: [0, 0, 0, 0, 0]\nsegments: [{motion: free, to_q: [0, 200, 0, 0, 0]}]\n"
    )
    with pytest.raises(
        ScenarioError, match=r"q2 = 200 deg is outside its joint limits \[0, 150\] deg"
    ):
        run_scenario(path, None)
    path.write_text(
        head + "start: [0, 0, 10, 0, 0]\nsegments: [{motion: free, to_q: [0, 0, 0, 0, 0]}]\n"
    )
    with pytest.raises(
        ScenarioError, match=r"q3 = 10 deg is outside its joint limits \[-150, 0\]"
    ) as info:
        run_scenario(path, None)
    assert info.value.location == "start[2]"
    # On the limit itself is allowed (the report's free-motion example starts at q3 = 0).
    path.write_text(
        head
        + "start: [0, 150, -150, 180, 180]\ncompare: false\n"
        + "segments: [{motion: free, to_q: [0, 0, 0, 0, 0]}]\n"
    )
    assert run_scenario(path, None).ok


def test_unreachable_target_names_the_segment(tmp_path: Path) -> None:
    body = "segments: [{motion: line, to_pose: [[1, 0, 0, 5], [0, -1, 0, 0], [0, 0, -1, 0]]}]\n"
    with pytest.raises(ScenarioError, match=r"segment 0 \(line\) leaves the arm's reach") as info:
        run_scenario(_write(tmp_path, body), None)
    assert isinstance(info.value.__cause__, PathNotFollowableError)


def test_cli_runs_a_scenario_and_reports_bad_input(tmp_path: Path, capsys) -> None:
    assert (
        main(["run", str(SCENARIOS / "free_motion.yaml"), "--out", str(tmp_path), "--quick"]) == 0
    )
    assert "trajectory free motion" in capsys.readouterr().out
    bad = _write(tmp_path, "segments: [{motion: free, to_q: [0, 0, 0, 0, 0], tt: -1, ta: 0.5}]")
    assert main(["run", str(bad), "--out", str(tmp_path / "x")]) == 2
    assert "segments[0].tt: Input should be greater than 0 (line 3)" in capsys.readouterr().err


def test_trajectory_of_the_so101_follows_its_line_and_limits(tmp_path: Path) -> None:
    import lynxplan

    robot = lynxplan.load_robot("so101")
    start = robot.ik(position=[0.17, 0.05, 0.03], approach=[0, 0, -1], roll=-1.57).q
    end = robot.ik(position=[0.24, -0.05, 0.03], approach=[0, 0, -1], roll=-1.57).q
    body = {
        "kind": "trajectory",
        "robot": {"name": "so101"},
        "start": start.tolist(),
        "sample_rate": 500,
        "segments": [{"motion": "line", "to_q": end.tolist(), "tt": 1.5, "ta": 0.4}],
        "expect": {"max_line_deviation": "<= 1e-9 m", "joint_limits_respected": True},
    }
    outcome = run_scenario(body, tmp_path, quick=True)
    assert outcome.ok, outcome.failed_expectations
    table = np.loadtxt(tmp_path / "trajectory.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(robot.fk(table[:, 1:6])[:, :3, 3], table[:, -3:], atol=1e-12)
    # Out of the SO-101's limits (within the AL5's): named at run time by key path.
    body["start"] = [0.0, 0.0, 0.0, 0.0, 3.0]
    with pytest.raises(ScenarioError, match=r"start\[4\]: q5 = 3 rad is outside its joint limits"):
        run_scenario(body)
