"""Free motion in joint space: ``q(t) = qs + (qe - qs) s(t)`` with the LSPB law (SPEC Part 2)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from lynxplan import guards
from lynxplan.arm.kinematics import as_configurations
from lynxplan.exceptions import InputError, ShapeError
from lynxplan.trajectory.limits import MotionLimits
from lynxplan.trajectory.lspb import LspbTiming, unit_lspb
from lynxplan.trajectory.timing import auto_timing_linear


def check_timing(timing: LspbTiming | None, name: str = "timing") -> None:
    """A fixed timing must be an :class:`LspbTiming` within the documented duration range."""
    if timing is None:
        return
    if not isinstance(timing, LspbTiming):
        raise InputError(f"{name} must be an LspbTiming or None. Got: {type(timing).__name__}")
    guards.duration(f"{name}.tt", timing.tt)


def as_configuration(q: np.ndarray | list[float], name: str) -> np.ndarray:
    """Validate one configuration: shape (5,), finite, ``|q| <= 100 rad`` (see
    :mod:`lynxplan.guards`). Returns a read-only float copy."""
    array = guards.float_array(name, q)
    if array.shape != (5,):
        raise ShapeError(name, "(5,)", array.shape)
    out: np.ndarray = as_configurations(guards.angles(name, array), name)[0].copy()
    out.setflags(write=False)
    return out


class JointSamples(NamedTuple):
    """Joint trajectory samples of one segment."""

    q: np.ndarray
    """Joint angles, shape (N, 5), in [rad]."""
    qd: np.ndarray
    """Joint velocities, shape (N, 5), in [rad/s]."""
    qdd: np.ndarray
    """Joint accelerations, shape (N, 5), in [rad/s^2]."""
    branch: np.ndarray
    """IK branch per sample, shape (N,), int (-1 for free motion: no IK involved)."""
    orientation_residual: np.ndarray
    """Angle between the interpolated and the reached tool orientation, shape (N,), in [rad]
    (0 for free motion)."""


@dataclass(frozen=True)
class FreeSegment:
    """A joint-space LSPB segment; all joints start and stop together.

    Attributes:
        q_start: Start configuration, shape (5,), in [rad].
        q_end: End configuration, shape (5,), in [rad].
        timing: The LSPB timing (``tt``, ``ta``).
    """

    q_start: np.ndarray
    q_end: np.ndarray
    timing: LspbTiming

    kind = "free"

    @property
    def duration(self) -> float:
        """Segment duration ``tt``, in [s]."""
        return self.timing.tt

    def joint_path(self, s: np.ndarray) -> np.ndarray:
        """Geometric joint path at path parameters ``s`` (m,) in [0, 1]; shape (m, 5) in [rad]."""
        s = np.asarray(s, dtype=float)
        return np.asarray(self.q_start + np.multiply.outer(s, self.q_end - self.q_start))

    def path_derivatives(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``dq/ds`` and ``d2q/ds2`` at ``s`` (m,), each shape (m, 5), in [rad]."""
        s = np.asarray(s, dtype=float)
        tangent = np.broadcast_to(self.q_end - self.q_start, (s.size, 5)).copy()
        return tangent, np.zeros_like(tangent)

    def sample(self, t: np.ndarray) -> JointSamples:
        """Joint samples at times since the segment start ``t`` (N,), in [s]."""
        law = unit_lspb(np.asarray(t, dtype=float)[:, None], self.timing)
        delta = self.q_end - self.q_start
        n = law.position.shape[0]
        return JointSamples(
            self.q_start + delta * law.position,
            delta * law.velocity,
            delta * law.acceleration,
            np.full(n, -1, dtype=np.int64),
            np.zeros(n),
        )


def free_segment(
    q_start: np.ndarray | list[float],
    q_end: np.ndarray | list[float],
    timing: LspbTiming | None = None,
    *,
    limits: MotionLimits | None = None,
) -> FreeSegment:
    """A free-motion segment; ``timing=None`` picks the shortest LSPB within ``limits``.

    Args:
        q_start: Start configuration, shape (5,), in [rad].
        q_end: End configuration, shape (5,), in [rad].
        timing: Fixed timing, or None for auto-timing.
        limits: Velocity and acceleration limits for auto-timing (default: URDF + defaults).
    """
    qs, qe = as_configuration(q_start, "q_start"), as_configuration(q_end, "q_end")
    check_timing(timing)
    if timing is None:
        lim = limits or MotionLimits()
        timing = auto_timing_linear(qe - qs, lim.velocity, lim.acceleration)
    return FreeSegment(qs, qe, timing)
