"""A serial chain read from a Pinocchio model, and numba forward kinematics of it.

The chain is stored as a product of exponentials in the joint frames: joint ``i`` sits at the
fixed placement ``M_i`` relative to joint ``i - 1`` (joint 0: relative to the base) and turns
about its unit axis ``u_i`` (in its own frame); the tool sits at ``M_tool`` relative to the last
joint. ``T(q) = M_1 R(u_1, q_1) M_2 R(u_2, q_2) ... M_n R(u_n, q_n) M_tool``. This is the same
model Pinocchio evaluates (the tests compare them to 1e-15 m); the kernels exist because the IK
solvers call FK millions of times from compiled loops.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numba
import numpy as np

from lynxplan.exceptions import ModelError


@dataclass(frozen=True)
class Chain:
    """Joint placements and axes of a revolute serial chain, in [m] and unit vectors.

    Attributes:
        placements: Shape (n + 1, 4, 4): ``M_1 .. M_n`` then ``M_tool`` (read-only).
        axes: Shape (n, 3): unit joint axes, each in its own joint frame (read-only).
    """

    placements: np.ndarray
    axes: np.ndarray

    @property
    def n(self) -> int:
        """Number of joints."""
        return int(self.axes.shape[0])


def _local_axis(joint: Any) -> np.ndarray:
    short = joint.shortname()
    for suffix, axis in (("RX", (1.0, 0, 0)), ("RY", (0, 1.0, 0)), ("RZ", (0, 0, 1.0))):
        if short.endswith(suffix) or short.endswith("RUB" + suffix[1:]):
            return np.array(axis, dtype=float)
    if "RevoluteUnaligned" in short or "RevoluteUnboundedUnaligned" in short:
        unaligned = np.array(joint.extract().axis, dtype=float)
        return np.asarray(unaligned / np.linalg.norm(unaligned), dtype=float)
    raise ModelError(f"joint {joint.id}: type {short} is not revolute; only revolute chains")


def chain_from_model(model: Any, tool_frame_id: int) -> Chain:
    """The chain from the base to a frame. Joints must be revolute and form one serial path.

    Raises:
        ModelError: a prismatic/spherical/free joint, or joints off the path to the tool.
    """
    frame = model.frames[tool_frame_id]
    path: list[int] = []
    joint = int(frame.parentJoint)
    while joint != 0:
        path.append(joint)
        joint = int(model.parents[joint])
    path.reverse()
    if path != list(range(1, model.njoints)):
        names = [model.names[j] for j in range(1, model.njoints) if j not in path]
        raise ModelError(f"joints {names} are not on the path from the base to {frame.name!r}")
    if model.nq != len(path):
        raise ModelError(
            f"expected {len(path)} revolute joints (nq = {len(path)}); nq = {model.nq}"
        )
    placements = np.empty((len(path) + 1, 4, 4))
    axes = np.empty((len(path), 3))
    for i, j in enumerate(path):
        axes[i] = _local_axis(model.joints[j])
        placements[i] = model.jointPlacements[j].homogeneous
    placements[-1] = frame.placement.homogeneous
    placements.setflags(write=False)
    axes.setflags(write=False)
    return Chain(placements, axes)


@numba.njit(cache=True, nogil=True, inline="always")
def _mul_rot_axis(t: np.ndarray, u: np.ndarray, q: float, out: np.ndarray) -> None:
    """out[:3, :3] = t[:3, :3] @ R(u, q) (Rodrigues); out[:3, 3] = t[:3, 3]."""
    s, c = math.sin(q), math.cos(q)
    v = 1.0 - c
    r00 = c + u[0] * u[0] * v
    r01 = u[0] * u[1] * v - u[2] * s
    r02 = u[0] * u[2] * v + u[1] * s
    r10 = u[1] * u[0] * v + u[2] * s
    r11 = c + u[1] * u[1] * v
    r12 = u[1] * u[2] * v - u[0] * s
    r20 = u[2] * u[0] * v - u[1] * s
    r21 = u[2] * u[1] * v + u[0] * s
    r22 = c + u[2] * u[2] * v
    for i in range(3):
        a0, a1, a2 = t[i, 0], t[i, 1], t[i, 2]
        out[i, 0] = a0 * r00 + a1 * r10 + a2 * r20
        out[i, 1] = a0 * r01 + a1 * r11 + a2 * r21
        out[i, 2] = a0 * r02 + a1 * r12 + a2 * r22
        out[i, 3] = t[i, 3]


@numba.njit(cache=True, nogil=True, inline="always")
def _mul_placement(t: np.ndarray, m: np.ndarray, out: np.ndarray) -> None:
    """out[:3] = (t @ m)[:3] for homogeneous 4x4 (rows 0-2 only)."""
    for i in range(3):
        a0, a1, a2 = t[i, 0], t[i, 1], t[i, 2]
        for j in range(3):
            out[i, j] = a0 * m[0, j] + a1 * m[1, j] + a2 * m[2, j]
        out[i, 3] = a0 * m[0, 3] + a1 * m[1, 3] + a2 * m[2, 3] + t[i, 3]


@numba.njit(cache=True, nogil=True)
def chain_fk(
    placements: np.ndarray, axes: np.ndarray, q: np.ndarray, out: np.ndarray, work: np.ndarray
) -> None:
    """Tool pose of one configuration: q (n,) [rad] -> out (4, 4) [m]; work: scratch (4, 4)."""
    n = axes.shape[0]
    for i in range(4):
        for j in range(4):
            out[i, j] = placements[0, i, j]
    for i in range(n):
        _mul_rot_axis(out, axes[i], q[i], work)
        _mul_placement(work, placements[i + 1], out)
    out[3, 0] = 0.0
    out[3, 1] = 0.0
    out[3, 2] = 0.0
    out[3, 3] = 1.0


@numba.njit(cache=True, nogil=True)
def chain_fk_jacobian(
    placements: np.ndarray,
    axes: np.ndarray,
    q: np.ndarray,
    out: np.ndarray,
    jac: np.ndarray,
    work: np.ndarray,
    origins: np.ndarray,
) -> None:
    """Tool pose and geometric Jacobian (LOCAL_WORLD_ALIGNED, rows v then w), shape (6, n).

    ``origins``: scratch (n, 6): each joint's origin and world axis.
    """
    n = axes.shape[0]
    for i in range(4):
        for j in range(4):
            out[i, j] = placements[0, i, j]
    for i in range(n):
        for r in range(3):
            origins[i, r] = out[r, 3]
            origins[i, 3 + r] = (
                out[r, 0] * axes[i, 0] + out[r, 1] * axes[i, 1] + out[r, 2] * axes[i, 2]
            )
        _mul_rot_axis(out, axes[i], q[i], work)
        _mul_placement(work, placements[i + 1], out)
    for i in range(n):
        wx, wy, wz = origins[i, 3], origins[i, 4], origins[i, 5]
        dx, dy, dz = out[0, 3] - origins[i, 0], out[1, 3] - origins[i, 1], out[2, 3] - origins[i, 2]
        jac[0, i] = wy * dz - wz * dy
        jac[1, i] = wz * dx - wx * dz
        jac[2, i] = wx * dy - wy * dx
        jac[3, i] = wx
        jac[4, i] = wy
        jac[5, i] = wz
    out[3, 0] = 0.0
    out[3, 1] = 0.0
    out[3, 2] = 0.0
    out[3, 3] = 1.0


@numba.njit(cache=True, nogil=True)
def chain_fk_batch(
    placements: np.ndarray, axes: np.ndarray, q: np.ndarray, out: np.ndarray
) -> None:
    """Tool poses of q (N, n) [rad] into out (N, 4, 4) [m]."""
    work = np.empty((4, 4))
    for k in range(q.shape[0]):
        chain_fk(placements, axes, q[k], out[k], work)


@numba.njit(cache=True, nogil=True)
def chain_jacobian_batch(
    placements: np.ndarray, axes: np.ndarray, q: np.ndarray, out: np.ndarray
) -> None:
    """Geometric Jacobians (LOCAL_WORLD_ALIGNED) of q (N, n) into out (N, 6, n)."""
    n = axes.shape[0]
    work = np.empty((4, 4))
    pose = np.empty((4, 4))
    origins = np.empty((n, 6))
    for k in range(q.shape[0]):
        chain_fk_jacobian(placements, axes, q[k], pose, out[k], work, origins)
