"""Numerical IK for any revolute chain: Levenberg-Marquardt with joint limits, multi-start.

Each target is solved from the reference configuration first, then from fixed pseudo-random
starts within the limits (deterministic: the same seed gives the same answers), until one start
converges. A solution counts only if forward kinematics on the chain reproduces the target within
:data:`NUMERICAL_POSITION_TOLERANCE` and :data:`NUMERICAL_ORIENTATION_TOLERANCE`; failures are
reported, never returned as solutions.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np

from lynxplan.constants import (
    NUMERICAL_CONVERGED,
    NUMERICAL_ORIENTATION_TOLERANCE,
    NUMERICAL_POSITION_TOLERANCE,
)
from lynxplan.robots.chain import chain_fk_jacobian
from lynxplan.robots.ik.family_polish import lu_factor, lu_solve

MAX_ITERATIONS = 200
DEFAULT_STARTS = 128


@numba.njit(cache=True, nogil=True)
def _error(
    pose: np.ndarray, target: np.ndarray, approach_only: bool, e: np.ndarray, u: np.ndarray
) -> None:
    """Position error then orientation error (Siciliano: 0.5 sum n_i x n_t,i; approach: a_t - a)."""
    for i in range(3):
        e[i] = target[i, 3] - pose[i, 3]
        e[3 + i] = 0.0
    if approach_only:  # a_t - a, whose Jacobian is w x a (see _approach_rows)
        for i in range(3):
            e[3 + i] = target[i, 2] - (pose[i, 0] * u[0] + pose[i, 1] * u[1] + pose[i, 2] * u[2])
        return
    scale = 0.5
    for c in range(3):
        u0, u1, u2 = pose[0, c], pose[1, c], pose[2, c]
        v0, v1, v2 = target[0, c], target[1, c], target[2, c]
        e[3] += scale * (u1 * v2 - u2 * v1)
        e[4] += scale * (u2 * v0 - u0 * v2)
        e[5] += scale * (u0 * v1 - u1 * v0)


@numba.njit(cache=True, nogil=True)
def _approach_rows(pose: np.ndarray, jac: np.ndarray, u: np.ndarray) -> None:
    """Angular rows w_i -> w_i x a: the rate of the approach axis a = R u per joint."""
    a0 = pose[0, 0] * u[0] + pose[0, 1] * u[1] + pose[0, 2] * u[2]
    a1 = pose[1, 0] * u[0] + pose[1, 1] * u[1] + pose[1, 2] * u[2]
    a2 = pose[2, 0] * u[0] + pose[2, 1] * u[1] + pose[2, 2] * u[2]
    for i in range(jac.shape[1]):
        w0, w1, w2 = jac[3, i], jac[4, i], jac[5, i]
        jac[3, i] = w1 * a2 - w2 * a1
        jac[4, i] = w2 * a0 - w0 * a2
        jac[5, i] = w0 * a1 - w1 * a0


@numba.njit(cache=True, nogil=True)
def _linearised(
    arm: NumericalArm,
    q: np.ndarray,
    target: np.ndarray,
    approach_only: bool,
    frames: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    e: np.ndarray,
) -> float:
    """The pose and Jacobian at q (n,) [rad] into frames = (pose (4, 4), jac (6, n), and the
    FK's scratch (4, 4), (n, 6)), the error against the target into e (6,) (``_error``; for
    ``approach_only`` the Jacobian's angular rows are the approach axis's rates); returns the
    squared error's sum."""
    pose, jac, work, origins = frames
    chain_fk_jacobian(arm.placements, arm.axes, q, pose, jac, work, origins)
    if approach_only:
        _approach_rows(pose, jac, arm.approach_axis)
    _error(pose, target, approach_only, e, arm.approach_axis)
    cost = 0.0
    for i in range(6):
        cost += e[i] * e[i]
    return cost


@numba.njit(cache=True, nogil=True)
def _angle(pose: np.ndarray, target: np.ndarray, approach_only: bool, u: np.ndarray) -> float:
    if approach_only:
        a0 = pose[0, 0] * u[0] + pose[0, 1] * u[1] + pose[0, 2] * u[2]
        a1 = pose[1, 0] * u[0] + pose[1, 1] * u[1] + pose[1, 2] * u[2]
        a2 = pose[2, 0] * u[0] + pose[2, 1] * u[1] + pose[2, 2] * u[2]
        c0 = a1 * target[2, 2] - a2 * target[1, 2]
        c1 = a2 * target[0, 2] - a0 * target[2, 2]
        c2 = a0 * target[1, 2] - a1 * target[0, 2]
        d = a0 * target[0, 2] + a1 * target[1, 2] + a2 * target[2, 2]
        return math.atan2(math.sqrt(c0 * c0 + c1 * c1 + c2 * c2), d)
    tr = 0.0
    m = np.zeros((3, 3))
    for i in range(3):
        for j in range(3):
            for r in range(3):
                m[i, j] += target[r, i] * pose[r, j]
        tr += m[i, i]
    s0, s1, s2 = m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]
    return math.atan2(0.5 * math.sqrt(s0 * s0 + s1 * s1 + s2 * s2), 0.5 * (tr - 1.0))


class NumericalArm(NamedTuple):
    """What :func:`numerical_ik_kernel` knows of the arm (writable, C-contiguous arrays)."""

    placements: np.ndarray
    """(n + 1, 4, 4) joint placements and the tool's (``chain.py``) [m]."""
    axes: np.ndarray
    """(n, 3) joint axes (unit vectors)."""
    lower: np.ndarray
    """(n,) lower joint limits [rad]."""
    upper: np.ndarray
    """(n,) upper joint limits [rad]."""
    approach_axis: np.ndarray
    """(3,) the tool's approach axis in the tool frame (unit vector)."""


class NumericalResult(NamedTuple):
    """The outputs of :func:`numerical_ik_kernel` for N targets."""

    q: np.ndarray
    """(N, n) best configuration found [rad]."""
    success: np.ndarray
    """(N,) bool: verified within tolerance."""
    position_error: np.ndarray
    """(N,) of q [m]."""
    orientation_error: np.ndarray
    """(N,) of q [rad]."""
    iterations: np.ndarray
    """(N,) int64: total iterations used."""

    @classmethod
    def empty(cls, n: int, nq: int) -> NumericalResult:
        """Uninitialised outputs (the kernel writes every row)."""
        return cls(
            np.empty((n, nq)),
            np.empty(n, dtype=np.bool_),
            np.empty(n),
            np.empty(n),
            np.empty(n, dtype=np.int64),
        )


@numba.njit(cache=True, nogil=True)
def numerical_ik_kernel(  # noqa: PLR0912, PLR0915 (numba kernel: one compiled loop per pose)
    arm: NumericalArm,
    targets: np.ndarray,
    approach_only: bool,
    reference: np.ndarray,
    starts: np.ndarray,
    result: NumericalResult,
) -> None:
    """Levenberg-Marquardt IK of N targets (see module docstring).

    Args:
        arm: The chain, its limits and the tool's approach axis (:class:`NumericalArm`).
        targets: (N, 4, 4) poses [m]; approach_only: only column 2 of the rotation counts: the
            tool axis ``arm.approach_axis`` must point along it.
        reference: (N, n) or (1, n) first start [rad]; starts: (S, n) further starts [rad].
        result: The outputs (:class:`NumericalResult`).
    """
    placements, axes, lower, upper, approach_axis = arm
    q_out, success, position_error, orientation_error, iterations = result
    n = axes.shape[0]
    frames = (np.empty((4, 4)), np.empty((6, n)), np.empty((4, 4)), np.empty((n, 6)))
    pose, jac, work, origins = frames
    e, e_new = np.empty(6), np.empty(6)
    q, q_new = np.empty(n), np.empty(n)
    a = np.empty((n + 1, n))  # the normal equations, then their LU factors (``lu_factor``)
    b, step = np.empty(n), np.empty(n)
    for k in range(targets.shape[0]):
        target = targets[k]
        best_cost = np.inf
        total = 0
        success[k] = False
        for s in range(starts.shape[0] + 1):
            if s == 0:
                q[:] = reference[k if reference.shape[0] > 1 else 0]
            else:
                q[:] = starts[s - 1]
            for j in range(n):
                q[j] = min(max(q[j], lower[j]), upper[j])
            lam = 1e-3
            cost = _linearised(arm, q, target, approach_only, frames, e)
            for _ in range(MAX_ITERATIONS):
                total += 1
                if cost < NUMERICAL_CONVERGED * NUMERICAL_CONVERGED:
                    break
                for i in range(n):
                    b[i] = 0.0
                    for r in range(6):
                        b[i] += jac[r, i] * e[r]
                    for j in range(n):
                        acc = 0.0
                        for r in range(6):
                            acc += jac[r, i] * jac[r, j]
                        a[i, j] = acc
                    a[i, i] += lam * (1.0 + a[i, i])
                lu_factor(a)  # damped normal equations: positive definite, never singular
                lu_solve(a, b, step)
                for j in range(n):
                    q_new[j] = min(max(q[j] + step[j], lower[j]), upper[j])
                new_cost = _linearised(arm, q_new, target, approach_only, frames, e_new)
                if new_cost < cost:
                    q[:] = q_new
                    e[:] = e_new
                    cost = new_cost
                    lam = max(lam / 3.0, 1e-12)
                else:
                    lam *= 4.0
                    chain_fk_jacobian(placements, axes, q, pose, jac, work, origins)
                    if approach_only:
                        _approach_rows(pose, jac, approach_axis)
                    if lam > 1e8:
                        break
            chain_fk_jacobian(placements, axes, q, pose, jac, work, origins)
            d0, d1, d2 = (
                pose[0, 3] - target[0, 3],
                pose[1, 3] - target[1, 3],
                pose[2, 3] - target[2, 3],
            )
            perr = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            oerr = _angle(pose, target, approach_only, approach_axis)
            score = perr + 0.1 * oerr
            if score < best_cost:
                best_cost = score
                q_out[k, :] = q
                position_error[k] = perr
                orientation_error[k] = oerr
            if perr <= NUMERICAL_POSITION_TOLERANCE and oerr <= NUMERICAL_ORIENTATION_TOLERANCE:
                success[k] = True
                q_out[k, :] = q
                position_error[k] = perr
                orientation_error[k] = oerr
                break
        iterations[k] = total
