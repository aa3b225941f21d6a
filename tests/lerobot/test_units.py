"""LeRobot frames <-> joint vectors: the documented mapping checked through the servo ticks
(LeRobot's own normalisation written out independently here), and round trips."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lynxplan.lerobot import CalibrationError, FrameError, lerobot_units, read_calibration
from lynxplan.lerobot.units import GRIPPER_KEY
from tests.lerobot.sample import SAMPLE_CALIBRATION

#: Linear maps of doubles: agreement to rounding.
ATOL = 1e-12
ARM = ("shoulder_pan", "shoulder_lift", "elbow_flex", "wrist_flex", "wrist_roll")


def lerobot_normalize(ticks: float, motor: str, use_degrees: bool) -> float:
    """lerobot 0.4's ``MotorsBus._normalize`` for an STS3215 (Feetech: apply_drive_mode)."""
    c = SAMPLE_CALIBRATION[motor]
    lo, hi, drive = c["range_min"], c["range_max"], c["drive_mode"]
    if use_degrees and motor != "gripper":
        return (ticks - (lo + hi) / 2) * 360 / 4095
    bounded = min(hi, max(lo, ticks))
    if motor == "gripper":
        norm = (bounded - lo) / (hi - lo) * 100
        return 100 - norm if drive else norm
    norm = (bounded - lo) / (hi - lo) * 200 - 100
    return -norm if drive else norm


def urdf_angle(ticks: float, motor: str) -> float:
    """The documented physical mapping: axis sign (+1 on the SO-101) * (-1)**drive_mode *
    (ticks - middle) * 2 pi / 4095."""
    c = SAMPLE_CALIBRATION[motor]
    return (
        (-1) ** c["drive_mode"]
        * (ticks - (c["range_min"] + c["range_max"]) / 2)
        * 2
        * math.pi
        / 4095
    )


@pytest.mark.parametrize("use_degrees", [True, False])
def test_frames_from_ticks_give_the_urdf_angles(so101, use_degrees):
    units = lerobot_units(so101, SAMPLE_CALIBRATION, use_degrees=use_degrees)
    rng = np.random.default_rng(1)
    for _ in range(20):
        ticks = {
            m: rng.uniform(c["range_min"], c["range_max"]) for m, c in SAMPLE_CALIBRATION.items()
        }
        frame = {f"{m}.pos": lerobot_normalize(t, m, use_degrees) for m, t in ticks.items()}
        joints = units.to_joints(frame)
        expected = [urdf_angle(ticks[m], m) for m in ARM]
        np.testing.assert_allclose(joints.q, expected, rtol=0, atol=ATOL)
        assert joints.gripper == pytest.approx(frame[GRIPPER_KEY], abs=0)


def test_hand_values(so101):
    degrees = lerobot_units(so101, SAMPLE_CALIBRATION)
    q = degrees.to_joints(
        {"shoulder_pan.pos": 30.0, "shoulder_lift.pos": -90.0, "elbow_flex.pos": 30.0,
         "wrist_flex.pos": 0.0, "wrist_roll.pos": 180.0, "gripper.pos": 12.5, "camera": "x"}
    ).q  # fmt: skip
    # elbow_flex is mounted reversed (drive_mode 1): +30 LeRobot degrees is -30 URDF degrees
    np.testing.assert_allclose(np.degrees(q), [30.0, -90.0, -30.0, 0.0, 180.0], atol=1e-12)
    ranged = lerobot_units(so101, SAMPLE_CALIBRATION, use_degrees=False)
    # shoulder_lift at +50: halfway from the middle to range_max: 1186 / 2 ticks
    q = ranged.to_q([0.0, 50.0, 0.0, 0.0, -100.0])
    assert q[1] == pytest.approx(593 * 2 * math.pi / 4095, abs=ATOL)
    assert q[4] == pytest.approx(-math.pi, abs=ATOL)
    # without a calibration, degrees are LeRobot's kinematics convention: deg2rad
    plain = lerobot_units(so101)
    np.testing.assert_allclose(plain.to_q([10, 20, 30, 40, 50]), np.radians([10, 20, 30, 40, 50]))


@pytest.mark.parametrize("use_degrees", [True, False])
def test_round_trips_one_frame_and_arrays(so101_calibrated, use_degrees):
    units = lerobot_units(so101_calibrated, SAMPLE_CALIBRATION, use_degrees=use_degrees)
    q = so101_calibrated.random_configurations(50, seed=3)
    grip = np.linspace(0.0, 100.0, 50)
    frames = units.to_action(q, grip)
    assert isinstance(frames, list) and len(frames) == 50
    assert tuple(frames[0]) == units.keys
    back = units.to_joints(frames)
    np.testing.assert_allclose(back.q, q, rtol=0, atol=ATOL)
    np.testing.assert_allclose(back.gripper, grip, rtol=0, atol=0)
    one = units.to_action(q[7], 40.0)
    assert isinstance(one, dict)
    np.testing.assert_allclose(units.to_joints(one).q, q[7], atol=ATOL)
    # a dict of columns (a dataset's episode) -> arrays
    columns = {k: np.array([f[k] for f in frames]) for k in units.keys}
    np.testing.assert_allclose(units.to_joints(columns).q, q, atol=ATOL)
    np.testing.assert_allclose(units.to_q(units.to_values(q)), q, atol=ATOL)
    if not use_degrees:  # the calibrated limits are the ends of LeRobot's -100..100
        ends = units.to_values(so101_calibrated.limits.position.T)
        np.testing.assert_allclose(ends, [[-100.0] * 5, [100.0] * 5], atol=1e-9)


def test_a_frame_without_the_gripper_and_an_action_without_it(so101):
    units = lerobot_units(so101)
    joints = units.to_joints({f"{m}.pos": 0.0 for m in ARM})
    assert np.isnan(joints.gripper)
    assert GRIPPER_KEY not in units.to_action(np.zeros(5))


def test_errors(so101):
    units = lerobot_units(so101)
    with pytest.raises(FrameError, match=r"no 'wrist_roll.pos'; its keys: shoulder_pan.pos"):
        units.to_joints({f"{m}.pos": 0.0 for m in ARM[:4]})
    bad = {f"{m}.pos": 0.0 for m in ARM} | {"elbow_flex.pos": float("nan")}
    with pytest.raises(FrameError, match=r"elbow_flex.pos contains NaN"):
        units.to_joints(bad)
    with pytest.raises(FrameError, match=r"elbow_flex.pos = 'x': must be a number"):
        units.to_joints(bad | {"elbow_flex.pos": "x"})
    with pytest.raises(CalibrationError, match=r"-100..100 units .* need the arm's calibration"):
        lerobot_units(so101, use_degrees=False)
    with pytest.raises(CalibrationError, match=r"no motor 'shoulder_pan'"):
        lerobot_units(so101, read_calibration({"gripper": SAMPLE_CALIBRATION["gripper"]}))
