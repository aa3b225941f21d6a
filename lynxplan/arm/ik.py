"""Analytic inverse kinematics of the 5-DOF arm, every branch (SPEC Part 1).

A 5-DOF arm cannot reach an arbitrary 6-D pose: the approach axis ``a`` and the tool point must lie
in the vertical plane through the base axis at angle q1. The solver places the tool point exactly,
projects the approach axis into that plane and takes the roll q5 from the target's ``n`` axis; the
angle between the target and the reached orientation is the *orientation residual*.

Branches, in this order: (front, elbow up), (front, elbow down), (back, elbow up), (back, elbow
down). "Front" faces the tool point (q1 = atan2(y, x)); "back" is q1 + pi with the arm leaning back
over the base. "Elbow up" means the elbow lies above the shoulder-to-wrist line.

Every kernel here is compiled with numba and loops over a batch on one core.
"""

from __future__ import annotations

import math
from enum import IntEnum
from typing import NamedTuple

import numba
import numpy as np

from lynxplan._fastmath import atan2, sincos
from lynxplan.arm.geometry import ArmGeometry, JointLimits
from lynxplan.arm.kinematics import fk_kernel
from lynxplan.constants import (
    BASE_AXIS_TOLERANCE,
    LIMIT_SNAP_TOLERANCE,
    REACH_TOLERANCE,
    RIGIDITY_REPAIR_TOLERANCE,
)
from lynxplan.exceptions import NonFiniteInputError, ShapeError

BRANCH_NAMES = ("front/elbow-up", "front/elbow-down", "back/elbow-up", "back/elbow-down")
TWO_PI = 2.0 * math.pi
#: IEEE-safe fast-math flags: fused multiply-add and division by reciprocal (rounding differs
#: by an ulp; no assumptions about NaN, infinity or signed zeros, which the kernels rely on).
_FAST = {"contract", "arcp"}


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _dot3(u: np.ndarray, v: np.ndarray) -> float:
    """Dot product of two 3-vectors (numba's ``@`` calls BLAS: slow for 3 elements)."""
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]


class IkStatus(IntEnum):
    """Outcome of the IK of one pose."""

    OK = 0
    """Solved: four branches (some may be outside the joint limits)."""
    OUT_OF_REACH = 1
    """The wrist centre lies outside the reachable annulus; ``reach_miss`` says by how much."""
    NOT_RIGID = 2
    """The rotation part is further than the repair tolerance from orthonormal."""
    NON_FINITE = 3
    """The pose contains NaN or infinity."""


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


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _orthonormalise(a: np.ndarray, n: np.ndarray, o: np.ndarray, approach_only: bool) -> None:
    """Gram-Schmidt from the approach axis, in place: a normalised; unless ``approach_only``,
    n made orthogonal to a and normalised, and o = a x n."""
    scale = 1.0 / math.sqrt(_dot3(a, a))
    for i in range(3):
        a[i] *= scale
    if approach_only:
        return
    along = _dot3(n, a)
    for i in range(3):
        n[i] -= along * a[i]
    scale = 1.0 / math.sqrt(_dot3(n, n))
    for i in range(3):
        n[i] *= scale
    o[0] = a[1] * n[2] - a[2] * n[1]
    o[1] = a[2] * n[0] - a[0] * n[2]
    o[2] = a[0] * n[1] - a[1] * n[0]


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _mark_unsolved(
    k: int, q_out: np.ndarray, within_out: np.ndarray, residual_out: np.ndarray
) -> None:
    """NaN angles and residual, no branch within limits, for pose k (loops: no views)."""
    residual_out[k] = np.nan
    for b in range(4):
        within_out[k, b] = False
        for j in range(5):
            q_out[k, b, j] = np.nan


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _wrap_into_limits(x: float, lo: float, hi: float, tol: float) -> tuple[float, bool]:
    """Angle x moved by whole turns into [lo, hi] (snapping within tol), or nearest outside."""
    if lo <= x <= hi:
        return x, True
    turns = math.floor((x - lo) / TWO_PI)  # floor is one instruction; % calls fmod
    y = x - turns * TWO_PI  # y in [lo, lo + 2 pi) up to rounding
    if y <= hi:
        return y, True
    if y <= hi + tol:
        return hi, True
    if y >= lo + TWO_PI - tol:
        return lo, True
    above, below = y - hi, lo + TWO_PI - y
    return (y, False) if above <= below else (y - TWO_PI, False)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _angle_between_frames(
    n_t: np.ndarray,
    o_t: np.ndarray,
    a_t: np.ndarray,
    n_s: np.ndarray,
    o_s: np.ndarray,
    a_s: np.ndarray,
) -> float:
    """Rotation angle of R_t^T R_s, in [rad], accurate near 0 (atan2 of sine and cosine)."""
    m00, m11, m22 = _dot3(n_t, n_s), _dot3(o_t, o_s), _dot3(a_t, a_s)
    m01, m10 = _dot3(n_t, o_s), _dot3(o_t, n_s)
    m02, m20 = _dot3(n_t, a_s), _dot3(a_t, n_s)
    m12, m21 = _dot3(o_t, a_s), _dot3(a_t, o_s)
    sx, sy, sz = 0.5 * (m21 - m12), 0.5 * (m02 - m20), 0.5 * (m10 - m01)
    sine = math.sqrt(sx * sx + sy * sy + sz * sz)
    cosine = 0.5 * (m00 + m11 + m22 - 1.0)
    if sine < 1e-4 and cosine > 0.0:
        # Reachable targets land here: asin(x) = x + x^3/6 + O(x^5), exact to ~1e-21 rad.
        return sine + sine * sine * sine / 6.0
    return atan2(sine, cosine)


@numba.njit(cache=True, nogil=True, fastmath=_FAST)
def ik_kernel(
    T: np.ndarray,
    q_ref: np.ndarray,
    a2: float,
    a3: float,
    d5: float,
    lower: np.ndarray,
    upper: np.ndarray,
    limit_tol: float,
    approach_only: bool,
    q_out: np.ndarray,
    within_out: np.ndarray,
    residual_out: np.ndarray,
    status_out: np.ndarray,
    miss_out: np.ndarray,
    deviation_out: np.ndarray,
) -> None:
    """IK of poses T (N, 4, 4) into q_out (N, 4, 5) and the per-pose outputs (see IkBatch).

    q_ref (M, 5) with M = 1 or N gives q1 on the base axis and q5 when the roll is free.
    """
    n_t = np.empty(3)
    o_t = np.empty(3)
    a_t = np.empty(3)
    n_s = np.empty(3)
    o_s = np.empty(3)
    a_s = np.empty(3)
    for k in range(T.shape[0]):
        # Plain indices, no per-pose views: a view costs reference-count updates in numba.
        r_k = k if q_ref.shape[0] > 1 else 0
        miss_out[k] = 0.0
        deviation_out[k] = 0.0
        finite = True
        for i in range(4):
            for j in range(4):
                if not math.isfinite(T[k, i, j]):
                    finite = False
        if not finite:
            status_out[k] = IkStatus.NON_FINITE
            _mark_unsolved(k, q_out, within_out, residual_out)
            continue
        px, py, pz = T[k, 0, 3], T[k, 1, 3], T[k, 2, 3]
        if max(abs(px), abs(py), abs(pz)) > FAR_AWAY_K:  # keeps squares below overflow
            status_out[k] = IkStatus.OUT_OF_REACH
            miss_out[k] = max(abs(px), abs(py), abs(pz)) - (a2 + a3 + d5)
            _mark_unsolved(k, q_out, within_out, residual_out)
            continue
        for i in range(3):
            a_t[i] = T[k, i, 2]
            n_t[i] = T[k, i, 0]
        # Rigidity: max |R^T R - I| and the bottom row; repair by Gram-Schmidt from the approach.
        dev = max(abs(T[k, 3, 0]), abs(T[k, 3, 1]), abs(T[k, 3, 2]), abs(T[k, 3, 3] - 1.0))
        if not approach_only:
            for i in range(3):
                for j in range(i, 3):  # R^T R is symmetric
                    dot = (
                        T[k, 0, i] * T[k, 0, j] + T[k, 1, i] * T[k, 1, j] + T[k, 2, i] * T[k, 2, j]
                    )
                    dev = max(dev, abs(dot - (1.0 if i == j else 0.0)))
        else:
            dev = max(dev, abs(math.sqrt(_dot3(a_t, a_t)) - 1.0))
        deviation_out[k] = dev
        if dev > RIGIDITY_REPAIR_TOLERANCE_K:
            status_out[k] = IkStatus.NOT_RIGID
            _mark_unsolved(k, q_out, within_out, residual_out)
            continue
        _orthonormalise(a_t, n_t, o_t, approach_only)

        # Arm plane: radial unit vector towards the tool point (front branch).
        rho = math.sqrt(px * px + py * py)
        if rho > BASE_AXIS_TOLERANCE_K:
            c1, s1 = px / rho, py / rho
        else:
            # On the base axis q1 is free: face the approach if it leans, else keep the reference.
            horizontal = math.hypot(a_t[0], a_t[1])
            if horizontal > 1e-9:
                c1, s1 = a_t[0] / horizontal, a_t[1] / horizontal
            else:
                c1, s1 = math.cos(q_ref[r_k, 0]), math.sin(q_ref[r_k, 0])
        # Approach projected into the plane: a_s = (c1 s234, s1 s234, -c234).
        s234 = c1 * a_t[0] + s1 * a_t[1]
        c234 = -a_t[2]
        norm = math.sqrt(s234 * s234 + c234 * c234)
        if norm < 1e-12:  # approach normal to the arm plane: any pitch is as good
            s234, c234 = sincos(q_ref[r_k, 1] + q_ref[r_k, 2] + q_ref[r_k, 3])
        else:
            s234, c234 = s234 / norm, c234 / norm
        # Wrist centre in plane coordinates (radial r, height z).
        r_w = c1 * px + s1 * py - d5 * s234
        z_w = pz + d5 * c234
        dist = math.sqrt(r_w * r_w + z_w * z_w)
        if dist > a2 + a3:
            miss_out[k] = dist - (a2 + a3)
        elif dist < abs(a2 - a3):
            miss_out[k] = abs(a2 - a3) - dist
        if not miss_out[k] <= REACH_TOLERANCE_K:  # also catches an overflowed (inf/NaN) miss
            status_out[k] = IkStatus.OUT_OF_REACH
            _mark_unsolved(k, q_out, within_out, residual_out)
            continue
        c3 = (r_w * r_w + z_w * z_w - a2 * a2 - a3 * a3) / (2.0 * a2 * a3)
        c3 = min(1.0, max(-1.0, c3))  # elbow stretched or folded: clamp
        s3 = math.sqrt(1.0 - c3 * c3)
        q3_abs = atan2(s3, c3)
        beta = atan2(a3 * s3, a2 + a3 * c3)
        # Front-branch angles; the back branch (plane direction reversed) follows from identities
        # instead of more atan2 calls: q1 + pi, q234 -> -q234, phi -> pi - phi, q5 + pi.
        q1_front = atan2(s1, c1)
        q234_front = atan2(s234, c234)
        phi_front = atan2(z_w, r_w)
        # Roll from n: q5 = atan2(n.y4, n.x4), x4 = (c1 c234, s1 c234, s234), y4 = (s1, -c1, 0).
        n_x4 = n_t[0] * c1 * c234 + n_t[1] * s1 * c234 + n_t[2] * s234
        n_y4 = n_t[0] * s1 - n_t[1] * c1
        q5_front = q_ref[r_k, 4] if approach_only else atan2(n_y4, n_x4)
        # q3 takes the values -q3_abs and +q3_abs, q1 and q5 one value per base branch: wrap
        # each once (14 wraps a pose instead of 20).
        q3_neg, q3_neg_in = _wrap_into_limits(-q3_abs, lower[2], upper[2], limit_tol)
        q3_pos, q3_pos_in = _wrap_into_limits(q3_abs, lower[2], upper[2], limit_tol)
        for base in range(2):
            if base == 0:
                q1, q234, phi, q5, r_b = q1_front, q234_front, phi_front, q5_front, r_w
            else:
                q1 = q1_front - math.pi if q1_front > 0.0 else q1_front + math.pi
                q234 = -q234_front
                phi = math.pi - phi_front if phi_front >= 0.0 else -math.pi - phi_front
                if not approach_only:
                    q5 = q5_front - math.pi if q5_front > 0.0 else q5_front + math.pi
                r_b = -r_w
            q1_wrapped, q1_in = _wrap_into_limits(q1, lower[0], upper[0], limit_tol)
            q5_wrapped, q5_in = _wrap_into_limits(q5, lower[4], upper[4], limit_tol)
            for elbow in range(2):
                # Elbow above the shoulder-wrist line: q3 < 0 when the wrist is ahead (r_b >= 0).
                negative = (elbow == 0) == (r_b >= 0.0)
                q3 = -q3_abs if negative else q3_abs
                q2 = phi + beta if negative else phi - beta
                q4 = q234 - q2 - q3
                q2_wrapped, q2_in = _wrap_into_limits(q2, lower[1], upper[1], limit_tol)
                q4_wrapped, q4_in = _wrap_into_limits(q4, lower[3], upper[3], limit_tol)
                branch = 2 * base + elbow
                q_out[k, branch, 0] = q1_wrapped
                q_out[k, branch, 1] = q2_wrapped
                q_out[k, branch, 2] = q3_neg if negative else q3_pos
                q_out[k, branch, 3] = q4_wrapped
                q_out[k, branch, 4] = q5_wrapped
                q3_in = q3_neg_in if negative else q3_pos_in
                within_out[k, branch] = q1_in and q2_in and q3_in and q4_in and q5_in
        # Reached orientation (same for every branch, before any snapping onto a limit).
        a_s[0], a_s[1], a_s[2] = c1 * s234, s1 * s234, -c234
        if approach_only:
            dot = _dot3(a_t, a_s)
            cx = a_t[1] * a_s[2] - a_t[2] * a_s[1]
            cy = a_t[2] * a_s[0] - a_t[0] * a_s[2]
            cz = a_t[0] * a_s[1] - a_t[1] * a_s[0]
            residual_out[k] = atan2(math.sqrt(cx * cx + cy * cy + cz * cz), dot)
        else:
            h = math.sqrt(n_x4 * n_x4 + n_y4 * n_y4)
            c5, s5 = (n_x4 / h, n_y4 / h) if h > 1e-300 else (1.0, 0.0)
            x4x, x4y, x4z = c1 * c234, s1 * c234, s234
            n_s[0], n_s[1], n_s[2] = c5 * x4x + s5 * s1, c5 * x4y - s5 * c1, c5 * x4z
            o_s[0], o_s[1], o_s[2] = -s5 * x4x + c5 * s1, -s5 * x4y - c5 * c1, -s5 * x4z
            residual_out[k] = _angle_between_frames(n_t, o_t, a_t, n_s, o_s, a_s)
        status_out[k] = IkStatus.OK


# Module constants read by the kernels (numba freezes globals at compile time).
RIGIDITY_REPAIR_TOLERANCE_K = RIGIDITY_REPAIR_TOLERANCE
BASE_AXIS_TOLERANCE_K = BASE_AXIS_TOLERANCE
REACH_TOLERANCE_K = REACH_TOLERANCE
#: Translations beyond this, in [m], are out of reach before any arithmetic can overflow.
FAR_AWAY_K = 1e9

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
    if ref.shape != (5,) and ref.shape != (n, 5):
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
    ik_kernel(
        poses,
        ref,
        geometry.a2,
        geometry.a3,
        geometry.d5,
        limits.lower,
        limits.upper,
        float(limit_tolerance),
        approach_only,
        q,
        within,
        residual,
        status,
        miss,
        deviation,
    )
    for array in (q, within, residual, status, miss, deviation):
        array.setflags(write=False)
    return IkBatch(q, within, residual, status, miss, deviation)


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
def _rotation_angle(target: np.ndarray, reached: np.ndarray) -> float:
    """Angle of target^T reached for 3x3 blocks of 4x4 arrays, in [rad]."""
    return _angle_between_frames(
        target[:3, 0].copy(),
        target[:3, 1].copy(),
        target[:3, 2].copy(),
        reached[:3, 0].copy(),
        reached[:3, 1].copy(),
        reached[:3, 2].copy(),
    )


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

    ``params`` = (a2, a3, d5, limit_tol, lower (5), upper (5)); ``flags`` bit 0 = approach only,
    bit 1 = report selection rule. Writes ``rows`` (4, 8): q (5), within, position error,
    orientation error per branch; ``scalars`` (5,): residual, status, miss, deviation, selected
    (-1 when no branch qualifies). Packed so the call boxes no Python objects.
    """
    approach_only = (flags & 1) != 0
    report_rule = (flags & 2) != 0
    a2, a3, d5, limit_tol = params[0], params[1], params[2], params[3]
    q = np.empty((1, 4, 5))
    within = np.empty((1, 4), dtype=np.bool_)
    residual, status = np.empty(1), np.empty(1, dtype=np.int8)
    miss, deviation = np.empty(1), np.empty(1)
    ik_kernel(
        T.reshape(1, 4, 4),
        q_ref.reshape(1, 5),
        a2,
        a3,
        d5,
        params[4:9],
        params[9:14],
        limit_tol,
        approach_only,
        q,
        within,
        residual,
        status,
        miss,
        deviation,
    )
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
