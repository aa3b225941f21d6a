"""The example end to end through the real command line: the SO-101 writes "OK"
(scenarios/so101_writing.yaml) -> ``lynxplan lerobot export`` -> frames.csv and a LeRobot dataset
whose every frame is within the calibrated limits and the servo's speed and acceleration; then
``lynxplan lerobot check`` of that dataset against the scenario's scene, and of a recording that
leaves the limits."""

from __future__ import annotations

import json
import math
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from lynxplan.lerobot import lerobot_units, load_calibrated, read_csv, read_episode
from lynxplan.lerobot.servo import DEFAULT_MAX_ACCELERATION, DEFAULT_MAX_VELOCITY
from tests.lerobot.sample import SAMPLE_CALIBRATION

pytest.importorskip("pyarrow", reason="the [lerobot] extra (pyarrow) is needed")

ROOT = Path(__file__).resolve().parents[2]
SCENARIO = ROOT / "scenarios" / "so101_writing.yaml"
#: Bounds hold up to the export's relative rounding allowance.
BOUND_RTOL = 1e-9


def _cli(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "lynxplan.cli", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=cwd,
    )


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    folder = tmp_path_factory.mktemp("export")
    cal = folder / "cal.json"
    cal.write_text(json.dumps(SAMPLE_CALIBRATION))
    out = folder / "out" / "so101_frames"
    done = _cli(
        "lerobot", "export", SCENARIO, "--calibration", cal, "--fps", "30", "--out", out,
        "--gripper", "40",
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    return cal, out, done


def test_every_exported_frame_is_within_the_limits_and_the_servo(exported):
    cal, out, done = exported
    assert "wrote" in done.stdout and "frames at 30 fps" in done.stdout
    warning_lines = done.stderr.strip().splitlines()
    assert len(warning_lines) == 1 and "shoulder_pan" in warning_lines[0]  # the calibration's
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_calibrated("so101", cal)
    units = lerobot_units(robot, cal)
    t, frames = read_csv(out / "frames.csv")
    q = units.to_joints(frames).q
    assert len(t) > 500 and t[-1] >= 20.4 - 1e-9  # the 20.4 s scenario, slowed if need be
    np.testing.assert_allclose(np.diff(t), 1 / 30, atol=1e-12)
    # limits: the calibrated ranges, |q| <= (range_max - range_min) / 2 * 2 pi / 4095
    half = np.array(
        [
            (SAMPLE_CALIBRATION[m]["range_max"] - SAMPLE_CALIBRATION[m]["range_min"]) / 2
            for m in ("shoulder_pan", "shoulder_lift", "elbow_flex", "wrist_flex", "wrist_roll")
        ]
    ) * (2 * math.pi / 4095)
    assert (np.abs(q) <= half + 1e-9).all()
    # servo: finite differences, the arm at rest before the first frame and after the last
    padded = np.vstack((q[:1], q[:1], q, q[-1:], q[-1:]))
    velocity = np.abs(np.diff(padded, axis=0)).max() * 30
    acceleration = np.abs(np.diff(padded, n=2, axis=0)).max() * 30**2
    assert velocity <= DEFAULT_MAX_VELOCITY * (1 + BOUND_RTOL)
    assert acceleration <= DEFAULT_MAX_ACCELERATION * (1 + BOUND_RTOL)
    assert {f["gripper.pos"] for f in frames} == {40.0}
    # the first frame is the scenario's home pose H: q = [0, -60, 60, 60, -90] deg
    np.testing.assert_allclose(np.degrees(q[0]), [0, -60, 60, 60, -90], atol=1e-9)
    # the dataset holds the same frames (float32)
    episode = read_episode(out / "dataset", 0, "action")
    assert episode.fps == 30 and episode.robot_type == "so101_follower"
    np.testing.assert_allclose(episode.values[:, :5], units.to_values(q), atol=1e-4)
    marker = json.loads((out / "dataset" / "lynxplan.json").read_text())
    assert marker["units"] == "deg" and marker["scenario"].endswith("so101_writing.yaml")


def test_check_the_exported_dataset_against_the_scene(exported, tmp_path):
    cal, out, _ = exported
    figures = tmp_path / "check"
    done = _cli(
        "lerobot", "check", out / "dataset", "--calibration", cal, "--scene", SCENARIO,
        "--out", figures,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "within limits: yes" in done.stdout and "collision free: yes" in done.stdout
    # the scenario measured 20.2 mm (jaw to back_wall); frames are its samples at 30 fps
    clearance = float(done.stdout.split("min clearance ")[1].split(" mm")[0])
    assert 19.0 <= clearance <= 21.0
    names = sorted(p.name for p in figures.iterdir())
    assert names == ["clearance.png", "joints.png", "recorded.html", "tool_path.png"]


def test_check_a_recording_that_leaves_the_limits(exported, tmp_path):
    cal, out, _ = exported
    lines = (out / "frames.csv").read_text().splitlines()
    header = lines[0].split(",")
    column = header.index("elbow_flex.pos")
    rows = [line.split(",") for line in lines[1:]]
    rows[10][column] = "-99.0"  # elbow_flex's calibrated range is +-95.38 deg (reversed motor)
    bad = tmp_path / "recorded.csv"
    bad.write_text("\n".join([lines[0], *(",".join(r) for r in rows)]) + "\n")
    done = _cli("lerobot", "check", bad, "--calibration", cal)
    assert done.returncode == 1
    assert "within limits: NO" in done.stdout
    assert "elbow_flex: 1 frame(s) from t = 0.333 s, farthest +99.00 deg" in done.stdout


def test_bad_input_is_one_line(tmp_path):
    done = _cli("lerobot", "export", SCENARIO, "--fps", "29.97", "--out", tmp_path / "x")
    assert done.returncode == 2
    assert done.stderr.strip() == "lynxplan: error: --fps = 29.97: must be a whole number >= 1"
    done = _cli("lerobot", "check", tmp_path, "--calibration", tmp_path / "none.json")
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1
    done = _cli("lerobot", "check", tmp_path)
    assert done.returncode == 2 and "not a LeRobot dataset" in done.stderr


def test_a_plan_scenario_exports_its_planned_motion(tmp_path):
    """A plan (the SO-101 between two posts) is planned with its seed and exported: the frames
    start at the scenario's start, end at a goal the scenario asks for (FK against its goal
    position and approach), and hold the servo bounds."""
    import yaml

    from lynxplan.planning.problem import ROBOT_GOAL_ORIENTATION_TOLERANCE
    from lynxplan.robots import load_robot

    scenario = ROOT / "scenarios" / "planning" / "s02_so101_between_posts.yaml"
    spec = yaml.safe_load(scenario.read_text())
    done = _cli("lerobot", "export", scenario, "--fps", "30", "--out", tmp_path / "plan")
    assert done.returncode == 0, done.stderr
    robot = load_robot("so101")
    units = lerobot_units(robot, None)
    _, frames = read_csv(tmp_path / "plan" / "frames.csv")
    q = units.to_joints(frames).q
    np.testing.assert_allclose(np.degrees(q[0]), spec["start"], atol=1e-9)
    tool = robot.fk(q[-1])
    np.testing.assert_allclose(tool[:3, 3], spec["goal"]["position"], atol=1e-6)
    # the planner's goal region: the approach within its documented orientation tolerance
    cosine = float(np.dot(tool[:3, 2], spec["goal"]["approach"]))
    assert math.acos(min(1.0, cosine)) <= ROBOT_GOAL_ORIENTATION_TOLERANCE * (1 + 1e-9)
    padded = np.vstack((q[:1], q[:1], q, q[-1:], q[-1:]))
    assert np.abs(np.diff(padded, axis=0)).max() * 30 <= DEFAULT_MAX_VELOCITY * (1 + BOUND_RTOL)
    assert np.abs(np.diff(padded, n=2, axis=0)).max() * 900 <= DEFAULT_MAX_ACCELERATION * (
        1 + BOUND_RTOL
    )


def test_a_scenario_of_another_robot_is_refused_in_one_line(tmp_path):
    al5_plan = ROOT / "scenarios" / "planning" / "p02_box_between.yaml"
    done = _cli("lerobot", "export", al5_plan, "--out", tmp_path / "x")
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1
    assert "robot 'al5'" in done.stderr and "so100/so101" in done.stderr
    assert not (tmp_path / "x").exists()
