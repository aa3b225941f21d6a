"""Servo-safe frames: every exported frame within the STS3215 bounds (checked by finite
differences written out here), on the trajectory's joint path, within the joint limits; CSV
round trip; playback to a recording fake robot on a fake clock."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from lynxplan.exceptions import InputError
from lynxplan.lerobot import PlaybackError, lerobot_units
from lynxplan.lerobot.export import read_csv, servo_frames, servo_frames_of, write_csv
from lynxplan.lerobot.play import play
from lynxplan.lerobot.servo import (
    DEFAULT_MAX_ACCELERATION,
    DEFAULT_MAX_VELOCITY,
    STS3215_NO_LOAD_SPEED,
    STS3215_PROFILE_ACCELERATION,
)
from tests.lerobot.sample import SAMPLE_CALIBRATION

#: Bounds hold up to the export's relative rounding allowance.
BOUND_RTOL = 1e-9


def frame_peaks(q: np.ndarray, fps: float) -> tuple[float, float]:
    """Largest |speed| and |acceleration| of frames q (K, m), the arm at rest around them."""
    padded = np.vstack((q[:1], q[:1], q, q[-1:], q[-1:]))
    velocity = np.abs(np.diff(padded, axis=0)) * fps
    acceleration = np.abs(np.diff(padded, n=2, axis=0)) * fps**2
    return float(velocity.max()), float(acceleration.max())


def test_servo_figures():
    assert pytest.approx(math.radians(60) / 0.2222, rel=1e-3) == STS3215_NO_LOAD_SPEED
    assert pytest.approx(38.96, abs=0.01) == STS3215_PROFILE_ACCELERATION
    assert pytest.approx(2.356, abs=1e-3) == DEFAULT_MAX_VELOCITY


def test_a_fast_polyline_is_slowed_into_the_servo_bounds(so101_calibrated):
    robot = so101_calibrated
    units = lerobot_units(robot, SAMPLE_CALIBRATION)
    waypoints = robot.random_configurations(6, seed=5) * 0.8
    t = np.arange(6) * 0.2  # ~1 rad in 0.2 s: far too fast, and kinks at every waypoint
    gripper = np.array([0, 100, 0, 100, 0, 100.0])
    out = servo_frames(robot, units, t, waypoints, gripper=gripper, fps=30)
    assert out.time_scale > 2
    velocity, acceleration = frame_peaks(out.q, 30)
    assert velocity <= DEFAULT_MAX_VELOCITY * (1 + BOUND_RTOL)
    assert acceleration <= DEFAULT_MAX_ACCELERATION * (1 + BOUND_RTOL)
    np.testing.assert_allclose(out.peak_velocity.max(), velocity, rtol=1e-12)
    # the gripper motor too: its 0..100 spans 1490 ticks
    grip_rad = out.gripper[:, None] * (3524 - 2034) * 2 * math.pi / 4095 / 100
    g_velocity, g_acceleration = frame_peaks(grip_rad, 30)
    assert g_velocity <= DEFAULT_MAX_VELOCITY * (1 + BOUND_RTOL)
    assert g_acceleration <= DEFAULT_MAX_ACCELERATION * (1 + BOUND_RTOL)
    # every frame within the limits, from the first waypoint to the last, at fixed times
    assert np.all(out.q >= robot.limits.lower) and np.all(out.q <= robot.limits.upper)
    np.testing.assert_allclose(out.q[0], waypoints[0], atol=0)
    np.testing.assert_allclose(out.q[-1], waypoints[-1], atol=1e-12)
    np.testing.assert_allclose(np.diff(out.t), 1 / 30, atol=1e-12)
    # on the joint path: each frame on a segment between consecutive waypoints
    for frame in out.q:
        gaps = []
        for a, b in itertools.pairwise(waypoints):
            s = np.clip(np.dot(frame - a, b - a) / np.dot(b - a, b - a), 0, 1)
            gaps.append(np.abs(a + s * (b - a) - frame).max())
        assert min(gaps) <= 1e-9
    # the LeRobot frames: degrees, keys in bus order with the gripper last
    frames = out.frames()
    assert tuple(frames[0]) == units.keys
    np.testing.assert_allclose([f["shoulder_pan.pos"] for f in frames], np.degrees(out.q[:, 0]))


def test_a_gentle_trajectory_is_kept_as_timed(so101):
    units = lerobot_units(so101)
    t = np.linspace(0.0, 4.0, 401)
    q = 0.2 * np.sin(np.pi * t / 4.0)[:, None] ** 2 * np.ones(so101.nq)
    out = servo_frames(so101, units, t, q, fps=25)
    assert out.time_scale == 1.0 and len(out.t) == 101
    np.testing.assert_allclose(out.q, q[::4], atol=1e-12)
    assert np.isnan(out.gripper).all() and "gripper.pos" not in out.frames()[0]


def test_servo_frames_of_a_plan_like_object(so101):
    class Samples:
        t = np.array([0.0, 1.0])
        q = np.zeros((2, 5))

    out = servo_frames_of(so101, lerobot_units(so101), Samples())
    assert len(out.t) == 31 and out.time_scale == 1.0
    with pytest.raises(InputError, match=r"int has no t and q samples"):
        servo_frames_of(so101, lerobot_units(so101), 3)


def test_csv_round_trip_and_no_overwrite(tmp_path, so101_calibrated):
    units = lerobot_units(so101_calibrated, SAMPLE_CALIBRATION, use_degrees=False)
    q = so101_calibrated.random_configurations(3, seed=2)
    out = servo_frames(so101_calibrated, units, [0, 1, 2], q, gripper=[10, 20, 30])
    path = write_csv(out, tmp_path / "frames.csv")
    t, frames = read_csv(path)
    np.testing.assert_array_equal(t, out.t)
    assert frames == out.frames()  # shortest exact float text: bit-identical
    assert path.read_text().splitlines()[0] == "t," + ",".join(units.keys)
    path.write_text("mine")
    with pytest.raises(InputError, match=r"frames.csv exists; pass overwrite=True"):
        write_csv(out, path)
    assert path.read_text() == "mine"
    write_csv(out, path, overwrite=True)
    assert read_csv(path)[1] == frames
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]
    with pytest.raises(InputError, match=r"first column must be t"):
        read_csv(_text(tmp_path / "bad.csv", "a,b\n1,2\n"))
    with pytest.raises(InputError, match=r"nope.csv: file not found"):
        read_csv(tmp_path / "nope.csv")


def _text(path, text):
    path.write_text(text)
    return path


def test_bad_trajectories(so101):
    units = lerobot_units(so101)
    with pytest.raises(InputError, match=r"t must be strictly increasing"):
        servo_frames(so101, units, [0, 0], np.zeros((2, 5)))
    with pytest.raises(InputError, match=r"q \(2, 5\). Got: \(2,\) and \(2, 4\)"):
        servo_frames(so101, units, [0, 1], np.zeros((2, 4)))
    with pytest.raises(InputError, match=r"sample 1, elbow_flex = 2 rad is outside the joint"):
        servo_frames(so101, units, [0, 1], [[0, 0, 0, 0, 0], [0, 0, 2, 0, 0]])
    with pytest.raises(InputError, match=r"max_velocity = 0: must be finite and > 0"):
        servo_frames(so101, units, [0, 1], np.zeros((2, 5)), max_velocity=0)


class RecordingRobot:
    """A LeRobot-like follower: records each action with the (fake) time it was sent."""

    def __init__(self, clock, observation=None, connected=True):
        self.clock = clock
        self.observation = observation or {}
        self.is_connected = connected
        self.sent: list[tuple[float, dict]] = []

    def get_observation(self):
        return dict(self.observation)

    def send_action(self, action):
        self.sent.append((self.clock.now, dict(action)))
        return action


class FakeClock:
    def __init__(self):
        self.now = 100.0

    def __call__(self):
        return self.now

    def sleep(self, seconds):
        assert seconds > 0
        self.now += seconds


def test_play_streams_every_frame_on_schedule(so101_calibrated):
    units = lerobot_units(so101_calibrated, SAMPLE_CALIBRATION)
    q = so101_calibrated.random_configurations(2, seed=7) * 0.5
    out = servo_frames(so101_calibrated, units, [0, 0.5], q, gripper=[0, 60])
    clock = FakeClock()
    first = out.frames()[0]
    robot = RecordingRobot(clock, observation=first | {"camera": None})
    report = play(robot, out, clock=clock, sleep=clock.sleep)
    assert report.sent == len(out.t) and report.late == 0
    assert [a for _, a in robot.sent] == out.frames()
    np.testing.assert_allclose([s for s, _ in robot.sent], 100.0 + out.t, atol=1e-9)


def test_play_refuses(so101):
    units = lerobot_units(so101)
    frames = units.to_action(np.zeros((3, 5)), 0.0)
    clock = FakeClock()
    with pytest.raises(PlaybackError, match=r"object has no send_action"):
        play(object(), frames, 30)
    with pytest.raises(PlaybackError, match=r"RecordingRobot is not connected"):
        play(RecordingRobot(clock, connected=False), frames, 30)
    with pytest.raises(PlaybackError, match=r"fps = None: must be finite and > 0"):
        play(RecordingRobot(clock), frames)
    far = RecordingRobot(clock, observation={"elbow_flex.pos": 40.0})
    with pytest.raises(PlaybackError, match=r"first frame elbow_flex.pos = 0 is 40 from the arm"):
        play(far, frames, 30, clock=clock, sleep=clock.sleep)
    assert far.sent == []
    bad = [frames[0] | {"wrist_roll.pos": float("nan")}]
    with pytest.raises(PlaybackError, match=r"frame 0: wrist_roll.pos = nan must be a finite"):
        play(RecordingRobot(clock), bad, 30)
