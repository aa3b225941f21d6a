"""Errors of the LeRobot bridge: each one line naming the file, key or value and what is allowed
(the CLI exits 2 on them, as on every :class:`lynxplan.exceptions.InputError`)."""

from __future__ import annotations

from lynxplan.exceptions import InputError


class CalibrationError(InputError):
    """A LeRobot calibration file is missing, unreadable or does not fit the robot.

    Attributes:
        source: The file (or ``"calibration"`` for one given as a mapping).
        reason: What is wrong, naming the motor and key.
    """

    def __init__(self, source: str, reason: str) -> None:
        self.source = source
        self.reason = reason
        super().__init__(f"calibration {source}: {reason}")


class FrameError(InputError):
    """A LeRobot action/observation frame lacks a motor key or holds a value it cannot."""


class PlaybackError(InputError):
    """``play`` was given something it cannot stream (no ``send_action``, a bad fps, ...)."""


class CalibrationWarning(UserWarning):
    """A calibrated range passes the URDF's joint limits (one line naming the joints)."""
