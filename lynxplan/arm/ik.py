"""Analytic inverse kinematics of the 5-DOF arm, every branch (SPEC Part 1).

A 5-DOF arm cannot reach an arbitrary 6-D pose: the approach axis ``a`` and the tool point must lie
in the vertical plane through the base axis at angle q1. The solver places the tool point exactly,
projects the approach axis into that plane and takes the roll q5 from the target's ``n`` axis; the
angle between the target and the reached orientation is the *orientation residual*.

Branches, in this order: (front, elbow up), (front, elbow down), (back, elbow up), (back, elbow
down). "Front" faces the tool point (q1 = atan2(y, x)); "back" is q1 + pi with the arm leaning back
over the base. "Elbow up" means the elbow lies above the shoulder-to-wrist line.

The kernels are compiled with numba (:mod:`lynxplan.arm.ik_kernel`, the branch selection in
:mod:`lynxplan.arm.ik_select`) and loop over a batch on one core.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from lynxplan import _jit
from lynxplan._arrays import kernel_input
from lynxplan.arm.geometry import ArmGeometry, JointLimits
from lynxplan.arm.ik_kernel import (
    FAR_AWAY_K,
    IkOutputs,
    IkParams,
    IkStatus,
    ik_kernel,
)
from lynxplan.arm.ik_select import ik_single_kernel, select_continuous, select_continuous_kernel
from lynxplan.constants import LIMIT_SNAP_TOLERANCE
from lynxplan.exceptions import NonFiniteInputError, ShapeError

__all__ = [
    "BRANCH_NAMES",
    "FAR_AWAY_K",
    "IkBatch",
    "IkOutputs",
    "IkParams",
    "IkStatus",
    "as_poses",
    "ik_kernel",
    "ik_single_kernel",
    "select_continuous",
    "select_continuous_kernel",
    "solve_ik_batch",
]

BRANCH_NAMES = ("front/elbow-up", "front/elbow-down", "back/elbow-up", "back/elbow-down")


class IkBatch(NamedTuple):
    """IK of N poses, all branches. Arrays are read-only."""

    q: np.ndarray
    """Joint angles, shape (N, 4, 5), in [rad], wrapped into the limits where possible; NaN
    where the status is not OK."""
    within_limits: np.ndarray
    """Whether each branch is within the joint limits (after snapping), shape (N, 4), bool."""
    orientation_error: np.ndarray
    """Angle between target and reached orientation, shape (N,), in [rad] (same for every
    branch: they reach the same orientation)."""
    status: np.ndarray
    """:class:`IkStatus` per pose, shape (N,), int8."""
    reach_miss: np.ndarray
    """Distance by which the wrist centre misses the reachable annulus, shape (N,), in [m];
    0 when reachable."""
    deviation: np.ndarray
    """Deviation of each pose's rotation from orthonormal, ``max |R^T R - I|``, shape (N,)."""


_jit.listen()  # the IK kernels: a notice when their first compile takes long

_DEFAULT_GEOMETRY = ArmGeometry()
_DEFAULT_LIMITS = JointLimits()


def as_poses(T: np.ndarray, name: str = "T") -> np.ndarray:
    """Validate poses: shape (4, 4) or (N, 4, 4). Returns a contiguous float (N, 4, 4) array."""
    from lynxplan.guards import float_array  # strings, ragged lists: InputError, not ValueError

    array = float_array(name, T)
    if array.ndim not in (2, 3) or array.shape[-2:] != (4, 4):
        raise ShapeError(name, "(4, 4) or (N, 4, 4)", array.shape)
    return np.ascontiguousarray(array.reshape(-1, 4, 4))


def _as_reference(q_reference: np.ndarray | None, n: int) -> np.ndarray:
    if q_reference is None:
        return np.zeros((1, 5))
    from lynxplan.guards import float_array

    ref = float_array("q_reference", q_reference)
    if ref.shape not in ((5,), (n, 5)):
        raise ShapeError("q_reference", f"(5,) or ({n}, 5)", ref.shape)
    if not np.isfinite(ref).all():  # also for one (5,) reference
        raise NonFiniteInputError("q_reference")
    return np.ascontiguousarray(ref.reshape(-1, 5))


def solve_ik_batch(
    T: np.ndarray,
    *,
    geometry: ArmGeometry = _DEFAULT_GEOMETRY,
    limits: JointLimits = _DEFAULT_LIMITS,
    q_reference: np.ndarray | None = None,
    approach_only: bool = False,
    limit_tolerance: float = LIMIT_SNAP_TOLERANCE,
) -> IkBatch:
    """Solve the IK of many poses, all four branches. Never raises for unreachable poses.

    Args:
        T: Target tool poses, shape (N, 4, 4) (or (4, 4)), translations in [m]. Rotations within
            the rigidity repair tolerance of orthonormal are re-orthonormalised.
        geometry: Arm dimensions.
        limits: Joint limits used for wrapping and the within-limit flags.
        q_reference: Shape (5,) or (N, 5), in [rad]: q1 when the tool is on the base axis with a
            vertical approach, q5 when ``approach_only``. Default: zeros.
        approach_only: Treat column 2 of the rotation as the only orientation target (5-D target:
            position + approach direction); column 0 and 1 are ignored.
        limit_tolerance: Angles this far outside a limit, in [rad], are snapped onto it.

    Returns:
        An :class:`IkBatch` with per-pose status (poses that fail do not raise).
    """
    poses = as_poses(T)
    n = poses.shape[0]
    ref = _as_reference(q_reference, n)
    q = np.empty((n, 4, 5))
    within = np.empty((n, 4), dtype=np.bool_)
    residual = np.empty(n)
    status = np.empty(n, dtype=np.int8)
    miss = np.empty(n)
    deviation = np.empty(n)
    params = IkParams(
        geometry.a2,
        geometry.a3,
        geometry.d5,
        kernel_input(limits.lower),
        kernel_input(limits.upper),
        float(limit_tolerance),
        bool(approach_only),
    )
    outputs = IkOutputs(q, within, residual, status, miss, deviation)
    ik_kernel(kernel_input(poses), kernel_input(ref), params, outputs)
    for array in (q, within, residual, status, miss, deviation):
        array.setflags(write=False)
    return IkBatch(q, within, residual, status, miss, deviation)
