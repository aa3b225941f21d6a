"""Stream frames to a connected LeRobot robot, one ``send_action`` per frame at a fixed rate.

The robot is duck-typed: anything with ``send_action(dict)`` (LeRobot's ``SOFollower`` and every
``Robot`` subclass); when it has ``is_connected`` it must be True, and when it has
``get_observation`` the first frame must be near the arm's current position (no jump at the
start: move there first, e.g. with frames from :func:`lynxplan.lerobot.export.servo_frames` from
the observed configuration).

Frames are sent on a fixed schedule ``start + k / fps`` (not ``sleep(1/fps)`` after each send, which
drifts by the send time); a frame whose time has passed is sent at once and counted late.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any, NamedTuple

from lynxplan.lerobot.errors import PlaybackError
from lynxplan.lerobot.export import ServoFrames

#: Default largest distance of the first frame from the arm's observed position, per motor, in
#: LeRobot units (degrees, or -100..100 units).
DEFAULT_START_TOLERANCE = 5.0


class PlayReport(NamedTuple):
    """What :func:`play` sent."""

    sent: int
    """Frames sent."""
    late: int
    """Frames sent after their scheduled time (the previous send took longer than a frame)."""
    max_lateness: float
    """Largest delay of a frame behind its schedule, in [s]."""


def _frames(frames: ServoFrames | Sequence[Mapping[str, float]]) -> list[dict[str, float]]:
    if isinstance(frames, ServoFrames):
        return frames.frames()
    rows = [dict(frame) for frame in frames]
    for i, frame in enumerate(rows):
        bad = [
            k for k, v in frame.items() if not isinstance(v, (int, float)) or not math.isfinite(v)
        ]
        if bad:
            raise PlaybackError(f"frame {i}: {bad[0]} = {frame[bad[0]]!r} must be a finite number")
    return rows


def _check_start(robot: Any, first: Mapping[str, float], tolerance: float) -> None:
    observation = robot.get_observation()
    for key, value in first.items():
        if key in observation and abs(float(observation[key]) - value) > tolerance:
            raise PlaybackError(
                f"first frame {key} = {value:.4g} is {abs(float(observation[key]) - value):.4g} "
                f"from the arm's {float(observation[key]):.4g} (more than {tolerance:g}): move the "
                "arm to the first frame first"
            )


def play(
    robot: Any,
    frames: ServoFrames | Sequence[Mapping[str, float]],
    fps: float | None = None,
    *,
    start_tolerance: float | None = DEFAULT_START_TOLERANCE,
    clock: Callable[[], float] = time.monotonic,
    sleep: Callable[[float], object] = time.sleep,
) -> PlayReport:
    """Send each frame with ``robot.send_action`` at ``fps`` frames per second.

    Args:
        robot: A connected LeRobot robot (duck-typed, see the module docstring).
        frames: :class:`ServoFrames` or LeRobot action dicts.
        fps: Frames per second; default: the ``ServoFrames``' own (required for dicts).
        start_tolerance: Largest |first frame - observed position| per motor in LeRobot units;
            None: no check.
        clock, sleep: Time source [s] and sleep function (a test's fake clock).

    Raises:
        PlaybackError: no ``send_action``, a robot not connected, a missing or non-positive fps,
            a non-finite frame value, or a first frame far from the arm.
    """
    if not callable(getattr(robot, "send_action", None)):
        raise PlaybackError(f"{type(robot).__name__} has no send_action(action) method")
    if getattr(robot, "is_connected", True) is False:
        raise PlaybackError(f"{type(robot).__name__} is not connected (call robot.connect())")
    rate = frames.fps if fps is None and isinstance(frames, ServoFrames) else fps
    if rate is None or not (rate > 0 and math.isfinite(rate)):
        raise PlaybackError(f"fps = {rate}: must be finite and > 0")
    rows = _frames(frames)
    if rows and start_tolerance is not None and callable(getattr(robot, "get_observation", None)):
        _check_start(robot, rows[0], start_tolerance)
    start = clock()
    late, worst = 0, 0.0
    for k, frame in enumerate(rows):
        wait = start + k / rate - clock()
        if wait > 0:
            sleep(wait)
        elif k > 0:
            late += 1
            worst = max(worst, -wait)
        robot.send_action(frame)
    return PlayReport(len(rows), late, worst)
