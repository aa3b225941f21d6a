"""Numerical IK baseline: Pinocchio closed-loop IK with damped least squares.

Only for comparison with the analytic IK (accuracy, speed, success rate). For a 5-joint arm the
damped step solves the 5x5 system (J^T J + lambda I) dq = J^T e, not the 6x6 one.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np


class ClikResult(NamedTuple):
    """Outcome of one CLIK solve."""

    q: np.ndarray
    """Final configuration, shape (5,), in [rad]."""
    success: bool
    """Whether the 6-D error fell below the tolerance."""
    iterations: int
    """Iterations used."""
    error: float
    """Final norm of the 6-D error (log of the pose error, [m] and [rad] mixed)."""


def solve_clik(
    model: Any,
    data: Any,
    frame_id: int,
    target: np.ndarray,
    q_start: np.ndarray,
    *,
    damping: float = 1e-6,
    tolerance: float = 1e-9,
    max_iterations: int = 1000,
    step: float = 1.0,
) -> ClikResult:
    """Damped-least-squares CLIK towards ``target`` (4, 4) from ``q_start`` (5,), in [rad]."""
    import pinocchio as pin

    desired = pin.SE3(target[:3, :3], target[:3, 3])
    q = np.array(q_start, dtype=float)
    damping_matrix = damping * np.eye(model.nv)
    for iteration in range(1, max_iterations + 1):
        pin.forwardKinematics(model, data, q)
        current = pin.updateFramePlacement(model, data, frame_id)
        error = pin.log6(current.actInv(desired)).vector
        norm = float(np.linalg.norm(error))
        if norm < tolerance:
            return ClikResult(q, True, iteration, norm)
        J = pin.computeFrameJacobian(model, data, q, frame_id, pin.ReferenceFrame.LOCAL)
        J = pin.Jlog6(current.actInv(desired)) @ J
        dq = np.linalg.solve(J.T @ J + damping_matrix, J.T @ error)
        q = pin.integrate(model, q, step * dq)
    return ClikResult(q, False, max_iterations, norm)
