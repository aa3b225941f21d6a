"""``play`` drives LeRobot's own ``SOFollower`` (lerobot 0.4.x), its serial port replaced by six
virtual STS3215 servos (tests/lerobot/virtual_so101.py): LeRobot's connect, observation and
``send_action`` code runs as on a real arm, down to the ``Goal_Position`` bytes on the bus.

LeRobot's robots import torch, so this runs in the interpreter named by
``LYNXPLAN_LEROBOT_PYTHON`` when that one has ``lerobot`` and ``feetech-servo-sdk`` (the
``lerobot-dataset`` venv of test_dataset_lerobot.py does not: add them, e.g.
``pip install --no-deps lerobot==0.4.4`` and ``pip install draccus==0.10.0 deepdiff pyserial
feetech-servo-sdk termcolor accelerate einops`` beside torch), and is skipped, with this reason,
otherwise.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from lynxplan.lerobot import PlaybackError, lerobot_units, play, servo_frames
from tests.lerobot.sample import SAMPLE_CALIBRATION

LEROBOT_PYTHON = os.environ.get("LYNXPLAN_LEROBOT_PYTHON", "")
SCRIPT = Path(__file__).with_name("virtual_so101.py")
ARM = ("shoulder_pan", "shoulder_lift", "elbow_flex", "wrist_flex", "wrist_roll")


def _has_lerobot_robots() -> bool:
    if not LEROBOT_PYTHON or not Path(LEROBOT_PYTHON).is_file():
        return False
    probe = "import scservo_sdk, lerobot.robots.so_follower"
    done = subprocess.run([LEROBOT_PYTHON, "-c", probe], capture_output=True, timeout=300)
    return done.returncode == 0


pytestmark = pytest.mark.skipif(
    not _has_lerobot_robots(),
    reason="LeRobot's SOFollower needs lerobot 0.4.x + torch (not in CI): set "
    "LYNXPLAN_LEROBOT_PYTHON to a Python with lerobot and feetech-servo-sdk (see this module)",
)


def lerobot_ticks(value: float, motor: str, use_degrees: bool) -> float:
    """The goal of a LeRobot value, by the issue's documented mapping (before LeRobot's int())."""
    c = SAMPLE_CALIBRATION[motor]
    lo, hi, drive = c["range_min"], c["range_max"], c["drive_mode"]
    if motor == "gripper":
        return lo + (100 - value if drive else value) / 100 * (hi - lo)
    if use_degrees:
        return (lo + hi) / 2 + value * 4095 / 360
    return lo + ((-value if drive else value) + 100) / 200 * (hi - lo)


class Follower:
    """LeRobot's SOFollower in the side interpreter, seen through its methods."""

    def __init__(self, folder: Path, use_degrees: bool, start: dict[str, int]) -> None:
        args = [LEROBOT_PYTHON, str(SCRIPT), str(folder), "my_follower", str(int(use_degrees))]
        self.process = subprocess.Popen(
            [*args, json.dumps(start)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=sys.stderr,
            text=True,
            env={**os.environ, "HF_HUB_OFFLINE": "1"},
        )
        self.version = self._answer()["lerobot"]

    def _answer(self):
        line = self.process.stdout.readline()
        assert line, "the SOFollower process ended (its stderr is above)"
        return json.loads(line)

    def _call(self, op: str, **args):
        self.process.stdin.write(json.dumps({"op": op, **args}) + "\n")
        self.process.stdin.flush()
        return self._answer()

    @property
    def is_connected(self) -> bool:
        return self._call("connected")

    def get_observation(self) -> dict[str, float]:
        return self._call("observe")

    def send_action(self, action: dict[str, float]) -> dict[str, float]:
        return self._call("send", action=action)

    def goals(self) -> list[dict[int, int]]:
        return [{int(k): v for k, v in goal.items()} for goal in self._call("goals")]

    def close(self) -> None:
        self.process.stdin.close()
        self.process.wait(timeout=60)


@pytest.fixture
def follower_folder(tmp_path):
    (tmp_path / "my_follower.json").write_text(json.dumps(SAMPLE_CALIBRATION))
    return tmp_path


def _frames(robot, use_degrees):
    units = lerobot_units(robot, SAMPLE_CALIBRATION, use_degrees=use_degrees)
    q = robot.random_configurations(3, seed=5) * 0.5
    return servo_frames(robot, units, [0.0, 0.6, 1.2], q, gripper=[10, 80, 40], fps=30)


def _start_ticks(frames, use_degrees) -> dict[str, int]:
    first = frames.frames()[0]
    return {m: round(lerobot_ticks(first[f"{m}.pos"], m, use_degrees)) for m in SAMPLE_CALIBRATION}


class FakeClock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now

    def sleep(self, seconds: float) -> None:
        self.now += seconds


@pytest.mark.parametrize("use_degrees", [True, False])
def test_play_lands_every_frame_as_goal_ticks(so101_calibrated, follower_folder, use_degrees):
    frames = _frames(so101_calibrated, use_degrees)
    follower = Follower(follower_folder, use_degrees, _start_ticks(frames, use_degrees))
    try:
        assert follower.is_connected
        clock = FakeClock()
        report = play(follower, frames, clock=clock, sleep=clock.sleep)
        goals = follower.goals()
    finally:
        follower.close()
    assert report.sent == len(frames.t) == len(goals) and report.late == 0
    ids = {m: SAMPLE_CALIBRATION[m]["id"] for m in SAMPLE_CALIBRATION}
    for frame, goal, q in zip(frames.frames(), goals, frames.q, strict=True):
        assert set(goal) == set(ids.values())
        for motor, servo in ids.items():
            # LeRobot truncates to whole ticks: within one tick of the documented mapping
            assert abs(goal[servo] - lerobot_ticks(frame[f"{motor}.pos"], motor, use_degrees)) < 1
        # ... and the ticks are the frame's URDF angles (axis +1 on the SO-101, drive_mode sign)
        for j, motor in enumerate(ARM):
            c = SAMPLE_CALIBRATION[motor]
            angle = (-1) ** c["drive_mode"] * (
                goal[ids[motor]] - (c["range_min"] + c["range_max"]) / 2
            )
            assert abs(angle * 2 * math.pi / 4095 - q[j]) <= 2 * math.pi / 4095 * 1.0001
    np.testing.assert_allclose(frames.gripper[[0, -1]], [10, 40])
    print(f"LeRobot SOFollower: lerobot {follower.version}")


def test_play_refuses_a_first_frame_far_from_the_arm(so101_calibrated, follower_folder):
    frames = _frames(so101_calibrated, True)
    start = _start_ticks(frames, True)
    start["elbow_flex"] += 200  # 17.6 degrees away from the first frame
    follower = Follower(follower_folder, True, start)
    try:
        with pytest.raises(PlaybackError, match=r"first frame elbow_flex.pos = .* from the arm's"):
            play(follower, frames)
        assert follower.goals() == []  # nothing was sent
    finally:
        follower.close()
