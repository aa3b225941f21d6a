"""The bridge to LeRobot (huggingface/lerobot): SO-100/SO-101 arms driven by ``send_action``.

- :mod:`~lynxplan.lerobot.calibration`: a LeRobot calibration file -> a model whose joint limits
  are the calibrated ranges (:func:`load_calibrated`), with the documented ticks <-> URDF mapping;
- :mod:`~lynxplan.lerobot.units`: action/observation dicts <-> joint vectors
  (:func:`lerobot_units`);
- :mod:`~lynxplan.lerobot.track`: continuous IK of a stream of tool targets in LeRobot units;
- :mod:`~lynxplan.lerobot.servo`: the STS3215's velocity and acceleration figures;
- :mod:`~lynxplan.lerobot.export`: any trajectory -> servo-safe frames at an fps, and CSV;
- :mod:`~lynxplan.lerobot.play`: stream frames to a connected LeRobot robot;
- :mod:`~lynxplan.lerobot.dataset`: frames as a LeRobot dataset (v3.0), a recorded episode read
  back (pyarrow and pandas: the ``[lerobot]`` extra);
- :mod:`~lynxplan.lerobot.recorded`: recorded joint positions -> tool path, limit and collision
  checks, figures and meshcat HTML.

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
from lynxplan.lerobot.dataset import RecordedEpisode, read_episode, write_dataset
from lynxplan.lerobot.errors import CalibrationError, CalibrationWarning, FrameError, PlaybackError
from lynxplan.lerobot.export import ServoFrames, read_csv, servo_frames, servo_frames_of, write_csv
from lynxplan.lerobot.play import PlayReport, play
from lynxplan.lerobot.recorded import RecordedCheck, check_recorded, joints_of, write_recorded
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
    "RecordedCheck",
    "RecordedEpisode",
    "ServoFrames",
    "calibrated_limits",
    "check_recorded",
    "default_calibration_path",
    "joints_of",
    "lerobot_units",
    "load_calibrated",
    "play",
    "read_calibration",
    "read_csv",
    "read_episode",
    "servo_frames",
    "servo_frames_of",
    "track_targets",
    "write_csv",
    "write_dataset",
    "write_recorded",
]
