"""LeRobot calibration files and the joint limits they give an SO-100/SO-101 model.

A LeRobot follower arm keeps one JSON file per arm (``$HF_LEROBOT_HOME/calibration/robots/
so_follower/<id>.json``; releases before 0.4: ``so101_follower/``) holding, per motor,
``{id, drive_mode, homing_offset, range_min, range_max}``. ``range_min``/``range_max`` are the
servo's position readings (ticks, 4096 per turn, after the servo subtracts ``homing_offset``) at
the two ends of the range the user swept during ``lerobot-calibrate``.

The mapping to the URDF's joint angles (the convention of LeRobot's own kinematics, which feeds
``deg2rad`` of its degree readings to the URDF; see :mod:`lynxplan.lerobot.units`):

    q [rad] = s * (ticks - (range_min + range_max) / 2) * 2 pi / 4095,
    s = (URDF axis sign) * (-1) ** drive_mode

so the URDF's zero is the middle of the calibrated range (LeRobot's 0 degrees) and the calibrated
range is the symmetric interval ``|q| <= (range_max - range_min) / 2 * 2 pi / 4095``. 4095 (the
resolution less one) is the divisor LeRobot's ``MotorsBus._normalize`` uses.

:func:`load_calibrated` gives a :class:`~lynxplan.robots.Robot` whose joint limits are these
calibrated ranges: the arm's real reach, which LeRobot's own normalisation clamps to. Where a
calibrated range passes the URDF's limits (LeRobot issue #4046: a joint calibrated to -103 degrees
against a -100 degree URDF limit made the solver jump to another configuration) the calibrated
range is used and one warning line names every such joint.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from lynxplan.lerobot.errors import CalibrationError, CalibrationWarning

if TYPE_CHECKING:
    from lynxplan.robots.robot import Robot

#: The STS3215's encoder: ticks per turn (12 bits).
TICKS_PER_TURN = 4096
#: LeRobot's divisor from ticks to degrees (``model_resolution_table["sts3215"] - 1``).
LEROBOT_TICKS_DIVISOR = TICKS_PER_TURN - 1
#: One tick in [rad] as LeRobot counts it (2 pi / 4095).
RADIANS_PER_TICK = 2.0 * math.pi / LEROBOT_TICKS_DIVISOR
#: SO-100/SO-101 arm motors in bus order (ids 1..5), named as the URDF's joints.
ARM_MOTORS = ("shoulder_pan", "shoulder_lift", "elbow_flex", "wrist_flex", "wrist_roll")
#: The gripper motor (id 6): LeRobot reads it 0..100 over its calibrated range.
GRIPPER_MOTOR = "gripper"
_KEYS = ("id", "drive_mode", "homing_offset", "range_min", "range_max")


@dataclass(frozen=True)
class MotorCalibration:
    """One motor's entry of a LeRobot calibration file (LeRobot's ``MotorCalibration``).

    Attributes:
        id: Bus id.
        drive_mode: 0 or 1; 1 reverses the motor's direction relative to the joint.
        homing_offset: Offset the servo subtracts from its raw position, in [ticks].
        range_min, range_max: Ends of the calibrated range, in [ticks] (range_min < range_max).
    """

    id: int
    drive_mode: int
    homing_offset: int
    range_min: int
    range_max: int

    @property
    def middle(self) -> float:
        """Middle of the calibrated range, in [ticks] (LeRobot's 0 degrees)."""
        return (self.range_min + self.range_max) / 2.0

    @property
    def half_range(self) -> float:
        """Half the calibrated range, in [rad] (LeRobot's ticks-to-angle scale)."""
        return (self.range_max - self.range_min) / 2.0 * RADIANS_PER_TICK


@dataclass(frozen=True)
class Calibration:
    """A LeRobot calibration: every motor's entry, by motor name.

    Attributes:
        motors: Motor name -> :class:`MotorCalibration`.
        source: Where it was read (a path, or ``"calibration"`` for a mapping).
    """

    motors: Mapping[str, MotorCalibration]
    source: str

    def motor(self, name: str) -> MotorCalibration:
        """The entry of one motor.

        Raises:
            CalibrationError: no such motor (the message lists those there are).
        """
        if name not in self.motors:
            raise CalibrationError(
                self.source, f"no motor {name!r}; motors: {', '.join(self.motors) or 'none'}"
            )
        return self.motors[name]


def _integer(source: str, motor: str, key: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or value != int(value):
        raise CalibrationError(source, f"{motor}.{key} = {value!r}: must be an integer")
    return int(value)


def _motor(source: str, name: str, entry: Any) -> MotorCalibration:
    if not isinstance(entry, Mapping):
        raise CalibrationError(source, f"{name}: must be an object with keys {', '.join(_KEYS)}")
    missing = [k for k in _KEYS if k not in entry]
    if missing:
        raise CalibrationError(source, f"{name}: missing {', '.join(missing)}")
    values = {k: _integer(source, name, k, entry[k]) for k in _KEYS}
    if values["drive_mode"] not in (0, 1):
        raise CalibrationError(
            source, f"{name}.drive_mode = {values['drive_mode']}: must be 0 or 1"
        )
    low, high = values["range_min"], values["range_max"]
    if not 0 <= low < high < TICKS_PER_TURN:
        raise CalibrationError(
            source,
            f"{name}: range_min = {low}, range_max = {high}: must be "
            f"0 <= range_min < range_max <= {TICKS_PER_TURN - 1}",
        )
    return MotorCalibration(**values)


def read_calibration(calibration: str | Path | Mapping[str, Any] | Calibration) -> Calibration:
    """A LeRobot calibration from its JSON file (or the file's content as a mapping).

    Raises:
        CalibrationError: missing or unreadable file, a motor without one of the five keys, a
            non-integer value, ``drive_mode`` not 0/1, or ``range_min >= range_max``.
    """
    if isinstance(calibration, Calibration):
        return calibration
    if isinstance(calibration, Mapping):
        source, content = "calibration", calibration
    else:
        path = Path(calibration)
        source = str(path)
        if not path.is_file():
            raise CalibrationError(source, "file not found")
        try:
            content = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise CalibrationError(source, f"not readable JSON ({exc})") from exc
    if not isinstance(content, Mapping) or not content:
        raise CalibrationError(source, "must be a JSON object of motors")
    motors = {str(name): _motor(source, str(name), entry) for name, entry in content.items()}
    return Calibration(motors, source)


def default_calibration_path(arm_id: str) -> Path:
    """Where LeRobot keeps the calibration of the follower arm ``arm_id``:
    ``$HF_LEROBOT_HOME/calibration/robots/so_follower/<id>.json`` (default home:
    ``$HF_HOME/lerobot``, else ``~/.cache/huggingface/lerobot``), or the ``so101_follower/``
    folder of earlier releases when only that file exists."""
    home = os.environ.get("HF_LEROBOT_HOME")
    if home is None:
        hf_home = os.environ.get("HF_HOME", str(Path.home() / ".cache" / "huggingface"))
        home = str(Path(hf_home) / "lerobot")
    robots = Path(home).expanduser() / "calibration" / "robots"
    current = robots / "so_follower" / f"{arm_id}.json"
    older = robots / "so101_follower" / f"{arm_id}.json"
    return older if not current.is_file() and older.is_file() else current


def urdf_axis_signs(robot: Robot) -> dict[str, int]:
    """The sign of each arm joint's URDF axis (of its largest component): +1 for ``0 0 1``,
    -1 for ``0 0 -1``; joints without an ``<axis>`` (URDF default ``1 0 0``) give +1."""
    import xml.etree.ElementTree as ET

    root = ET.fromstring(robot.urdf_path.read_text(encoding="utf-8"))
    signs = {}
    for joint in root.iter("joint"):
        axis = joint.find("axis")
        xyz = [
            float(v) for v in ((axis.get("xyz") if axis is not None else None) or "1 0 0").split()
        ]
        signs[str(joint.get("name"))] = 1 if xyz[int(np.argmax(np.abs(xyz)))] >= 0 else -1
    return {name: signs.get(name, 1) for name in robot.joint_names}


class CalibratedLimits(NamedTuple):
    """Joint limits from a calibration, and how they compare with the URDF's."""

    position: np.ndarray
    """Calibrated position limits in the robot's joint order, shape (n, 2), in [rad]."""
    beyond_urdf: tuple[str, ...]
    """Joints whose calibrated range passes the URDF's limits."""
    message: str | None
    """The one-line warning naming those joints, or None."""


def calibrated_limits(robot: Robot, calibration: Calibration) -> CalibratedLimits:
    """The calibrated range of every arm joint mapped to the URDF's angles (module docstring).

    Raises:
        CalibrationError: an arm joint of ``robot`` has no motor in the calibration.
    """
    half = np.array([calibration.motor(name).half_range for name in robot.joint_names])
    position = np.column_stack((-half, half))
    position.setflags(write=False)
    urdf = robot.limits.position
    beyond = tuple(
        name
        for name, (lo, hi), (u_lo, u_hi) in zip(robot.joint_names, position, urdf, strict=True)
        if lo < u_lo or hi > u_hi
    )
    message = None
    if beyond:
        parts = [
            f"{name} {math.degrees(position[i, 0]):+.1f}..{math.degrees(position[i, 1]):+.1f} deg"
            f" (URDF {math.degrees(urdf[i, 0]):+.1f}..{math.degrees(urdf[i, 1]):+.1f})"
            for i, name in enumerate(robot.joint_names)
            if name in beyond
        ]
        message = (
            f"calibration {calibration.source}: calibrated range passes the URDF limits: "
            f"{'; '.join(parts)}; using the calibrated range"
        )
    return CalibratedLimits(position, beyond, message)


def load_calibrated(
    name_or_urdf: str | Path,
    calibration: str | Path | Mapping[str, Any] | Calibration,
    *,
    tool: str | None = None,
    base: Any = None,
    package_dirs: list[str] | tuple[str, ...] | None = None,
    srdf: str | Path | None = None,
) -> Robot:
    """A robot (``"so101"``, ``"so100"`` or a URDF whose arm joints are named as LeRobot's
    motors) whose joint limits are the calibrated ranges of a LeRobot calibration.

    Warns (:class:`CalibrationWarning`, one line) when a calibrated range passes the URDF's
    limits; the calibrated range is used. ``tool``, ``base``, ``package_dirs``, ``srdf``: as
    :func:`lynxplan.load_robot` (``load_robot(name, calibration=PATH)`` calls this).

    Raises:
        CalibrationError: unreadable calibration, or an arm joint without its motor.
        UnknownRobotError, ModelError: as :func:`lynxplan.load_robot`.
    """
    from lynxplan.robots.loading import load_model
    from lynxplan.robots.robot import Robot

    cal = read_calibration(calibration)
    loaded, builtin = load_model(
        name_or_urdf, tool=tool, base=base, package_dirs=package_dirs, srdf=srdf
    )
    limits = calibrated_limits(Robot(loaded, builtin), cal)
    if limits.message is not None:
        warnings.warn(limits.message, CalibrationWarning, stacklevel=2)
    model = loaded.model.copy()
    lower, upper = model.lowerPositionLimit.copy(), model.upperPositionLimit.copy()
    lower[: len(limits.position)] = limits.position[:, 0]
    upper[: len(limits.position)] = limits.position[:, 1]
    model.lowerPositionLimit, model.upperPositionLimit = lower, upper
    return Robot(dataclasses.replace(loaded, model=model), builtin)
