"""Straight-line (Cartesian) motion: ``p(t) = ps + (pe - ps) s(t)`` (SPEC Part 2).

The tool point follows the segment with the LSPB law ``s(t)``; the orientation is interpolated by
one of four modes:

- ``consistent`` (default): within what the 5-DOF arm can reach. The approach axis stays in the
  arm's vertical plane through the tool point, its pitch ``q234`` and the roll ``q5`` move linearly
  in ``s`` between the end poses' values (so the roll stays inside its limits when both ends are).
- ``slerp``: shortest-arc rotation at a constant rate in ``s``.
- ``lerp``: the report's linear blend of quaternion components (normalised for use).
- ``drive``: the report's appendix method, Paul's drive transform (translation, rotation about a
  unit vector, rotation about the approach axis).

Every sample is solved by the arm's analytic IK (:mod:`lynxplan.trajectory.kinematics`: the AL5's
kernels by default, or a yaw-pitch-pitch-pitch-roll robot from URDF), on the branch continuous
with the previous sample. The
full-SO(3) modes pass through orientations the arm cannot reach: the IK projects them (the
residual is reported) and its roll can leave the joint limits (reported as violations).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from lynxplan import guards
from lynxplan.constants import PATH_GRID_POINTS
from lynxplan.exceptions import InputError
from lynxplan.trajectory.free import JointSamples, as_configuration, check_timing
from lynxplan.trajectory.kinematics import Al5Kinematics, PathKinematics, PathTargets
from lynxplan.trajectory.limits import MotionLimits
from lynxplan.trajectory.lspb import LspbTiming, unit_lspb
from lynxplan.trajectory.rotations import (
    component_blend,
    drive_transforms,
    matrix_to_quaternion,
    quaternion_to_matrix,
    slerp,
)
from lynxplan.trajectory.timing import auto_timing_path

OrientationMode = Literal["consistent", "slerp", "lerp", "drive"]
ORIENTATION_MODES: tuple[str, ...] = ("consistent", "slerp", "lerp", "drive")


def _wrap(angle: float) -> float:
    """Angle wrapped into (-pi, pi]."""
    return math.pi - (math.pi - angle) % (2 * math.pi)


@dataclass(frozen=True)
class PathGrid:
    """A joint path solved on a uniform grid of the path parameter.

    Attributes:
        s: Path parameter, shape (m,), from 0 to 1.
        q: Joint angles, shape (m, 5), in [rad].
        dq_ds: First derivative, shape (m, 5), in [rad].
        d2q_ds2: Second derivative, shape (m, 5), in [rad].
    """

    s: np.ndarray
    q: np.ndarray
    dq_ds: np.ndarray
    d2q_ds2: np.ndarray


def _derivatives(q: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """Second-order finite differences of a uniformly sampled path (m >= 4 rows)."""
    first = np.gradient(q, h, axis=0, edge_order=2)
    second = np.empty_like(q)
    second[1:-1] = (q[2:] - 2 * q[1:-1] + q[:-2]) / h**2
    second[0] = (2 * q[0] - 5 * q[1] + 4 * q[2] - q[3]) / h**2
    second[-1] = (2 * q[-1] - 5 * q[-2] + 4 * q[-3] - q[-4]) / h**2
    return first, second


@dataclass(frozen=True)
class LineSegment:
    """A straight tool-point line with LSPB timing, solved by the analytic IK.

    Attributes:
        T_start: Start tool pose, shape (4, 4), in [m].
        T_end: End tool pose, shape (4, 4), in [m].
        q_start: Configuration at the start, shape (5,), in [rad]; fixes the IK branch.
        q_end: Configuration reached at the end of the line (IK, continuous branch), in [rad].
        timing: The LSPB timing of the path parameter.
        mode: Orientation interpolation mode.
        limits: Joint limits (the IK prefers branches within them).
        grid: The joint path solved on a uniform grid (derivatives for rates and timing).
        roll: Roll joint angle at the start and the end (``consistent`` mode), in [rad].
        pitch: Approach pitch at the start and the end (``consistent`` mode), in [rad].
        kinematics: The arm's FK and path IK.
    """

    T_start: np.ndarray
    T_end: np.ndarray
    q_start: np.ndarray
    q_end: np.ndarray
    timing: LspbTiming
    mode: str
    limits: MotionLimits
    grid: PathGrid
    roll: tuple[float, float]
    pitch: tuple[float, float]
    kinematics: PathKinematics

    kind = "line"

    @property
    def duration(self) -> float:
        """Segment duration ``tt``, in [s]."""
        return self.timing.tt

    def targets(self, s: np.ndarray) -> np.ndarray:
        """Interpolated tool targets at ``s`` (m,): poses (m, 4, 4) (in ``consistent`` mode only
        the translation is meaningful: the approach pitch and the roll are interpolated)."""
        s = np.asarray(s, dtype=float)
        p0, p1 = self.T_start[:3, 3], self.T_end[:3, 3]
        out = np.zeros((s.size, 4, 4))
        out[:, 3, 3] = 1.0
        out[:, :3, 3] = p0 + np.multiply.outer(s, p1 - p0)
        if self.mode == "consistent":
            out[:, :3, :3] = np.eye(3)
            return out
        if self.mode == "drive":
            return drive_transforms(self.T_start, self.T_end, s)
        quat0 = matrix_to_quaternion(self.T_start[:3, :3])
        quat1 = matrix_to_quaternion(self.T_end[:3, :3])
        blend = slerp if self.mode == "slerp" else component_blend
        out[:, :3, :3] = quaternion_to_matrix(blend(quat0, quat1, s))
        return out

    def solve(
        self, s: np.ndarray, q_before: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """IK along the line at increasing ``s`` (m,), continuous from ``q_before`` (5,).

        Returns:
            ``(q (m, 5) in [rad], branch (m,), orientation residual (m,) in [rad])``.

        Raises:
            PathNotFollowableError: a sample is out of reach.
        """
        return _solve_line(self, np.asarray(s, dtype=float), q_before)

    def joint_path(self, s: np.ndarray) -> np.ndarray:
        """Geometric joint path at increasing ``s`` (m,) in [0, 1]; shape (m, 5) in [rad]."""
        return self.solve(s, self.q_start)[0]

    def path_derivatives(self, s: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
        """``dq/ds`` and ``d2q/ds2`` at ``s`` (m,) from the grid, each (m, 5), in [rad]
        (a scalar ``s`` gives shape (5,)).

        ``dq/ds`` is a cubic Hermite interpolant (its slopes are the grid's ``d2q/ds2``);
        ``d2q/ds2`` is interpolated linearly.
        """
        g = self.grid
        s = np.clip(np.asarray(s, dtype=float), 0.0, 1.0)
        h = g.s[1] - g.s[0]
        i = np.minimum((s / h).astype(np.int64), g.s.size - 2)
        u = ((s - g.s[i]) / h)[..., None]
        f0, f1, m0, m1 = g.dq_ds[i], g.dq_ds[i + 1], g.d2q_ds2[i], g.d2q_ds2[i + 1]
        first = (
            (2 * u**3 - 3 * u**2 + 1) * f0
            + (u**3 - 2 * u**2 + u) * h * m0
            + (3 * u**2 - 2 * u**3) * f1
            + (u**3 - u**2) * h * m1
        )
        return first, m0 + u * (m1 - m0)

    def sample(self, t: np.ndarray) -> JointSamples:
        """Joint samples at increasing times since the segment start ``t`` (N,), in [s]."""
        law = unit_lspb(np.asarray(t, dtype=float), self.timing)
        q, branch, residual = self.solve(law.position, self.q_start)
        first, second = self.path_derivatives(law.position)
        sd, sdd = law.velocity[:, None], law.acceleration[:, None]
        return JointSamples(q, first * sd, first * sdd + second * sd**2, branch, residual)


def _solve_line(
    segment: LineSegment, s: np.ndarray, q_before: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    targets = PathTargets(segment.targets(s))
    if segment.mode == "consistent":
        pitch = segment.pitch[0] + s * (segment.pitch[1] - segment.pitch[0])
        roll = segment.roll[0] + s * (segment.roll[1] - segment.roll[0])
        targets = PathTargets(targets.poses, pitch, roll)
    ik = segment.kinematics.solve(targets, q_before, segment.limits, s)
    return ik.q, ik.branch, ik.residual


def _check_mode(mode: str) -> None:
    if mode not in ORIENTATION_MODES:
        raise InputError(
            f"unknown orientation mode {mode!r}; valid modes: {', '.join(ORIENTATION_MODES)}"
        )


def line_segment(
    T_start: np.ndarray,
    T_end: np.ndarray,
    q_start: np.ndarray | list[float],
    timing: LspbTiming | None = None,
    *,
    mode: str = "consistent",
    limits: MotionLimits | None = None,
    kinematics: PathKinematics | None = None,
) -> LineSegment:
    """A straight-line segment between two tool poses, solved on the grid.

    Args:
        T_start: Start pose, shape (4, 4), in [m]; should be the FK of ``q_start``.
        T_end: End pose, shape (4, 4), in [m].
        q_start: Start configuration, shape (5,), in [rad]; fixes the IK branch.
        timing: Fixed LSPB timing, or None for the shortest within ``limits``.
        mode: ``consistent`` (default), ``slerp``, ``lerp`` or ``drive``.
        limits: Joint limits (default: URDF + documented defaults).
        kinematics: The arm (default: the AL5's closed-form kernels).

    Raises:
        InputError: unknown mode, or ``T_start`` far from the FK of ``q_start``.
        PathNotFollowableError: the line leaves the arm's reach.
    """
    _check_mode(mode)
    T0 = guards.poses("T_start", T_start, batch=False)
    T1 = guards.poses("T_end", T_end, batch=False)
    return line_segment_from_checked_poses(
        T0, T1, q_start, timing, mode=mode, limits=limits, kinematics=kinematics
    )


def line_segment_from_checked_poses(
    T_start: np.ndarray,
    T_end: np.ndarray,
    q_start: np.ndarray | list[float],
    timing: LspbTiming | None = None,
    *,
    mode: str = "consistent",
    limits: MotionLimits | None = None,
    kinematics: PathKinematics | None = None,
) -> LineSegment:
    """:func:`line_segment` of poses that are known to be rigid transforms within range: the FK
    of configurations, or poses the caller has checked (:func:`lynxplan.guards.poses`).

    The rest is checked as by :func:`line_segment`: the mode, the start configuration, the
    timing, the distance of ``T_start`` from the FK of ``q_start``.
    """
    _check_mode(mode)
    lim = limits or MotionLimits()
    kin = kinematics or Al5Kinematics()
    T0 = np.array(T_start, dtype=float)
    T1 = np.array(T_end, dtype=float)
    qs = as_configuration(q_start, "q_start")
    check_timing(timing)
    gap = float(np.linalg.norm(kin.tool_poses(qs[None])[0, :3, 3] - T0[:3, 3]))
    if gap > 1e-6:
        raise InputError(f"T_start is {gap * 1000:.4g} mm from the tool point of q_start")
    q_end_pose = kin.nearest(T1, qs, lim)
    pitch0 = kin.pitch(T0, qs)
    pitch = (pitch0, pitch0 + _wrap(kin.pitch(T1, q_end_pose) - pitch0))
    roll = (float(qs[-1]), float(q_end_pose[-1]))
    s_grid = np.linspace(0.0, 1.0, PATH_GRID_POINTS)
    # Grid first with a placeholder timing, then the real timing (auto-timing needs the grid).
    draft = LineSegment(
        T0,
        T1,
        qs,
        qs,
        LspbTiming(1.0, 0.5),
        mode,
        lim,
        PathGrid(s_grid, s_grid, s_grid, s_grid),
        roll,
        pitch,
        kin,
    )
    q_grid = draft.joint_path(s_grid)
    dq, ddq = _derivatives(q_grid, s_grid[1] - s_grid[0])
    grid = PathGrid(s_grid, q_grid, dq, ddq)
    for array in (q_grid, dq, ddq, T0, T1):
        array.setflags(write=False)
    if timing is None:
        timing = auto_timing_path(s_grid, dq, ddq, lim.velocity, lim.acceleration)
    q_end = q_grid[-1].copy()
    q_end.setflags(write=False)
    return LineSegment(T0, T1, qs, q_end, timing, mode, lim, grid, roll, pitch, kin)
