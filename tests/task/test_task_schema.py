"""Task scenario schema: every kind of bad input gives one message with file, key path, reason."""

from __future__ import annotations

import copy
import json

import numpy as np
import pytest
from task_fixtures import BASE, scenario_dict, write_scenario

from lynxplan.cli import main
from lynxplan.exceptions import ScenarioError, ScenarioValueError
from lynxplan.scenarios import load_scenario
from lynxplan.task.setup import resolve
from lynxplan.units import INCH

# The report's T_O2 (SPEC Part 3, inches) and its joint angles in degrees.
T_O2 = [
    [-0.3196, 0.9455, -0.0621, -2.8966],
    [0.9281, 0.3256, 0.1804, 8.4123],
    [0.1908, 0, -0.9816, 0.5472],
]
Q_O2_DEG = [109, 79, -93, 25, 0]
#: The report prints poses to 4 decimals: the IK of T_O2 lands within this of the table, in [deg].
PRINTED_POSE_ANGLE_TOLERANCE = 0.02


def _load(tmp_path, data):
    """Validate, then resolve (robot, obstacles, waypoint IK, plan) as a run does first."""
    loaded = load_scenario(write_scenario(tmp_path / "s.yaml", data))
    try:
        resolve(loaded.scenario)
    except ScenarioValueError as exc:
        raise loaded.located(exc) from exc
    return loaded.scenario


def test_base_scenario_is_valid(tmp_path):
    scenario = _load(tmp_path, BASE)
    setup = resolve(scenario)
    assert setup.route == (("K3", "K4"), ("K4", "I3"))
    np.testing.assert_allclose(setup.waypoints["K4"], np.radians([79, 70, -77, 29, 0]), atol=1e-15)
    box = setup.obstacles[0]
    np.testing.assert_allclose(box.centre, np.array([0.0, 13.0, -0.25]) * INCH, atol=1e-15)
    np.testing.assert_allclose(box.size, np.array([0.4, 10, 3.5]) * INCH, atol=1e-15)


@pytest.mark.parametrize(
    ("change", "location", "reason"),
    [
        ({"colour": "red"}, "colour", "Extra inputs are not permitted"),
        ({"sample_rate": "fast"}, "sample_rate", "valid number"),
        ({"sample_rate": -5}, "sample_rate", "greater than 0"),
        ({"units": {"length": "ft", "angle": "deg"}}, r"units\.length", "'m', 'mm' or 'in'"),
        ({"units": {"length": "in", "angle": "grad"}}, r"units\.angle", "'rad' or 'deg'"),
        ({"timing": {"tt": 1.0, "ta": 0.8}}, r"timing", "blends overlap"),
        ({"timing": "fast"}, r"timing", "Input should be 'auto'"),
        ({"waypoints": {}}, "waypoints", "at least 1 item"),
        ({"expect": {"min_clearance": ">= 0.2 ft"}}, r"expect\.min_clearance", "unknown unit 'ft'"),
        ({"expect": {"min_clearance": "about 3"}}, r"expect\.min_clearance", "not a comparison"),
        ({"expect": {"max_duration": "<= 3 in"}}, r"expect\.max_duration", "unknown unit 'in'"),
        ({"expect": {"collision_free": "maybe"}}, r"expect\.collision_free", "true or false"),
        ({"expect": {"colour": "red"}}, r"expect\.colour", "unknown expectation 'colour'"),
        ({"robot": {"urdf": "/nonexistent.urdf"}}, r"robot\.urdf", "URDF file not found"),
    ],
)
def test_schema_errors_name_file_key_and_reason(tmp_path, change, location, reason):
    with pytest.raises(ScenarioError, match=rf"s\.yaml, {location}( \(line \d+\))?: .*{reason}"):
        _load(tmp_path, scenario_dict(**change))


def test_missing_field(tmp_path):
    data = scenario_dict()
    del data["segments"]
    with pytest.raises(ScenarioError, match=r"s\.yaml, segments: Field required"):
        _load(tmp_path, data)


def _with_segment(index, **changes):
    data = copy.deepcopy(BASE)
    data["segments"][index].update(changes)
    return data


def _with_waypoint(name, entry):
    data = copy.deepcopy(BASE)
    data["waypoints"][name] = entry
    return data


@pytest.mark.parametrize(
    ("data", "location", "reason"),
    [
        (_with_segment(1, to="K9"), r"segments\[1\]\.to", "unknown waypoint 'K9'; waypoints: K3"),
        (_with_segment(0, **{"from": "X"}), r"segments\[0\]\.from", "unknown waypoint 'X'"),
        (_with_segment(1, **{"from": "K3"}), r"segments\[1\]\.from", "ends at 'K4'"),
        (_with_segment(1, motion="spline"), r"segments\[1\]\.motion", "'free', 'line' or 'plan'"),
        (_with_segment(1, tt=2), r"segments\[1\]\.tt", "Extra inputs"),
        (_with_segment(1, timing={"tt": 2.0}), r"segments\[1\]\.timing\.ta", "required"),
        (_with_waypoint("K4", {"q": [0, 0, 0]}), r"waypoints\.K4\.q", "at least 5 items"),
        (
            _with_waypoint("K4", {"q": [79, 170, -77, 29, 0]}),
            r"waypoints\.K4\.q\[1\]",
            "q2 = 170 is outside the joint limits",
        ),
        (
            _with_waypoint("K4", {"q": [79, 70, -77, 29, 0], "pose": T_O2}),
            r"waypoints\.K4",
            "exactly one of q, pose, position",
        ),
        (
            _with_waypoint("K4", {"position": [0, 30, 0], "approach": [0, 0, -1]}),
            r"waypoints\.K4\.position",
            "unreachable waypoint: pose is out of reach",
        ),
        (
            _with_waypoint("K4", {"pose": [[1, 0, 0, 0], [0, 1, 0, 25], [0, 0, 1, 0]]}),
            r"waypoints\.K4\.pose",
            "unreachable waypoint",
        ),
    ],
)
def test_reference_and_reachability_errors(tmp_path, data, location, reason):
    with pytest.raises(ScenarioError, match=rf"s\.yaml, {location}( \(line \d+\))?: .*{reason}"):
        _load(tmp_path, data)


def test_obstacle_errors(tmp_path):
    bad_box = {"type": "box", "min_corner": [0, 0, 0], "centre": [0, 0, 0], "size": [1, 1, 1]}
    with pytest.raises(ScenarioError, match=r"obstacles\[0\]: .*exactly one of min_corner"):
        _load(tmp_path, scenario_dict(obstacles=[bad_box]))
    with pytest.raises(ScenarioError, match=r"obstacles\[0\]\.size\[1\]: .*greater than 0"):
        _load(
            tmp_path,
            scenario_dict(obstacles=[{"type": "box", "centre": [0, 0, 0], "size": [1, -1, 1]}]),
        )
    with pytest.raises(ScenarioError, match=r"obstacles\[0\]: .*'box', 'sphere', 'cylinder'"):
        _load(tmp_path, scenario_dict(obstacles=[{"type": "cone", "centre": [0, 0, 0]}]))
    skew = {
        "type": "box",
        "centre": [0, 0, 0],
        "size": [1, 1, 1],
        "rotation": [[1, 0, 0], [0, 1, 0], [0, 0.5, 1]],
    }
    with pytest.raises(ScenarioError, match=r"obstacles\[0\]: .*not a proper rotation"):
        _load(tmp_path, scenario_dict(obstacles=[skew]))
    twins = [{"name": "a", "type": "sphere", "centre": [0, 0, 30], "radius": 1}] * 2
    with pytest.raises(ScenarioError, match=r"obstacles\[1\]\.name: duplicate obstacle name 'a'"):
        _load(tmp_path, scenario_dict(obstacles=twins))


def test_line_leaving_the_reach_is_located_at_its_segment(tmp_path):
    data = copy.deepcopy(BASE)
    data["waypoints"]["east"] = {"q": [0, 0, 0, 90, 0]}
    data["waypoints"]["west"] = {"q": [180, 0, 0, 90, 0]}
    data["segments"] = [{"from": "east", "to": "west", "motion": "line"}]
    # The line between the two stretched poses passes too close to the base axis for the wrist.
    with pytest.raises(
        ScenarioError, match=r"s\.yaml, segments\[0\]: line motion to 'west': .*leaves the arm's"
    ):
        _load(tmp_path, data)


def test_robot_outside_the_five_joint_family_is_rejected_at_run_time(tmp_path):
    from example_robot_data.robots_loader import getModelPath

    ur5 = "ur_description/urdf/ur5_robot.urdf"
    data = scenario_dict(robot={"urdf": f"{getModelPath(ur5)}/{ur5}", "tool": "tool0"})
    with pytest.raises(ScenarioError, match=r"robot\.urdf: robot .* has 6 joints; task and"):
        _load(tmp_path, data)
    with pytest.raises(ScenarioError, match=r"robot\.name: unknown robot 'so102'"):
        _load(tmp_path, scenario_dict(robot={"name": "so102"}))


def test_pose_and_approach_waypoints_are_solved_by_ik(tmp_path):
    data = _with_waypoint("K4", {"pose": T_O2})
    scenario = _load(tmp_path, data)
    np.testing.assert_allclose(
        np.degrees(resolve(scenario).waypoints["K4"]), Q_O2_DEG, atol=PRINTED_POSE_ANGLE_TOLERANCE
    )
    # Position + approach of O2's pen (5-D target): q5 is free and taken from q_reference (0).
    data = _with_waypoint(
        "K4", {"position": [row[3] for row in T_O2], "approach": [row[2] for row in T_O2]}
    )
    scenario = _load(tmp_path, data)
    np.testing.assert_allclose(
        np.degrees(resolve(scenario).waypoints["K4"]), Q_O2_DEG, atol=PRINTED_POSE_ANGLE_TOLERANCE
    )


def test_oriented_obstacles(tmp_path):
    obstacles = [
        {
            "name": "tilted",
            "type": "box",
            "centre": [0, 20, 0],
            "size": [1, 2, 3],
            "rpy": [0, 0, 90],
        },
        {"name": "ball", "type": "sphere", "centre": [0, 20, 10], "radius": 1},
        {
            "name": "post",
            "type": "cylinder",
            "centre": [10, 10, 0],
            "radius": 0.5,
            "length": 4,
            "axis": [1, 0, 0],
        },
    ]
    scenario = _load(tmp_path, scenario_dict(obstacles=obstacles))
    box, ball, post = resolve(scenario).obstacles
    # yaw 90 deg maps the box's x axis onto +y.
    np.testing.assert_allclose(box.rotation[:, 0], [0, 1, 0], atol=1e-15)
    assert ball.radius == pytest.approx(1 * INCH, abs=1e-15)
    np.testing.assert_allclose(post.rotation[:, 2], [1, 0, 0], atol=1e-15)


def test_validate_and_schema_commands(tmp_path, capsys):
    good = write_scenario(tmp_path / "good.yaml", BASE)
    assert main(["validate", str(good)]) == 0
    assert "good.yaml: valid task scenario" in capsys.readouterr().out
    bad = write_scenario(tmp_path / "bad.yaml", _with_segment(1, to="nowhere"))
    assert main(["validate", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.strip().count("\n") == 0  # one line
    assert "bad.yaml, segments[1].to: unknown waypoint 'nowhere'" in err
    assert main(["schema", "task"]) == 0
    schema = json.loads(capsys.readouterr().out)
    assert schema["properties"]["kind"]["const"] == "task"
    assert "from" in schema["$defs"]["SegmentEntry"]["properties"]
    assert main(["schema", "nosuchkind"]) == 2
    assert "unknown kind 'nosuchkind'" in capsys.readouterr().err
