"""Numba kernel: every IK branch of a yaw-pitch-pitch-pitch-roll arm (see ``family.py``).

For a fixed roll angle the problem is closed-form (``family_geometry.py``). When the tool point
is on the roll axis the roll does not move it, so the roll is taken from the target (best roll
about the approach axis) or given. When the tool point is off the roll axis and the roll is not
given, the rolls are the roots of one scalar function on the roll joint's range
(``roll_search.py``); without a root, the roll that comes nearest is used and the residual
reported. When the model is only close to the family (URDF angles written to 5 digits), each
closed-form answer is polished by Newton's method on the exact chain (``family_polish.py``), and
where the ideal roll equation is within the model's deviation of zero its roots are searched on
the exact chain instead (``exact_roll_equation.py``).
Every branch is then verified by FK of the exact chain. Angles in [rad], lengths in [m].
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np

from lynxplan.constants import BRANCH_DUPLICATE_TOLERANCE, POLISH_CONDITION_TOLERANCE
from lynxplan.robots import family as F  # noqa: N812
from lynxplan.robots.ik.family_geometry import (
    MODE_APPROACH,
    MODE_PITCH,
    MODE_POSE,
    TWO_PI,
    branch,
)
from lynxplan.robots.ik.family_polish import (
    branch_orientation_error,
    copy5,
    is_duplicate,
    polish,
    settle_reaching,
)
from lynxplan.robots.ik.roll_equation import SCRATCH_ROWS, prepare_roll_terms
from lynxplan.robots.ik.roll_search import (
    GRID_SIZE,
    MAX_ROOTS,
    ROOT_GRID,
    exact_candidates,
    nearest_roll,
    roll_candidates,
    sample_roll_grid,
)
from lynxplan.robots.results import BranchSlots

__all__ = [
    "MAX_ROOTS",
    "MODE_APPROACH",
    "MODE_PITCH",
    "MODE_POSE",
    "ROOT_GRID",
    "family_ik_closed_form",
    "family_ik_general",
    "family_ik_kernel",
]


class KernelTargets(NamedTuple):
    """The targets of :func:`family_ik_kernel` (kernel inputs: writable, C-contiguous)."""

    poses: np.ndarray
    """(N, 4, 4); for approach targets only column 2 (approach) and 3 count [m]."""
    mode: int
    """MODE_POSE, MODE_APPROACH or MODE_PITCH."""
    pitch: np.ndarray
    """(N,) approach pitch for MODE_PITCH [rad] (from straight down towards outward)."""
    roll: np.ndarray
    """(N,) roll joint angle [rad], NaN where free."""
    reference: np.ndarray
    """(N, 5) or (1, 5) joint angles [rad]: yaw on the base axis, the pitch sum when the
    approach is along the pitch axis, the roll where free and not determined."""


def family_ik_kernel(
    prm: np.ndarray,
    placements: np.ndarray,
    axes: np.ndarray,
    goals: KernelTargets,
    slots: BranchSlots,
    miss_out: np.ndarray,
) -> None:
    """Every branch of N targets.

    Args:
        prm: Packed family parameters (``family.py``).
        placements, axes: The exact chain (``chain.py``).
        goals: The N targets and their reference (:class:`KernelTargets`).
        slots: (N, B, ...) outputs (:class:`BranchSlots`): angles, flags (branch exists;
            within joint limits), position and orientation errors on the exact chain [m],
            [rad]; B = 4 (closed form) or 4 * MAX_ROOTS (root search).
        miss_out: (N, B) output: by how much the closed form missed the reach, [m].
    """
    closed_form_only = prm[F.EXACT] != 0.0 and prm[F.OFF_AXIS] == 0.0
    kernel = family_ik_closed_form if closed_form_only else family_ik_general
    kernel(prm, placements, axes, goals, slots, miss_out)


@numba.njit(cache=True, nogil=True)
def family_ik_closed_form(
    prm: np.ndarray,
    placements: np.ndarray,
    axes: np.ndarray,
    goals: KernelTargets,
    slots: BranchSlots,
    miss_out: np.ndarray,
) -> None:
    """:func:`family_ik_kernel` for a model of the family exactly with the tool point on the roll
    axis (the AL5): neither the roll search nor the Newton polish is compiled (neither runs)."""
    _family_ik(prm, placements, axes, goals, slots, miss_out, None, None)


@numba.njit(cache=True, nogil=True)
def family_ik_general(
    prm: np.ndarray,
    placements: np.ndarray,
    axes: np.ndarray,
    goals: KernelTargets,
    slots: BranchSlots,
    miss_out: np.ndarray,
) -> None:
    """:func:`family_ik_kernel` for any other model (the SO-101: close to the family, the tool
    off the roll axis)."""
    _family_ik(prm, placements, axes, goals, slots, miss_out, True, True)


@numba.njit(cache=True, nogil=True)
def _family_ik(  # noqa: PLR0912, PLR0915 (numba kernel: one compiled loop per pose)
    prm: np.ndarray,
    placements: np.ndarray,
    axes: np.ndarray,
    goals: KernelTargets,
    slots: BranchSlots,
    miss_out: np.ndarray,
    polish_code: bool | None,
    search_code: bool | None,
) -> None:
    """:func:`family_ik_kernel`'s work. ``polish_code`` and ``search_code``: None where the
    model never needs the Newton polish (a model of the family exactly) or the roll search (the
    tool point on the roll axis), else True; constants: numba prunes the ``is not None``
    branches of a None when it compiles, so their code is not compiled (the branches also test
    the model at run time)."""
    targets, mode, pitch, roll, reference = goals
    q_out, valid, within, position_error, orientation_error = slots
    nb = q_out.shape[1]
    per_side = nb // 2
    lower, upper = prm[F.LOWER : F.LOWER + 5], prm[F.UPPER : F.UPPER + 5]
    sig5 = prm[F.SIGMA + 4]
    lo5, hi5 = sig5 * lower[4], sig5 * upper[4]
    if lo5 > hi5:
        lo5, hi5 = hi5, lo5
    if hi5 - lo5 > TWO_PI:
        hi5 = lo5 + TWO_PI
    rt0 = prm[F.RT0 : F.RT0 + 9]
    g = np.empty((SCRATCH_ROWS, 4))  # G = Rt Rt0^T, the approach axis, roll constants
    pose, work = np.empty((4, 4)), np.empty((4, 4))
    roots = np.empty(2 * MAX_ROOTS)
    q = np.empty(5)
    trial = np.empty(5)
    scratch = np.empty((6, 5))
    scratch4 = np.empty((2, 4, 4))
    scratch5 = np.empty((6, 5))
    grid_x, grid_f = np.empty(GRID_SIZE), np.empty(GRID_SIZE)
    nearest = 0.0
    exact = prm[F.EXACT] != 0.0
    off_axis = prm[F.OFF_AXIS] != 0.0
    for n in range(targets.shape[0]):
        target = targets[n]
        ref = reference[n if reference.shape[0] > 1 else 0]
        phi_ref = prm[F.SIGMA] * ref[0]
        sum_ref = prm[F.SIGMA + 1] * ref[1] + prm[F.SIGMA + 2] * ref[2] + prm[F.SIGMA + 3] * ref[3]
        if mode == MODE_POSE:
            for i in range(3):  # G = Rt Rt0^T
                for j in range(3):
                    g[i, j] = (
                        target[i, 0] * rt0[3 * j]
                        + target[i, 1] * rt0[3 * j + 1]
                        + target[i, 2] * rt0[3 * j + 2]
                    )
        if mode == MODE_POSE:  # approach = Rt (Rt0^T r)
            for i in range(3):
                g[i, 3] = g[i, 0] * prm[F.R] + g[i, 1] * prm[F.R + 1] + g[i, 2] * prm[F.R + 2]
        else:
            for i in range(3):
                g[i, 3] = target[i, 2]
        roll_given = roll[n]
        need_roots = off_axis and math.isnan(roll_given) and mode != MODE_PITCH
        if search_code is not None and need_roots:
            prepare_roll_terms(prm, target, g)
        theta_fixed = sig5 * (ref[4] if math.isnan(roll_given) else roll_given)
        for b in range(nb):
            valid[n, b] = False
            within[n, b] = False
            position_error[n, b] = np.nan
            orientation_error[n, b] = np.nan
            miss_out[n, b] = np.nan
            for j in range(5):
                q_out[n, b, j] = np.nan
        chain_problem = (prm, placements, axes, target, g, mode, pitch[n])
        for side in range(2):
            problem = (prm, target, g, mode, side, phi_ref, sum_ref)
            count = 1
            roots[0] = theta_fixed
            rooted = True
            if search_code is not None and need_roots:
                m = sample_roll_grid(problem, lo5, hi5, grid_x, grid_f)
                count = roll_candidates(problem, grid_x, grid_f, m, roots)
                if polish_code is not None and not exact:
                    count = exact_candidates(
                        problem,
                        (
                            problem,
                            chain_problem,
                            np.int64(0),
                            q,
                            scratch,
                            scratch4,
                            scratch5,
                            trial,
                        ),
                        (
                            problem,
                            chain_problem,
                            np.int64(1),
                            q,
                            scratch,
                            scratch4,
                            scratch5,
                            trial,
                        ),
                        grid_x,
                        grid_f,
                        m,
                        roots,
                        count,
                    )
                if count == 0:  # no root: the nearest roll, held during the polish
                    count, rooted = 1, False
                    nearest = nearest_roll(problem, grid_x, grid_f, m)
                    roots[0] = nearest
                    if polish_code is not None and not exact and MAX_ROOTS >= 2:
                        # the exact model may still have a close pair of roots the nearly
                        # identical ideal model lacks: try Newton from either side first
                        count = 2
                        roots[0], roots[1] = nearest - 2e-3, nearest + 2e-3
            for ri in range(count):
                for elbow in range(2):
                    b = side * per_side + ri * 2 + elbow
                    miss = branch(problem, pitch[n], roots[ri], elbow, q)
                    polished = False
                    hold = False
                    # (tentative roots come only from a model close to the family)
                    if (
                        polish_code is not None
                        and need_roots
                        and rooted
                        and roots[MAX_ROOTS + ri] == 1.0
                    ):
                        # a tentative root: a branch only if Newton converges on the exact model
                        if (
                            polish(chain_problem, np.nan, q, scratch, scratch4, scratch5)
                            >= POLISH_CONDITION_TOLERANCE
                        ):
                            firm = 0
                            for j in range(count):
                                firm += roots[MAX_ROOTS + j] == 0.0
                            if firm > 0:
                                continue
                            # only tentative roots on this side: keep the nearest, roll held
                            miss = branch(problem, pitch[n], roots[ri], elbow, q)
                            hold = True
                        else:
                            polished = True
                    elif polish_code is not None and not exact and not rooted:
                        copy5(q, trial)
                        if (
                            polish(chain_problem, np.nan, trial, scratch, scratch4, scratch5)
                            < POLISH_CONDITION_TOLERANCE
                        ):
                            copy5(trial, q)
                            polished = True
                        else:
                            miss = branch(problem, pitch[n], nearest, elbow, q)
                    if polish_code is not None and not exact and not polished:
                        rg = roll_given
                        if math.isnan(rg) and (
                            mode == MODE_PITCH
                            or (mode == MODE_APPROACH and not off_axis)
                            or not rooted
                            or hold
                        ):
                            rg = q[4]
                        polish(chain_problem, rg, q, scratch, scratch4, scratch5)
                    inside, err = settle_reaching(prm, placements, axes, target, q, pose, work)
                    # the same branch reached twice (merged roots, a fold)
                    if is_duplicate(q_out[n], valid[n], b, q, BRANCH_DUPLICATE_TOLERANCE):
                        continue
                    for j in range(5):
                        q_out[n, b, j] = q[j]
                    valid[n, b] = True
                    within[n, b] = inside
                    position_error[n, b] = err
                    orientation_error[n, b] = branch_orientation_error(
                        prm, target, g, mode, pitch[n], q, pose
                    )
                    miss_out[n, b] = miss
