"""LeRobot action/observation frames <-> lynxplan joint vectors, for one frame or many.

LeRobot speaks ``{"shoulder_pan.pos": v, ..., "wrist_roll.pos": v, "gripper.pos": g}``. Its arm
values are, per ``MotorsBus._normalize`` (lerobot 0.4.x), with ``mid = (range_min + range_max)/2``
and ``h = (range_max - range_min) / 2`` in [ticks]:

- degrees (``use_degrees=True``): ``v = (ticks - mid) * 360 / 4095`` (drive_mode not applied);
- range (``use_degrees=False``, LeRobot's default): ``v = +-((ticks - min) / (max - min) * 200 -
  100)`` in -100..100, negated when ``drive_mode`` is 1;
- the gripper always ``g = (ticks - min) / (max - min) * 100`` in 0..100 (``100 - g`` when
  ``drive_mode`` is 1).

With the URDF angle ``q = a * (-1)**drive_mode * (ticks - mid) * 2 pi / 4095`` (``a`` the sign
of the URDF joint axis; :mod:`lynxplan.lerobot.calibration`) each arm joint is one linear map:

- degrees: ``q = a * (-1)**drive_mode * v * pi / 180``;
- range: ``q = a * v / 100 * h * 2 pi / 4095`` (the drive mode cancels: LeRobot applied it).

Degrees need no calibration (drive_mode 0 is assumed, the SO-101's; LeRobot's own kinematics
takes ``deg2rad`` of the readings as URDF angles); the range mode needs one (``h``). The gripper
stays a separate channel in LeRobot's 0..100 (lynxplan's SO-100/SO-101 models hold the jaw fixed).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from lynxplan.lerobot.calibration import (
    GRIPPER_MOTOR,
    Calibration,
    read_calibration,
    urdf_axis_signs,
)
from lynxplan.lerobot.errors import CalibrationError, FrameError

if TYPE_CHECKING:
    from pathlib import Path

    from lynxplan.robots.robot import Robot

#: LeRobot's key suffix of a position action/observation.
POSITION_SUFFIX = ".pos"
#: The gripper channel's key.
GRIPPER_KEY = GRIPPER_MOTOR + POSITION_SUFFIX
#: LeRobot's gripper range (RANGE_0_100).
GRIPPER_RANGE = (0.0, 100.0)


class JointFrames(NamedTuple):
    """LeRobot frames as lynxplan values."""

    q: np.ndarray
    """Arm joint angles, shape (n,) for one frame or (N, n), in [rad] (URDF angles)."""
    gripper: np.ndarray
    """Gripper channel, shape () or (N,), LeRobot's 0..100; NaN where the frame has none."""


class LeRobotUnits:
    """The per-joint linear map between LeRobot values and URDF angles of one robot.

    Attributes:
        motors: Arm motor names, in the robot's joint order.
        use_degrees: LeRobot degrees (True) or -100..100 (False).
        scale: ``q = scale * v`` per joint, shape (n,), in [rad] per LeRobot unit.
        calibration: The calibration used, or None.
    """

    def __init__(
        self,
        motors: Sequence[str],
        scale: np.ndarray,
        use_degrees: bool,
        calibration: Calibration | None,
    ) -> None:
        self.motors = tuple(motors)
        self.scale = np.array(scale, dtype=float)
        self.scale.setflags(write=False)
        self.use_degrees = use_degrees
        self.calibration = calibration

    @property
    def keys(self) -> tuple[str, ...]:
        """Action keys: the arm motors' then the gripper's."""
        return (*(m + POSITION_SUFFIX for m in self.motors), GRIPPER_KEY)

    @property
    def unit(self) -> str:
        """The arm values' unit: ``"deg"`` or ``"-100..100"``."""
        return "deg" if self.use_degrees else "-100..100"

    def __repr__(self) -> str:
        return f"LeRobotUnits(motors={self.motors}, unit={self.unit!r})"

    # -- arrays ----------------------------------------------------------------------------------
    def to_q(self, values: Any) -> np.ndarray:
        """LeRobot arm values, shape (n,) or (N, n) -> URDF angles, same shape, in [rad]."""
        return np.asarray(np.asarray(values, dtype=float) * self.scale)

    def to_values(self, q: Any) -> np.ndarray:
        """URDF angles, shape (n,) or (N, n), in [rad] -> LeRobot arm values, same shape."""
        return np.asarray(np.asarray(q, dtype=float) / self.scale)

    # -- frames ----------------------------------------------------------------------------------
    def to_joints(self, frames: Mapping[str, Any] | Sequence[Mapping[str, Any]]) -> JointFrames:
        """LeRobot frames -> joint angles and gripper channel.

        Args:
            frames: One action/observation dict (values scalars -> shapes (n,) and ();
                values arrays of length N -> (N, n) and (N,)), or a sequence of N dicts.
                Keys other than ``<motor>.pos`` (camera images, ...) are ignored.

        Raises:
            FrameError: an arm motor's key is missing or a value is not finite.
        """
        if isinstance(frames, Mapping):
            values = np.stack([self._column(frames, k) for k in self.keys[:-1]], axis=-1)
            gripper = (
                self._column(frames, GRIPPER_KEY)
                if GRIPPER_KEY in frames
                else np.full(values.shape[:-1], np.nan)
            )
            return JointFrames(self.to_q(values), np.asarray(gripper, dtype=float))
        parts = [self.to_joints(frame) for frame in frames]
        if not parts:
            return JointFrames(np.empty((0, len(self.motors))), np.empty(0))
        return JointFrames(np.stack([p.q for p in parts]), np.stack([p.gripper for p in parts]))

    @staticmethod
    def _column(frame: Mapping[str, Any], key: str) -> np.ndarray:
        if key not in frame:
            keys = ", ".join(map(str, frame)) or "none"
            raise FrameError(f"LeRobot frame has no {key!r}; its keys: {keys}")
        try:
            value = np.asarray(frame[key], dtype=float)
        except (TypeError, ValueError) as exc:
            raise FrameError(f"LeRobot frame {key} = {frame[key]!r}: must be a number") from exc
        if not np.all(np.isfinite(value)):
            raise FrameError(f"LeRobot frame {key} contains NaN or infinite values")
        return value

    def to_action(self, q: Any, gripper: Any = None) -> dict[str, float] | list[dict[str, float]]:
        """Joint angles -> LeRobot action dicts.

        Args:
            q: Shape (n,) -> one dict, or (N, n) -> a list of N dicts, in [rad].
            gripper: Gripper channel (0..100), scalar or shape (N,); None: no gripper key.
        """
        values = self.to_values(q)
        grip = None if gripper is None else np.broadcast_to(gripper, values.shape[:-1])
        keys = self.keys

        def one(row: np.ndarray, g: Any) -> dict[str, float]:
            frame = {k: float(v) for k, v in zip(keys, row, strict=False)}
            if g is not None:
                frame[GRIPPER_KEY] = float(g)
            return frame

        if values.ndim == 1:
            return one(values, grip)
        return [one(values[i], None if grip is None else grip[i]) for i in range(len(values))]


def lerobot_units(
    robot: Robot,
    calibration: str | Path | Mapping[str, Any] | Calibration | None = None,
    *,
    use_degrees: bool = True,
) -> LeRobotUnits:
    """The units of ``robot``'s arm joints as a LeRobot SO follower reads them.

    Args:
        robot: The model (``load_robot("so101")`` or :func:`load_calibrated`); its arm joints are
            named as LeRobot's motors.
        calibration: The arm's LeRobot calibration (file, mapping or :class:`Calibration`);
            required when ``use_degrees`` is False.
        use_degrees: The follower's ``use_degrees`` setting.

    Raises:
        CalibrationError: range units without a calibration, or a joint without its motor.
    """
    cal = None if calibration is None else read_calibration(calibration)
    axis = urdf_axis_signs(robot)
    names = robot.joint_names
    if use_degrees:
        drive = [0 if cal is None else cal.motor(n).drive_mode for n in names]
        scale = [axis[n] * (-1) ** d * math.pi / 180.0 for n, d in zip(names, drive, strict=True)]
    else:
        if cal is None:
            raise CalibrationError(
                "missing", "the -100..100 units (use_degrees=False) need the arm's calibration"
            )
        scale = [axis[n] * cal.motor(n).half_range / 100.0 for n in names]
    return LeRobotUnits(names, np.array(scale), use_degrees, cal)
