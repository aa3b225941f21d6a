"""Forward kinematics of the planar 3-RRR: every real assembly mode for given actuated angles.

Method (a polynomial elimination, complete by construction). With the actuated angles fixed, the
elbows ``E_i`` are known and platform joint i must lie on the circle of radius L about ``E_i``.
Writing ``A_i(alpha) = E_i + rp u_i(alpha)`` (``u_i`` the unit vector of SPEC's ``phi_i``), the
three closure equations are ``|c - A_i(alpha)|^2 = L^2`` for the platform centre ``c``.
Subtracting the first from the others gives a 2x2 *linear* system ``M(alpha) c = b(alpha)``;
Cramer's rule gives ``c = (Nx, Ny) / D`` and substituting into the first equation leaves one
equation in ``alpha`` alone::

    f(alpha) = (Nx - A_1x D)^2 + (Ny - A_1y D)^2 - L^2 D^2 = 0.

Because every quantity is built from rotations of fixed vectors and rotation-invariant dot and
cross products, ``X + iY = (Nx - A_1x D) + i (Ny - A_1y D)`` only contains the harmonics
``z^2, z, 1, z^-1`` of ``z = exp(i alpha)`` and ``D`` is of degree 1, so ``f`` is a real
trigonometric polynomial of degree 3: ``z^3 f`` is a polynomial of degree 6 in ``z`` — the
classical sextic of the planar 3-RRR (at most 6 assembly modes). Its coefficients are computed
exactly (to rounding) by the DFT of 16 samples of ``f``; all six roots are the eigenvalues of the
companion matrix. Every real solution ``(c, alpha)`` makes ``f(alpha) = 0`` (if ``D(alpha) = 0`` a
consistent singular system has ``Nx = Ny = 0``, so ``f = 0`` too), hence appears among the roots
with ``|z| = 1``: nothing is missed. For each such root, ``c`` is recovered by intersecting the
leg circles 1 and 2 (choosing the intersection that meets circle 3), polished by Newton steps on
the three closure equations, and kept only if the IK of the pose reproduces the actuated angles
(which also rejects spurious roots). Roots are accepted slightly off the unit circle because a
double root at a Type II singularity splits by ~sqrt(eps).

Units: angles in [rad], lengths in [m]; poses ``(xc, yc, alpha)``.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np

from lynxplan.constants import (
    PARALLEL_FK_DUPLICATE_TOLERANCE,
    PARALLEL_FK_UNIT_CIRCLE_TOLERANCE,
    PARALLEL_FK_VERIFY_TOLERANCE,
)
from lynxplan.exceptions import (
    DegenerateForwardKinematicsError,
    NoAssemblyModeError,
    ShapeError,
)
from lynxplan.parallel._legs import (
    LegConstants,
    anchor,
    closure_value,
    elbow_half_angle,
    leg_offset,
)
from lynxplan.parallel.geometry import PLATFORM_PHASES, ParallelGeometry
from lynxplan.parallel.ik import WORKING_MODES, elbows, leg_constants

_DEFAULT_GEOMETRY = ParallelGeometry()
_SAMPLES = 16
_NEWTON_STEPS = 3


class ModeSlots(NamedTuple):
    """:func:`fk_kernel`'s outputs for N solves, up to six assembly modes each."""

    poses: np.ndarray
    """(N, 6, 3) platform poses (xc, yc, alpha) [m, m, rad], sorted by alpha."""
    modes: np.ndarray
    """(N, 6) int64 working-mode index of each pose."""
    errors: np.ndarray
    """(N, 6) largest |IK(pose) - theta| of each pose [rad]."""
    counts: np.ndarray
    """(N,) int64 how many modes each solve has."""


class ParallelFKResult(NamedTuple):
    """All real assembly modes for one set of actuated angles."""

    poses: np.ndarray
    """Platform poses ``(xc, yc, alpha)``, shape (M, 3), in [m, m, rad], alpha in (-pi, pi]."""
    working_modes: np.ndarray
    """Index into :data:`~lynxplan.parallel.ik.WORKING_MODES` of each pose, shape (M,)."""
    ik_error: np.ndarray
    """Largest |IK(pose) - theta| of each pose in its working mode, shape (M,), in [rad]."""

    @property
    def n_modes(self) -> int:
        """Number of real assembly modes (0 to 6)."""
        return int(self.poses.shape[0])

    def mode_labels(self) -> list[str]:
        """Working-mode label (e.g. ``"+-+"``) of each assembly mode."""
        return [WORKING_MODES[m] for m in self.working_modes]


def _as_thetas(theta: np.ndarray) -> np.ndarray:
    """Actuated angles (3,) or (N, 3) in range (:func:`lynxplan.guards.configurations`)."""
    from lynxplan import guards

    return guards.configurations("theta", theta, dof=3).reshape(-1, 3)


@numba.njit(cache=True, nogil=True)
def closure_kernel(
    elbow: np.ndarray, alpha: np.ndarray, phase: np.ndarray, rp: float, el: float, out: np.ndarray
) -> None:
    """``f(alpha[n, k])`` for elbows (N, 3, 2) into ``out`` (N, K)."""
    for n in range(alpha.shape[0]):
        for k in range(alpha.shape[1]):
            out[n, k] = closure_value(elbow[n], alpha[n, k], phase, rp, el)


def closure_polynomial(
    elbow: np.ndarray, alpha: np.ndarray, distal: float, rp: float
) -> np.ndarray:
    """``f(alpha)`` of the module docstring for elbows (N, 3, 2) at angles (N, K) -> (N, K)."""
    phases = np.array(PLATFORM_PHASES)
    phase = np.stack([np.cos(phases), np.sin(phases)], axis=1)
    angles = np.ascontiguousarray(np.asarray(alpha, dtype=float))
    out = np.empty(angles.shape)
    closure_kernel(np.ascontiguousarray(elbow, dtype=float), angles, phase, rp, distal, out)
    return out


@numba.njit(cache=True, nogil=True)
def sextic_kernel(elbow: np.ndarray, legs: LegConstants, out: np.ndarray) -> None:
    """Coefficients of ``z^3 f(z)`` (highest power first) for elbows (N, 3, 2) into ``out``
    (N, 7): the DFT of 16 samples of ``f`` (exact for a trigonometric polynomial of degree 3)."""
    _, phase, rp, _, el = legs
    samples = np.empty(_SAMPLES)
    for n in range(elbow.shape[0]):
        for j in range(_SAMPLES):
            samples[j] = closure_value(elbow[n], 2.0 * math.pi * j / _SAMPLES, phase, rp, el)
        for k in range(-3, 4):
            acc = 0.0 + 0.0j
            for j in range(_SAMPLES):
                angle = -2.0 * math.pi * k * j / _SAMPLES
                acc += samples[j] * complex(math.cos(angle), math.sin(angle))
            out[n, 3 - k] = acc / _SAMPLES


def sextic_coefficients(elbow: np.ndarray, geometry: ParallelGeometry) -> np.ndarray:
    """Coefficients of ``z^3 f(z)``, highest power first, shape (N, 7), from elbows (N, 3, 2)."""
    out = np.empty((elbow.shape[0], 7), dtype=np.complex128)
    sextic_kernel(np.ascontiguousarray(elbow), leg_constants(geometry), out)
    return out


@numba.njit(cache=True, nogil=True)
def _wrap(angle: float) -> float:
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


@numba.njit(cache=True, nogil=True)
def _closure_newton(elbow: np.ndarray, pose: np.ndarray, legs: LegConstants) -> None:
    """Polish ``pose`` (3,) in place on the closure equations |c - A_i(alpha)|^2 = L^2
    (Levenberg-damped Gauss-Newton steps, so a singular Jacobian at a Type II singularity does
    not blow up); scalar code, no allocation."""
    _, phase, rp, _, el = legs
    for _ in range(_NEWTON_STEPS):
        ca, sa = math.cos(pose[2]), math.sin(pose[2])
        # Normal equations (J^T J + mu I) step = J^T g, accumulated row by row.
        n00 = n01 = n02 = n11 = n12 = n22 = 0.0
        r0 = r1 = r2 = 0.0
        for i in range(3):
            rx, ry, cphi, sphi = leg_offset(pose[0], pose[1], ca, sa, phase, elbow, rp, i)
            g = rx * rx + ry * ry - el * el
            j0, j1, j2 = 2.0 * rx, 2.0 * ry, -2.0 * rp * (-rx * sphi + ry * cphi)
            n00 += j0 * j0
            n01 += j0 * j1
            n02 += j0 * j2
            n11 += j1 * j1
            n12 += j1 * j2
            n22 += j2 * j2
            r0 += j0 * g
            r1 += j1 * g
            r2 += j2 * g
        mu = 1e-14 * (n00 + n11 + n22) + 1e-300
        n00 += mu
        n11 += mu
        n22 += mu
        # Cramer's rule on the symmetric 3x3 system.
        c00 = n11 * n22 - n12 * n12
        c01 = n02 * n12 - n01 * n22
        c02 = n01 * n12 - n02 * n11
        det = n00 * c00 + n01 * c01 + n02 * c02
        pose[0] -= (r0 * c00 + r1 * c01 + r2 * c02) / det
        pose[1] -= (r0 * c01 + r1 * (n00 * n22 - n02 * n02) + r2 * (n01 * n02 - n00 * n12)) / det
        pose[2] -= (r0 * c02 + r1 * (n01 * n02 - n00 * n12) + r2 * (n00 * n11 - n01 * n01)) / det


@numba.njit(cache=True, nogil=True)
def _verify(pose: np.ndarray, theta: np.ndarray, legs: LegConstants) -> tuple[float, int]:
    """Largest |IK(pose) - theta| (wrapped) in the best-matching working mode, and that mode."""
    base, phase, rp, s, el = legs
    worst, mode = 0.0, 0
    ca, sa = math.cos(pose[2]), math.sin(pose[2])
    for i in range(3):
        dx, dy, _, _ = leg_offset(pose[0], pose[1], ca, sa, phase, base, rp, i)
        dist = math.sqrt(dx * dx + dy * dy)
        if dist == 0.0:
            return math.inf, 0
        half = elbow_half_angle(dist, s, el)
        direction = math.atan2(dy, dx)
        plus = abs(_wrap(direction + half - theta[i]))
        minus = abs(_wrap(direction - half - theta[i]))
        if minus < plus:
            mode |= 1 << (2 - i)
        worst = max(worst, min(plus, minus))
    return worst, mode


@numba.njit(cache=True, nogil=True)
def _sextic_roots(c: np.ndarray) -> np.ndarray:
    """Roots of the polynomial ``c`` (7,), highest power first, as the companion matrix's
    eigenvalues after trimming negligible end coefficients (a lower degree); may be empty."""
    scale = 0.0
    for k in range(7):
        scale = max(scale, abs(c[k]))
    first, last = 0, 6
    while first < 7 and abs(c[first]) <= 1e-10 * scale:
        first += 1
    while last > first and abs(c[last]) <= 1e-10 * scale:
        last -= 1
    degree = max(last - first, 0)
    companion = np.zeros((degree, degree), dtype=np.complex128)
    for j in range(degree):
        companion[0, j] = -c[first + 1 + j] / c[first]
    for j in range(degree - 1):
        companion[j + 1, j] = 1.0
    if degree == 0:
        return np.empty(0, dtype=np.complex128)
    return np.linalg.eigvals(companion)


@numba.njit(cache=True, nogil=True)
def _centre_from_legs_a_b(
    elbow: np.ndarray, alpha: float, legs: LegConstants, pose: np.ndarray
) -> None:
    """``pose[:2]``: the intersection of leg circles A and B (radius L about ``A_i(alpha)``) that
    lies closest to circle C; ``pose[2] = alpha``."""
    _, phase, rp, _, el = legs
    ca, sa = math.cos(alpha), math.sin(alpha)
    ax0, ay0 = anchor(elbow, ca, sa, phase, rp, 0)
    ax1, ay1 = anchor(elbow, ca, sa, phase, rp, 1)
    ax2, ay2 = anchor(elbow, ca, sa, phase, rp, 2)
    chx, chy = ax1 - ax0, ay1 - ay0
    length = max(math.sqrt(chx * chx + chy * chy), 1e-300)
    half = math.sqrt(max(el * el - 0.25 * length * length, 0.0))
    best = math.inf
    for side in (1.0, -1.0):
        cx = 0.5 * (ax0 + ax1) - side * half * chy / length
        cy = 0.5 * (ay0 + ay1) + side * half * chx / length
        miss = abs(math.sqrt((cx - ax2) ** 2 + (cy - ay2) ** 2) - el)
        if miss < best:
            best = miss
            pose[0], pose[1] = cx, cy
    pose[2] = alpha


@numba.njit(cache=True, nogil=True)
def _insert_mode(
    n: int,
    pose: np.ndarray,
    mode: int,
    error: float,
    duplicate_tolerance: float,
    out: ModeSlots,
) -> None:
    """Add an assembly mode of solve n to ``out``, kept sorted by
    platform angle, unless a pose within ``duplicate_tolerance`` is already there."""
    poses, modes, errors, counts = out
    tol = duplicate_tolerance
    for m in range(counts[n]):
        near = math.hypot(poses[n, m, 0] - pose[0], poses[n, m, 1] - pose[1])
        if near <= tol and abs(_wrap(poses[n, m, 2] - pose[2])) <= tol:
            return
    m = counts[n]  # insertion, sorted by platform angle
    while m > 0 and poses[n, m - 1, 2] > pose[2]:
        poses[n, m] = poses[n, m - 1]
        modes[n, m] = modes[n, m - 1]
        errors[n, m] = errors[n, m - 1]
        m -= 1
    poses[n, m, 0], poses[n, m, 1], poses[n, m, 2] = pose[0], pose[1], pose[2]
    modes[n, m] = mode
    errors[n, m] = error
    counts[n] += 1


@numba.njit(cache=True, nogil=True)
def fk_kernel(
    coefficients: np.ndarray,
    elbow: np.ndarray,
    theta: np.ndarray,
    legs: LegConstants,
    tolerances: np.ndarray,
    out: ModeSlots,
) -> None:
    """Assembly modes of each solve n from its sextic ``coefficients[n]`` (7,), highest power
    first: roots on the unit circle -> centre from leg circles A and B -> Newton -> IK check ->
    dedupe -> sort by alpha, into ``out`` (every solve's count; the modes it counts);
    ``tolerances`` = (unit circle, IK verification, duplicate)."""
    pose = np.empty(3)
    counts = out.counts
    for n in range(coefficients.shape[0]):
        counts[n] = 0
        for z in _sextic_roots(coefficients[n]):
            if abs(abs(z) - 1.0) >= tolerances[0]:
                continue
            _centre_from_legs_a_b(elbow[n], math.atan2(z.imag, z.real), legs, pose)
            _closure_newton(elbow[n], pose, legs)
            pose[2] = _wrap(pose[2])
            error, mode = _verify(pose, theta[n], legs)
            if error <= tolerances[1] and counts[n] < 6:
                _insert_mode(n, pose, mode, error, tolerances[2], out)


def solve_fk_batch(
    theta: np.ndarray, geometry: ParallelGeometry = _DEFAULT_GEOMETRY
) -> list[ParallelFKResult]:
    """All real assembly modes for many sets of actuated angles.

    Args:
        theta: Actuated angles, shape (3,) or (N, 3), in [rad].
        geometry: Robot dimensions.

    Returns:
        One :class:`ParallelFKResult` per row of ``theta`` (possibly with zero poses).

    Raises:
        DegenerateForwardKinematicsError: the closure polynomial vanishes identically.
    """
    thetas = _as_thetas(theta)
    elbow = elbows(thetas, geometry)
    coefficients = sextic_coefficients(elbow, geometry)
    scale = (geometry.proximal + geometry.distal + geometry.base_circumradius) ** 6
    degenerate = np.max(np.abs(coefficients), axis=1) <= 1e-14 * scale
    if np.any(degenerate):
        bad = thetas[int(np.argmax(degenerate))]
        raise DegenerateForwardKinematicsError((float(bad[0]), float(bad[1]), float(bad[2])))
    count = thetas.shape[0]
    poses, modes = np.empty((count, 6, 3)), np.empty((count, 6), dtype=np.int64)
    errors, counts = np.empty((count, 6)), np.empty(count, dtype=np.int64)
    tolerances = np.array(
        [
            PARALLEL_FK_UNIT_CIRCLE_TOLERANCE,
            PARALLEL_FK_VERIFY_TOLERANCE,
            PARALLEL_FK_DUPLICATE_TOLERANCE,
        ]
    )
    fk_kernel(
        np.ascontiguousarray(coefficients),
        np.ascontiguousarray(elbow),
        np.ascontiguousarray(thetas),
        leg_constants(geometry),
        tolerances,
        ModeSlots(poses, modes, errors, counts),
    )
    return [
        ParallelFKResult(poses[n, : counts[n]], modes[n, : counts[n]], errors[n, : counts[n]])
        for n in range(count)
    ]


def solve_fk(theta: np.ndarray, geometry: ParallelGeometry = _DEFAULT_GEOMETRY) -> ParallelFKResult:
    """All real assembly modes (0 to 6) for actuated angles ``theta``, shape (3,), in [rad],
    sorted by platform angle."""
    array = _as_thetas(theta)
    if np.ndim(theta) != 1:
        raise ShapeError("theta", "(3,)", np.shape(theta))
    return solve_fk_batch(array, geometry)[0]


def pose_distance(
    pose: np.ndarray, reference: np.ndarray, geometry: ParallelGeometry
) -> np.ndarray:
    """Distance between poses (..., 3) and a reference (3,), in [m]: centre distance plus the arc
    the platform joints travel for the (wrapped) orientation difference (``rp |delta alpha|``)."""
    pose = np.asarray(pose, dtype=float)
    angle = np.abs(np.angle(np.exp(1j * (pose[..., 2] - reference[2]))))
    return np.asarray(
        np.hypot(pose[..., 0] - reference[0], pose[..., 1] - reference[1])
        + geometry.platform_circumradius * angle
    )


def nearest_assembly_mode(
    theta: np.ndarray, reference: np.ndarray, geometry: ParallelGeometry = _DEFAULT_GEOMETRY
) -> np.ndarray:
    """The assembly mode of ``theta`` (3,) in [rad] nearest to pose ``reference`` (3,) in
    [m, m, rad] by :func:`pose_distance`; shape (3,).

    Raises:
        NoAssemblyModeError: no real assembly mode exists.
    """
    from lynxplan import guards

    reference = guards.planar_poses("reference", reference)
    if reference.shape != (3,):
        raise ShapeError("reference", "(3,)", reference.shape)
    result = solve_fk(theta, geometry)
    if result.n_modes == 0:
        raise NoAssemblyModeError(tuple(float(t) for t in np.asarray(theta, dtype=float)))  # type: ignore[arg-type]
    return np.array(result.poses[np.argmin(pose_distance(result.poses, reference, geometry))])
