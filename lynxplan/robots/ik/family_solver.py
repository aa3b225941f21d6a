"""Python side of the yaw-pitch-pitch-pitch-roll solver: kernel calls, the near-axis rescue,
the single-pose path, results. Every function takes the
arm's plain :class:`~lynxplan.robots.ik.description.Kinematics`."""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING, Any

import numpy as np

from lynxplan import _jit
from lynxplan._arrays import kernel_input
from lynxplan.constants import (
    BRANCH_DUPLICATE_TOLERANCE,
    NEAR_AXIS_MARGIN,
    POSE_EXACT,
    REACH_TOLERANCE,
    RESCUE_NEAR_MISS,
)
from lynxplan.robots.ik import family_kernel as fk_
from lynxplan.robots.ik import pose_kernel as _pk
from lynxplan.robots.ik.elbow_labels import orient_elbows
from lynxplan.robots.ik.pose_block import pose_block_kernel
from lynxplan.robots.results import BranchSlots, RobotIkBatch, RobotIkResult
from lynxplan.robots.selection import assemble_result

if TYPE_CHECKING:
    from lynxplan.robots.ik.description import Kinematics
    from lynxplan.robots.targets import Target

_jit.listen()  # the IK kernels: a notice when their first compile takes long

_SIDES = ("front", "back")
_ELBOWS = ("elbow-up", "elbow-down")


#: Full poses of an off-axis tool with the roll free: rolls per side in the batch layout. The
#: orientation fixes the yaw up to a flip by pi, and with it the roll: a 5-joint arm of the family
#: reaches one pose with at most two rolls per side (the flip's), each with two elbows.
POSE_ROLLS = 2


@functools.cache
def branch_names(slots: int) -> tuple[str, ...]:
    """Names of the branch slots: side/elbow (4 slots) or side/roll-i/elbow (4 per roll)."""
    if slots == 4:
        return tuple(f"{s}/{e}" for s in _SIDES for e in _ELBOWS)
    return tuple(
        f"{s}/roll-{r + 1}/{e}" for s in _SIDES for r in range(slots // 4) for e in _ELBOWS
    )


def slot_count(kinematics: Kinematics, target: Target) -> int:
    """Branch slots of the batch layout: 4 (side x elbow: the roll given, or fixed by the
    orientation of a tool on the roll axis), 4 * POSE_ROLLS (full poses of an off-axis tool)
    or 4 * MAX_ROOTS (approach targets of an off-axis tool: every root of the roll equation)."""
    if not needs_root_search(kinematics, target):
        return 4
    return 4 * (POSE_ROLLS if target.kind == fk_.MODE_POSE else fk_.MAX_ROOTS)


def needs_root_search(kinematics: Kinematics, target: Target) -> bool:
    """Whether the roll is found by root search (off-axis tool, roll not given, not pitch)."""
    family = kinematics.family
    assert family is not None
    return (
        not family.tool_on_roll_axis
        and target.kind != fk_.MODE_PITCH
        and bool(np.isnan(target.roll).any())
    )


def solve_poses(
    kinematics: Kinematics, target: Target, reference: np.ndarray, block: bool
) -> RobotIkBatch:
    """Full poses, roll free: the closed form (``pose_block`` when ``block``, else the scalar
    ``pose_kernel``) gives each pose it solves its exact branches, each within
    REACH_TOLERANCE; the rest (out of reach, degenerate, a given roll) goes through the roll
    search (``family_kernel``) and the near-axis rescue, its roots packed into the pose layout."""
    n = target.poses.shape[0]
    slots = slot_count(kinematics, target)
    out = BranchSlots.empty(n, slots)
    # the rows by index: a boolean mask would be scanned whole by each of the ~10 uses
    distance = np.empty(n)
    rest = np.flatnonzero(~_pose_fill(kinematics, target, reference, out, distance, block))
    reachable = np.ones(n, dtype=np.bool_)
    if rest.size:
        sub, ref = _rows(target, reference, rest)
        part = BranchSlots.empty(sub.poses.shape[0], 4 if slots == 4 else 4 * fk_.MAX_ROOTS)
        _kernel(kinematics, sub, ref, part)
        reachable[rest], distance[rest] = _general(kinematics, sub, part)
        _orient(kinematics, part)
        out.put(rest, pack_rolls(part, slots // 4))
    return _batch(out, reachable, distance, slots)


def solve_roll_search(
    kinematics: Kinematics, target: Target, reference: np.ndarray
) -> RobotIkBatch:
    """Approach and pitch targets, and a given roll: the roll search (``family_kernel``), then
    the near-axis rescue (numerical, on a model only close to the family)."""
    slots = slot_count(kinematics, target)
    out = BranchSlots.empty(target.poses.shape[0], slots)
    _kernel(kinematics, target, reference, out)
    reachable, distance = _general(kinematics, target, out)
    _orient(kinematics, out)
    return _batch(out, reachable, distance, slots)


def _orient(kinematics: Kinematics, out: BranchSlots) -> None:
    """Each branch the roll search and the rescue found, in the slot of its elbow (the closed
    forms place theirs: ``elbow_labels``)."""
    assert kinematics.family is not None
    orient_elbows(kinematics.family.packed, out)


def _batch(
    out: BranchSlots, reachable: np.ndarray, distance: np.ndarray, slots: int
) -> RobotIkBatch:
    q, valid, within, perr, oerr = out
    for array in (q, valid, within, perr, oerr, reachable, distance):
        array.setflags(write=False)
    return RobotIkBatch(q, valid, within, perr, oerr, reachable, distance, branch_names(slots))


def _rows(target: Target, reference: np.ndarray, mask: np.ndarray) -> tuple[Target, np.ndarray]:
    """The targets in ``mask`` ((N,) bool, or row indices) and their references."""
    sub = type(target)(
        np.ascontiguousarray(target.poses[mask]), target.kind, target.pitch[mask], target.roll[mask]
    )
    ref = reference if reference.shape[0] == 1 else np.ascontiguousarray(reference[mask])
    return sub, ref


def pack_rolls(part: BranchSlots, rolls: int) -> BranchSlots:
    """The root-search layout (2 sides x R roots x 2 elbows) packed to ``rolls`` roots per side:
    the roots whose branches come nearest the target position (in root order). A reachable
    full pose has at most two rolls per side (``POSE_ROLLS``), so none of its branches is
    dropped; an unreachable one keeps its nearest solutions."""
    n, width = part.valid.shape
    per_side = width // 4
    if per_side <= rolls:
        return part
    nearest = np.where(part.valid, part.position_error, np.inf).reshape(n, 2, per_side, 2)
    keep = np.sort(np.argsort(nearest.min(axis=3), axis=2, kind="stable")[:, :, :rolls], axis=2)

    def packed(array: np.ndarray) -> np.ndarray:
        shaped = array.reshape(n, 2, per_side, 2, *array.shape[2:])
        index = keep.reshape(n, 2, rolls, *([1] * (shaped.ndim - 3)))
        return np.take_along_axis(shaped, index, axis=2).reshape(n, 4 * rolls, *array.shape[2:])

    return BranchSlots(*(packed(array) for array in part))


def _general(
    kinematics: Kinematics, target: Target, out: BranchSlots
) -> tuple[np.ndarray, np.ndarray]:
    """After the general kernel: the near-axis rescue, then which targets are reachable (N,)
    bool and their distance (N,) [m] (the smallest branch position error); a reachable target's
    solutions are the branches that reach it (the others are dropped from ``out``)."""
    rescue_near_axis(kinematics, target, out)
    distance = np.where(out.valid, out.position_error, np.inf).min(axis=1)
    reachable = distance <= REACH_TOLERANCE
    out.valid[...] &= ~(reachable[:, None] & (out.position_error > REACH_TOLERANCE))
    return reachable, distance


#: Besides the closed-form branches, the rescue starts from this many fixed random configurations.
RESCUE_STARTS = 16
RESCUE_SEED = 5
#: Approach targets: the rescue starts from each branch with its roll moved by these [rad].
ROLL_NUDGES = (-0.8, -0.4, -0.2, -0.1, 0.1, 0.2, 0.4, 0.8)


def rescue_near_axis(kinematics: Kinematics, target: Target, out: BranchSlots) -> None:
    """Near-family models (off-axis tool): Levenberg-Marquardt on the exact chain adds the
    branches the ideal model misses. Full poses near the yaw axis with no exact branch: from
    each branch and fixed random starts. Approach targets with the roll free and no exact
    branch: also from each branch with its roll nudged (near-double roots split differently).

    The numerical solver accepts only answers that reach the pose to 1e-10 m and 1e-9 rad.
    """
    from lynxplan.robots.ik.numerical import NumericalArm, NumericalResult, numerical_ik_kernel

    q, valid, within, perr, oerr = out
    family = kinematics.family
    assert family is not None
    if family.exact or family.tool_on_roll_axis or target.kind == fk_.MODE_PITCH:
        return
    exact_count = np.count_nonzero(valid & (oerr <= POSE_EXACT), axis=1)
    if exact_count.all():  # every target has an exact branch: nothing to rescue
        return
    lower, upper = kinematics.lower.copy(), kinematics.upper.copy()
    approach_only = target.kind == fk_.MODE_APPROACH
    if approach_only:
        # near-double roots of the approach equation split differently on the exact model:
        # with no exact branch found, look next to the branches along the roll
        # (also when no branch reaches the position: the polish failed on every one)
        near_miss = np.where(valid, perr, np.inf).min(axis=1) <= RESCUE_NEAR_MISS
        rows = np.flatnonzero(near_miss & np.isnan(target.roll) & (exact_count == 0))
    else:
        k = np.array(family.yaw_axis)
        d = target.poses[:, :3, 3] - family.packed[0:3]
        rho = np.linalg.norm(d - np.outer(d @ k, k), axis=1)
        near = rho < abs(family.lateral_offset) + family.tool_offset[1] + NEAR_AXIS_MARGIN
        near_miss = np.where(valid, perr, np.inf).min(axis=1) <= RESCUE_NEAR_MISS
        rows = np.flatnonzero(near & near_miss & (exact_count == 0))
    axis = np.array(family.approach_in_tool)
    chain = kinematics.chain
    arm = NumericalArm(chain.placements, chain.axes, lower, upper, axis)
    for row in rows:
        branches = q[row][valid[row]]
        if approach_only:
            nudged = [branches + np.array([0, 0, 0, 0, s]) for s in ROLL_NUDGES]
            extra = np.random.default_rng(RESCUE_SEED).uniform(
                lower, upper, size=(RESCUE_STARTS, 5)
            )
            seeds = np.ascontiguousarray(np.vstack((*nudged, extra)))
        else:
            extra = np.random.default_rng(RESCUE_SEED).uniform(
                lower, upper, size=(RESCUE_STARTS, 5)
            )
            seeds = np.ascontiguousarray(np.vstack((branches, extra)))
        n = seeds.shape[0]
        result = NumericalResult.empty(n, 5)
        numerical_ik_kernel(
            arm,
            np.repeat(target.poses[row : row + 1], n, 0),
            approach_only,
            seeds,
            np.empty((0, 5)),
            result,
        )
        found, ok, p_err, o_err, _ = result
        for i in np.flatnonzero(ok):
            taken = q[row][valid[row]]
            if (
                taken.size
                and np.abs(taken - found[i]).max(axis=1).min() < BRANCH_DUPLICATE_TOLERANCE
            ):
                continue
            free = np.flatnonzero(~valid[row])
            if free.size == 0:
                break
            slot = free[0]
            q[row, slot], valid[row, slot], within[row, slot] = found[i], True, True
            perr[row, slot], oerr[row, slot] = p_err[i], o_err[i]


def _kernel(
    kinematics: Kinematics, target: Target, reference: np.ndarray, out: BranchSlots
) -> None:
    family = kinematics.family
    assert family is not None
    miss = np.empty(out.valid.shape)
    fk_.family_ik_kernel(
        family.packed,
        kinematics.chain.placements,
        kinematics.chain.axes,
        fk_.KernelTargets(
            kernel_input(target.poses),
            target.kind,
            kernel_input(target.pitch),
            kernel_input(target.roll),
            kernel_input(reference),
        ),
        out,
        miss,
    )


def solve_pose_one(
    kinematics: Kinematics, pose: Any, reference: np.ndarray
) -> RobotIkResult | None:
    """One full pose (4, 4) with the roll free, the lean way (one kernel call, no batch
    arrays): the result, or None where the pose needs the general
    path (not finite or rigid, out of reach, degenerate). ``reference`` (n,) [rad]."""
    pose = np.ascontiguousarray(pose, dtype=float)
    family = kinematics.family
    assert family is not None
    slots = 4 if family.tool_on_roll_axis else 4 * POSE_ROLLS
    table = np.empty((slots, _pk.SLOT_COLUMNS))
    chain = kinematics.chain
    count = _pk.pose_one(
        family.packed,
        chain.placements,
        chain.axes,
        kernel_input(pose),
        kernel_input(reference),
        slots,
        table,
    )
    if count == 0:
        return None
    q = table[:count, :5].copy()
    rows = table[:count].tolist()
    names = branch_names(slots)
    errors = [row[_pk.COMPACT_POSITION_ERROR] for row in rows]
    return assemble_result(
        q,
        [names[int(row[_pk.SLOT])] for row in rows],
        [row[_pk.COMPACT_WITHIN] != 0.0 for row in rows],
        errors,
        [row[_pk.COMPACT_ORIENTATION_ERROR] for row in rows],
        True,
        min(errors),
        reference,
        kinematics.solver_name,
    )


def _pose_fill(
    kinematics: Kinematics,
    target: Target,
    reference: np.ndarray,
    out: BranchSlots,
    distance: np.ndarray,
    block: bool,
) -> np.ndarray:
    """Full poses the orientation solves in closed form (``pose_block`` when ``block``, else
    the scalar ``pose_kernel``); returns which. The others (out of reach,
    degenerate, a given roll) need the general kernel (root search). distance (N,): output,
    each target's smallest position error over its slots [m]."""
    family = kinematics.family
    assert family is not None
    solved = np.empty(target.poses.shape[0], dtype=np.bool_)
    kernel = pose_block_kernel if block else _pk.pose_kernel
    kernel(
        family.packed,
        kinematics.chain.placements,
        kinematics.chain.axes,
        kernel_input(target.poses),
        kernel_input(reference),
        out,
        solved,
        distance,
    )
    solved &= np.isnan(target.roll)
    return solved
