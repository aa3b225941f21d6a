"""Recorded data in: joint positions -> tool path (against Pinocchio's frame placement), limit
violations named, collisions found against a box put on the path, figures and HTML written."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lynxplan.collision import axis_aligned_box
from lynxplan.exceptions import InputError
from lynxplan.lerobot import check_recorded, lerobot_units, write_recorded
from tests.lerobot.sample import SAMPLE_CALIBRATION


@pytest.fixture(scope="module")
def recording(so101_calibrated):
    robot = so101_calibrated
    t = np.arange(60) / 30.0
    start, end = np.radians([-30, -20, 30, 60, -90]), np.radians([30, 10, 10, 70, -60])
    s = 0.5 - 0.5 * np.cos(np.pi * t / t[-1])
    return robot, t, start + s[:, None] * (end - start)


def test_tool_path_limits_and_a_clear_scene(recording):
    robot, t, q = recording
    check = check_recorded(robot, t, q, self_collision=True)
    for k in (0, 17, 59):  # the tool point, independently: Pinocchio's frame placement
        np.testing.assert_allclose(check.tool[k], robot.frame_placement(q[k])[:3, 3], atol=1e-9)
    assert check.within_limits and check.limit_violations() == []
    assert check.collision_free is True and check.within_servo
    # peak speed of the cosine ramp: (pi / 2) * span / duration, sampled
    span = np.abs(q[-1] - q[0])
    assert check.peak_velocity.max() == pytest.approx(math.pi / 2 * span.max() / t[-1], rel=0.01)


def test_frames_outside_the_limits_are_named(recording):
    robot, t, q = recording
    bad = q.copy()
    upper = robot.limits.upper[2]
    bad[20:25, 2] = upper + np.radians([0.5, 1.0, 2.0, 1.0, 0.5])
    check = check_recorded(robot, t, bad, self_collision=False)
    assert not check.within_limits and check.collision is None
    assert check.outside[:, 2].sum() == 5 and check.outside.sum() == 5
    (line,) = check.limit_violations()
    assert line.startswith("elbow_flex: 5 frame(s) from t = 0.667 s")
    assert f"{math.degrees(upper) + 2:+.2f} deg at t = 0.733 s" in line


def test_a_box_on_the_path_is_a_contact(recording, tmp_path):
    robot, t, q = recording
    middle = robot.fk(q[30])[:3, 3]
    box = axis_aligned_box("block", middle - 0.01, [0.02, 0.02, 0.02])  # around the tool
    check = check_recorded(robot, t, q, obstacles=[box], self_collision=False)
    assert check.collision_free is False
    contacts = check.collision.contacts
    assert {c.obstacle for c in contacts} == {"block"}
    assert any(c.t_start <= t[30] <= c.t_end for c in contacts)
    written = write_recorded(robot, check, tmp_path / "out", obstacles=[box], name="rec")
    assert [p.name for p in written] == ["tool_path.png", "joints.png", "clearance.png", "rec.html"]
    assert all(p.stat().st_size > 1000 for p in written)
    assert "<html" in (tmp_path / "out" / "rec.html").read_text()[:2000].lower()


def test_units_of_a_recording_and_bad_input(recording):
    robot, t, q = recording
    units = lerobot_units(robot, SAMPLE_CALIBRATION, use_degrees=False)
    frames = units.to_action(q, gripper=10.0)
    back = units.to_joints(frames)
    np.testing.assert_allclose(back.q, q, atol=1e-12)
    with pytest.raises(InputError, match="strictly increasing"):
        check_recorded(robot, t[::-1], q)
    with pytest.raises(InputError, match=r"q \(K, 5\)"):
        check_recorded(robot, t, q[:, :4])
