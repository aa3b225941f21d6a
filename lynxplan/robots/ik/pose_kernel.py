"""Numba kernel: full poses of a yaw-pitch-pitch-pitch-roll arm in closed form, before any
root search (needed by an off-axis tool point, whose roll the position does not fix).

A full target pose fixes the orientation, and the orientation of a yaw-pitch-pitch-pitch-roll
arm fixes its yaw, pitch sum and roll up to one flip: the yaw puts the approach axis in the arm
plane (``phi`` or ``phi + pi``), the pitch sum follows from the approach in that plane, the roll
is the best roll about the approach axis. With the roll known the tool point is fixed in the
wrist link and the branch is closed-form (``family_geometry.branch``: two elbows). A target is
*solved here* when one of these branches reaches the pose exactly on the exact chain
(position and orientation to :data:`POSE_EXACT`); every exact branch of the pose has this
orientation, so no other branch exists. Targets not solved here (the pose is out of reach, so
the nearest orientation is wanted; the approach along the yaw axis, which leaves the yaw to the
position) go to the general kernel (``family_kernel``: the roll root search of an off-axis tool).

Slots are those of the batch layouts (``family_solver.slot_count``): ``side * 2 + elbow``
(tool on the roll axis: each flip is one side) or ``side * per_side + 2 * flip + elbow`` (an
off-axis tool: the flip is the roll's index, ``per_side`` = 4). Angles in [rad], lengths in [m].
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np

from lynxplan.constants import (
    AXIAL_APPROACH,
    BRANCH_DUPLICATE_TOLERANCE,
    MIN_DEVIATION,
    MIN_FALL,
    POSE_EXACT,
    POSE_POLISH_TOLERANCE,
    REACH_MISS,
    RIGID_TOLERANCE,
    YAW_MATCH,
    YAW_MATCH_DEVIATIONS,
    YAW_MATCH_LENGTH,
)
from lynxplan.robots import family as F  # noqa: N812
from lynxplan.robots.chain import chain_fk, chain_fk_jacobian
from lynxplan.robots.ik.elbow_labels import orient_table
from lynxplan.robots.ik.family_geometry import (
    MODE_POSE,
    across_yaw_axis,
    best_roll,
    branch,
    from_yaw_axis,
    hypot,
    pitch_sum,
    wrap,
    yaw,
)
from lynxplan.robots.ik.family_polish import (
    is_duplicate,
    lu_factor,
    lu_solve,
    settle_pose,
)
from lynxplan.robots.results import BranchSlots


@numba.njit(cache=True, nogil=True, inline="always")
def yaw_match(deviation: float, reach: float, axial: float, rho: float, lateral: float) -> float:
    """How far [rad] the yaw one side of the lateral offset gives may miss the yaw of the
    orientation on a branch of the exact chain: at most YAW_MATCH_DEVIATIONS times what the
    deviation [rad] of the model from the ideal family moves each: the orientation's yaw by
    deviation / axial (the approach's component [1] off the yaw axis), the side's by
    deviation * reach / sqrt(rho^2 - lateral^2) (reach: the two links' length [m]; rho: the
    target's distance from the yaw axis [m]; lateral: the lateral offset at the roll [m],
    where the yaw turns fastest with the target); and at most YAW_MATCH + YAW_MATCH_LENGTH /
    rho, YAW_MATCH raised to the orientation's part for an approach near the yaw axis (whose
    poses the general kernel's root search would otherwise take, ~30 us each)."""
    dev = max(deviation, MIN_DEVIATION)
    across = math.sqrt(max(rho * rho - lateral * lateral, 1e-300))
    axial_part = YAW_MATCH_DEVIATIONS * dev / max(axial, 1e-300)
    moved = axial_part + YAW_MATCH_DEVIATIONS * dev * reach / across
    return min(max(YAW_MATCH, axial_part) + YAW_MATCH_LENGTH / max(rho, 1e-12), moved)


#: Gauss-Newton iterations of the polish at most (it stops below
#: ``constants.POSE_POLISH_TOLERANCE``).
NEWTON_STEPS = 60


class PoseScratch(NamedTuple):
    """Work arrays of one full-pose solve (``solve_target``, ``polish_pose``)."""

    g: np.ndarray
    """(3, 4): the target's rotation in the family frame and its point."""
    pose: np.ndarray
    """(4, 4): the exact chain's pose at q."""
    work: np.ndarray
    """(4, 4): FK scratch."""
    q: np.ndarray
    """(5,) [rad]: the branch being solved."""
    jac: np.ndarray
    """(6, 5): the geometric Jacobian."""
    origins: np.ndarray
    """(5, 6): the joint axes' origins and directions."""
    normal: np.ndarray
    """(7, 5): J^T J, its LU row order, J^T e."""
    vectors: np.ndarray
    """(3, 6): the error, the step, the q before it."""


@numba.njit(cache=True, nogil=True)
def new_pose_scratch() -> PoseScratch:
    """Fresh (uninitialised) work arrays of one full-pose solve."""
    return PoseScratch(
        np.empty((3, 4)),
        np.empty((4, 4)),
        np.empty((4, 4)),
        np.empty(5),
        np.empty((6, 5)),
        np.empty((5, 6)),
        np.empty((7, 5)),
        np.empty((3, 6)),
    )


@numba.njit(cache=True, nogil=True)
def polish_pose(  # noqa: PLR0912 (numba: one compiled loop)
    placements: np.ndarray,
    axes: np.ndarray,
    target: np.ndarray,
    q: np.ndarray,
    scratch: PoseScratch,
) -> bool:
    """Gauss-Newton on the pose error of the exact chain, from a closed-form branch of the
    nearly identical ideal model (~1e-6 away): position error [m] and the rotation vector
    vee(R Rt^T - Rt R^T) / 2 [rad] against the geometric Jacobian (6, 5). The target is reachable
    exactly (zero residual), so it converges quadratically (linearly next to a fold of the
    elbow); stops when the error stops falling by MIN_FALL (a step that made it worse undone).

    The chord method: the Jacobian and its factors are kept while the error falls by MIN_FALL
    (from 1e-6 away the first Jacobian is 1e-6 from the last one, so the chord steps fall as
    fast as Newton's: 1e-6, 1e-12, 1e-18), each later step costing a pose instead of a pose and
    a Jacobian; after a chord step that stalls, Newton steps from the better of the two q, and
    the polish stops when a Newton step stalls.

    Scratch (:class:`PoseScratch`): pose, work, jac, origins, normal (J^T J, its LU row order,
    and J^T e), vectors (the error, the step and the q before it). Returns whether
    scratch.pose holds the exact chain's pose at the final q (False after an undone step).
    """
    pose, work, jac = scratch.pose, scratch.work, scratch.jac
    origins, normal, vectors = scratch.origins, scratch.normal, scratch.vectors
    previous = math.inf
    factored = False  # normal holds the factors of J^T J of the last fresh Jacobian in jac
    chord = True  # until a chord step stalls; then Newton to the end
    e, step, before = vectors[0], vectors[1, :5], vectors[2, :5]
    before[:] = q
    for _ in range(NEWTON_STEPS):
        fresh = not (factored and chord)
        if fresh:
            chain_fk_jacobian(placements, axes, q, pose, jac, work, origins)
        else:
            chain_fk(placements, axes, q, pose, work)
        for i in range(3):
            e[i] = pose[i, 3] - target[i, 3]
        # R Rt^T - Rt R^T, its vee / 2: the small rotation from the target to the pose
        m01 = m10 = m02 = m20 = m12 = m21 = 0.0
        for k in range(3):
            m01 += pose[0, k] * target[1, k]
            m10 += pose[1, k] * target[0, k]
            m02 += pose[0, k] * target[2, k]
            m20 += pose[2, k] * target[0, k]
            m12 += pose[1, k] * target[2, k]
            m21 += pose[2, k] * target[1, k]
        e[3], e[4], e[5] = 0.5 * (m21 - m12), 0.5 * (m02 - m20), 0.5 * (m10 - m01)
        size = 0.0
        for i in range(6):
            size = max(size, abs(e[i]))
        if size < POSE_POLISH_TOLERANCE:
            return True
        if not size * MIN_FALL <= previous:
            worse = not size <= previous
            if fresh:  # a step with a fresh Jacobian stalled: stop (undo it if it made it worse)
                if worse:
                    q[:] = before
                return not worse
            # a chord step stalled: a fresh Jacobian at the better of the two, judged afresh
            if worse:
                q[:] = before
            chord = False
            previous = math.inf
            continue
        previous = size
        before[:] = q
        if fresh:
            for i in range(5):
                for j in range(5):
                    total = 0.0
                    for k in range(6):
                        total += jac[k, i] * jac[k, j]
                    normal[i, j] = total
            if not lu_factor(normal[:6]):
                return True
            factored = True
        for i in range(5):
            total = 0.0
            for k in range(6):
                total += jac[k, i] * e[k]
            normal[6, i] = total
        lu_solve(normal[:6], normal[6], step)
        for j in range(5):
            q[j] -= step[j]
    chain_fk(placements, axes, q, pose, work)
    return True


#: Columns of one target's slot table (``solve_target``): q (5), then these.
VALID, WITHIN, POSITION_ERROR, ORIENTATION_ERROR = 5, 6, 7, 8
SLOT_COLUMNS = 9


@numba.njit(cache=True, nogil=True)
def solve_target(  # noqa: PLR0912, PLR0915 (numba: one compiled pass over the candidates)
    prm: np.ndarray,
    placements: np.ndarray,
    axes: np.ndarray,
    target: np.ndarray,
    ref: np.ndarray,
    out: np.ndarray,
    scratch: PoseScratch,
) -> bool:
    """The exact branches of one full pose (4, 4) where the orientation gives the roll, into
    the slot table out (B, SLOT_COLUMNS) (every slot written; NaN / 0 where no branch); ref (5,)
    [rad]. Returns whether an exact branch was found (the target is complete). scratch: work
    arrays (:class:`PoseScratch`).
    """
    g, pose, q = scratch.g, scratch.pose, scratch.q
    nb = out.shape[0]
    per_side = nb // 2
    rt0 = prm[F.RT0 : F.RT0 + 9]
    exact_model = prm[F.EXACT] != 0.0
    for b in range(nb):
        for j in range(5):
            out[b, j] = np.nan
        out[b, VALID] = 0.0
        out[b, WITHIN] = 0.0
        out[b, POSITION_ERROR] = np.nan
        out[b, ORIENTATION_ERROR] = np.nan
    phi_ref = prm[F.SIGMA] * ref[0]
    sum_ref = prm[F.SIGMA + 1] * ref[1] + prm[F.SIGMA + 2] * ref[2] + prm[F.SIGMA + 3] * ref[3]
    for i in range(3):  # G = Rt Rt0^T, approach = G r
        for j in range(3):
            g[i, j] = (
                target[i, 0] * rt0[3 * j]
                + target[i, 1] * rt0[3 * j + 1]
                + target[i, 2] * rt0[3 * j + 2]
            )
    for i in range(3):
        g[i, 3] = g[i, 0] * prm[F.R] + g[i, 1] * prm[F.R + 1] + g[i, 2] * prm[F.R + 2]
    a_h = g[0, 3] * prm[F.H] + g[1, 3] * prm[F.H + 1] + g[2, 3] * prm[F.H + 2]
    a_p = g[0, 3] * prm[F.P] + g[1, 3] * prm[F.P + 1] + g[2, 3] * prm[F.P + 2]
    if hypot(a_h, a_p) <= AXIAL_APPROACH:
        return False
    d0, d1, d2 = from_yaw_axis(prm, target)
    rho = across_yaw_axis(prm, d0, d1, d2)[2]
    axial = hypot(a_h, a_p)
    reach = hypot(prm[F.O3] - prm[F.O2], prm[F.O3 + 1] - prm[F.O2 + 1]) + hypot(
        prm[F.O4] - prm[F.O3], prm[F.O4 + 1] - prm[F.O3 + 1]
    )
    solved = False
    mode = np.int64(MODE_POSE)  # not a literal: pitch_sum and branch compile once, for every mode
    for flip in range(2):
        # the yaw that puts the approach in the arm plane (its outward component > 0 or < 0)
        phi = math.atan2(-a_p, a_h) + flip * math.pi
        big_phi, _ = pitch_sum(prm, mode, g[0, 3], g[1, 3], g[2, 3], 0.0, phi, sum_ref)
        theta = best_roll(prm, g, phi, big_phi)
        lat = (
            prm[F.LAM4]
            + prm[F.W0 + 2]
            + math.cos(theta) * prm[F.E1 + 2]
            + math.sin(theta) * prm[F.E2 + 2]
        )
        match = yaw_match(prm[F.DEVIATION], reach, axial, rho, lat)
        for side in range(2):
            phi_side, lateral = yaw(prm, d0, d1, d2, theta, side, phi_ref)
            if lateral > REACH_MISS or abs(wrap(phi_side - phi)) > match:
                continue
            problem = (prm, target, g, mode, side, phi_ref, sum_ref)
            for elbow in range(2):
                b = side * per_side + (flip * 2 if per_side > 2 else 0) + elbow
                if out[b, VALID] != 0.0:
                    continue
                if branch(problem, 0.0, theta, elbow, q) > REACH_MISS:
                    continue
                current = False
                if not exact_model:
                    current = polish_pose(placements, axes, target, q, scratch)
                inside, err, angle = settle_pose(
                    prm, placements, axes, target, q, pose, scratch.work, current
                )
                if not (err <= POSE_EXACT and angle <= POSE_EXACT):
                    continue
                if is_duplicate(out, out[:, VALID], nb, q, BRANCH_DUPLICATE_TOLERANCE):
                    continue
                for j in range(5):
                    out[b, j] = q[j]
                out[b, VALID] = 1.0
                out[b, WITHIN] = 1.0 if inside else 0.0
                out[b, POSITION_ERROR] = err
                out[b, ORIENTATION_ERROR] = angle
                solved = True
    orient_table(prm, out, out[:, VALID])  # each branch in its elbow's slot
    return solved


@numba.njit(cache=True, nogil=True)
def _is_rigid(pose: np.ndarray) -> bool:
    """Whether pose (4, 4) is finite with a rotation block orthonormal to RIGID_TOLERANCE and
    the last row 0 0 0 1 (NaN fails every comparison)."""
    for j in range(4):
        if not math.isfinite(pose[3, j]) or not math.isfinite(pose[0, j] + pose[1, j] + pose[2, j]):
            return False
    if abs(pose[3, 0]) + abs(pose[3, 1]) + abs(pose[3, 2]) + abs(pose[3, 3] - 1.0) > 0.0:
        return False
    for i in range(3):
        for j in range(i, 3):
            dot = pose[0, i] * pose[0, j] + pose[1, i] * pose[1, j] + pose[2, i] * pose[2, j]
            if not abs(dot - (1.0 if i == j else 0.0)) <= RIGID_TOLERANCE:
                return False
    return True


#: Columns of ``pose_one``'s compact table: q (5), then these.
SLOT, COMPACT_WITHIN, COMPACT_POSITION_ERROR, COMPACT_ORIENTATION_ERROR = 5, 6, 7, 8


@numba.njit(cache=True, nogil=True)
def pose_one(
    prm: np.ndarray,
    placements: np.ndarray,
    axes: np.ndarray,
    target: np.ndarray,
    ref: np.ndarray,
    slots: int,
    compact: np.ndarray,
) -> int:
    """``solve_target`` of one pose (4, 4), ref (5,) [rad], in a layout of ``slots`` slots.

    Returns the number k of exact branches (0: not solved here), written to compact[:k]
    (rows: q (5) [rad], slot index, within limits 1/0, position error [m], orientation error
    [rad]); compact has shape (slots, SLOT_COLUMNS).
    Poses that are not finite, not rigid (last row 0 0 0 1, rotation orthonormal to
    RIGID_TOLERANCE) return 0: the general path checks and repairs them.
    """
    if not _is_rigid(target):
        return 0
    out = np.empty((slots, SLOT_COLUMNS))
    solved = solve_target(prm, placements, axes, target, ref, out, new_pose_scratch())
    if not solved:
        return 0
    k = 0
    for b in range(slots):
        if out[b, VALID] != 0.0:
            for j in range(5):
                compact[k, j] = out[b, j]
            compact[k, SLOT] = b
            compact[k, COMPACT_WITHIN] = out[b, WITHIN]
            compact[k, COMPACT_POSITION_ERROR] = out[b, POSITION_ERROR]
            compact[k, COMPACT_ORIENTATION_ERROR] = out[b, ORIENTATION_ERROR]
            k += 1
    return k


@numba.njit(cache=True, nogil=True, inline="always")
def smallest_error(errors: np.ndarray, n: int) -> float:
    """The smallest of errors[n, :] (a target's errors over its branch slots, (N, B)), the
    empty slots' NaN skipped (NaN where every slot is empty): ``np.fmin.reduce`` of the row."""
    best = np.nan
    for b in range(errors.shape[1]):
        e = errors[n, b]
        best = e if (e < best) | math.isnan(best) else best
    return best


@numba.njit(cache=True, nogil=True, inline="always")
def write_slots(out: np.ndarray, n: int, slots: BranchSlots, distance: np.ndarray) -> None:
    """Target n's slots from :func:`solve_target`'s rows ``out`` (B, SLOT_COLUMNS) into the
    batch outputs (see :func:`pose_kernel`), and its smallest position error."""
    q_out, valid, within = slots.q, slots.valid, slots.within
    position_error, orientation_error = slots.position_error, slots.orientation_error
    for b in range(q_out.shape[1]):
        for j in range(5):
            q_out[n, b, j] = out[b, j]
        valid[n, b] = out[b, VALID] != 0.0
        within[n, b] = out[b, WITHIN] != 0.0
        position_error[n, b] = out[b, POSITION_ERROR]
        orientation_error[n, b] = out[b, ORIENTATION_ERROR]
    distance[n] = smallest_error(position_error, n)


@numba.njit(cache=True, nogil=True)
def pose_kernel(
    prm: np.ndarray,
    placements: np.ndarray,
    axes: np.ndarray,
    targets: np.ndarray,
    reference: np.ndarray,
    slots: BranchSlots,
    solved: np.ndarray,
    distance: np.ndarray,
) -> None:
    """``solve_target`` of N full poses, in the batch arrays.

    Args:
        prm, placements, axes: Packed family parameters and the exact chain.
        targets: (N, 4, 4) target poses.
        reference: (N, 5) or (1, 5) joint angles [rad] (the yaw kept on the base axis).
        slots: (N, B, ...) outputs in the kernel's layout (:class:`BranchSlots`); every slot
            of every target is written.
        solved: (N,) output: True where an exact branch was found (the target is complete).
        distance: (N,) output: each target's smallest position error over its slots [m]
            (``smallest_error``).
    """
    out = np.empty((slots.q.shape[1], SLOT_COLUMNS))
    scratch = new_pose_scratch()
    for n in range(targets.shape[0]):
        ref = reference[n if reference.shape[0] > 1 else 0]
        solved[n] = solve_target(prm, placements, axes, targets[n], ref, out, scratch)
        write_slots(out, n, slots, distance)
