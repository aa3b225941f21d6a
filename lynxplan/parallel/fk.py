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
exactly (to rounding) by the FFT of 16 samples of ``f``; all six roots are the eigenvalues of the
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

import numpy as np

from lynxplan.constants import (
    PARALLEL_FK_DUPLICATE_TOLERANCE,
    PARALLEL_FK_UNIT_CIRCLE_TOLERANCE,
    PARALLEL_FK_VERIFY_TOLERANCE,
)
from lynxplan.exceptions import (
    DegenerateForwardKinematicsError,
    NoAssemblyModeError,
    NonFiniteInputError,
    ShapeError,
)
from lynxplan.parallel.geometry import PLATFORM_PHASES, ParallelGeometry
from lynxplan.parallel.ik import WORKING_MODES, elbows, solve_ik_batch

_DEFAULT_GEOMETRY = ParallelGeometry()
_SAMPLES = 16
_NEWTON_STEPS = 3


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
    array = np.asarray(theta, dtype=float)
    if array.ndim not in (1, 2) or array.shape[-1] != 3:
        raise ShapeError("theta", "(3,) or (N, 3)", array.shape)
    if not np.all(np.isfinite(array)):
        raise NonFiniteInputError("theta")
    return array.reshape(-1, 3)


def _anchors(elbow: np.ndarray, alpha: np.ndarray, rp: float) -> np.ndarray:
    """``A_i(alpha) = E_i + rp u_i(alpha)``: elbow (N, 3, 2), alpha (N, K) -> (N, K, 3, 2)."""
    phi = alpha[..., None] + np.array(PLATFORM_PHASES)
    u = np.stack([np.cos(phi), np.sin(phi)], axis=-1)
    return elbow[:, None] + rp * u


def closure_polynomial(
    elbow: np.ndarray, alpha: np.ndarray, distal: float, rp: float
) -> np.ndarray:
    """``f(alpha)`` of the module docstring for elbows (N, 3, 2) at angles (N, K) -> (N, K)."""
    a = _anchors(elbow, alpha, rp)
    m = 2.0 * (a[..., 1:, :] - a[..., :1, :])
    b = np.sum(a[..., 1:, :] ** 2, axis=-1) - np.sum(a[..., :1, :] ** 2, axis=-1)
    d = m[..., 0, 0] * m[..., 1, 1] - m[..., 0, 1] * m[..., 1, 0]
    nx = b[..., 0] * m[..., 1, 1] - b[..., 1] * m[..., 0, 1]
    ny = m[..., 0, 0] * b[..., 1] - m[..., 1, 0] * b[..., 0]
    x = nx - a[..., 0, 0] * d
    y = ny - a[..., 0, 1] * d
    return np.asarray(x * x + y * y - distal**2 * d * d)


def sextic_coefficients(elbow: np.ndarray, geometry: ParallelGeometry) -> np.ndarray:
    """Coefficients of ``z^3 f(z)``, highest power first, shape (N, 7), from elbows (N, 3, 2)."""
    alpha = np.broadcast_to(
        np.arange(_SAMPLES) * (2.0 * math.pi / _SAMPLES), (elbow.shape[0], _SAMPLES)
    )
    f = closure_polynomial(elbow, alpha, geometry.distal, geometry.platform_circumradius)
    c = np.fft.fft(f, axis=-1) / _SAMPLES  # c[k] multiplies exp(i k alpha); c[-k] = conj(c[k])
    # z^3 f = sum_{k=-3..3} c_k z^(k+3); highest power (k = 3) first.
    return np.concatenate([c[:, 3::-1], c[:, -1:-4:-1]], axis=1)


def _roots(coefficients: np.ndarray) -> list[np.ndarray]:
    """All roots of each polynomial (N, 7): batched companion eigenvalues, or np.roots."""
    scale = np.max(np.abs(coefficients), axis=1)
    lead = coefficients[:, 0]
    regular = np.abs(lead) > 1e-9 * scale
    result: list[np.ndarray] = [np.empty(0, dtype=complex)] * coefficients.shape[0]
    index = np.flatnonzero(regular)
    if index.size:
        companion = np.zeros((index.size, 6, 6), dtype=complex)
        companion[:, 0, :] = -coefficients[index, 1:] / lead[index, None]
        companion[:, np.arange(1, 6), np.arange(5)] = 1.0
        eig = np.linalg.eigvals(companion)
        for j, n in enumerate(index):
            result[n] = eig[j]
    for n in np.flatnonzero(~regular):
        trimmed = np.where(np.abs(coefficients[n]) > 1e-13 * scale[n], coefficients[n], 0.0)
        result[n] = np.roots(trimmed) if np.any(trimmed) else np.empty(0, dtype=complex)
    return result


def _centres(elbow: np.ndarray, alpha: np.ndarray, geometry: ParallelGeometry) -> np.ndarray:
    """Platform centre for each (elbow set (K, 3, 2), alpha (K,)): intersection of leg circles
    1 and 2 that lies closest to circle 3, shape (K, 2)."""
    a = _anchors(elbow, alpha[:, None], geometry.platform_circumradius)[:, 0]
    el = geometry.distal
    chord = a[:, 1] - a[:, 0]
    length = np.maximum(np.linalg.norm(chord, axis=1), 1e-300)
    half = np.sqrt(np.maximum(el * el - (length / 2) ** 2, 0.0))
    mid = (a[:, 0] + a[:, 1]) / 2
    normal = np.stack([-chord[:, 1], chord[:, 0]], axis=1) / length[:, None]
    candidates = np.stack([mid + half[:, None] * normal, mid - half[:, None] * normal], axis=1)
    miss = np.abs(np.linalg.norm(candidates - a[:, None, 2], axis=2) - el)
    return candidates[np.arange(len(alpha)), np.argmin(miss, axis=1)]


def _newton(elbow: np.ndarray, poses: np.ndarray, geometry: ParallelGeometry) -> np.ndarray:
    """Polish poses (K, 3) on the closure equations |c - A_i(alpha)|^2 = L^2 (pseudo-inverse
    steps, so a singular Jacobian at a Type II singularity does not blow up)."""
    rp, el = geometry.platform_circumradius, geometry.distal
    phases = np.array(PLATFORM_PHASES)
    for _ in range(_NEWTON_STEPS):
        phi = poses[:, 2:3] + phases
        a = elbow + rp * np.stack([np.cos(phi), np.sin(phi)], axis=-1)
        r = poses[:, None, :2] - a
        g = np.sum(r * r, axis=-1) - el * el
        da = rp * np.stack([-np.sin(phi), np.cos(phi)], axis=-1)
        jac = np.concatenate([2 * r, -2 * np.sum(r * da, axis=-1, keepdims=True)], axis=-1)
        poses = poses - np.einsum("kij,kj->ki", np.linalg.pinv(jac, rcond=1e-12), g)
    return poses


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
    roots = _roots(coefficients)
    owner, alpha = [], []
    for n, z in enumerate(roots):
        if np.max(np.abs(coefficients[n])) <= 1e-14 * scale:
            raise DegenerateForwardKinematicsError(tuple(float(t) for t in thetas[n]))  # type: ignore[arg-type]
        keep = np.abs(np.abs(z) - 1.0) < PARALLEL_FK_UNIT_CIRCLE_TOLERANCE
        owner.extend([n] * int(np.sum(keep)))
        alpha.extend(np.angle(z[keep]))
    owner_array = np.array(owner, dtype=int)
    alpha_array = np.array(alpha, dtype=float)
    results: list[list[tuple[np.ndarray, int, float]]] = [[] for _ in range(thetas.shape[0])]
    if owner_array.size:
        centres = _centres(elbow[owner_array], alpha_array, geometry)
        poses = _newton(elbow[owner_array], np.column_stack([centres, alpha_array]), geometry)
        poses[:, 2] = np.angle(np.exp(1j * poses[:, 2]))
        ik = solve_ik_batch(poses, geometry).angles
        error = np.abs(np.angle(np.exp(1j * (ik - thetas[owner_array][:, None, :])))).max(axis=2)
        error = np.where(np.isnan(error), np.inf, error)
        mode = np.argmin(error, axis=1)
        best = error[np.arange(len(mode)), mode]
        for k in np.flatnonzero(best <= PARALLEL_FK_VERIFY_TOLERANCE):
            found = results[owner_array[k]]
            if all(_distinct(poses[k], other) for other, _, _ in found):
                found.append((poses[k], int(mode[k]), float(best[k])))
    return [_result(found) for found in results]


def _distinct(a: np.ndarray, b: np.ndarray) -> bool:
    angle = abs(math.remainder(a[2] - b[2], 2 * math.pi))
    return bool(
        np.hypot(*(a[:2] - b[:2])) > PARALLEL_FK_DUPLICATE_TOLERANCE
        or angle > PARALLEL_FK_DUPLICATE_TOLERANCE
    )


def _result(found: list[tuple[np.ndarray, int, float]]) -> ParallelFKResult:
    found.sort(key=lambda item: float(item[0][2]))
    poses = np.array([p for p, _, _ in found]).reshape(-1, 3)
    return ParallelFKResult(
        poses, np.array([m for _, m, _ in found], dtype=int), np.array([e for _, _, e in found])
    )


def solve_fk(theta: np.ndarray, geometry: ParallelGeometry = _DEFAULT_GEOMETRY) -> ParallelFKResult:
    """All real assembly modes (0 to 6) for actuated angles ``theta``, shape (3,), in [rad],
    sorted by platform angle."""
    array = np.asarray(theta, dtype=float)
    if array.shape != (3,):
        raise ShapeError("theta", "(3,)", array.shape)
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
    reference = np.asarray(reference, dtype=float)
    if reference.shape != (3,):
        raise ShapeError("reference", "(3,)", reference.shape)
    if not np.all(np.isfinite(reference)):
        raise NonFiniteInputError("reference")
    result = solve_fk(theta, geometry)
    if result.n_modes == 0:
        raise NoAssemblyModeError(tuple(float(t) for t in np.asarray(theta, dtype=float)))  # type: ignore[arg-type]
    return np.array(result.poses[np.argmin(pose_distance(result.poses, reference, geometry))])
