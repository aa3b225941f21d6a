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
def _angle_of_matrix(
    m00: float,
    m01: float,
    m02: float,
    m10: float,
    m11: float,
    m12: float,
    m20: float,
    m21: float,
    m22: float,
) -> float:
    """Rotation angle of the rotation matrix M, in [rad], accurate near 0 (atan2 of sine and
    cosine; the small-angle series by a select, so array loops over it vectorise)."""
    sx, sy, sz = 0.5 * (m21 - m12), 0.5 * (m02 - m20), 0.5 * (m10 - m01)
    sine = math.sqrt(sx * sx + sy * sy + sz * sz)
    cosine = 0.5 * (m00 + m11 + m22 - 1.0)
    # Reachable targets are small angles: asin(x) = x + x^3/6 + O(x^5), exact to ~1e-21 rad.
    small = (sine < 1e-4) & (cosine > 0.0)
    return sine + sine * sine * sine / 6.0 if small else atan2(sine, cosine)


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
    return _angle_of_matrix(
        _dot3(n_t, n_s),
        _dot3(n_t, o_s),
        _dot3(n_t, a_s),
        _dot3(o_t, n_s),
        _dot3(o_t, o_s),
        _dot3(o_t, a_s),
        _dot3(a_t, n_s),
        _dot3(a_t, o_s),
        _dot3(a_t, a_s),
    )


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


#: Poses per block: the kernel makes three passes over a block (admit the poses, the closed
#: form, write the branches), its per-pose scalars staying in L1 between them.
BLOCK = 256
# Rows of the block's scratch: inputs of the closed form (admit), then its outputs.
_PX, _PY, _PZ, _AX, _AY, _AZ, _NX, _NY, _NZ, _Q1_REF, _PITCH_REF, _Q5_REF = range(12)
_Q1, _Q234, _PHI, _Q5, _RW, _Q3_ABS, _BETA, _MISS, _RESIDUAL = range(12, 21)
_ROWS = 21


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _admit(
    T: np.ndarray,
    q_ref: np.ndarray,
    start: int,
    m: int,
    approach_only: bool,
    out: IkOutputs,
    s: np.ndarray,
    admitted: np.ndarray,
) -> None:
    """Pass 1 over poses start .. start + m: step 1, admit the pose (finite, not far away,
    rigid to the repair tolerance; else its status now), its position, Gram-Schmidt axes
    and references into the scratch columns."""
    a_t, n_t, o_t = np.empty(3), np.empty(3), np.empty(3)
    for i in range(m):
        # Plain indices, no per-pose views: a view costs reference-count updates in numba.
        k = start + i
        r_k = k if q_ref.shape[0] > 1 else 0
        admitted[i] = False
        for row in range(_ROWS):
            s[row, i] = 0.0
        out.miss[k] = 0.0
        out.deviation[k] = 0.0
        if not _is_finite(T, k):
            _mark_unsolved(k, IkStatus.NON_FINITE, out)
            continue
        px, py, pz = T[k, 0, 3], T[k, 1, 3], T[k, 2, 3]
        far = max(abs(px), abs(py), abs(pz))
        if far > FAR_AWAY_K:  # keeps squares below overflow
            out.miss[k] = far  # the kernel subtracts the reach
            _mark_unsolved(k, IkStatus.OUT_OF_REACH, out)
            continue
        out.deviation[k] = _rigidity_deviation(T, k, approach_only)
        if out.deviation[k] > RIGIDITY_REPAIR_TOLERANCE_K:
            _mark_unsolved(k, IkStatus.NOT_RIGID, out)
            continue
        for j in range(3):
            a_t[j] = T[k, j, 2]
            n_t[j] = T[k, j, 0]
        _orthonormalise(a_t, n_t, o_t, approach_only)
        admitted[i] = True
        s[_PX, i], s[_PY, i], s[_PZ, i] = px, py, pz
        s[_AX, i], s[_AY, i], s[_AZ, i] = a_t[0], a_t[1], a_t[2]
        s[_NX, i], s[_NY, i], s[_NZ, i] = n_t[0], n_t[1], n_t[2]
        s[_Q1_REF, i] = q_ref[r_k, 0]
        s[_PITCH_REF, i] = q_ref[r_k, 1] + q_ref[r_k, 2] + q_ref[r_k, 3]
        s[_Q5_REF, i] = q_ref[r_k, 4]


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _closed_form(  # noqa: PLR0915 (one vectorised pass: every step is a select)
    m: int, a2: float, a3: float, d5: float, approach_only: bool, s: np.ndarray
) -> None:
    """Pass 2, steps 2-3 and 5 over the block's columns: the arm plane, the reach, the angles of
    the front branch, the orientation residual. No branch and no call: the loop vectorises
    (the columns of poses not admitted compute values nobody reads)."""
    for i in range(m):
        px, py, pz = s[_PX, i], s[_PY, i], s[_PZ, i]
        ax, ay, az = s[_AX, i], s[_AY, i], s[_AZ, i]
        nx, ny, nz = s[_NX, i], s[_NY, i], s[_NZ, i]
        # Step 2: the arm plane's radial unit vector (c1, s1) towards the tool point (front
        # branch); on the base axis q1 is free: face the approach if it leans, else keep the
        # reference. Then the approach projected into it, a_s = (c1 s234, s1 s234, -c234).
        rho = math.sqrt(px * px + py * py)
        horizontal = math.sqrt(ax * ax + ay * ay)
        s_ref, c_ref = sincos(s[_Q1_REF, i])
        leans = horizontal > 1e-9
        c1 = ax / horizontal if leans else c_ref
        s1 = ay / horizontal if leans else s_ref
        off_axis = rho > BASE_AXIS_TOLERANCE_K
        c1 = px / rho if off_axis else c1
        s1 = py / rho if off_axis else s1
        s234 = c1 * ax + s1 * ay
        c234 = -az
        norm = math.sqrt(s234 * s234 + c234 * c234)
        s_pitch, c_pitch = sincos(s[_PITCH_REF, i])
        normal = norm < 1e-12  # approach normal to the arm plane: any pitch is as good
        s234 = s_pitch if normal else s234 / norm
        c234 = c_pitch if normal else c234 / norm
        # Step 3: the wrist centre in plane coordinates (radial r, height z), the reach miss.
        r_w = c1 * px + s1 * py - d5 * s234
        z_w = pz + d5 * c234
        dist = math.sqrt(r_w * r_w + z_w * z_w)
        miss = dist - (a2 + a3) if dist > a2 + a3 else 0.0
        miss = abs(a2 - a3) - dist if dist < abs(a2 - a3) else miss
        c3 = (r_w * r_w + z_w * z_w - a2 * a2 - a3 * a3) / (2.0 * a2 * a3)
        c3 = min(1.0, max(-1.0, c3))  # elbow stretched or folded: clamp
        s3 = math.sqrt(1.0 - c3 * c3)
        # Roll from n: q5 = atan2(n.y4, n.x4), x4 = (c1 c234, s1 c234, s234), y4 = (s1, -c1, 0).
        n_x4 = nx * c1 * c234 + ny * s1 * c234 + nz * s234
        n_y4 = nx * s1 - ny * c1
        s[_Q3_ABS, i] = atan2(s3, c3)
        s[_BETA, i] = atan2(a3 * s3, a2 + a3 * c3)
        s[_Q1, i] = atan2(s1, c1)
        s[_Q234, i] = atan2(s234, c234)
        s[_PHI, i] = atan2(z_w, r_w)
        s[_Q5, i] = s[_Q5_REF, i] if approach_only else atan2(n_y4, n_x4)
        s[_RW, i] = r_w
        s[_MISS, i] = miss
        # Step 5: the residual. The reached approach a_s; approach targets: its angle to the
        # target's; full poses: the reached n and o axes (the same for every branch, before any
        # snapping onto a limit) and the angle of R_t^T R_s.
        as0, as1, as2 = c1 * s234, s1 * s234, -c234
        cx, cy, cz = ay * as2 - az * as1, az * as0 - ax * as2, ax * as1 - ay * as0
        dot = ax * as0 + ay * as1 + az * as2
        approach_residual = atan2(math.sqrt(cx * cx + cy * cy + cz * cz), dot)
        h = math.sqrt(n_x4 * n_x4 + n_y4 * n_y4)
        c5 = n_x4 / h if h > 1e-300 else 1.0
        s5 = n_y4 / h if h > 1e-300 else 0.0
        x4x, x4y, x4z = c1 * c234, s1 * c234, s234
        ns0, ns1, ns2 = c5 * x4x + s5 * s1, c5 * x4y - s5 * c1, c5 * x4z
        os0, os1, os2 = -s5 * x4x + c5 * s1, -s5 * x4y - c5 * c1, -s5 * x4z
        ox, oy, oz = ay * nz - az * ny, az * nx - ax * nz, ax * ny - ay * nx  # o_t = a_t x n_t
        frame_residual = _angle_of_matrix(
            nx * ns0 + ny * ns1 + nz * ns2,
            nx * os0 + ny * os1 + nz * os2,
            nx * as0 + ny * as1 + nz * as2,
            ox * ns0 + oy * ns1 + oz * ns2,
            ox * os0 + oy * os1 + oz * os2,
            ox * as0 + oy * as1 + oz * as2,
            ax * ns0 + ay * ns1 + az * ns2,
            ax * os0 + ay * os1 + az * os2,
            dot,
        )
        s[_RESIDUAL, i] = approach_residual if approach_only else frame_residual


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=_FAST)
def ik_kernel(T: np.ndarray, q_ref: np.ndarray, params: IkParams, out: IkOutputs) -> None:
    """IK of poses T (N, 4, 4) into ``out`` (see :class:`IkBatch`): admit the pose, find the arm
    plane, check the reach, write the four branches, measure the orientation residual.

    q_ref (M, 5) with M = 1 or N gives q1 on the base axis and q5 when the roll is free.
    Blocks of BLOCK poses, three passes each: admit (scalar), the closed form (one
    vectorised loop), the branches (scalar: the limits); compiled with numpy's error model
    (a division by zero gives inf or NaN instead of a test per division).
    """
    a2, a3, d5 = params.a2, params.a3, params.d5
    n = T.shape[0]
    # a constant width: the rows' distance is known at compile time, so the closed form's
    # loop needs no run-time aliasing checks between them (and vectorises)
    s = np.empty((_ROWS, BLOCK))
    admitted = np.empty(BLOCK, dtype=np.bool_)
    for start in range(0, n, BLOCK):
        m = min(BLOCK, n - start)
        _admit(T, q_ref, start, m, params.approach_only, out, s, admitted)
        _closed_form(m, a2, a3, d5, params.approach_only, s)
        for i in range(m):
            k = start + i
            if not admitted[i]:
                if out.status[k] == IkStatus.OUT_OF_REACH:
                    out.miss[k] -= a2 + a3 + d5
                continue
            out.miss[k] = s[_MISS, i]
            if not out.miss[k] <= REACH_TOLERANCE_K:  # also catches an overflowed miss
                _mark_unsolved(k, IkStatus.OUT_OF_REACH, out)
                continue
            front = (s[_Q1, i], s[_Q234, i], s[_PHI, i], s[_Q5, i], s[_RW, i])
            _write_branches(k, front, (s[_Q3_ABS, i], s[_BETA, i]), params, out.q, out.within)
            out.residual[k] = s[_RESIDUAL, i]
            out.status[k] = IkStatus.OK
