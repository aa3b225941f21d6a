"""numba kernels of the extended tool Jacobian, its derivative and the manipulability (closed form;
see :mod:`lynxplan.singularity.measures`)."""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True, nogil=True)
def _plane_terms(q: np.ndarray, a2: float, a3: float, d5: float) -> tuple[np.ndarray, np.ndarray]:
    """Radial r_i and height h_i of (tool - o_i) for i = shoulder, elbow, wrist centre."""
    s2, c2 = math.sin(q[1]), math.cos(q[1])
    s23, c23 = math.sin(q[1] + q[2]), math.cos(q[1] + q[2])
    q234 = q[1] + q[2] + q[3]
    s234, c234 = math.sin(q234), math.cos(q234)
    r = np.empty(3)
    h = np.empty(3)
    r[2], h[2] = d5 * s234, -d5 * c234
    r[1], h[1] = r[2] + a3 * c23, h[2] + a3 * s23
    r[0], h[0] = r[1] + a2 * c2, h[1] + a2 * s2
    return r, h


@numba.njit(cache=True, nogil=True)
def extended_jacobian_kernel(
    q: np.ndarray, a2: float, a3: float, d5: float, out: np.ndarray
) -> None:
    """Write the extended Jacobian E(q), shape (8, 5), of one configuration q (5,) into ``out``."""
    s1, c1 = math.sin(q[0]), math.cos(q[0])
    q234 = q[1] + q[2] + q[3]
    s234, c234 = math.sin(q234), math.cos(q234)
    r, h = _plane_terms(q, a2, a3, d5)
    out[:, :] = 0.0
    out[0, 0], out[1, 0] = -s1 * r[0], c1 * r[0]
    for i in range(3):
        # Column of joint i+2: (s1, -c1, 0) x (c1 r_i, s1 r_i, h_i) = (-c1 h_i, -s1 h_i, r_i).
        out[0, i + 1], out[1, i + 1], out[2, i + 1] = -c1 * h[i], -s1 * h[i], r[i]
        out[3, i + 1], out[4, i + 1] = s1, -c1
        out[6, i + 1] = 1.0
    out[5, 0] = 1.0
    out[3, 4], out[4, 4], out[5, 4] = c1 * s234, s1 * s234, -c234
    out[7, 0], out[7, 4] = -c234, 1.0


@numba.njit(cache=True, nogil=True)
def extended_jacobian_derivative_kernel(
    q: np.ndarray, a2: float, a3: float, d5: float, out: np.ndarray
) -> None:
    """Write dE/dq_j, shape (8, 5, 5) (last index j), of one configuration into ``out``.

    In the arm plane, d(r_i, h_i)/dq_j = (-h_k, r_k) with k = max(i, j) (joint j turns the part
    of the chain beyond both o_i and o_j); nothing depends on q5.
    """
    s1, c1 = math.sin(q[0]), math.cos(q[0])
    q234 = q[1] + q[2] + q[3]
    s234, c234 = math.sin(q234), math.cos(q234)
    r, h = _plane_terms(q, a2, a3, d5)
    out[:, :, :] = 0.0
    # j = 0 (q1): derivative of s1 -> c1, c1 -> -s1.
    out[0, 0, 0], out[1, 0, 0] = -c1 * r[0], -s1 * r[0]
    for i in range(3):
        out[0, i + 1, 0], out[1, i + 1, 0] = s1 * h[i], -c1 * h[i]
        out[3, i + 1, 0], out[4, i + 1, 0] = c1, s1
    out[3, 4, 0], out[4, 4, 0] = -s1 * s234, c1 * s234
    for j in range(3):
        out[0, 0, j + 1], out[1, 0, j + 1] = s1 * h[j], -c1 * h[j]
        for i in range(3):
            k = max(i, j)
            out[0, i + 1, j + 1] = -c1 * r[k]
            out[1, i + 1, j + 1] = -s1 * r[k]
            out[2, i + 1, j + 1] = -h[k]
        out[3, 4, j + 1], out[4, 4, j + 1], out[5, 4, j + 1] = c1 * c234, s1 * c234, s234
        out[7, 0, j + 1] = s234


@numba.njit(cache=True, nogil=True)
def manipulability_kernel(J: np.ndarray) -> float:
    """sqrt(det(J J^T)) of a (k, 5) task Jacobian, as |prod diag R| of J^T = Q R.

    The QR form keeps the accuracy of the smallest singular value near a singularity, where
    sqrt(det) of the product carries a noise of ~sqrt(eps) times the largest.
    """
    R = np.linalg.qr(np.ascontiguousarray(J.T))[1]
    m = 1.0
    for i in range(J.shape[0]):
        m *= abs(R[i, i])
    return m


@numba.njit(cache=True, nogil=True)
def gradient_kernel(J: np.ndarray, dJ: np.ndarray, m: float, out: np.ndarray) -> None:
    """dm/dq_j = m tr(J^+ dJ_j) = m sum((J J^T)^-1 J * dJ_j); zeros when m = 0."""
    out[:] = 0.0
    if m <= 0.0:
        return
    B = np.linalg.solve(J @ J.T, J)
    for j in range(5):
        total = 0.0
        for a in range(J.shape[0]):
            for b in range(5):
                total += B[a, b] * dJ[a, b, j]
        out[j] = m * total


@numba.njit(cache=True, nogil=True)
def measures_kernel(
    q: np.ndarray,
    rows: np.ndarray,
    a2: float,
    a3: float,
    d5: float,
    m_out: np.ndarray,
    grad_out: np.ndarray,
) -> None:
    """Manipulability (N,) and its gradient (N, 5) of the configurations q (N, 5)."""
    E = np.empty((8, 5))
    dE = np.empty((8, 5, 5))
    k = rows.shape[0]
    J = np.empty((k, 5))
    dJ = np.empty((k, 5, 5))
    for n in range(q.shape[0]):
        extended_jacobian_kernel(q[n], a2, a3, d5, E)
        extended_jacobian_derivative_kernel(q[n], a2, a3, d5, dE)
        for i in range(k):
            J[i] = E[rows[i]]
            dJ[i] = dE[rows[i]]
        m_out[n] = manipulability_kernel(J)
        gradient_kernel(J, dJ, m_out[n], grad_out[n])
