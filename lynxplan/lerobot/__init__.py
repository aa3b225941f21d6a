"""The bridge to LeRobot (huggingface/lerobot): SO-100/SO-101 arms driven by ``send_action``.

- :mod:`~lynxplan.lerobot.calibration`: a LeRobot calibration file -> a model whose joint limits
  are the calibrated ranges (:func:`load_calibrated`), with the documented ticks <-> URDF mapping;
- :mod:`~lynxplan.lerobot.units`: action/observation dicts <-> joint vectors
  (:func:`lerobot_units`);
- :mod:`~lynxplan.lerobot.track`: continuous IK of a stream of tool targets in LeRobot units;
- :mod:`~lynxplan.lerobot.servo`: the STS3215's velocity and acceleration figures;
- :mod:`~lynxplan.lerobot.export`: any trajectory -> servo-safe frames at an fps, and CSV;
- :mod:`~lynxplan.lerobot.play`: stream frames to a connected LeRobot robot.

Nothing here imports LeRobot itself: the robot given to :func:`play` is duck-typed.
"""

from __future__ import annotations

from lynxplan.lerobot.calibration import (
    Calibration,
    MotorCalibration,
    calibrated_limits,
    default_calibration_path,
    load_calibrated,
    read_calibration,
)
from lynxplan.lerobot.errors import CalibrationError, CalibrationWarning, FrameError, PlaybackError
from lynxplan.lerobot.export import ServoFrames, read_csv, servo_frames, servo_frames_of, write_csv
from lynxplan.lerobot.play import PlayReport, play
from lynxplan.lerobot.track import LeRobotTrack, track_targets
from lynxplan.lerobot.units import JointFrames, LeRobotUnits, lerobot_units

__all__ = [
    "Calibration",
    "CalibrationError",
    "CalibrationWarning",
    "FrameError",
    "JointFrames",
    "LeRobotTrack",
    "LeRobotUnits",
    "MotorCalibration",
    "PlayReport",
    "PlaybackError",
    "ServoFrames",
    "calibrated_limits",
    "default_calibration_path",
    "lerobot_units",
    "load_calibrated",
    "play",
    "read_calibration",
    "read_csv",
    "servo_frames",
    "servo_frames_of",
    "track_targets",
    "write_csv",
]
