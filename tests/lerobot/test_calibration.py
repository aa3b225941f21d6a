"""Calibration file -> joint limits in URDF radians, against values computed by hand from the
sample file's ticks (conftest.SAMPLE_CALIBRATION)."""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest

from lynxplan.lerobot.calibration import (
    calibrated_limits,
    default_calibration_path,
    load_calibrated,
    read_calibration,
    urdf_axis_signs,
)
from lynxplan.lerobot.errors import CalibrationError, CalibrationWarning
from tests.lerobot.sample import SAMPLE_CALIBRATION

#: Limits are sums of a few doubles: agreement to rounding.
ATOL_RAD = 1e-12


def test_limits_are_the_calibrated_ranges_in_urdf_radians(calibration_file):
    with pytest.warns(CalibrationWarning) as caught:
        robot = load_calibrated("so101", calibration_file)
    # by hand: half range in ticks * 360 / 4095 degrees
    half_deg = {
        "shoulder_pan": (3292 - 758) / 2 * 360 / 4095,  # 111.3846...
        "shoulder_lift": (3184 - 812) / 2 * 360 / 4095,  # 104.2637...
        "elbow_flex": (3080 - 910) / 2 * 360 / 4095,  # 95.3846...
        "wrist_flex": (3116 - 980) / 2 * 360 / 4095,  # 93.8901...
        "wrist_roll": 180.0,
    }
    assert half_deg["shoulder_pan"] == pytest.approx(111.384615, abs=1e-6)
    expected = np.array([[-math.radians(d), math.radians(d)] for d in half_deg.values()])
    np.testing.assert_allclose(robot.limits.position, expected, rtol=0, atol=ATOL_RAD)
    np.testing.assert_allclose(robot.model.lowerPositionLimit, expected[:, 0], atol=ATOL_RAD)
    # one warning, one line, naming exactly the joints past the URDF limits
    assert len(caught) == 1
    message = str(caught[0].message)
    assert "\n" not in message
    for name in ("shoulder_pan", "shoulder_lift", "wrist_roll"):
        assert name in message
    for name in ("elbow_flex", "wrist_flex"):
        assert name not in message
    assert "+104.3" in message and "URDF -100.0..+100.0" in message
    # the family (and its closed-form IK) survives the new limits
    assert robot.family is not None
    q = np.radians([100.0, -103.0, 30.0, -20.0, 170.0])  # past the URDF limits, within the cal
    pose = robot.fk(q)
    result = robot.ik(pose, q_reference=q)
    np.testing.assert_allclose(result.q, q, atol=1e-7)


def test_a_calibration_within_the_urdf_limits_warns_nothing(tmp_path, so101):
    inside = {k: dict(v) for k, v in SAMPLE_CALIBRATION.items()}
    for name in ("shoulder_pan", "shoulder_lift", "wrist_roll"):
        inside[name].update(range_min=1000, range_max=3000)  # 87.9 deg a side
    path = tmp_path / "inside.json"
    path.write_text(json.dumps(inside))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        robot = load_calibrated("so101", path)
    assert robot.limits.position[0, 1] == pytest.approx(math.radians(1000 * 360 / 4095), abs=1e-12)
    limits = calibrated_limits(so101, read_calibration(path))
    assert limits.beyond_urdf == () and limits.message is None


def test_urdf_axis_signs_of_the_so101(so101):
    assert urdf_axis_signs(so101) == dict.fromkeys(so101.joint_names, 1)


def test_default_calibration_path(tmp_path, monkeypatch):
    monkeypatch.setenv("HF_LEROBOT_HOME", str(tmp_path))
    current = tmp_path / "calibration" / "robots" / "so_follower" / "arm.json"
    assert default_calibration_path("arm") == current
    older = tmp_path / "calibration" / "robots" / "so101_follower" / "arm.json"
    older.parent.mkdir(parents=True)
    older.write_text("{}")
    assert default_calibration_path("arm") == older


def _write(tmp_path, content):
    path = tmp_path / "bad.json"
    path.write_text(content if isinstance(content, str) else json.dumps(content))
    return path


def _with(motor, **changes):
    content = {k: dict(v) for k, v in SAMPLE_CALIBRATION.items()}
    content[motor].update(changes)
    return content


@pytest.mark.parametrize(
    ("content", "match"),
    [
        ("{not json", "not readable JSON"),
        ("[]", "must be a JSON object of motors"),
        (_with("elbow_flex", range_min=3000, range_max=1000), r"elbow_flex: range_min = 3000"),
        (_with("wrist_flex", range_max=5000), r"range_max <= 4095"),
        (_with("gripper", drive_mode=2), r"gripper.drive_mode = 2: must be 0 or 1"),
        (_with("shoulder_pan", id="one"), r"shoulder_pan.id = 'one': must be an integer"),
        ({"shoulder_pan": {"id": 1}}, r"shoulder_pan: missing drive_mode, homing_offset"),
    ],
)
def test_bad_calibration_files_are_one_line_errors(tmp_path, content, match):
    with pytest.raises(CalibrationError, match=match) as info:
        read_calibration(_write(tmp_path, content))
    assert "\n" not in str(info.value)


def test_missing_file_and_missing_motor(tmp_path, so101):
    with pytest.raises(CalibrationError, match=r"nope.json: file not found"):
        load_calibrated("so101", tmp_path / "nope.json")
    partial = {k: v for k, v in SAMPLE_CALIBRATION.items() if k != "wrist_flex"}
    with pytest.raises(CalibrationError, match=r"no motor 'wrist_flex'; motors: shoulder_pan"):
        calibrated_limits(so101, read_calibration(partial))
