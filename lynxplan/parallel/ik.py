"""Inverse kinematics of the planar 3-RRR parallel robot (SPEC Part 4), all 8 working modes.

For leg i with ``d_i`` the vector from base joint i to platform joint i,
``theta_i = atan2(d_iy, d_ix) +- acos((S^2 - L^2 + |d_i|^2) / (2 S |d_i|))`` (law of cosines in the
triangle base joint / elbow / platform joint). Working modes are listed in the report's order:
the branch of theta_1 outermost, theta_3 innermost, "+" first (``"+++", "++-", ..., "---"``).
Angles are not wrapped (as in the report): ``theta`` lies in ``(-2 pi, 2 pi)``.

Poses are ``(xc, yc, alpha)`` in [m, m, rad]; actuated angles in [rad].
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np

from lynxplan.constants import ACOS_CLAMP_TOLERANCE
from lynxplan.exceptions import (
    LegUnreachableError,
    ShapeError,
    leg_unreachable_reason,
)
from lynxplan.parallel._legs import LegConstants, elbow_half_angle, leg_offset, mode_sign
from lynxplan.parallel.geometry import LEG_NAMES, PLATFORM_PHASES, ParallelGeometry

#: Working-mode labels in the report's order: sign of the acos term for legs A, B, C.
WORKING_MODES: tuple[str, ...] = tuple(
    "".join("+-"[(m >> (2 - leg)) & 1] for leg in range(3)) for m in range(8)
)

_DEFAULT_GEOMETRY = ParallelGeometry()


def mode_index(mode: int | str) -> int:
    """Index 0..7 of a working mode given as index or label (``"+-+"``)."""
    from lynxplan.exceptions import InputError

    if isinstance(mode, str):
        if mode not in WORKING_MODES:
            raise InputError(
                f"unknown working mode {mode!r}; valid modes: {', '.join(WORKING_MODES)}"
            )
        return WORKING_MODES.index(mode)
    integral = isinstance(mode, (int, np.integer)) or (
        isinstance(mode, (float, np.floating)) and float(mode).is_integer()
    )
    if isinstance(mode, (bool, np.bool_)) or not integral or not 0 <= int(mode) < 8:
        raise InputError(f"working mode index must be an integer in 0..7. Got: {mode!r:.60}")
    return int(mode)


def kernel_constants(geometry: ParallelGeometry) -> tuple[np.ndarray, np.ndarray]:
    """Base joints (3, 2) and platform phases' (cos, sin), shape (3, 2), for the kernels."""
    phases = np.array(PLATFORM_PHASES)
    return geometry.base_joints, np.stack([np.cos(phases), np.sin(phases)], axis=1)


def leg_constants(geometry: ParallelGeometry) -> LegConstants:
    """The dimensions of ``geometry`` packed for the kernels."""
    base, phase = kernel_constants(geometry)
    return LegConstants(
        np.ascontiguousarray(base, dtype=float),
        phase,
        float(geometry.platform_circumradius),
        float(geometry.proximal),
        float(geometry.distal),
    )


@numba.njit(cache=True, nogil=True)
def ik_kernel(poses: np.ndarray, legs: LegConstants, out: np.ndarray, distance: np.ndarray) -> None:
    """Write the 8 working modes of ``poses`` (N, 3) into ``out`` (N, 8, 3), NaN where a leg does
    not reach; the leg distances |d_i| into ``distance`` (N, 3)."""
    base, phase, rp, s, el = legs
    lo, hi = abs(s - el), s + el
    for k in range(poses.shape[0]):
        ca, sa = math.cos(poses[k, 2]), math.sin(poses[k, 2])
        for i in range(3):
            dx, dy, _, _ = leg_offset(poses[k, 0], poses[k, 1], ca, sa, phase, base, rp, i)
            dist = math.sqrt(dx * dx + dy * dy)
            distance[k, i] = dist
            plus = math.nan
            minus = math.nan
            if (
                dist > 0.0
                and lo - dist <= ACOS_CLAMP_TOLERANCE * hi
                and dist - hi <= ACOS_CLAMP_TOLERANCE * hi
            ):
                base_angle = math.atan2(dy, dx)
                half = elbow_half_angle(dist, s, el)
                plus = base_angle + half
                minus = base_angle - half
            for m in range(8):
                out[k, m, i] = minus if mode_sign(m, i) < 0.0 else plus


class ParallelIKResult(NamedTuple):
    """IK of a batch of poses: all 8 working modes, NaN where a leg does not reach."""

    angles: np.ndarray
    """Actuated angles, shape (N, 8, 3), in [rad]; row order of :data:`WORKING_MODES`."""
    leg_distance: np.ndarray
    """Base-joint-to-platform-joint distance per leg, shape (N, 3), in [m]."""
    reachable: np.ndarray
    """Whether each leg reaches, shape (N, 3), bool."""
    reach: tuple[float, float]
    """Distance range ``(|S - L|, S + L)`` every leg spans, in [m]."""

    def reason(self, k: int) -> str:
        """Why pose ``k`` has no solution (naming each leg that fails), or ``""`` if it has."""
        return "; ".join(
            leg_unreachable_reason(LEG_NAMES[i], float(self.leg_distance[k, i]), *self.reach)
            for i in range(3)
            if not self.reachable[k, i]
        )


def as_poses(
    poses: np.ndarray | list[float] | tuple[float, ...], name: str = "poses"
) -> np.ndarray:
    """Validate poses: shape (3,) or (N, 3), in range (:func:`lynxplan.guards.planar_poses`)
    -> float array (N, 3)."""
    from lynxplan import guards

    return np.ascontiguousarray(guards.planar_poses(name, poses).reshape(-1, 3))


def solve_ik_batch(
    poses: np.ndarray, geometry: ParallelGeometry = _DEFAULT_GEOMETRY
) -> ParallelIKResult:
    """All 8 working modes of many poses; unreachable poses give NaN rows and a reason.

    Args:
        poses: Platform poses ``(xc, yc, alpha)``, shape (3,) or (N, 3), in [m, m, rad].
        geometry: Robot dimensions.
    """
    array = as_poses(poses)
    out = np.empty((array.shape[0], 8, 3))
    distance = np.empty((array.shape[0], 3))
    ik_kernel(array, leg_constants(geometry), out, distance)
    reachable = ~np.isnan(out[:, 0, :])
    return ParallelIKResult(out, distance, reachable, geometry.leg_reach)


def solve_ik(pose: np.ndarray, geometry: ParallelGeometry = _DEFAULT_GEOMETRY) -> np.ndarray:
    """All 8 working modes of one pose.

    Args:
        pose: ``(xc, yc, alpha)``, shape (3,), in [m, m, rad].
        geometry: Robot dimensions.

    Returns:
        Actuated angles, shape (8, 3), in [rad], in the order of :data:`WORKING_MODES`.

    Raises:
        LegUnreachableError: naming the first leg that cannot reach and the range it spans.
    """
    array = as_poses(pose, "pose")
    if np.ndim(pose) != 1:
        raise ShapeError("pose", "(3,)", np.shape(pose))
    result = solve_ik_batch(array, geometry)
    for i in range(3):
        if not result.reachable[0, i]:
            raise LegUnreachableError(LEG_NAMES[i], float(result.leg_distance[0, i]), *result.reach)
    return np.asarray(result.angles[0])


def platform_joints(
    poses: np.ndarray, geometry: ParallelGeometry = _DEFAULT_GEOMETRY
) -> np.ndarray:
    """Platform joint positions, shape (..., 3, 2), in [m], of poses (..., 3) in [m, m, rad]."""
    poses = np.asarray(poses, dtype=float)
    phi = poses[..., 2:3] + np.array(PLATFORM_PHASES)
    rp = geometry.platform_circumradius
    return np.stack(
        [poses[..., 0:1] - rp * np.cos(phi), poses[..., 1:2] - rp * np.sin(phi)], axis=-1
    )


def elbows(theta: np.ndarray, geometry: ParallelGeometry = _DEFAULT_GEOMETRY) -> np.ndarray:
    """Elbow (passive proximal-distal joint) positions, shape (..., 3, 2), in [m], of actuated
    angles ``theta`` (..., 3) in [rad]."""
    theta = np.asarray(theta, dtype=float)
    s = geometry.proximal
    return geometry.base_joints + s * np.stack([np.cos(theta), np.sin(theta)], axis=-1)
