"""Closed-form forward kinematics and geometric Jacobian of the 5-DOF arm (SPEC Part 1).

All functions take joint angles in [rad] and return lengths in [m]. The kernels are compiled with
numba and loop over a batch on one core; the public functions accept one configuration, shape
(5,), or a batch, shape (N, 5).
"""

from __future__ import annotations

import numba
import numpy as np

from lynxplan._arrays import kernel_input
from lynxplan._fastmath import sincos
from lynxplan.arm.closed_form import tool_pose_from_sines
from lynxplan.arm.configuration import as_configurations
from lynxplan.arm.geometry import ArmGeometry
from lynxplan.exceptions import ShapeError

__all__ = [
    "as_configurations",
    "fk_kernel",
    "forward_kinematics",
    "jacobian_kernel",
    "tool_jacobian",
]

_DEFAULT_GEOMETRY = ArmGeometry()


_tool_pose = numba.njit(cache=True, nogil=True, inline="always")(tool_pose_from_sines)


@numba.njit(cache=True, nogil=True)
def fk_kernel(q: np.ndarray, a2: float, a3: float, d5: float, out: np.ndarray) -> None:
    """Write the tool transforms of the configurations ``q`` (N, 5) into ``out`` (N, 4, 4)."""
    for k in range(q.shape[0]):
        s1, c1 = sincos(q[k, 0])
        s2, c2 = sincos(q[k, 1])
        s3, c3 = sincos(q[k, 2])
        s4, c4 = sincos(q[k, 3])
        s5, c5 = sincos(q[k, 4])
        _tool_pose((s1, s2, s3, s4, s5), (c1, c2, c3, c4, c5), a2, a3, d5, out[k])


@numba.njit(cache=True, nogil=True)
def jacobian_kernel(q: np.ndarray, a2: float, a3: float, d5: float, out: np.ndarray) -> None:
    """Write the geometric tool Jacobians (LOCAL_WORLD_ALIGNED) of ``q`` (N, 5) into ``out``.

    ``out`` has shape (N, 6, 5): rows 0-2 map joint rates to the tool point's linear velocity in
    [m/s], rows 3-5 to the angular velocity in [rad/s], both in base-frame axes.
    """
    for k in range(q.shape[0]):
        s1, c1 = sincos(q[k, 0])
        s2, c2 = sincos(q[k, 1])
        s23, c23 = sincos(q[k, 1] + q[k, 2])
        q234 = q[k, 1] + q[k, 2] + q[k, 3]
        s234, c234 = sincos(q234)
        # Column i: z_{i-1} x (p - o_{i-1}) and z_{i-1}. z0 = (0,0,1); z1 = z2 = z3 = (s1,-c1,0);
        # z4 = approach axis. Distances in the arm plane: radial r_i and height h_i of p - o_i.
        r_tool = d5 * s234 + a3 * c23 + a2 * c2
        h_tool = a3 * s23 + a2 * s2 - d5 * c234
        r_elbow, h_elbow = r_tool - a2 * c2, h_tool - a2 * s2
        r_wrist, h_wrist = d5 * s234, -d5 * c234
        j = out[k]
        j[0, 0] = -s1 * r_tool
        j[1, 0] = c1 * r_tool
        j[2, 0] = 0.0
        # (s1, -c1, 0) x (c1 r, s1 r, h) = (-c1 h, -s1 h, r)
        j[0, 1], j[1, 1], j[2, 1] = -c1 * h_tool, -s1 * h_tool, r_tool
        j[0, 2], j[1, 2], j[2, 2] = -c1 * h_elbow, -s1 * h_elbow, r_elbow
        j[0, 3], j[1, 3], j[2, 3] = -c1 * h_wrist, -s1 * h_wrist, r_wrist
        j[0, 4], j[1, 4], j[2, 4] = 0.0, 0.0, 0.0
        j[3, 0], j[4, 0], j[5, 0] = 0.0, 0.0, 1.0
        for col in range(1, 4):
            j[3, col], j[4, col], j[5, col] = s1, -c1, 0.0
        j[3, 4], j[4, 4], j[5, 4] = c1 * s234, s1 * s234, -c234


def forward_kinematics(
    q: np.ndarray, geometry: ArmGeometry = _DEFAULT_GEOMETRY, *, out: np.ndarray | None = None
) -> np.ndarray:
    """Tool (pen tip) pose in the base frame.

    Args:
        q: Joint angles, shape (5,) or (N, 5), in [rad].
        geometry: Arm dimensions.
        out: Optional C-contiguous float array of shape (N, 4, 4) to write into (saves the
            allocation in tight loops over large batches).

    Returns:
        Homogeneous transforms, shape (4, 4) or (N, 4, 4), translations in [m].
    """
    batch = as_configurations(q)
    shape = (batch.shape[0], 4, 4)
    if out is None:
        out = np.empty(shape)
    elif out.shape != shape or out.dtype != np.float64 or not out.flags.c_contiguous:
        raise ShapeError("out", f"{shape}, float64, C-contiguous", out.shape)
    fk_kernel(kernel_input(batch), geometry.a2, geometry.a3, geometry.d5, out)
    return out[0] if np.ndim(q) == 1 else out


def tool_jacobian(q: np.ndarray, geometry: ArmGeometry = _DEFAULT_GEOMETRY) -> np.ndarray:
    """Geometric Jacobian of the tool frame in base-frame axes (Pinocchio LOCAL_WORLD_ALIGNED).

    Args:
        q: Joint angles, shape (5,) or (N, 5), in [rad].
        geometry: Arm dimensions.

    Returns:
        Shape (6, 5) or (N, 6, 5): rows (vx, vy, vz) in [m/rad], rows (wx, wy, wz) unitless.
    """
    batch = as_configurations(q)
    out = np.empty((batch.shape[0], 6, 5))
    jacobian_kernel(batch, geometry.a2, geometry.a3, geometry.d5, out)
    return out[0] if np.ndim(q) == 1 else out
