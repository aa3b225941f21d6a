"""Singularities of the planar 3-RRR (SPEC Parts 4 and 5).

Differentiating the closure ``|P_i - E_i|^2 = L^2`` (``P_i`` platform joint, ``E_i`` elbow, both
functions of the pose and of ``theta_i``) gives ``A xdot = B thetadot`` with, for leg i and the
distal-link vector ``n_i = P_i - E_i``:

- direct Jacobian row ``A_i = [n_ix, n_iy, (P_i - c) x n_i]`` (``xdot = (xc', yc', alpha')``);
- inverse Jacobian ``B = diag((E_i - B_i) x n_i)`` (``B_i`` base joint, ``x`` the planar cross).

Type I (``det B = 0``): a leg is fully stretched or folded, ``|P_i - B_i| = S + L`` or ``|S - L|``:
for a fixed orientation these are circles, the boundary of the constant-orientation workspace.
Type II (``det A = 0``): the three distal-link lines are concurrent or parallel; the platform
gains a motion with the actuators locked. The indices returned here are dimensionless:
``det A / (L^3 rp)`` and ``B_ii / (S L)`` (the sine of the elbow angle).

Poses in [m, m, rad], angles in [rad].
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np

from lynxplan.parallel._legs import (
    LegConstants,
    det3,
    elbow_half_angle,
    jacobian_row,
    leg_offset,
    mode_sign,
)
from lynxplan.parallel.geometry import ParallelGeometry
from lynxplan.parallel.ik import (
    as_poses,
    leg_constants,
    mode_index,
    platform_joints,
    solve_ik_batch,
)

_DEFAULT_GEOMETRY = ParallelGeometry()


class Jacobians(NamedTuple):
    """Velocity relation ``A xdot = diag(B) thetadot`` of the 3-RRR at given poses and angles."""

    direct: np.ndarray
    """``A``, shape (N, 3, 3): rows map ``(xc', yc', alpha')`` in [m/s, m/s, rad/s] to [m^2/s]."""
    inverse: np.ndarray
    """Diagonal of ``B``, shape (N, 3), in [m^2]."""


@numba.njit(cache=True, nogil=True)
def jacobian_kernel(
    poses: np.ndarray,
    theta: np.ndarray,
    legs: LegConstants,
    direct: np.ndarray,
    inverse: np.ndarray,
) -> None:
    """``A`` (N, 3, 3) into ``direct`` and the diagonal of ``B`` (N, 3) into ``inverse`` at poses
    (N, 3) with actuated angles ``theta`` (N, 3)."""
    base, phase, rp, s, _ = legs
    for k in range(poses.shape[0]):
        ca, sa = math.cos(poses[k, 2]), math.sin(poses[k, 2])
        for i in range(3):
            dx, dy, cphi, sphi = leg_offset(poses[k, 0], poses[k, 1], ca, sa, phase, base, rp, i)
            row = jacobian_row(dx, dy, cphi, sphi, theta[k, i], rp, s)
            direct[k, i, 0], direct[k, i, 1], direct[k, i, 2], inverse[k, i] = row


def jacobians(
    poses: np.ndarray, theta: np.ndarray, geometry: ParallelGeometry = _DEFAULT_GEOMETRY
) -> Jacobians:
    """Direct and inverse Jacobians of poses (N, 3) with actuated angles ``theta`` (N, 3)."""
    poses = as_poses(poses)
    theta = np.ascontiguousarray(np.asarray(theta, dtype=float).reshape(-1, 3))
    direct = np.empty((poses.shape[0], 3, 3))
    inverse = np.empty((poses.shape[0], 3))
    jacobian_kernel(poses, theta, leg_constants(geometry), direct, inverse)
    return Jacobians(direct, inverse)


def type2_index(
    poses: np.ndarray, mode: int | str, geometry: ParallelGeometry = _DEFAULT_GEOMETRY
) -> np.ndarray:
    """Type II index ``det A / (L^3 rp)`` of working mode ``mode`` at poses (N, 3); NaN where the
    pose is unreachable. Zero on a Type II singularity."""
    poses = as_poses(poses)
    theta = solve_ik_batch(poses, geometry).angles[:, mode_index(mode)]
    scale = geometry.distal**3 * geometry.platform_circumradius
    with np.errstate(invalid="ignore"):
        return np.asarray(np.linalg.det(jacobians(poses, theta, geometry).direct) / scale)


def type1_index(
    poses: np.ndarray, mode: int | str, geometry: ParallelGeometry = _DEFAULT_GEOMETRY
) -> np.ndarray:
    """Type I index per leg, ``B_ii / (S L)`` = sine of the elbow angle, shape (N, 3), of working
    mode ``mode``; zero when a leg is stretched or folded, NaN where unreachable."""
    poses = as_poses(poses)
    theta = solve_ik_batch(poses, geometry).angles[:, mode_index(mode)]
    return np.asarray(
        jacobians(poses, theta, geometry).inverse / (geometry.proximal * geometry.distal)
    )


@numba.njit(cache=True, nogil=True)
def type2_grid_kernel(
    x: np.ndarray, y: np.ndarray, alpha: float, mode: int, legs: LegConstants, out: np.ndarray
) -> None:
    """Type II index of working mode ``mode`` on the grid ``y`` (ny,) x ``x`` (nx,) at
    orientation ``alpha``, into ``out`` (ny, nx); NaN where a leg does not reach."""
    base, phase, rp, s, el = legs
    lo, hi = abs(s - el), s + el
    ca, sa = math.cos(alpha), math.sin(alpha)
    scale = el * el * el * rp
    a = np.empty((3, 3))
    for i in range(y.shape[0]):
        for j in range(x.shape[0]):
            ok = True
            for leg in range(3):
                dx, dy, cphi, sphi = leg_offset(x[j], y[i], ca, sa, phase, base, rp, leg)
                dist = math.sqrt(dx * dx + dy * dy)
                if dist < lo or dist > hi or dist == 0.0:
                    ok = False
                    break
                half = elbow_half_angle(dist, s, el)
                theta = math.atan2(dy, dx) + mode_sign(mode, leg) * half
                a[leg, 0], a[leg, 1], a[leg, 2], _ = jacobian_row(dx, dy, cphi, sphi, theta, rp, s)
            out[i, j] = det3(a) / scale if ok else math.nan


def type2_grid(
    x: np.ndarray,
    y: np.ndarray,
    alpha: float,
    mode: int | str,
    geometry: ParallelGeometry = _DEFAULT_GEOMETRY,
) -> np.ndarray:
    """Type II index on a grid, shape (len(y), len(x)); NaN outside the workspace.

    Args:
        x: Grid abscissae, shape (nx,), in [m].
        y: Grid ordinates, shape (ny,), in [m].
        alpha: Platform orientation, in [rad].
        mode: Working mode (index or label).
        geometry: Robot dimensions.
    """
    out = np.empty((len(y), len(x)))
    type2_grid_kernel(
        np.ascontiguousarray(x, dtype=float),
        np.ascontiguousarray(y, dtype=float),
        float(alpha),
        mode_index(mode),
        leg_constants(geometry),
        out,
    )
    return out


class Type1Circle(NamedTuple):
    """A Type I locus at fixed orientation: leg ``leg`` stretched or folded."""

    leg: int
    """Leg index 0..2 (A, B, C)."""
    kind: str
    """``"stretched"`` (radius S + L) or ``"folded"`` (radius |S - L|)."""
    centre: np.ndarray
    """Centre of the circle of platform centres, shape (2,), in [m]."""
    radius: float
    """Radius, in [m]."""


def type1_circles(
    alpha: float, geometry: ParallelGeometry = _DEFAULT_GEOMETRY
) -> list[Type1Circle]:
    """The six Type I loci (circles of platform centres) at orientation ``alpha`` in [rad].

    Leg i is stretched/folded when ``|c - rp u_i(alpha) - B_i| = S + L`` / ``|S - L|``, i.e. the
    centre ``c`` lies on a circle about ``B_i + rp u_i(alpha)``.
    """
    lo, hi = geometry.leg_reach
    offsets = geometry.base_joints - platform_joints(np.array([0.0, 0.0, alpha]), geometry)
    return [
        Type1Circle(leg, kind, offsets[leg], radius)
        for leg in range(3)
        for kind, radius in (("stretched", hi), ("folded", lo))
    ]
