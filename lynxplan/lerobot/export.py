"""Any joint trajectory -> servo-safe LeRobot action frames at a fixed fps, and their CSV.

The trajectory (samples ``t``, ``q``: a plan, a task's samples, a tracked stream) is resampled at
``fps`` by linear interpolation between its samples (so the frames stay on its joint path, the
path lynxplan checked for limits and collisions) and slowed down uniformly, by the smallest factor
found, until every frame is within the servo's bounds: with the arm at rest before the first frame
and after the last, each joint's ``|q[k+1] - q[k]| * fps <= max_velocity`` and
``|q[k+1] - 2 q[k] + q[k-1]| * fps**2 <= max_acceleration``; the gripper too when the calibration
gives its range. The figures are the STS3215's (:mod:`lynxplan.lerobot.servo`).

Uniform slowing keeps the path and the relative timing; it is not time-optimal (a plan timed by
lynxplan within tighter joint limits needs none).
"""

from __future__ import annotations

import math
import os
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from lynxplan.exceptions import InputError
from lynxplan.lerobot.calibration import GRIPPER_MOTOR, RADIANS_PER_TICK
from lynxplan.lerobot.servo import DEFAULT_FPS, DEFAULT_MAX_ACCELERATION, DEFAULT_MAX_VELOCITY
from lynxplan.lerobot.units import GRIPPER_KEY, GRIPPER_RANGE, LeRobotUnits

if TYPE_CHECKING:
    from lynxplan.robots.robot import Robot

#: Frames within a bound up to this relative rounding count as within it.
BOUND_RELATIVE_TOLERANCE = 1e-9
#: Joint angles this far past a limit [rad] are rounding (a plan's end on its limit), not an error.
LIMIT_TOLERANCE = 1e-9
#: Bisection steps of the slow-down factor (to 2**-30 of the bracket).
SLOWDOWN_BISECTIONS = 30
#: Longest frame sequence produced (one hour at 30 fps), a guard against absurd inputs.
MAX_FRAMES = 108_000


class ServoFrames(NamedTuple):
    """Action frames at a fixed rate within the servo's velocity and acceleration bounds."""

    fps: float
    """Frame rate, in [frames/s]."""
    t: np.ndarray
    """Frame times from the first, shape (K,), in [s] (``k / fps``)."""
    q: np.ndarray
    """Joint angles, shape (K, n), in [rad]."""
    gripper: np.ndarray
    """Gripper channel, shape (K,), 0..100; NaN when the trajectory had none."""
    values: np.ndarray
    """The arm values in LeRobot units, shape (K, n)."""
    time_scale: float
    """How much slower than the input the frames run (1: as given)."""
    peak_velocity: np.ndarray
    """Largest |joint speed| of the frames, shape (n,), in [rad/s] (finite differences)."""
    peak_acceleration: np.ndarray
    """Largest |joint acceleration| of the frames, shape (n,), in [rad/s^2]."""
    units: LeRobotUnits
    """The units of ``values``."""

    @property
    def keys(self) -> tuple[str, ...]:
        """The action keys of a frame (with ``gripper.pos`` when there is a gripper channel)."""
        keys = self.units.keys
        return keys if not np.isnan(self.gripper).all() else keys[:-1]

    def frames(self) -> list[dict[str, float]]:
        """The LeRobot action dicts, one per frame."""
        grip = None if np.isnan(self.gripper).all() else self.gripper
        rows = self.units.to_action(self.q, grip)
        return rows if isinstance(rows, list) else [rows]


def _samples(robot: Robot, t: Any, q: Any) -> tuple[np.ndarray, np.ndarray]:
    times = np.asarray(t, dtype=float)
    joints = np.asarray(q, dtype=float)
    if times.ndim != 1 or times.size < 1 or joints.shape != (times.size, robot.nq):
        raise InputError(
            f"trajectory: t must have shape (N,) and q ({times.size}, {robot.nq}). "
            f"Got: {times.shape} and {joints.shape}"
        )
    if not (np.all(np.isfinite(times)) and np.all(np.isfinite(joints))):
        raise InputError("trajectory: t and q must be finite")
    if np.any(np.diff(times) <= 0):
        raise InputError("trajectory: t must be strictly increasing")
    lower, upper = robot.limits.lower, robot.limits.upper
    outside = np.argwhere((joints < lower - LIMIT_TOLERANCE) | (joints > upper + LIMIT_TOLERANCE))
    if outside.size:
        k, j = (int(v) for v in outside[0])
        raise InputError(
            f"trajectory: sample {k}, {robot.joint_names[j]} = {joints[k, j]:.6g} rad is outside "
            f"the joint limits [{lower[j]:.6g}, {upper[j]:.6g}]"
        )
    return times - times[0], np.clip(joints, lower, upper)


def _resample(times: np.ndarray, channels: np.ndarray, scale: float, fps: float) -> np.ndarray:
    """``channels`` (N, m) at the frame times of the trajectory slowed by ``scale``."""
    duration = scale * float(times[-1])
    count = math.ceil(duration * fps - 1e-9) + 1
    if count > MAX_FRAMES:
        raise InputError(
            f"trajectory of {duration:.4g} s at {fps:g} fps needs {count} frames, more than "
            f"{MAX_FRAMES}; give a shorter trajectory or higher servo bounds"
        )
    frame_times = np.minimum(np.arange(count) / fps, duration) / scale
    return np.column_stack([np.interp(frame_times, times, c) for c in channels.T])


def _peaks(frames: np.ndarray, fps: float) -> tuple[np.ndarray, np.ndarray]:
    """Peak |velocity| and |acceleration| per channel, the arm at rest before and after."""
    padded = np.vstack((frames[:1], frames[:1], frames, frames[-1:], frames[-1:]))
    velocity = np.abs(np.diff(padded, axis=0)).max(axis=0) * fps
    acceleration = np.abs(np.diff(padded, n=2, axis=0)).max(axis=0) * fps**2
    return velocity, acceleration


def _excess(frames: np.ndarray, fps: float, v_max: np.ndarray, a_max: np.ndarray) -> float:
    """The largest ratio of a frame figure to its bound (<= 1: within the bounds)."""
    velocity, acceleration = _peaks(frames, fps)
    return float(max((velocity / v_max).max(), (acceleration / a_max).max()))


def _slowdown(
    times: np.ndarray, channels: np.ndarray, fps: float, v_max: np.ndarray, a_max: np.ndarray
) -> float:
    """The smallest uniform slow-down found that puts every frame within the bounds."""
    limit = 1.0 + BOUND_RELATIVE_TOLERANCE
    excess = _excess(_resample(times, channels, 1.0, fps), fps, v_max, a_max)
    if excess <= limit:
        return 1.0
    low, high = 1.0, max(excess, 1.0 + 1e-6)
    while _excess(_resample(times, channels, high, fps), fps, v_max, a_max) > limit:
        low, high = high, 2.0 * high  # the resampling can overshoot a factor's promise
    for _ in range(SLOWDOWN_BISECTIONS):
        middle = 0.5 * (low + high)
        if _excess(_resample(times, channels, middle, fps), fps, v_max, a_max) <= limit:
            high = middle
        else:
            low = middle
    return high


def _gripper_radians_per_unit(units: LeRobotUnits) -> float | None:
    """The gripper motor's angle per LeRobot unit [rad], when the calibration gives it."""
    if units.calibration is None or GRIPPER_MOTOR not in units.calibration.motors:
        return None
    motor = units.calibration.motors[GRIPPER_MOTOR]
    return (motor.range_max - motor.range_min) * RADIANS_PER_TICK / 100.0


def servo_frames(
    robot: Robot,
    units: LeRobotUnits,
    t: Any,
    q: Any,
    *,
    gripper: Any = None,
    fps: float = DEFAULT_FPS,
    max_velocity: float = DEFAULT_MAX_VELOCITY,
    max_acceleration: float = DEFAULT_MAX_ACCELERATION,
) -> ServoFrames:
    """A trajectory as servo-safe frames at ``fps`` (module docstring).

    Args:
        robot: The model whose limits the trajectory must respect.
        units: The LeRobot units of the frames (:func:`~lynxplan.lerobot.lerobot_units`).
        t: Sample times, shape (N,), strictly increasing, in [s].
        q: Joint angles, shape (N, n), in [rad].
        gripper: Gripper channel per sample, shape (N,) or scalar, 0..100 (clipped into it).
        fps: Frame rate, in [frames/s].
        max_velocity: Joint speed bound, in [rad/s] (default: half the STS3215's no-load speed).
        max_acceleration: Joint acceleration bound, in [rad/s^2] (default: half LeRobot's
            servo profile acceleration).

    Raises:
        InputError: malformed samples, a sample outside the joint limits, a non-positive bound.
    """
    for name, value in (
        ("fps", fps),
        ("max_velocity", max_velocity),
        ("max_acceleration", max_acceleration),
    ):
        if not (value > 0 and math.isfinite(value)):
            raise InputError(f"{name} = {value}: must be finite and > 0")
    times, joints = _samples(robot, t, q)
    n = robot.nq
    grip = (
        None if gripper is None else np.broadcast_to(np.asarray(gripper, dtype=float), times.shape)
    )
    if grip is not None and not np.all(np.isfinite(grip)):
        raise InputError("gripper must be finite (0..100)")
    channels, v_max, a_max = joints, np.full(n, max_velocity), np.full(n, max_acceleration)
    per_unit = _gripper_radians_per_unit(units)
    if grip is not None:
        clipped = np.clip(grip, *GRIPPER_RANGE)
        channels = np.column_stack((joints, clipped))
        # the gripper motor's own bounds when the calibration gives its range; else unbounded
        v_max = np.append(v_max, max_velocity / per_unit if per_unit else math.inf)
        a_max = np.append(a_max, max_acceleration / per_unit if per_unit else math.inf)
    time_scale = _slowdown(times, channels, fps, v_max, a_max) if len(times) > 1 else 1.0
    frames = _resample(times, channels, time_scale, fps) if len(times) > 1 else channels
    q_frames = np.ascontiguousarray(frames[:, :n])
    grip_frames = frames[:, n] if grip is not None else np.full(len(frames), np.nan)
    velocity, acceleration = _peaks(q_frames, fps)
    out = ServoFrames(
        float(fps),
        np.arange(len(frames)) / fps,
        q_frames,
        np.ascontiguousarray(grip_frames),
        units.to_values(q_frames),
        time_scale,
        velocity,
        acceleration,
        units,
    )
    for array in out[1:8]:
        if isinstance(array, np.ndarray):
            array.setflags(write=False)
    return out


def servo_frames_of(
    robot: Robot, units: LeRobotUnits, trajectory: Any, **options: Any
) -> ServoFrames:
    """:func:`servo_frames` of an object with ``t`` and ``q`` (``lynxplan.plan``'s
    ``PlannedTrajectory``, a plan's samples) or with ``sample()`` giving one (a ``Plan``)."""
    if not (hasattr(trajectory, "t") and hasattr(trajectory, "q")) and hasattr(
        trajectory, "sample"
    ):
        trajectory = trajectory.sample()
    if not (hasattr(trajectory, "t") and hasattr(trajectory, "q")):
        raise InputError(
            f"{type(trajectory).__name__} has no t and q samples (nor a sample() giving them)"
        )
    return servo_frames(robot, units, trajectory.t, trajectory.q, **options)


def write_csv(frames: ServoFrames, path: str | Path, *, overwrite: bool = False) -> Path:
    """Write the frames as CSV: a header ``t`` then the action keys, one row per frame
    (``t`` in [s], values in LeRobot units, shortest exact float text).

    Raises:
        InputError: the file exists and ``overwrite`` is False (lynxplan does not replace a
            file it was not asked to), or its folder does not exist.
    """
    target = Path(path)
    if target.exists() and not overwrite:
        raise InputError(f"{target} exists; pass overwrite=True to replace it")
    if not target.parent.is_dir():
        raise InputError(f"{target.parent} is not a folder")
    keys = frames.keys
    columns = [frames.t, *frames.values.T]
    if GRIPPER_KEY in keys:
        columns.append(frames.gripper)
    lines = [",".join(("t", *keys))]
    lines += [",".join(repr(float(v)) for v in row) for row in zip(*columns, strict=True)]
    descriptor, temporary = tempfile.mkstemp(prefix=f".{target.name}.", dir=target.parent)
    try:
        with os.fdopen(descriptor, "w", encoding="utf-8", newline="\n") as stream:
            stream.write("\n".join(lines) + "\n")
        os.replace(temporary, target)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
    return target


def read_csv(path: str | Path) -> tuple[np.ndarray, list[dict[str, float]]]:
    """Frames written by :func:`write_csv`: the times (K,) [s] and the action dicts.

    Raises:
        InputError: no such file, or a file without a ``t`` column or with non-numbers.
    """
    source = Path(path)
    if not source.is_file():
        raise InputError(f"{source}: file not found")
    lines = source.read_text(encoding="utf-8").splitlines()
    header = lines[0].split(",") if lines else []
    if not header or header[0] != "t":
        raise InputError(f"{source}: first column must be t (a lynxplan frames CSV)")
    try:
        rows = np.array([[float(v) for v in line.split(",")] for line in lines[1:]], dtype=float)
    except ValueError as exc:
        raise InputError(f"{source}: {exc}") from exc
    rows = rows.reshape(-1, len(header))
    frames = [dict(zip(header[1:], map(float, row[1:]), strict=True)) for row in rows]
    return rows[:, 0], frames
