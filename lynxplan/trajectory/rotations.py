"""Batch rotation helpers on scipy's ``Rotation``/``Slerp``: quaternions (w, x, y, z), axis-angle,
the report's component blend and Paul's drive transform."""

from __future__ import annotations

import numpy as np


def _wxyz(xyzw: np.ndarray) -> np.ndarray:
    return np.concatenate([xyzw[..., 3:], xyzw[..., :3]], axis=-1)


def _xyzw(wxyz: np.ndarray) -> np.ndarray:
    return np.concatenate([wxyz[..., 1:], wxyz[..., :1]], axis=-1)


def matrix_to_quaternion(R: np.ndarray) -> np.ndarray:
    """Unit quaternions (w, x, y, z), w >= 0, of rotation matrices, shape (..., 3, 3) -> (..., 4)
    (scipy's ``Rotation.from_matrix``)."""
    from scipy.spatial.transform import Rotation

    R = np.asarray(R, dtype=float)
    quaternion = Rotation.from_matrix(R.reshape(-1, 3, 3)).as_quat(canonical=True)
    return _wxyz(quaternion).reshape(*R.shape[:-2], 4)


def quaternion_to_matrix(quaternion: np.ndarray) -> np.ndarray:
    """Rotation matrices of quaternions (w, x, y, z), shape (..., 4) -> (..., 3, 3).

    The quaternions are normalised first (a component blend is not unit-norm); scipy's
    ``Rotation.from_quat``.
    """
    from scipy.spatial.transform import Rotation

    qn = np.asarray(quaternion, dtype=float)
    matrices = Rotation.from_quat(_xyzw(qn.reshape(-1, 4))).as_matrix()
    return np.asarray(matrices.reshape(*qn.shape[:-1], 3, 3))


def axis_angle_matrix(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotations about unit ``axis`` (3,) by ``angle`` (m,) in [rad]; (m, 3, 3) (scipy's
    ``Rotation.from_rotvec``)."""
    from scipy.spatial.transform import Rotation

    k = np.asarray(axis, dtype=float)
    angle = np.asarray(angle, dtype=float)
    matrices = Rotation.from_rotvec(np.multiply.outer(angle, k)).as_matrix()
    return np.asarray(matrices.reshape(-1, 3, 3))


def slerp(q0: np.ndarray, q1: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Shortest-arc spherical interpolation of unit quaternions (4,) at ``s`` (m,) -> (m, 4)
    (scipy's ``Slerp``); returned with the sign continuous from ``q0``."""
    from scipy.spatial.transform import Rotation, Slerp

    q0, q1 = np.asarray(q0, dtype=float), np.asarray(q1, dtype=float)
    ends = Rotation.from_quat(_xyzw(np.stack([q0, q1])))
    out = _wxyz(Slerp([0.0, 1.0], ends)(np.asarray(s, dtype=float)).as_quat())
    return np.where((out @ q0)[:, None] < 0.0, -out, out)


def component_blend(q0: np.ndarray, q1: np.ndarray, s: np.ndarray) -> np.ndarray:
    """The report's orientation interpolation: ``q0 + s (q1 - q0)`` component by component.

    Not unit-norm and not at a constant angular rate; ``q1`` is negated when needed so the blend
    takes the shorter way (a blend through the origin would have no rotation).
    """
    q0, q1 = np.asarray(q0, dtype=float), np.asarray(q1, dtype=float)
    if q0 @ q1 < 0:
        q1 = -q1
    return np.asarray(q0 + np.asarray(s, dtype=float)[:, None] * (q1 - q0))


def drive_parameters(T_a: np.ndarray, T_b: np.ndarray) -> tuple[np.ndarray, float, float, float]:
    """Paul's drive transform from pose A to pose B (Paul 1981; the report's appendix).

    ``T_b = T_a D(1)`` with ``D(r) = Trans(r d) Rot(k, r theta) Rot(z, r phi)``: a translation
    ``d`` in A's axes, a rotation by ``theta`` about the unit vector ``k = (-sin psi, cos psi, 0)``
    (swinging A's approach axis onto B's) and a rotation by ``phi`` about the approach axis.

    Returns:
        ``(d (3,) in [m], psi, theta, phi in [rad])``.
    """
    R_a, R_b = T_a[:3, :3], T_b[:3, :3]
    d = R_a.T @ (T_b[:3, 3] - T_a[:3, 3])
    relative = R_a.T @ R_b
    a_b = relative[
        :, 2
    ]  # B's approach in A's axes = (cos psi sin theta, sin psi sin theta, cos th)
    psi = float(np.arctan2(a_b[1], a_b[0]))
    theta = float(np.arctan2(np.hypot(a_b[0], a_b[1]), a_b[2]))
    swing = axis_angle_matrix(np.array([-np.sin(psi), np.cos(psi), 0.0]), np.array([theta]))[0]
    twist = swing.T @ relative  # rotation about z by phi
    phi = float(np.arctan2(twist[1, 0], twist[0, 0]))
    return d, psi, theta, phi


def drive_transforms(T_a: np.ndarray, T_b: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Poses ``T_a D(r)`` of Paul's drive transform at fractions ``r`` (m,), shape (m, 4, 4)."""
    d, psi, theta, phi = drive_parameters(T_a, T_b)
    r = np.asarray(r, dtype=float)
    swing = axis_angle_matrix(np.array([-np.sin(psi), np.cos(psi), 0.0]), r * theta)
    twist = axis_angle_matrix(np.array([0.0, 0.0, 1.0]), r * phi)
    out = np.zeros((r.size, 4, 4))
    out[:, :3, :3] = T_a[:3, :3] @ swing @ twist
    out[:, :3, 3] = T_a[:3, 3] + np.multiply.outer(r, T_a[:3, :3] @ d)
    out[:, 3, 3] = 1.0
    return out
