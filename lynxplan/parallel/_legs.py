"""Scalar 3-RRR leg formulas shared by every kernel (IK, FK, Jacobians, workspace): one of each.

Conventions of the kernels: ``base`` (3, 2) holds the base joints ``B_i`` in [m], ``phase`` (3, 2)
the ``(cos, sin)`` of each platform phase (SPEC Part 4), ``rp`` the platform circumradius, ``s``
the proximal and ``el`` the distal link length, all in [m]; ``(ca, sa)`` is the ``(cos, sin)`` of
the platform angle alpha. ``u_i(alpha)`` is the unit vector of ``phi_i = alpha + phase_i``.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np


class LegConstants(NamedTuple):
    """The robot's dimensions as the kernels take them (one structured parameter)."""

    base: np.ndarray
    """Base joints ``B_i``, shape (3, 2), in [m]."""
    phase: np.ndarray
    """``(cos, sin)`` of each platform phase, shape (3, 2)."""
    rp: float
    """Platform circumradius, in [m]."""
    s: float
    """Proximal link length S, in [m]."""
    el: float
    """Distal link length L, in [m]."""


@numba.njit(cache=True, nogil=True)
def platform_direction(ca: float, sa: float, phase: np.ndarray, i: int) -> tuple[float, float]:
    """``u_i(alpha) = (cos phi_i, sin phi_i)`` by the angle-sum rule."""
    return ca * phase[i, 0] - sa * phase[i, 1], sa * phase[i, 0] + ca * phase[i, 1]


@numba.njit(cache=True, nogil=True)
def leg_offset(
    x: float,
    y: float,
    ca: float,
    sa: float,
    phase: np.ndarray,
    origin: np.ndarray,
    rp: float,
    i: int,
) -> tuple[float, float, float, float]:
    """``d_i = c - rp u_i(alpha) - origin_i`` for centre ``c = (x, y)``: the vector from
    ``origin_i`` (base joint or elbow, row ``i`` of ``origin``) to platform joint i; returns
    ``(d_x, d_y, cos phi_i, sin phi_i)``."""
    cphi, sphi = platform_direction(ca, sa, phase, i)
    return x - rp * cphi - origin[i, 0], y - rp * sphi - origin[i, 1], cphi, sphi


@numba.njit(cache=True, nogil=True)
def anchor(
    origin: np.ndarray, ca: float, sa: float, phase: np.ndarray, rp: float, i: int
) -> tuple[float, float]:
    """``A_i(alpha) = origin_i + rp u_i(alpha)``: the point platform centre ``c`` must keep at
    distance L (origin = elbows, FK) or in the reach annulus (origin = base joints, workspace)."""
    cphi, sphi = platform_direction(ca, sa, phase, i)
    return origin[i, 0] + rp * cphi, origin[i, 1] + rp * sphi


@numba.njit(cache=True, nogil=True)
def elbow_half_angle(dist: float, s: float, el: float) -> float:
    """The law-of-cosines angle at the base joint between ``d_i`` and the proximal link,
    ``acos((S^2 - L^2 + |d_i|^2) / (2 S |d_i|))`` with the argument clamped to [-1, 1]."""
    arg = (s * s - el * el + dist * dist) / (2.0 * s * dist)
    return math.acos(min(1.0, max(-1.0, arg)))


@numba.njit(cache=True, nogil=True)
def mode_sign(mode: int, leg: int) -> float:
    """Sign of the acos term of ``leg`` in working mode index ``mode`` ("+" first)."""
    return -1.0 if (mode >> (2 - leg)) & 1 else 1.0


@numba.njit(cache=True, nogil=True)
def jacobian_row(
    dx: float, dy: float, cphi: float, sphi: float, theta: float, rp: float, s: float
) -> tuple[float, float, float, float]:
    """Row i of ``A xdot = diag(B) thetadot`` (SPEC Part 5) from the leg offset ``d_i``
    (base joint to platform joint), ``u_i`` and the actuated angle ``theta`` [rad]:
    ``(n_x, n_y, (P_i - c) x n_i, (E_i - B_i) x n_i)`` with ``n_i = P_i - E_i``."""
    arm_x, arm_y = s * math.cos(theta), s * math.sin(theta)
    nx, ny = dx - arm_x, dy - arm_y
    return nx, ny, -rp * cphi * ny + rp * sphi * nx, arm_x * ny - arm_y * nx


@numba.njit(cache=True, nogil=True)
def det3(a: np.ndarray) -> float:
    """Determinant of a 3x3 matrix by cofactors along the first row."""
    return float(
        a[0, 0] * (a[1, 1] * a[2, 2] - a[1, 2] * a[2, 1])
        - a[0, 1] * (a[1, 0] * a[2, 2] - a[1, 2] * a[2, 0])
        + a[0, 2] * (a[1, 0] * a[2, 1] - a[1, 1] * a[2, 0])
    )


@numba.njit(cache=True, nogil=True)
def closure_value(
    elbow: np.ndarray, alpha: float, phase: np.ndarray, rp: float, el: float
) -> float:
    """``f(alpha)`` of :mod:`lynxplan.parallel.fk` for one set of elbows (3, 2): the closure
    equation with the platform centre eliminated by Cramer's rule."""
    ca, sa = math.cos(alpha), math.sin(alpha)
    ax0, ay0 = anchor(elbow, ca, sa, phase, rp, 0)
    ax1, ay1 = anchor(elbow, ca, sa, phase, rp, 1)
    ax2, ay2 = anchor(elbow, ca, sa, phase, rp, 2)
    m00, m01 = 2.0 * (ax1 - ax0), 2.0 * (ay1 - ay0)
    m10, m11 = 2.0 * (ax2 - ax0), 2.0 * (ay2 - ay0)
    a0 = ax0 * ax0 + ay0 * ay0
    b0 = ax1 * ax1 + ay1 * ay1 - a0
    b1 = ax2 * ax2 + ay2 * ay2 - a0
    d = m00 * m11 - m01 * m10
    x = b0 * m11 - b1 * m01 - ax0 * d
    y = m00 * b1 - m10 * b0 - ay0 * d
    return x * x + y * y - el * el * d * d
