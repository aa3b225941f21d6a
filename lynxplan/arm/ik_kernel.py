"""The analytic IK kernel of the 5-DOF arm (see :mod:`lynxplan.arm.ik`), in named steps.

Every function here is compiled with numba; the steps inline into :func:`ik_kernel`, which loops
over a batch on one core.
"""

from __future__ import annotations

import math
from enum import IntEnum
from typing import NamedTuple

import numba
import numpy as np

from lynxplan._fastmath import atan2, sincos
from lynxplan.constants import BASE_AXIS_TOLERANCE, REACH_TOLERANCE, RIGIDITY_REPAIR_TOLERANCE

TWO_PI = 2.0 * math.pi
#: IEEE-safe fast-math flags: fused multiply-add and division by reciprocal (rounding differs
#: by an ulp; no assumptions about NaN, infinity or signed zeros, which the kernels rely on).
_FAST = {"contract", "arcp"}


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _dot3(u: np.ndarray, v: np.ndarray) -> float:
    """Dot product of two 3-vectors (numba's ``@`` calls BLAS: slow for 3 elements)."""
    return float(u[0] * v[0] + u[1] * v[1] + u[2] * v[2])


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


class IkParams(NamedTuple):
    """Arm and limit constants of :func:`ik_kernel` (one structured parameter)."""

    a2: float
    """Upper-arm length, in [m]."""
    a3: float
    """Forearm length, in [m]."""
    d5: float
    """Wrist-to-tool distance, in [m]."""
    lower: np.ndarray
    """Lower joint limits, shape (5,), in [rad]."""
    upper: np.ndarray
    """Upper joint limits, shape (5,), in [rad]."""
    limit_tol: float
    """Angles this far outside a limit are snapped onto it, in [rad]."""
    approach_only: bool
    """Only the approach axis (rotation column 2) is a target; q5 comes from the reference."""


class IkOutputs(NamedTuple):
    """The arrays :func:`ik_kernel` writes, N poses (fields as in :class:`IkBatch`)."""

    q: np.ndarray
    """(N, 4, 5) float."""
    within: np.ndarray
    """(N, 4) bool."""
    residual: np.ndarray
    """(N,) float."""
    status: np.ndarray
    """(N,) int8."""
    miss: np.ndarray
    """(N,) float."""
    deviation: np.ndarray
    """(N,) float."""


# Module constants read by the kernels (numba freezes globals at compile time).
RIGIDITY_REPAIR_TOLERANCE_K = RIGIDITY_REPAIR_TOLERANCE
BASE_AXIS_TOLERANCE_K = BASE_AXIS_TOLERANCE
REACH_TOLERANCE_K = REACH_TOLERANCE
#: Translations beyond this, in [m], are out of reach before any arithmetic can overflow.
FAR_AWAY_K = 1e9


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
def _mark_unsolved(k: int, status: int, out: IkOutputs) -> None:
    """Status of pose k, NaN angles and residual, no branch within limits (loops: no views)."""
    out.status[k] = status
    out.residual[k] = np.nan
    for b in range(4):
        out.within[k, b] = False
        for j in range(5):
            out.q[k, b, j] = np.nan


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def wrap_into_limits(x: float, lo: float, hi: float, tol: float) -> tuple[float, bool]:
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


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _is_finite(T: np.ndarray, k: int) -> bool:
    """Step 1a: whether pose k has no NaN or infinity."""
    finite = True
    for i in range(4):
        for j in range(4):
            if not math.isfinite(T[k, i, j]):
                finite = False
    return finite


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _rigidity_deviation(T: np.ndarray, k: int, approach_only: bool) -> float:
    """Step 1b: ``max |R^T R - I|`` and the bottom row's deviation of pose k (only the approach
    axis's norm when ``approach_only``); up to the repair tolerance, Gram-Schmidt repairs it."""
    dev = max(abs(T[k, 3, 0]), abs(T[k, 3, 1]), abs(T[k, 3, 2]), abs(T[k, 3, 3] - 1.0))
    if approach_only:
        norm2 = T[k, 0, 2] * T[k, 0, 2] + T[k, 1, 2] * T[k, 1, 2] + T[k, 2, 2] * T[k, 2, 2]
        return float(max(dev, abs(math.sqrt(norm2) - 1.0)))
    for i in range(3):
        for j in range(i, 3):  # R^T R is symmetric
            dot = T[k, 0, i] * T[k, 0, j] + T[k, 1, i] * T[k, 1, j] + T[k, 2, i] * T[k, 2, j]
            dev = max(dev, abs(dot - (1.0 if i == j else 0.0)))
    return float(dev)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _arm_plane(
    px: float, py: float, approach: tuple[float, float, float], q1_ref: float, pitch_ref: float
) -> tuple[float, float, float, float]:
    """Step 2: the arm plane's radial unit vector ``(c1, s1)`` towards the tool point (front
    branch) and the ``approach`` axis projected into it, ``(s234, c234)``; ``q1_ref`` and
    ``pitch_ref`` (q2 + q3 + q4) in [rad] decide where the pose leaves them free. Scalars only:
    array arguments would cost reference counting in the per-pose loop."""
    ax, ay, az = approach
    rho = math.sqrt(px * px + py * py)
    if rho > BASE_AXIS_TOLERANCE_K:
        c1, s1 = px / rho, py / rho
    else:
        # On the base axis q1 is free: face the approach if it leans, else keep the reference.
        horizontal = math.hypot(ax, ay)
        if horizontal > 1e-9:
            c1, s1 = ax / horizontal, ay / horizontal
        else:
            c1, s1 = math.cos(q1_ref), math.sin(q1_ref)
    # Approach projected into the plane: a_s = (c1 s234, s1 s234, -c234).
    s234 = c1 * ax + s1 * ay
    c234 = -az
    norm = math.sqrt(s234 * s234 + c234 * c234)
    if norm < 1e-12:  # approach normal to the arm plane: any pitch is as good
        s234, c234 = sincos(pitch_ref)
    else:
        s234, c234 = s234 / norm, c234 / norm
    return c1, s1, s234, c234


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _reach_miss(r_w: float, z_w: float, a2: float, a3: float) -> float:
    """Step 3: how far the wrist centre (plane coordinates) lies outside the annulus, in [m]."""
    dist = math.sqrt(r_w * r_w + z_w * z_w)
    if dist > a2 + a3:
        return dist - (a2 + a3)
    if dist < abs(a2 - a3):
        return abs(a2 - a3) - dist
    return 0.0


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _write_branches(
    k: int,
    front: tuple[float, float, float, float, float],
    elbow_angles: tuple[float, float],
    params: IkParams,
    q_out: np.ndarray,
    within_out: np.ndarray,
) -> None:
    """Step 4: the four branches of pose k from the front branch's ``(q1, q234, phi, q5, r_w)``
    and the elbow's ``(|q3|, beta)``, wrapped into the limits with their within-limit flags."""
    q1_front, q234_front, phi_front, q5_front, r_w = front
    q3_abs, beta = elbow_angles
    lower, upper, tol = params.lower, params.upper, params.limit_tol
    # q3 takes the values -q3_abs and +q3_abs, q1 and q5 one value per base branch: wrap
    # each once (14 wraps a pose instead of 20).
    q3_neg, q3_neg_in = wrap_into_limits(-q3_abs, lower[2], upper[2], tol)
    q3_pos, q3_pos_in = wrap_into_limits(q3_abs, lower[2], upper[2], tol)
    for base in range(2):
        # The back branch (plane direction reversed) follows from identities instead of more
        # atan2 calls: q1 + pi, q234 -> -q234, phi -> pi - phi, q5 + pi.
        if base == 0:
            q1, q234, phi, q5, r_b = q1_front, q234_front, phi_front, q5_front, r_w
        else:
            q1 = q1_front - math.pi if q1_front > 0.0 else q1_front + math.pi
            q234 = -q234_front
            phi = math.pi - phi_front if phi_front >= 0.0 else -math.pi - phi_front
            if not params.approach_only:
                q5 = q5_front - math.pi if q5_front > 0.0 else q5_front + math.pi
            r_b = -r_w
        q1_wrapped, q1_in = wrap_into_limits(q1, lower[0], upper[0], tol)
        q5_wrapped, q5_in = wrap_into_limits(q5, lower[4], upper[4], tol)
        for elbow in range(2):
            # Elbow above the shoulder-wrist line: q3 < 0 when the wrist is ahead (r_b >= 0).
            negative = (elbow == 0) == (r_b >= 0.0)
            q2 = phi + beta if negative else phi - beta
            q4 = q234 - q2 - (-q3_abs if negative else q3_abs)
            q2_wrapped, q2_in = wrap_into_limits(q2, lower[1], upper[1], tol)
            q4_wrapped, q4_in = wrap_into_limits(q4, lower[3], upper[3], tol)
            branch = 2 * base + elbow
            q_out[k, branch, 0] = q1_wrapped
            q_out[k, branch, 1] = q2_wrapped
            q_out[k, branch, 2] = q3_neg if negative else q3_pos
            q_out[k, branch, 3] = q4_wrapped
            q_out[k, branch, 4] = q5_wrapped
            q3_in = q3_neg_in if negative else q3_pos_in
            within_out[k, branch] = q1_in and q2_in and q3_in and q4_in and q5_in


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _approach_residual(a_t: np.ndarray, a_s: np.ndarray) -> float:
    """Step 5 (approach only): angle between the target and reached approach axes, in [rad]."""
    dot = _dot3(a_t, a_s)
    cx = a_t[1] * a_s[2] - a_t[2] * a_s[1]
    cy = a_t[2] * a_s[0] - a_t[0] * a_s[2]
    cz = a_t[0] * a_s[1] - a_t[1] * a_s[0]
    return atan2(math.sqrt(cx * cx + cy * cy + cz * cz), dot)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _reached_frame(
    c1: float,
    s1: float,
    c234: float,
    s234: float,
    n_x4: float,
    n_y4: float,
    n_s: np.ndarray,
    o_s: np.ndarray,
) -> None:
    """Step 5 (full pose): the reached ``n`` and ``o`` axes (same for every branch, before any
    snapping onto a limit) from the arm plane and the roll components ``(n.x4, n.y4)``."""
    h = math.sqrt(n_x4 * n_x4 + n_y4 * n_y4)
    c5, s5 = (n_x4 / h, n_y4 / h) if h > 1e-300 else (1.0, 0.0)
    x4x, x4y, x4z = c1 * c234, s1 * c234, s234
    n_s[0], n_s[1], n_s[2] = c5 * x4x + s5 * s1, c5 * x4y - s5 * c1, c5 * x4z
    o_s[0], o_s[1], o_s[2] = -s5 * x4x + c5 * s1, -s5 * x4y - c5 * c1, -s5 * x4z


@numba.njit(cache=True, nogil=True, fastmath=_FAST)
def ik_kernel(T: np.ndarray, q_ref: np.ndarray, params: IkParams, out: IkOutputs) -> None:
    """IK of poses T (N, 4, 4) into ``out`` (see :class:`IkBatch`): admit the pose, find the arm
    plane, check the reach, write the four branches, measure the orientation residual.

    q_ref (M, 5) with M = 1 or N gives q1 on the base axis and q5 when the roll is free.
    """
    a2, a3, d5 = params.a2, params.a3, params.d5
    n_t, o_t, a_t = np.empty(3), np.empty(3), np.empty(3)
    n_s, o_s, a_s = np.empty(3), np.empty(3), np.empty(3)  # scratch of the residual
    for k in range(T.shape[0]):
        # Plain indices, no per-pose views: a view costs reference-count updates in numba.
        r_k = k if q_ref.shape[0] > 1 else 0
        out.miss[k] = 0.0
        out.deviation[k] = 0.0
        if not _is_finite(T, k):
            _mark_unsolved(k, IkStatus.NON_FINITE, out)
            continue
        px, py, pz = T[k, 0, 3], T[k, 1, 3], T[k, 2, 3]
        far = max(abs(px), abs(py), abs(pz))
        if far > FAR_AWAY_K:  # keeps squares below overflow
            out.miss[k] = far - (a2 + a3 + d5)
            _mark_unsolved(k, IkStatus.OUT_OF_REACH, out)
            continue
        out.deviation[k] = _rigidity_deviation(T, k, params.approach_only)
        if out.deviation[k] > RIGIDITY_REPAIR_TOLERANCE_K:
            _mark_unsolved(k, IkStatus.NOT_RIGID, out)
            continue
        for i in range(3):
            a_t[i] = T[k, i, 2]
            n_t[i] = T[k, i, 0]
        _orthonormalise(a_t, n_t, o_t, params.approach_only)
        pitch_ref = q_ref[r_k, 1] + q_ref[r_k, 2] + q_ref[r_k, 3]
        approach = (a_t[0], a_t[1], a_t[2])
        c1, s1, s234, c234 = _arm_plane(px, py, approach, q_ref[r_k, 0], pitch_ref)
        # Wrist centre in plane coordinates (radial r, height z).
        r_w = c1 * px + s1 * py - d5 * s234
        z_w = pz + d5 * c234
        out.miss[k] = _reach_miss(r_w, z_w, a2, a3)
        if not out.miss[k] <= REACH_TOLERANCE_K:  # also catches an overflowed (inf/NaN) miss
            _mark_unsolved(k, IkStatus.OUT_OF_REACH, out)
            continue
        c3 = (r_w * r_w + z_w * z_w - a2 * a2 - a3 * a3) / (2.0 * a2 * a3)
        c3 = min(1.0, max(-1.0, c3))  # elbow stretched or folded: clamp
        s3 = math.sqrt(1.0 - c3 * c3)
        elbow_angles = (atan2(s3, c3), atan2(a3 * s3, a2 + a3 * c3))
        # Roll from n: q5 = atan2(n.y4, n.x4), x4 = (c1 c234, s1 c234, s234), y4 = (s1, -c1, 0).
        n_x4 = n_t[0] * c1 * c234 + n_t[1] * s1 * c234 + n_t[2] * s234
        n_y4 = n_t[0] * s1 - n_t[1] * c1
        q5_front = q_ref[r_k, 4] if params.approach_only else atan2(n_y4, n_x4)
        front = (atan2(s1, c1), atan2(s234, c234), atan2(z_w, r_w), q5_front, r_w)
        _write_branches(k, front, elbow_angles, params, out.q, out.within)
        a_s[0], a_s[1], a_s[2] = c1 * s234, s1 * s234, -c234
        if params.approach_only:
            out.residual[k] = _approach_residual(a_t, a_s)
        else:
            _reached_frame(c1, s1, c234, s234, n_x4, n_y4, n_s, o_s)
            out.residual[k] = _angle_between_frames(n_t, o_t, a_t, n_s, o_s, a_s)
        out.status[k] = IkStatus.OK
