"""Numba kernel: the full-pose solver of ``pose_kernel`` over blocks of poses, vectorised.

The same solution as :func:`lynxplan.robots.ik.pose_kernel.solve_target` (read its docstring
for the geometry), laid out for SIMD: a block of :data:`BLOCK` poses is transposed into scratch
rows (one row per quantity, one column per pose) and each candidate branch (flip of the yaw,
elbow) is solved for the whole block by one loop without branches or calls, which LLVM turns
into vector instructions (the layout: ``block_layout``):

1. the closed form on the ideal model (yaw, pitch sum, roll, the side of the lateral offset
   whose yaw matches, the two-link shoulder and elbow); for a tool off the roll axis, of the
   flip of the yaw the position can match, the other flip only where it may
   (``block_closed_form.screen_flips``);
2. on a model only close to the family, a fixed polish on the exact chain: two Gauss-Newton
   steps (pose and geometric Jacobian; where the pitch axes are parallel, as in the SO-101,
   solved by the family's structure, ``block_newton.newton_parallel``, else by an LDL^T
   factorisation of
   the normal equations): from ~1e-6 away the error falls to ~1e-12, then below rounding (a
   chord step in place of the second left ~6 % of the SO-101's candidates above
   VECTOR_EXACT); candidates that start farther away get a second polish, below;
3. the angles wrapped into the joint limits, and the pose of the exact chain at the final
   angles: the position and orientation errors that are reported. After a polish the sines
   and cosines of the final angles are carried from those of the start through each step and
   snap to the limits by their Taylor series (``block_newton.turn``: exact to rounding for steps up
   to
   BLOCK_TAYLOR_STEP, the only candidates taken there), not computed afresh.

A candidate is *taken* here only when its final errors are below :data:`VECTOR_EXACT` (far below
``POSE_EXACT``), and *rejected* (not an exact branch) when its error stopped falling far above
that. Any other candidate (still converging: next to a fold of the elbow Newton converges
linearly; or an ill-conditioned polish) that came within BLOCK_NOT_A_BRANCH of the pose is polished
once more from where it stopped, gathered with the others into whole vectors; what is still
unfinished is finished by the scalar solver's own polish (``pose_kernel.polish_pose``) from its
closed-form start, exactly as ``solve_target`` treats it. The candidate loops run on whole
vectors of :data:`LANES` (padding lanes repeat a candidate).
A pose where anything is unusual goes to the scalar ``solve_target``, whole: a near fold of a
near-family model (where the scalar solver starts the elbows apart), both sides of the lateral
offset matching the yaw, the approach along the yaw or the pitch axis, the target on the yaw
axis, or anything not finite. The fixed steps never decide alone that a branch does not exist
unless the candidate has stalled. Slots, validity and duplicates follow the scalar solver's
order, so both give the same branches (angles equal to ~1e-10 rad).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numba
import numpy as np
from numba.np.unsafe.ndarray import to_fixed_tuple

from lynxplan._fastmath import prefetch, prefetch_write, wide_vectors
from lynxplan.constants import BRANCH_DUPLICATE_TOLERANCE, POSE_EXACT
from lynxplan.robots import family as F  # noqa: N812
from lynxplan.robots.ik.block_closed_form import flip_branches, solve_closed_forms
from lynxplan.robots.ik.block_layout import (
    ALL_TAKEN,
    BLOCK,
    CANDIDATE,
    CANDIDATE_WIDTH,
    FLIP,
    LANES,
    POSE,
    Floats,
    chain_tuple,
    clear_slots,
    link_shape,
)
from lynxplan.robots.ik.block_newton import parallel_pitches
from lynxplan.robots.ik.block_settle import polish_settle, repolish, settle_all
from lynxplan.robots.ik.family_polish import is_duplicate, settle_pose
from lynxplan.robots.ik.pose_kernel import (
    SLOT_COLUMNS,
    new_pose_scratch,
    polish_pose,
    smallest_error,
    solve_target,
    write_slots,
)
from lynxplan.robots.results import BranchSlots

__all__ = ["BLOCK", "blocks", "pose_block_kernel"]

N_PARAMS = F.N_PARAMS  # a global: numba takes it as the constant to_fixed_tuple needs


class FamilyArrays(NamedTuple):
    """A family arm as the kernels read it."""

    packed: np.ndarray
    """The family's parameters, ``Family.packed`` (F.N_PARAMS,)."""
    placements: np.ndarray
    """The exact chain's joint placements (5, 4, 4) [m]."""
    axes: np.ndarray
    """The exact chain's joint axes (5, 3)."""


def pose_block_kernel(
    prm: np.ndarray,
    placements: np.ndarray,
    axes: np.ndarray,
    targets: np.ndarray,
    reference: np.ndarray,
    slots: BranchSlots,
    solved: np.ndarray,
    distance: np.ndarray,
) -> int:
    """``pose_kernel`` (same arguments and outputs), by blocks of BLOCK vectorised poses with
    the scalar ``solve_target`` for the poses that need it and the scalar polish for the
    candidates that need it (:func:`blocks`, compiled with this arm's closed form and Newton
    step only). Returns how many poses needed either.

    targets: (N, 4, 4) rigid poses; reference (N, 5) or (1, 5) [rad]; outputs (N, B, ...), every
    slot written; solved (N,): an exact branch was found; distance (N,): the smallest position
    error over the slots [m].
    """
    kernel = _variant(prm, placements, axes)
    done: int = kernel(
        FamilyArrays(prm, placements, axes), targets, reference, slots, solved, distance
    )
    return done


def _variant(prm: np.ndarray, placements: np.ndarray, axes: np.ndarray) -> Any:
    """The variant of :func:`blocks` for this arm (:data:`_VARIANTS`), remembered per arm (the
    test builds a chain tuple: ~10 us, a fifth of a 64-pose batch)."""
    key = (prm.tobytes(), placements.tobytes(), axes.tobytes())
    kernel = _CHOSEN.get(key)
    if kernel is None:
        if len(_CHOSEN) >= 64:  # bounded: a service may load many arms
            _CHOSEN.clear()
        off_axis = bool(prm[F.OFF_AXIS] != 0.0)
        ldl = not parallel_pitches(chain_tuple(placements, axes))
        kernel = _CHOSEN[key] = _VARIANTS[off_axis, ldl]
    return kernel


# The four variants of :func:`blocks`, its flags constants: numba prunes an ``is None`` branch
# on a constant (or None) argument when it compiles, so an arm compiles only its own closed
# form and Newton step (each ~30-50 s of compile on first use).
@numba.njit(cache=True, nogil=True)
def _on_axis_parallel(
    arm: FamilyArrays, targets: np.ndarray, reference: np.ndarray, slots: BranchSlots,
    solved: np.ndarray, distance: np.ndarray,
) -> int:  # fmt: skip
    return blocks(arm, targets, reference, slots, solved, distance, None, None)


@numba.njit(cache=True, nogil=True)
def _on_axis_ldl(
    arm: FamilyArrays, targets: np.ndarray, reference: np.ndarray, slots: BranchSlots,
    solved: np.ndarray, distance: np.ndarray,
) -> int:  # fmt: skip
    return blocks(arm, targets, reference, slots, solved, distance, None, True)


@numba.njit(cache=True, nogil=True)
def _off_axis_parallel(
    arm: FamilyArrays, targets: np.ndarray, reference: np.ndarray, slots: BranchSlots,
    solved: np.ndarray, distance: np.ndarray,
) -> int:  # fmt: skip
    return blocks(arm, targets, reference, slots, solved, distance, True, None)


@numba.njit(cache=True, nogil=True)
def _off_axis_ldl(
    arm: FamilyArrays, targets: np.ndarray, reference: np.ndarray, slots: BranchSlots,
    solved: np.ndarray, distance: np.ndarray,
) -> int:  # fmt: skip
    return blocks(arm, targets, reference, slots, solved, distance, True, True)


@numba.njit(cache=True, nogil=True)
def blocks(  # noqa: PLR0912, PLR0915 (numba: one compiled pass)
    arm: FamilyArrays,
    targets: np.ndarray,
    reference: np.ndarray,
    slots: BranchSlots,
    solved: np.ndarray,
    distance: np.ndarray,
    off_axis: bool | None,
    ldl: bool | None,
) -> int:
    """:func:`pose_block_kernel`'s work. ``off_axis``: None where the tool point is on the
    roll axis (its closed form), else True; ``ldl``: None where the pitch axes are parallel
    (``newton_parallel``'s steps), else True (``newton_ldl``'s). Both constants (see
    ``_VARIANTS``)."""
    wide_vectors()
    prm, placements, axes = arm.packed, arm.placements, arm.axes
    nb = slots.q.shape[1]
    per_side = nb // 2
    ch = chain_tuple(placements, axes)
    pr: Floats = to_fixed_tuple(prm, N_PARAMS)  # type: ignore[call-arg]
    exact = prm[F.EXACT] != 0.0
    shape = link_shape(prm)
    # the scratch rows and the candidate rows in one array (constant distances: ``closed_forms``)
    x_flat = np.zeros(POSE.rows * BLOCK + CANDIDATE.rows * CANDIDATE_WIDTH)
    s_flat, c_flat = x_flat[: POSE.rows * BLOCK], x_flat[POSE.rows * BLOCK :]
    c2_flat, slot_index = (
        np.empty(CANDIDATE.rows * CANDIDATE_WIDTH),
        np.empty(CANDIDATE_WIDTH, dtype=np.int64),
    )
    s, c = s_flat.reshape((POSE.rows, BLOCK)), c_flat.reshape((CANDIDATE.rows, CANDIDATE_WIDTH))
    owned = np.empty(BLOCK, dtype=np.int64)  # the candidates of pose i: its owned[i] lanes
    lane_of = np.empty(4 * BLOCK, dtype=np.int64)  # lane_of[4 * i : 4 * i + owned[i]]
    slot_of = np.empty(CANDIDATE_WIDTH, dtype=np.int64)
    out = np.empty((nb, SLOT_COLUMNS))
    scratch = new_pose_scratch()
    pose, qs = scratch.pose, scratch.q
    q_out, valid, within = slots.q, slots.valid, slots.within
    position_error, orientation_error = slots.position_error, slots.orientation_error
    taken = np.empty((4, 5))
    # the outputs flat: every slot of a block is emptied by contiguous loops (vector stores)
    q_flat, valid_flat, within_flat = q_out.reshape(-1), valid.reshape(-1), within.reshape(-1)
    p_flat, o_flat = position_error.reshape(-1), orientation_error.reshape(-1)
    fallbacks = 0
    deferred = np.empty(64, dtype=np.int64)  # the poses left to the scalar solver (grows)
    deferred_count = 0
    for start in range(0, targets.shape[0], BLOCK):
        m = min(BLOCK, targets.shape[0] - start)
        for i in range(m):
            for r in range(3):
                for col in range(4):
                    s[4 * r + col, i] = targets[start + i, r, col]
        solve_closed_forms(pr, shape, x_flat, m, off_axis)
        # the candidates of the poses that need no fallback, in the scalar solver's order: lane
        # i the elbow up and lane BLOCK + i the elbow down of pose i's first candidate flip
        # (written by closed_forms), then the other flip where it is a candidate too (rare:
        # its yaw misses by twice the lateral offset), gathered one by one
        mc = np.int64(2 * BLOCK)  # not a literal: one compile of repolish
        second_flips = False
        for i in range(m):  # by selects: the first flip's lanes and slots
            fall = (s[POSE.flips + FLIP.fallback, i] != 0.0) | (
                s[POSE.flips + FLIP.rows + FLIP.fallback, i] != 0.0
            )
            cand0 = s[POSE.flips + FLIP.candidate, i] != 0.0
            cand1 = s[POSE.flips + FLIP.rows + FLIP.candidate, i] != 0.0
            s[POSE.fallback, i] = 1.0 if fall else 0.0
            owned[i] = 2 if (not fall) and (cand0 or cand1) else 0
            second_flips = second_flips or ((not fall) and cand0 and cand1)
            base = POSE.flips + (0 if cand0 else FLIP.rows)
            side = s[base + FLIP.side, i]
            slot = int(side) * per_side + (0 if cand0 or per_side <= 2 else 2)
            # the elbow-up slot takes the elbow above the shoulder-wrist line: the two-link's
            # elbow 0 where the wrist lies ahead of the shoulder (``elbow_labels``)
            behind = 1 if s[base + FLIP.wrist_x, i] < 0.0 else 0
            lane_of[4 * i], lane_of[4 * i + 1] = i, BLOCK + i
            slot_of[i], slot_of[BLOCK + i] = slot + behind, slot + 1 - behind
        for i in range(m if second_flips else 0):  # the second candidate flips: gathered
            fall = s[POSE.fallback, i] != 0.0
            if (
                fall
                or s[POSE.flips + FLIP.candidate, i] == 0.0
                or s[POSE.flips + FLIP.rows + FLIP.candidate, i] == 0.0
            ):
                continue
            owned[i] = 0
            for flip in range(2):
                base = POSE.flips + flip * FLIP.rows
                if s[base + FLIP.candidate, i] == 0.0:
                    continue
                side = int(s[base + FLIP.side, i])
                for elbow in range(2):
                    lane = elbow * BLOCK + i if owned[i] < 2 else mc
                    if owned[i] >= 2:  # the second flip: gathered
                        for k in range(12):
                            c[k, mc] = s[k, i]
                        geometry = (s[base, i], s[base + 1, i], s[base + 2, i], s[base + 3, i],
                                    s[base + 4, i], s[base + 5, i], s[base + 6, i], s[base + 7, i],
                                    s[base + 8, i], s[base + 9, i], s[base + 10, i],
                                    s[base + 11, i])  # fmt: skip
                        up, down, s_up, c_up, s_down, c_down = flip_branches(pr, shape, geometry)
                        for k in range(5):
                            c[CANDIDATE.q + k, mc] = down[k] if elbow else up[k]
                            c[CANDIDATE.sines + k, mc] = s_down[k] if elbow else s_up[k]
                            c[CANDIDATE.cosines + k, mc] = c_down[k] if elbow else c_up[k]
                        c[CANDIDATE.fold, mc] = s[base + FLIP.fold, i]
                        mc += 1
                    lane_of[4 * i + owned[i]] = lane
                    behind = 1 if s[base + FLIP.wrist_x, i] < 0.0 else 0
                    slot_of[lane] = (
                        side * per_side + (flip * 2 if per_side > 2 else 0) + (elbow ^ behind)
                    )
                    owned[i] += 1
        for lane in range(2 * BLOCK, mc):
            for k in range(5):
                c[CANDIDATE.start + k, lane] = c[CANDIDATE.q + k, lane]
            c[CANDIDATE.fallback, lane] = 0.0
            c[CANDIDATE.previous_error, lane] = 0.0
        # whole vectors: the lanes past the last candidate repeat the first (a remainder
        # would run through the loops' scalar epilogue, ~8 times the cost per candidate)
        lanes = min((mc + LANES - 1) // LANES * LANES, CANDIDATE_WIDTH)
        for lane in range(mc, lanes):
            for k in range(CANDIDATE.rows):
                c[k, lane] = c[k, 0]
        if exact:
            settle_all(lanes, pr, ch, c_flat)
        else:
            polish_settle(lanes, pr, ch, c_flat, ldl)
        for i in range(BLOCK):  # the lanes of no candidate (no flip, past m): nothing to finish
            if i >= m or owned[i] == 0:
                c[CANDIDATE.fallback, i] = c[CANDIDATE.fallback, BLOCK + i] = 0.0
        if not exact:
            repolish(mc, pr, ch, c_flat, c2_flat, slot_index, ldl)
        clear_slots(start * nb, (start + m) * nb, q_flat, valid_flat, within_flat, p_flat, o_flat)
        for i in range(m):
            n = start + i
            # the next block's pose, prefetched (written out: an array passed to a function
            # costs two atomic reference counts a call): its target and its slots
            ahead = n + BLOCK
            if ahead < targets.shape[0]:
                prefetch(targets, 16 * ahead)  # 16 doubles a pose, 8 a cache line
                prefetch(targets, 16 * ahead + 8)
                for k in range(5 * nb * ahead, 5 * nb * (ahead + 1), 8):
                    prefetch_write(q_flat, k)
                if ahead % 8 == 0:
                    prefetch_write(valid_flat, nb * ahead)
                    prefetch_write(within_flat, nb * ahead)
                prefetch_write(p_flat, nb * ahead)
                prefetch_write(o_flat, nb * ahead)
            if s[POSE.fallback, i] != 0.0:  # solved after the blocks (below)
                if deferred_count == deferred.shape[0]:
                    grown = np.empty(2 * deferred.shape[0], dtype=np.int64)
                    grown[:deferred_count] = deferred
                    deferred = grown
                deferred[deferred_count] = n
                deferred_count += 1
                continue
            if owned[i] == 2:  # the common case: both elbows of one flip, both taken
                ka, kb = lane_of[4 * i], lane_of[4 * i + 1]
                both = (c[CANDIDATE.taken, ka] != 0.0) & (c[CANDIDATE.taken, kb] != 0.0)
                if both & (c[CANDIDATE.fallback, ka] == 0.0) & (c[CANDIDATE.fallback, kb] == 0.0):
                    gap = 0.0
                    for j in range(5):
                        gap = max(gap, abs(c[CANDIDATE.q + j, ka] - c[CANDIDATE.q + j, kb]))
                    pair = gap >= BRANCH_DUPLICATE_TOLERANCE  # else kb is a duplicate
                    for h in range(2 if pair else 1):
                        k = kb if h else ka
                        b = slot_of[k]
                        for j in range(5):
                            q_out[n, b, j] = c[CANDIDATE.q + j, k]
                        valid[n, b] = True
                        within[n, b] = c[CANDIDATE.within, k] != 0.0
                        position_error[n, b] = c[CANDIDATE.position_error, k]
                        orientation_error[n, b] = c[CANDIDATE.orientation_error, k]
                    solved[n] = True
                    # the smallest error over the slots (``smallest_error``: the others empty)
                    nearest = c[CANDIDATE.position_error, ka]
                    distance[n] = min(nearest, c[CANDIDATE.position_error, kb]) if pair else nearest
                    continue
            count = np.int64(0)  # not a literal 0: one compile of is_duplicate
            scalar = False
            for h in range(owned[i]):
                k = lane_of[4 * i + h]
                b = slot_of[k]
                if valid[n, b]:
                    continue
                if c[CANDIDATE.fallback, k] != 0.0:  # the scalar solver's polish of this candidate
                    scalar = True
                    for j in range(5):
                        qs[j] = c[CANDIDATE.start + j, k]
                    current = False
                    if not exact:
                        current = polish_pose(placements, axes, targets[n], qs, scratch)
                    inside, err, angle = settle_pose(
                        prm, placements, axes, targets[n], qs, pose, scratch.work, current
                    )
                    if not (err <= POSE_EXACT and angle <= POSE_EXACT):
                        continue
                else:
                    if c[CANDIDATE.taken, k] == 0.0:
                        continue
                    for j in range(5):
                        qs[j] = c[CANDIDATE.q + j, k]
                    inside, err, angle = (
                        c[CANDIDATE.within, k] != 0.0,
                        c[CANDIDATE.position_error, k],
                        c[CANDIDATE.orientation_error, k],
                    )
                if is_duplicate(taken, ALL_TAKEN, count, qs, BRANCH_DUPLICATE_TOLERANCE):
                    continue
                for j in range(5):
                    q_out[n, b, j] = qs[j]
                    taken[count, j] = qs[j]
                count += 1
                valid[n, b] = True
                within[n, b] = inside
                position_error[n, b] = err
                orientation_error[n, b] = angle
            solved[n] = count > 0
            distance[n] = smallest_error(position_error, n)
            fallbacks += 1 if scalar else 0
    # the poses for the scalar solver, one after the other: its code and branch history stay
    # warm (between two blocks' vector loops each one cost ~2.5 times as much)
    for d in range(deferred_count):
        n = deferred[d]
        ref = reference[n if reference.shape[0] > 1 else 0]
        solved[n] = solve_target(prm, placements, axes, targets[n], ref, out, scratch)
        write_slots(out, n, slots, distance)
    return fallbacks + deferred_count


#: (tool off the roll axis, LDL^T steps) -> the variant of :func:`blocks` that an arm compiles.
_VARIANTS = {
    (False, False): _on_axis_parallel,
    (False, True): _on_axis_ldl,
    (True, False): _off_axis_parallel,
    (True, True): _off_axis_ldl,
}
#: The variant of each arm seen (key: its arrays' bytes).
_CHOSEN: dict[tuple[bytes, bytes, bytes], Any] = {}
