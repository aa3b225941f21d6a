"""Branch selection: along a sampled path (continuity) and for one pose (FK-checked)."""

from __future__ import annotations

import math

import numba
import numpy as np

from lynxplan.arm.ik_kernel import (
    IkOutputs,
    IkParams,
    _angle_between_frames,
    _orthonormalise,
    ik_kernel,
)
from lynxplan.arm.kinematics import fk_kernel
from lynxplan.exceptions import ShapeError


@numba.njit(cache=True, nogil=True)
def select_continuous_kernel(
    q_all: np.ndarray,
    within: np.ndarray,
    q_start: np.ndarray,
    q_out: np.ndarray,
    branch_out: np.ndarray,
) -> None:
    """Per sample, the branch nearest the previous sample (see :func:`select_continuous`)."""
    previous = q_start.copy()
    for k in range(q_all.shape[0]):
        best, best_cost = -1, np.inf
        for b in range(4):
            if math.isnan(q_all[k, b, 0]):
                continue
            cost = 0.0
            for j in range(5):
                d = q_all[k, b, j] - previous[j]
                cost += d * d
            if not within[k, b]:
                cost += 1e6  # any within-limit branch beats every outside one
            if cost < best_cost:
                best, best_cost = b, cost
        branch_out[k] = best
        if best < 0:
            q_out[k, :] = np.nan
        else:
            q_out[k, :] = q_all[k, best, :]
            previous[:] = q_out[k, :]


def select_continuous(
    q_all: np.ndarray, within_limits: np.ndarray, q_start: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Pick along a sampled path the branch continuous with the previous sample.

    Args:
        q_all: All-branch IK solutions, shape (N, 4, 5), in [rad] (NaN rows are skipped).
        within_limits: Within-limit flags, shape (N, 4); within-limit branches are preferred.
        q_start: Configuration before the first sample, shape (5,), in [rad].

    Returns:
        ``(q, branch)``: shape (N, 5) in [rad] (NaN where no branch exists) and (N,) branch
        indices (-1 where none).
    """
    q_all = np.ascontiguousarray(q_all, dtype=float)
    if q_all.ndim != 3 or q_all.shape[1:] != (4, 5):
        raise ShapeError("q_all", "(N, 4, 5)", q_all.shape)
    start = np.asarray(q_start, dtype=float)
    if start.shape != (5,):
        raise ShapeError("q_start", "(5,)", start.shape)
    q = np.empty((q_all.shape[0], 5))
    branch = np.empty(q_all.shape[0], dtype=np.int64)
    select_continuous_kernel(q_all, np.ascontiguousarray(within_limits), start, q, branch)
    return q, branch


@numba.njit(cache=True, nogil=True)
def ik_single_kernel(
    T: np.ndarray,
    q_ref: np.ndarray,
    params: np.ndarray,
    flags: int,
    rows: np.ndarray,
    scalars: np.ndarray,
) -> None:
    """IK of one pose (4, 4), every branch checked by FK, and the selection, in one call.

    ``params`` = (a2, a3, d5, limit_tol, lower (5), upper (5)), lengths in [m], angles in [rad];
    ``flags`` bit 0 = approach only, bit 1 = report selection rule. Writes ``rows`` (4, 8): q
    (5), within, position error, orientation error per branch; ``scalars`` (5,): residual,
    status, miss, deviation, selected (-1 when no branch qualifies). Packed so the call boxes no
    Python objects.
    """
    approach_only = (flags & 1) != 0
    report_rule = (flags & 2) != 0
    a2, a3, d5 = params[0], params[1], params[2]
    q = np.empty((1, 4, 5))
    within = np.empty((1, 4), dtype=np.bool_)
    residual, status = np.empty(1), np.empty(1, dtype=np.int8)
    miss, deviation = np.empty(1), np.empty(1)
    # the limits as C arrays (copies): the same kernel types as the batch call from Python
    arm = IkParams(a2, a3, d5, params[4:9].copy(), params[9:14].copy(), params[3], approach_only)
    out = IkOutputs(q, within, residual, status, miss, deviation)
    ik_kernel(T.reshape(1, 4, 4), q_ref.reshape(1, 5), arm, out)
    rows[:, :] = np.nan
    rows[:, :5] = q[0]
    selected = -1
    if status[0] == 0:
        reached = np.empty((4, 4, 4))
        fk_kernel(q[0], a2, a3, d5, reached)
        # The target as the kernel used it: orthonormalised from the approach axis.
        n, o, a = T[:3, 0].copy(), np.zeros(3), T[:3, 2].copy()
        _orthonormalise(a, n, o, approach_only)
        best = np.inf
        for b in range(4):
            rows[b, 5] = 1.0 if within[0, b] else 0.0
            dx, dy, dz = (
                reached[b, 0, 3] - T[0, 3],
                reached[b, 1, 3] - T[1, 3],
                reached[b, 2, 3] - T[2, 3],
            )
            rows[b, 6] = math.sqrt(dx * dx + dy * dy + dz * dz)
            if approach_only:
                cosine = reached[b, 0, 2] * a[0] + reached[b, 1, 2] * a[1] + reached[b, 2, 2] * a[2]
                rows[b, 7] = math.acos(min(1.0, max(-1.0, cosine)))
            else:
                rows[b, 7] = _angle_between_frames(
                    n,
                    o,
                    a,
                    reached[b, :3, 0],
                    reached[b, :3, 1],
                    reached[b, :3, 2],
                )
            if not within[0, b]:
                continue
            if report_rule:
                if selected < 0 and q[0, b, 1] >= 0.0 and q[0, b, 2] <= 0.0:
                    selected = b
            else:
                cost = 0.0
                for j in range(5):
                    cost += (q[0, b, j] - q_ref[j]) ** 2
                if cost < best:
                    best, selected = cost, b
    scalars[0], scalars[1], scalars[2] = residual[0], status[0], miss[0]
    scalars[3], scalars[4] = deviation[0], selected
