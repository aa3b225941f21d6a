"""Small batch rotation helpers: quaternions (w, x, y, z), axis-angle, Paul's drive transform."""

from __future__ import annotations

import numpy as np


def matrix_to_quaternion(R: np.ndarray) -> np.ndarray:
    """Unit quaternions (w, x, y, z) of rotation matrices, shape (..., 3, 3) -> (..., 4).

    Uses the largest of the four candidate components (numerically safe for every rotation).
    """
    R = np.asarray(R, dtype=float)
    m00, m11, m22 = R[..., 0, 0], R[..., 1, 1], R[..., 2, 2]
    candidates = np.stack(
        [
            np.stack(
                [
                    1 + m00 + m11 + m22,
                    R[..., 2, 1] - R[..., 1, 2],
                    R[..., 0, 2] - R[..., 2, 0],
                    R[..., 1, 0] - R[..., 0, 1],
                ],
                -1,
            ),
            np.stack(
                [
                    R[..., 2, 1] - R[..., 1, 2],
                    1 + m00 - m11 - m22,
                    R[..., 0, 1] + R[..., 1, 0],
                    R[..., 0, 2] + R[..., 2, 0],
                ],
                -1,
            ),
            np.stack(
                [
                    R[..., 0, 2] - R[..., 2, 0],
                    R[..., 0, 1] + R[..., 1, 0],
                    1 - m00 + m11 - m22,
                    R[..., 1, 2] + R[..., 2, 1],
                ],
                -1,
            ),
            np.stack(
                [
                    R[..., 1, 0] - R[..., 0, 1],
                    R[..., 0, 2] + R[..., 2, 0],
                    R[..., 1, 2] + R[..., 2, 1],
                    1 - m00 - m11 + m22,
                ],
                -1,
            ),
        ],
        -2,
    )  # (..., 4 candidates, 4 components); candidate i has component i = 4 q_i^2 / (2 |q_i|)
    diagonal = np.stack(
        [1 + m00 + m11 + m22, 1 + m00 - m11 - m22, 1 - m00 + m11 - m22, 1 - m00 - m11 + m22], -1
    )
    best = np.argmax(diagonal, axis=-1)
    chosen = np.take_along_axis(candidates, best[..., None, None], axis=-2)[..., 0, :]
    quaternion = chosen / np.linalg.norm(chosen, axis=-1, keepdims=True)
    return np.where(quaternion[..., :1] < 0, -quaternion, quaternion)


def quaternion_to_matrix(quaternion: np.ndarray) -> np.ndarray:
    """Rotation matrices of quaternions (w, x, y, z), shape (..., 4) -> (..., 3, 3).

    The quaternions are normalised first (a component blend is not unit-norm).
    """
    qn = np.asarray(quaternion, dtype=float)
    qn = qn / np.linalg.norm(qn, axis=-1, keepdims=True)
    w, x, y, z = qn[..., 0], qn[..., 1], qn[..., 2], qn[..., 3]
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        -2,
    )


def axis_angle_matrix(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rodrigues rotations about unit ``axis`` (3,) by ``angle`` (m,) in [rad]; (m, 3, 3)."""
    k = np.asarray(axis, dtype=float)
    angle = np.asarray(angle, dtype=float)
    skew = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    c, s = np.cos(angle)[:, None, None], np.sin(angle)[:, None, None]
    return np.eye(3) * c + s * skew + (1 - c) * np.outer(k, k)


def slerp(q0: np.ndarray, q1: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Shortest-arc spherical interpolation of unit quaternions (4,) at ``s`` (m,) -> (m, 4)."""
    q0, q1 = np.asarray(q0, dtype=float), np.asarray(q1, dtype=float)
    if q0 @ q1 < 0:
        q1 = -q1
    cosine = min(1.0, float(q0 @ q1))
    theta = np.arccos(cosine)
    s = np.asarray(s, dtype=float)[:, None]
    if theta < 1e-9:
        return q0 + s * (q1 - q0)
    return (np.sin((1 - s) * theta) * q0 + np.sin(s * theta) * q1) / np.sin(theta)


def component_blend(q0: np.ndarray, q1: np.ndarray, s: np.ndarray) -> np.ndarray:
    """The report's orientation interpolation: ``q0 + s (q1 - q0)`` component by component.

    Not unit-norm and not at a constant angular rate; ``q1`` is negated when needed so the blend
    takes the shorter way (a blend through the origin would have no rotation).
    """
    q0, q1 = np.asarray(q0, dtype=float), np.asarray(q1, dtype=float)
    if q0 @ q1 < 0:
        q1 = -q1
    return q0 + np.asarray(s, dtype=float)[:, None] * (q1 - q0)


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
