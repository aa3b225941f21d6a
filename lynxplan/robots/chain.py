"""A serial chain read from a Pinocchio model, and numba forward kinematics of it.

The chain is stored as a product of exponentials in the joint frames: joint ``i`` sits at the
fixed placement ``M_i`` relative to joint ``i - 1`` (joint 0: relative to the base) and turns
about its unit axis ``u_i`` (in its own frame); the tool sits at ``M_tool`` relative to the last
joint. ``T(q) = M_1 R(u_1, q_1) M_2 R(u_2, q_2) ... M_n R(u_n, q_n) M_tool``. This is the same
model Pinocchio evaluates (the tests compare them to 1e-15 m); the kernels exist because the IK
solvers call FK millions of times from compiled loops.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numba
import numpy as np

from lynxplan._fastmath import sincos
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


#: Chains of at most this many joints take their sines and cosines in a first pass (into the
#: (4, 4) scratch): apart from the matrix products, they overlap better (~30 % faster FK).
_PREPASS_JOINTS = 8


@numba.njit(cache=True, nogil=True, inline="always")
def _joint_sincos(q: np.ndarray, work: np.ndarray, i: int) -> tuple[float, float]:
    """(sin q_i, cos q_i): from the first pass in work when the chain is short, else now."""
    if q.shape[0] <= _PREPASS_JOINTS:
        return work[i >> 1, 2 * (i & 1)], work[i >> 1, 2 * (i & 1) + 1]
    return sincos(q[i])


@numba.njit(cache=True, nogil=True, inline="always")
def _fk_pass(
    placements: np.ndarray,
    axes: np.ndarray,
    q: np.ndarray,
    out: np.ndarray,
    work: np.ndarray,
    origins: np.ndarray,
    with_origins: bool,
) -> None:
    """out (4, 4) = M_1 R(u_1, q_1) ... M_n R(u_n, q_n) M_tool, the running pose kept in local
    scalars (array stores between the products would serialise them). With ``with_origins``,
    origins[i] gets joint i's origin and world axis (the Jacobian's columns)."""
    n = axes.shape[0]
    if n <= _PREPASS_JOINTS:
        for i in range(n):
            work[i >> 1, 2 * (i & 1)], work[i >> 1, 2 * (i & 1) + 1] = sincos(q[i])
    t00, t01, t02, t03 = (
        placements[0, 0, 0],
        placements[0, 0, 1],
        placements[0, 0, 2],
        placements[0, 0, 3],
    )
    t10, t11, t12, t13 = (
        placements[0, 1, 0],
        placements[0, 1, 1],
        placements[0, 1, 2],
        placements[0, 1, 3],
    )
    t20, t21, t22, t23 = (
        placements[0, 2, 0],
        placements[0, 2, 1],
        placements[0, 2, 2],
        placements[0, 2, 3],
    )
    for i in range(n):
        u0, u1, u2 = axes[i, 0], axes[i, 1], axes[i, 2]
        if with_origins:
            origins[i, 0], origins[i, 1], origins[i, 2] = t03, t13, t23
            origins[i, 3] = t00 * u0 + t01 * u1 + t02 * u2
            origins[i, 4] = t10 * u0 + t11 * u1 + t12 * u2
            origins[i, 5] = t20 * u0 + t21 * u1 + t22 * u2
        s, c = _joint_sincos(q, work, i)
        v = 1.0 - c  # Rodrigues: R(u, q) = c I + s [u]x + (1 - c) u u^T
        r00, r01, r02 = c + u0 * u0 * v, u0 * u1 * v - u2 * s, u0 * u2 * v + u1 * s
        r10, r11, r12 = u1 * u0 * v + u2 * s, c + u1 * u1 * v, u1 * u2 * v - u0 * s
        r20, r21, r22 = u2 * u0 * v - u1 * s, u2 * u1 * v + u0 * s, c + u2 * u2 * v
        w00, w01, w02 = (
            t00 * r00 + t01 * r10 + t02 * r20,
            t00 * r01 + t01 * r11 + t02 * r21,
            t00 * r02 + t01 * r12 + t02 * r22,
        )
        w10, w11, w12 = (
            t10 * r00 + t11 * r10 + t12 * r20,
            t10 * r01 + t11 * r11 + t12 * r21,
            t10 * r02 + t11 * r12 + t12 * r22,
        )
        w20, w21, w22 = (
            t20 * r00 + t21 * r10 + t22 * r20,
            t20 * r01 + t21 * r11 + t22 * r21,
            t20 * r02 + t21 * r12 + t22 * r22,
        )
        m = i + 1
        m00, m01, m02, m03 = (
            placements[m, 0, 0],
            placements[m, 0, 1],
            placements[m, 0, 2],
            placements[m, 0, 3],
        )
        m10, m11, m12, m13 = (
            placements[m, 1, 0],
            placements[m, 1, 1],
            placements[m, 1, 2],
            placements[m, 1, 3],
        )
        m20, m21, m22, m23 = (
            placements[m, 2, 0],
            placements[m, 2, 1],
            placements[m, 2, 2],
            placements[m, 2, 3],
        )
        t03 = w00 * m03 + w01 * m13 + w02 * m23 + t03
        t13 = w10 * m03 + w11 * m13 + w12 * m23 + t13
        t23 = w20 * m03 + w21 * m13 + w22 * m23 + t23
        t00, t01, t02 = (
            w00 * m00 + w01 * m10 + w02 * m20,
            w00 * m01 + w01 * m11 + w02 * m21,
            w00 * m02 + w01 * m12 + w02 * m22,
        )
        t10, t11, t12 = (
            w10 * m00 + w11 * m10 + w12 * m20,
            w10 * m01 + w11 * m11 + w12 * m21,
            w10 * m02 + w11 * m12 + w12 * m22,
        )
        t20, t21, t22 = (
            w20 * m00 + w21 * m10 + w22 * m20,
            w20 * m01 + w21 * m11 + w22 * m21,
            w20 * m02 + w21 * m12 + w22 * m22,
        )
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = t00, t01, t02, t03
    out[1, 0], out[1, 1], out[1, 2], out[1, 3] = t10, t11, t12, t13
    out[2, 0], out[2, 1], out[2, 2], out[2, 3] = t20, t21, t22, t23
    out[3, 0], out[3, 1], out[3, 2], out[3, 3] = 0.0, 0.0, 0.0, 1.0


@numba.njit(cache=True, nogil=True)
def chain_fk(
    placements: np.ndarray, axes: np.ndarray, q: np.ndarray, out: np.ndarray, work: np.ndarray
) -> None:
    """Tool pose of one configuration: q (n,) [rad] -> out (4, 4) [m]; work: scratch (4, 4)."""
    _fk_pass(placements, axes, q, out, work, work, False)


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
    _fk_pass(placements, axes, q, out, work, origins, True)
    for i in range(n):
        wx, wy, wz = origins[i, 3], origins[i, 4], origins[i, 5]
        dx, dy, dz = out[0, 3] - origins[i, 0], out[1, 3] - origins[i, 1], out[2, 3] - origins[i, 2]
        jac[0, i] = wy * dz - wz * dy
        jac[1, i] = wz * dx - wx * dz
        jac[2, i] = wx * dy - wy * dx
        jac[3, i] = wx
        jac[4, i] = wy
        jac[5, i] = wz


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
