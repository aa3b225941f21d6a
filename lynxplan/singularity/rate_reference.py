"""The resolved-rate loop in plain Python/numpy with Pinocchio's Jacobians: the cross-check of the
numba kernel and the bench baseline."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from lynxplan.singularity.rate_kernel import RateOutputs, k1_kernel, k2_kernel
from lynxplan.singularity.rate_problem import (
    ResolvedRateProblem,
    ResolvedRateRun,
    Strategy,
    parse_strategy,
)


def run_reference(  # noqa: PLR0915 (mirrors the kernel's steps in one readable loop)
    problem: ResolvedRateProblem, strategy: str | Strategy, arm: Any, *, max_steps: int
) -> ResolvedRateRun:
    """The same algorithm as :func:`run_resolved_rate`, step by step in Python with numpy and
    Pinocchio (frame placement, LOCAL_WORLD_ALIGNED Jacobian, Jacobian time variation for dm/dq).

    Args:
        problem: As for :func:`run_resolved_rate`.
        strategy: Strategy name.
        arm: The :class:`lynxplan.arm.Arm` whose Pinocchio model is used.
        max_steps: Number of steps to run at most.
    """
    import pinocchio as pin

    chosen = parse_strategy(strategy)
    model, data, frame = arm.model, arm.data, arm.tool_frame_id
    rows, columns = list(problem.task.rows), problem.columns
    m_bar, sig, k_r, lam_min, lam_max, m_dls = problem.parameters.as_array().tolist()
    path, dt, gain = problem.path, problem.dt, problem.gain
    vmax = np.array(problem.velocity_limits)
    pitch_row = np.array([0.0, 1.0, 1.0, 1.0, 0.0])

    def extended(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        pin.framesForwardKinematics(model, data, q)
        J6 = pin.computeFrameJacobian(model, data, q, frame, pin.LOCAL_WORLD_ALIGNED)
        roll = np.array([-math.cos(q[1] + q[2] + q[3]), 0.0, 0.0, 0.0, 1.0])
        return np.vstack([J6, pitch_row, roll]), data.oMf[frame].translation.copy()

    def gradient(q: np.ndarray, J: np.ndarray, Jp: np.ndarray, m: float) -> np.ndarray:
        grad = np.zeros(5)
        for j in range(5):
            pin.computeJointJacobiansTimeVariation(model, data, q, np.eye(5)[j])
            dJ6 = pin.getFrameJacobianTimeVariation(model, data, frame, pin.LOCAL_WORLD_ALIGNED)
            dE = np.vstack([dJ6, np.zeros(5), np.zeros(5)])
            dE[7, 0] = math.sin(q[1] + q[2] + q[3]) if 1 <= j <= 3 else 0.0
            grad[j] = m * np.trace(Jp @ dE[rows])
        return grad

    out = RateOutputs.empty(max_steps)
    q, t, tau = np.array(problem.q0), 0.0, 0.0
    end = path.duration + path.hold
    count = max_steps
    for n in range(max_steps):
        E, p = extended(q)
        J = E[rows]
        x = np.array([*p, q[1] + q[2] + q[3]])
        xr_all, xrd_all = path.sample(np.array([tau]))
        e = xr_all[0][columns] - x[columns]
        ff = xrd_all[0][columns]
        m = math.sqrt(max(np.linalg.det(J @ J.T), 0.0))
        k1, rate = 0.0, 1.0
        if chosen == Strategy.DLS:
            lam2 = lam_min**2 + ((lam_max * (1.0 - m / m_dls)) ** 2 if m < m_dls else 0.0)
            qd = np.linalg.solve(J.T @ J + lam2 * np.eye(5), J.T @ (ff + gain * e))
        else:
            Jp = np.linalg.pinv(J) if m == 0.0 else np.linalg.solve(J @ J.T, J).T
            if chosen == Strategy.SPEED_LIMIT:
                qa, qb = Jp @ ff, Jp @ (gain * e)
                rate = _speed_scale_py(qa, qb, vmax)
                qd = rate * qa + qb
            elif chosen == Strategy.TR:
                d = gradient(q, J, Jp, m) @ Jp
                xc = ff + gain * e
                if np.linalg.norm(d) > 0.0:
                    nv = d / np.linalg.norm(d)
                    k1 = float(k1_kernel(m, m_bar, sig))
                    k2 = float(k2_kernel(m, m_bar, k_r))
                    projector = np.eye(len(rows)) - 0.5 * (1 - np.sign(xc @ nv)) * k1 * np.outer(
                        nv, nv
                    )
                    xc = projector @ xc + k2 * nv
                qd = Jp @ xc
            else:
                qd = Jp @ (ff + gain * e)
        for array, value in zip(out, (t, tau, q, qd, x, xr_all[0], m, k1), strict=True):
            array[n] = value
        if tau >= end - 1e-12:
            count = n + 1
            break
        q = q + qd * dt
        t += dt
        tau = min(tau + rate * dt, end)
    return ResolvedRateRun(chosen, problem.task, *(array[:count] for array in out))


def _speed_scale_py(a: np.ndarray, b: np.ndarray, vmax: np.ndarray) -> float:
    worst = float(np.max(np.abs(b) / vmax))
    if worst >= 1.0:
        b /= worst
        return 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        bounds = np.where(a > 0, (vmax - b) / a, np.where(a < 0, (vmax + b) / -a, np.inf))
    return float(max(min(1.0, bounds.min()), 0.0))
