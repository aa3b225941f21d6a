"""Newton polish of a closed-form branch on the exact chain, and the branch's errors (numba).

A model only close to the family (URDF angles written to 5 digits) gets each closed-form answer
polished by Newton's method on the exact chain, on the same five conditions the closed form
solves. Angles are in [rad], lengths in [m]; ``prm`` is the packed vector of ``family.py``.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from lynxplan.constants import (
    CHORD_RATE,
    POLISH_CONDITION_TOLERANCE,
    POLISH_FD_STEP,
    POSE_EXACT,
    REACH_TOLERANCE,
)
from lynxplan.robots import family as F  # noqa: N812
from lynxplan.robots.chain import chain_fk
from lynxplan.robots.ik.family_geometry import (
    MODE_APPROACH,
    MODE_PITCH,
    MODE_POSE,
    ChainProblem,
    rotate,
    wrap_into_limits,
)

#: Newton iterations at most (it stops below ``constants.POLISH_CONDITION_TOLERANCE``).
NEWTON_STEPS = 40


@numba.njit(cache=True, nogil=True)
def lu_factor(a: np.ndarray) -> bool:
    """LU factors of the square a[:n] (n = columns) in place, partial pivoting; the row order
    goes to a[n] (as floats). Returns False when a pivot vanishes (a singular matrix).

    Replaces LAPACK calls, whose per-call cost dominated the polish of 5x5 systems.
    """
    n = a.shape[1]
    for i in range(n):
        a[n, i] = i
    for col in range(n):
        pivot, best = col, abs(a[col, col])
        for row in range(col + 1, n):
            if abs(a[row, col]) > best:
                pivot, best = row, abs(a[row, col])
        if not best > 1e-300:
            return False
        if pivot != col:
            for j in range(n):
                a[col, j], a[pivot, j] = a[pivot, j], a[col, j]
            a[n, col], a[n, pivot] = a[n, pivot], a[n, col]
        inv = 1.0 / a[col, col]
        for row in range(col + 1, n):
            factor = a[row, col] * inv
            a[row, col] = factor
            if factor != 0.0:
                for j in range(col + 1, n):
                    a[row, j] -= factor * a[col, j]
    return True


@numba.njit(cache=True, nogil=True)
def lu_solve(lu: np.ndarray, b: np.ndarray, x: np.ndarray) -> None:
    """x = a^-1 b from the factors of ``lu_factor``."""
    n = lu.shape[1]
    for i in range(n):
        total = b[int(lu[n, i])]
        for j in range(i):
            total -= lu[i, j] * x[j]
        x[i] = total
    for i in range(n - 1, -1, -1):
        total = x[i]
        for j in range(i + 1, n):
            total -= lu[i, j] * x[j]
        x[i] = total / lu[i, i]


@numba.njit(cache=True, nogil=True, inline="always")
def copy5(src: np.ndarray, dst: np.ndarray) -> None:
    """dst[:5] = src[:5], element by element. A slice assignment (``dst[:] = src``) checks the
    shapes and compiles numba's error message for a mismatch (string formatting, ~2 s of the
    IK kernel's first compile); a plain copy is the same bits."""
    for j in range(5):
        dst[j] = src[j]


@numba.njit(cache=True, nogil=True, inline="always")
def reached_approach(prm: np.ndarray, pose: np.ndarray) -> tuple[float, float, float]:
    """The approach axis of a reached pose (4, 4), in the base frame: R (Rt0^T r)."""
    rt = prm[F.RT0 : F.RT0 + 9]
    r0, r1, r2 = prm[F.R], prm[F.R + 1], prm[F.R + 2]
    u0 = rt[0] * r0 + rt[3] * r1 + rt[6] * r2  # the approach in the tool frame: Rt0^T r
    u1 = rt[1] * r0 + rt[4] * r1 + rt[7] * r2
    u2 = rt[2] * r0 + rt[5] * r1 + rt[8] * r2
    return (
        pose[0, 0] * u0 + pose[0, 1] * u1 + pose[0, 2] * u2,
        pose[1, 0] * u0 + pose[1, 1] * u1 + pose[1, 2] * u2,
        pose[2, 0] * u0 + pose[2, 1] * u1 + pose[2, 2] * u2,
    )


@numba.njit(cache=True, nogil=True)
def conditions(
    problem: ChainProblem,
    roll_given: float,
    q: np.ndarray,
    pose: np.ndarray,
    work: np.ndarray,
    e: np.ndarray,
) -> None:
    """The five conditions the branch satisfies, evaluated on the exact chain into e (5,);
    pose and work: scratch (4, 4)."""
    prm, placements, axes, target, g, mode, pitch = problem
    chain_fk(placements, axes, q, pose, work)
    for i in range(3):
        e[i] = pose[i, 3] - target[i, 3]
    # approach axis and pitch axis of the reached configuration
    a0, a1, a2 = reached_approach(prm, pose)
    cy, sy = math.cos(prm[F.SIGMA] * q[0]), math.sin(prm[F.SIGMA] * q[0])
    k0, k1, k2 = prm[F.K], prm[F.K + 1], prm[F.K + 2]
    pp0, pp1, pp2 = rotate(k0, k1, k2, cy, sy, prm[F.P], prm[F.P + 1], prm[F.P + 2])
    if mode == MODE_PITCH:
        h0, h1, h2 = rotate(k0, k1, k2, cy, sy, prm[F.H], prm[F.H + 1], prm[F.H + 2])
        sp, cp = math.sin(pitch), math.cos(pitch)
        t0, t1, t2 = sp * h0 - cp * k0, sp * h1 - cp * k1, sp * h2 - cp * k2
    else:
        t0, t1, t2 = g[0, 3], g[1, 3], g[2, 3]
    # in-plane approach angle matches: (a x at) . p = 0
    c0 = a1 * t2 - a2 * t1
    c1 = a2 * t0 - a0 * t2
    c2 = a0 * t1 - a1 * t0
    e[3] = c0 * pp0 + c1 * pp1 + c2 * pp2
    if (
        not math.isnan(roll_given)
        or mode == MODE_PITCH
        or (mode == MODE_APPROACH and prm[F.OFF_AXIS] == 0.0)
    ):
        e[4] = q[4] - roll_given
    elif mode == MODE_APPROACH:  # the approach exactly: (a x at) . (a x p) = 0 as well
        w0 = a1 * pp2 - a2 * pp1
        w1 = a2 * pp0 - a0 * pp2
        w2 = a0 * pp1 - a1 * pp0
        e[4] = c0 * w0 + c1 * w1 + c2 * w2
    else:  # best roll about the approach axis: a . vee(Rt R^T - R Rt^T) = 0
        v0 = v1 = v2 = 0.0
        for m in range(3):
            v0 += target[2, m] * pose[1, m] - pose[2, m] * target[1, m]
            v1 += target[0, m] * pose[2, m] - pose[0, m] * target[2, m]
            v2 += target[1, m] * pose[0, m] - pose[1, m] * target[0, m]
        e[4] = a0 * v0 + a1 * v1 + a2 * v2


@numba.njit(cache=True, nogil=True)
def polish(
    problem: ChainProblem,
    roll_given: float,
    q: np.ndarray,
    scratch: np.ndarray,
    scratch4: np.ndarray,
    scratch5: np.ndarray,
) -> float:
    """Newton's method on the five conditions, on the exact chain (finite-difference Jacobian,
    kept while it converges fast: the chord method; refreshed when a step gains less than
    :data:`CHORD_RATE` or fails).

    Keeps the closed-form answer when Newton does not reduce the conditions (unreachable).
    """
    # scratch (6, 5): rows e, e2, qh, start, qt, step; (pose, work) in scratch4;
    # scratch5 (6, 5): the LU factors of the Jacobian and their row order
    pose, work = scratch4[0], scratch4[1]
    e, e2, qh, start, qt = scratch[0], scratch[1], scratch[2], scratch[3], scratch[4]
    step = scratch[5]
    jac = scratch5
    copy5(q, start)
    conditions(problem, roll_given, q, pose, work, e)
    first = max(abs(e[0]), abs(e[1]), abs(e[2]), abs(e[3]), abs(e[4]))
    norm = first
    factored = fresh = False
    for _ in range(NEWTON_STEPS):
        if norm < POLISH_CONDITION_TOLERANCE or not math.isfinite(norm):
            break
        if not factored:
            for j in range(5):
                copy5(q, qh)
                qh[j] += POLISH_FD_STEP
                conditions(problem, roll_given, qh, pose, work, e2)
                for i in range(5):
                    jac[i, j] = (e2[i] - e[i]) / POLISH_FD_STEP
            if not lu_factor(jac):
                break
            factored = fresh = True
        lu_solve(jac, e, step)
        # backtracking: the full step unless it increases the conditions
        t = 1.0
        accepted = False
        before = norm
        for _ in range(12):
            for j in range(5):
                qt[j] = q[j] - t * step[j]
            conditions(problem, roll_given, qt, pose, work, e2)
            trial = max(abs(e2[0]), abs(e2[1]), abs(e2[2]), abs(e2[3]), abs(e2[4]))
            if trial < norm:
                copy5(qt, q)
                copy5(e2, e)
                norm = trial
                accepted = True
                break
            t *= 0.5
        if not accepted and fresh:
            break
        # a stale Jacobian that no longer converges fast is computed again at the new point
        factored = accepted and norm <= CHORD_RATE * before
        fresh = False
    if not (norm <= first):
        copy5(start, q)
        return float(first)
    return float(norm)


@numba.njit(cache=True, nogil=True)
def rotation_angle(target: np.ndarray, pose: np.ndarray) -> float:
    """Angle of the rotation from target[:3, :3] to pose[:3, :3] [rad], accurate near 0."""
    tr = 0.0
    for i in range(3):
        tr += target[0, i] * pose[0, i] + target[1, i] * pose[1, i] + target[2, i] * pose[2, i]
    # vee of (Rt^T R - R^T Rt): rows of Rt^T R are columns of Rt dotted with columns of R
    m01 = m10 = m02 = m20 = m12 = m21 = 0.0
    for r in range(3):
        m01 += target[r, 0] * pose[r, 1]
        m10 += target[r, 1] * pose[r, 0]
        m02 += target[r, 0] * pose[r, 2]
        m20 += target[r, 2] * pose[r, 0]
        m12 += target[r, 1] * pose[r, 2]
        m21 += target[r, 2] * pose[r, 1]
    s0, s1, s2 = m21 - m12, m02 - m20, m10 - m01
    return math.atan2(0.5 * math.sqrt(s0 * s0 + s1 * s1 + s2 * s2), 0.5 * (tr - 1.0))


@numba.njit(cache=True, nogil=True)
def axis_angle(a0: float, a1: float, a2: float, t0: float, t1: float, t2: float) -> float:
    """Angle between the unit axes a and t [rad] (atan2 of |a x t| and a . t)."""
    c0, c1, c2 = a1 * t2 - a2 * t1, a2 * t0 - a0 * t2, a0 * t1 - a1 * t0
    return math.atan2(math.sqrt(c0 * c0 + c1 * c1 + c2 * c2), a0 * t0 + a1 * t1 + a2 * t2)


@numba.njit(cache=True, nogil=True)
def settle(
    prm: np.ndarray,
    placements: np.ndarray,
    axes: np.ndarray,
    target: np.ndarray,
    q: np.ndarray,
    pose: np.ndarray,
    work: np.ndarray,
    current: bool = False,
) -> tuple[bool, float]:
    """A branch's angles q (5,) wrapped in place into the limits of the packed parameters prm
    (snapping within their tolerance); its pose on the exact chain into pose (4, 4) (work:
    scratch), unless pose is ``current`` (holds the pose at q) and no angle moved. Returns
    (within the limits, position error against target [m])."""
    inside = True
    tol = prm[F.LIMIT_TOL]
    for j in range(5):
        x, ok = wrap_into_limits(q[j], prm[F.LOWER + j], prm[F.UPPER + j], tol)
        current = current and x == q[j]
        q[j] = x
        inside = inside and ok
    if not current:
        chain_fk(placements, axes, q, pose, work)
    return inside, position_error(pose, target)


@numba.njit(cache=True, nogil=True, inline="always")
def position_error(pose: np.ndarray, target: np.ndarray) -> float:
    """Distance between the tool points of two poses (4, 4) [m]."""
    err = 0.0
    for i in range(3):
        d = pose[i, 3] - target[i, 3]
        err += d * d
    return math.sqrt(err)


@numba.njit(cache=True, nogil=True)
def unsnapped(
    prm: np.ndarray,
    placements: np.ndarray,
    axes: np.ndarray,
    target: np.ndarray,
    raw: tuple[float, float, float, float, float],
    q: np.ndarray,
    pose: np.ndarray,
    work: np.ndarray,
) -> float:
    """Where ``settle`` snapped an angle of raw (the 5 angles before it) onto a limit: q (5,) =
    raw moved into the limits by whole turns only (``wrap_into_limits`` without a tolerance),
    its pose on the exact chain into pose (4, 4) and its position error against target [m].
    inf, q and pose untouched, where nothing snapped (q holds the same angles)."""
    lo, hi = prm[F.LOWER :], prm[F.UPPER :]
    free = (
        wrap_into_limits(raw[0], lo[0], hi[0], 0.0)[0],
        wrap_into_limits(raw[1], lo[1], hi[1], 0.0)[0],
        wrap_into_limits(raw[2], lo[2], hi[2], 0.0)[0],
        wrap_into_limits(raw[3], lo[3], hi[3], 0.0)[0],
        wrap_into_limits(raw[4], lo[4], hi[4], 0.0)[0],
    )
    moved = False
    for j in range(5):
        moved = moved or free[j] != q[j]
    if not moved:
        return np.inf
    for j in range(5):
        q[j] = free[j]
    chain_fk(placements, axes, q, pose, work)
    return position_error(pose, target)


@numba.njit(cache=True, nogil=True)
def settle_reaching(
    prm: np.ndarray,
    placements: np.ndarray,
    axes: np.ndarray,
    target: np.ndarray,
    q: np.ndarray,
    pose: np.ndarray,
    work: np.ndarray,
) -> tuple[bool, float]:
    """``settle``, except where snapping an angle onto its limit moves the tool point off a
    target the branch reaches (beyond REACH_TOLERANCE): the branch is then kept as it is,
    outside the limits (whole turns only). A snap never turns a branch that reaches into one
    that misses; a branch that misses anyway (out of reach) keeps its snap."""
    raw = (q[0], q[1], q[2], q[3], q[4])
    inside, err = settle(prm, placements, axes, target, q, pose, work)
    if err > REACH_TOLERANCE:
        held = (q[0], q[1], q[2], q[3], q[4])
        free = unsnapped(prm, placements, axes, target, raw, q, pose, work)
        if free <= REACH_TOLERANCE:
            return False, free
        if free < np.inf:  # the snapped branch after all
            for j in range(5):
                q[j] = held[j]
            chain_fk(placements, axes, q, pose, work)
    return inside, err


@numba.njit(cache=True, nogil=True)
def settle_pose(
    prm: np.ndarray,
    placements: np.ndarray,
    axes: np.ndarray,
    target: np.ndarray,
    q: np.ndarray,
    pose: np.ndarray,
    work: np.ndarray,
    current: bool,
) -> tuple[bool, float, float]:
    """``settle`` for a full pose: (within the limits, position error [m], orientation error
    [rad]). Where snapping an angle onto its limit moves the tool off the pose (beyond
    POSE_EXACT), the branch is kept as it is, outside the limits (whole turns only): a snap
    never turns an exact branch into none."""
    raw = (q[0], q[1], q[2], q[3], q[4])
    inside, err = settle(prm, placements, axes, target, q, pose, work, current)
    angle = rotation_angle(target, pose)
    if not (err <= POSE_EXACT and angle <= POSE_EXACT):
        free = unsnapped(prm, placements, axes, target, raw, q, pose, work)
        if free < np.inf:
            inside, err, angle = False, free, rotation_angle(target, pose)
    return inside, err, angle


@numba.njit(cache=True, nogil=True)
def is_duplicate(
    branches: np.ndarray, taken: np.ndarray, count: int, q: np.ndarray, tolerance: float
) -> bool:
    """Whether q (5,) is within tolerance [rad] in every joint of one of branches[:count]
    (rows: angles first) whose ``taken`` flag is set (bool, or float 1/0)."""
    for b in range(count):
        if taken[b]:
            gap = 0.0
            for j in range(5):
                gap = max(gap, abs(branches[b, j] - q[j]))
            if gap < tolerance:
                return True
    return False


@numba.njit(cache=True, nogil=True)
def branch_orientation_error(
    prm: np.ndarray,
    target: np.ndarray,
    g: np.ndarray,
    mode: int,
    pitch: float,
    q: np.ndarray,
    pose: np.ndarray,
) -> float:
    """Angle between target and reached orientation (pose) or approach axes (approach, pitch)."""
    if mode == MODE_POSE:
        return rotation_angle(target, pose)
    a0, a1, a2 = reached_approach(prm, pose)
    if mode == MODE_PITCH:
        k0, k1, k2 = prm[F.K], prm[F.K + 1], prm[F.K + 2]
        cy, sy = math.cos(prm[F.SIGMA] * q[0]), math.sin(prm[F.SIGMA] * q[0])
        h0, h1, h2 = rotate(k0, k1, k2, cy, sy, prm[F.H], prm[F.H + 1], prm[F.H + 2])
        sp, cp = math.sin(pitch), math.cos(pitch)
        t0, t1, t2 = sp * h0 - cp * k0, sp * h1 - cp * k1, sp * h2 - cp * k2
    else:
        t0, t1, t2 = g[0, 3], g[1, 3], g[2, 3]
    return axis_angle(a0, a1, a2, t0, t1, t2)
