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
from lynxplan.constants import (
    APPROACH_LEANS,
    BASE_AXIS_TOLERANCE,
    FAR_AWAY,
    FOLD_SNAP_TOLERANCE,
    RIGIDITY_REPAIR_TOLERANCE,
    ROLL_DEGENERATE,
    SMALL_ROTATION_SERIES,
    WRIST_SNAP_TOLERANCE,
)
from lynxplan.robots.ik.family_geometry import wrap_into_limits

TWO_PI = 2.0 * math.pi
# No fast-math flags: the kernels give the same bits compiled and interpreted (numba's
# NUMBA_DISABLE_JIT, the command line's single-target ik; tests/test_jit.py).


@numba.njit(cache=True, nogil=True, inline="always")
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
WRIST_SNAP_TOLERANCE_K = WRIST_SNAP_TOLERANCE
FOLD_SNAP_K = FOLD_SNAP_TOLERANCE  # elbow cosines this close to +-1 are +-1
FAR_AWAY_K = FAR_AWAY  # [m]: out of reach before any arithmetic can overflow


@numba.njit(cache=True, nogil=True, inline="always")
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


@numba.njit(cache=True, nogil=True, inline="always")
def _angle_of_matrix(m: tuple[float, ...]) -> float:
    """Rotation angle of the rotation matrix M (its 9 entries, row-major), in [rad], accurate
    near 0 (atan2 of sine and cosine; the small-angle series by a select, so array loops over
    it vectorise)."""
    m00, m01, m02, m10, m11, m12, m20, m21, m22 = m
    sx, sy, sz = 0.5 * (m21 - m12), 0.5 * (m02 - m20), 0.5 * (m10 - m01)
    sine = math.sqrt(sx * sx + sy * sy + sz * sz)
    cosine = 0.5 * (m00 + m11 + m22 - 1.0)
    # Reachable targets are small angles: asin(x) = x + x^3/6 + O(x^5), exact to ~1e-21 rad.
    small = (sine < SMALL_ROTATION_SERIES) & (cosine > 0.0)
    return sine + sine * sine * sine / 6.0 if small else atan2(sine, cosine)


@numba.njit(cache=True, nogil=True, inline="always")
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
        (
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
    )


#: Poses per block: the kernel transposes a block into scratch rows (one row a quantity),
#: solves it in one vectorised loop and transposes the results back; the rows stay in L1.
BLOCK = 128
# Rows of the block's scratch: the pose (row 4 i + j: T[i, j]), the references, then the results
# (q of branch b, joint j: row _Q + 5 b + j; the within-limit flags of branch b: _WITHIN + b).
_Q1_REF, _PITCH_REF, _Q5_REF = 16, 17, 18
_STATUS, _MISS, _DEVIATION, _RESIDUAL = 19, 20, 21, 22
_Q = 23
_WITHIN = _Q + 20
_ROWS = _WITHIN + 4


@numba.njit(cache=True, nogil=True, inline="always")
def _max(x: float, y: float) -> float:
    """The larger of x and y, NaN when either is NaN (a select: vectorises)."""
    return x if (x >= y) | math.isnan(x) else y


@numba.njit(cache=True, nogil=True, inline="always")
def _admit(s: np.ndarray, i: int, approach_only: bool) -> tuple[float, ...]:
    """Step 1 for column i: (finite, far, deviation, a (3), n (3)): finite is 0 for a finite
    pose (x * 0 is NaN for NaN and infinity), far its largest coordinate [m] (squares overflow
    beyond FAR_AWAY_K), deviation max |R^T R - I| and the bottom row's (only the approach axis's
    norm when approach_only); a and n by Gram-Schmidt from the approach axis."""
    finite = (s[0, i] + s[1, i] + s[2, i] + s[3, i] + s[4, i] + s[5, i] + s[6, i] + s[7, i]) * 0.0
    finite += (s[8, i] + s[9, i] + s[10, i] + s[11, i]) * 0.0
    finite += (s[12, i] + s[13, i] + s[14, i] + s[15, i]) * 0.0
    r00, r01, r02, px = s[0, i], s[1, i], s[2, i], s[3, i]
    r10, r11, r12, py = s[4, i], s[5, i], s[6, i], s[7, i]
    r20, r21, r22, pz = s[8, i], s[9, i], s[10, i], s[11, i]
    far = _max(_max(abs(px), abs(py)), abs(pz))
    bottom = _max(_max(abs(s[12, i]), abs(s[13, i])), _max(abs(s[14, i]), abs(s[15, i] - 1.0)))
    a_norm = math.sqrt(r02 * r02 + r12 * r12 + r22 * r22)
    d00 = r00 * r00 + r10 * r10 + r20 * r20 - 1.0
    d11 = r01 * r01 + r11 * r11 + r21 * r21 - 1.0
    d22 = r02 * r02 + r12 * r12 + r22 * r22 - 1.0
    d01 = r00 * r01 + r10 * r11 + r20 * r21
    d02 = r00 * r02 + r10 * r12 + r20 * r22
    d12 = r01 * r02 + r11 * r12 + r21 * r22
    full = _max(_max(_max(abs(d00), abs(d11)), _max(abs(d22), abs(d01))), _max(abs(d02), abs(d12)))
    deviation = _max(bottom, abs(a_norm - 1.0) if approach_only else full)
    scale = 1.0 / a_norm
    ax, ay, az = r02 * scale, r12 * scale, r22 * scale
    along = r00 * ax + r10 * ay + r20 * az
    nx, ny, nz = r00 - along * ax, r10 - along * ay, r20 - along * az
    scale = 1.0 / math.sqrt(nx * nx + ny * ny + nz * nz)
    return finite, far, deviation, ax, ay, az, nx * scale, ny * scale, nz * scale


@numba.njit(cache=True, nogil=True, inline="always")
def _branch(
    s: np.ndarray,
    i: int,
    b: int,
    base: tuple[float, bool, float, bool, float, float],
    negative: bool,
    common: tuple[float, float, float, bool, float, bool, float, float, float, float, float],
    solved: bool,
) -> None:
    """Step 4 for branch b of column i: base = (q1, q1 within, q5, q5 within, phi, q234) of its
    side (front or back, q1 and q5 wrapped), ``negative``: q3 < 0 (the elbow above the
    shoulder-wrist line when the wrist is ahead); q2 and q4 follow and are wrapped; NaN and
    not within when the pose is not solved."""
    q1, q1_in, q5, q5_in, phi, q234 = base
    beta, q3_abs, q3_neg, q3_neg_in, q3_pos, q3_pos_in, lo2, hi2, lo4, hi4, tol = common
    q2 = phi + beta if negative else phi - beta
    q4 = q234 - q2 - (-q3_abs if negative else q3_abs)
    q2w, q2_in = wrap_into_limits(q2, lo2, hi2, tol)
    q4w, q4_in = wrap_into_limits(q4, lo4, hi4, tol)
    row = _Q + 5 * b
    s[row, i] = q1 if solved else np.nan
    s[row + 1, i] = q2w if solved else np.nan
    s[row + 2, i] = (q3_neg if negative else q3_pos) if solved else np.nan
    s[row + 3, i] = q4w if solved else np.nan
    s[row + 4, i] = q5 if solved else np.nan
    q3_in = q3_neg_in if negative else q3_pos_in
    within = q1_in & q2_in & q3_in & q4_in & q5_in & solved
    s[_WITHIN + b, i] = 1.0 if within else 0.0


@numba.njit(cache=True, nogil=True, inline="always")
def _solve_block(  # noqa: PLR0915 (one vectorised pass: every step is a select)
    m: int, params: IkParams, s: np.ndarray
) -> None:
    """IK of the block's m columns (see :func:`ik_kernel`): no branch and no call, so the loop
    vectorises (a pose that is not admitted computes values that are then replaced)."""
    a2, a3, d5, tol = params.a2, params.a3, params.d5, params.limit_tol
    lower, upper, approach_only = params.lower, params.upper, params.approach_only
    lo1, lo2, lo3, lo4, lo5 = lower[0], lower[1], lower[2], lower[3], lower[4]
    hi1, hi2, hi3, hi4, hi5 = upper[0], upper[1], upper[2], upper[3], upper[4]
    for i in range(m):
        finite, far, deviation, ax, ay, az, nx, ny, nz = _admit(s, i, approach_only)
        px, py, pz = s[3, i], s[7, i], s[11, i]
        # Step 2: the arm plane's radial unit vector (c1, s1) towards the tool point (front
        # branch); on the base axis q1 is free: face the approach if it leans, else keep the
        # reference. Then the approach projected into it, a_s = (c1 s234, s1 s234, -c234).
        rho = math.sqrt(px * px + py * py)
        horizontal = math.sqrt(ax * ax + ay * ay)
        s_ref, c_ref = sincos(s[_Q1_REF, i])
        leans = horizontal > APPROACH_LEANS
        c1 = ax / horizontal if leans else c_ref
        s1 = ay / horizontal if leans else s_ref
        off_axis = rho > BASE_AXIS_TOLERANCE_K
        c1 = px / rho if off_axis else c1
        s1 = py / rho if off_axis else s1
        s234 = c1 * ax + s1 * ay
        c234 = -az
        norm = math.sqrt(s234 * s234 + c234 * c234)
        s_pitch, c_pitch = sincos(s[_PITCH_REF, i])
        normal = norm < ROLL_DEGENERATE  # approach normal to the arm plane: any pitch is as good
        s234 = s_pitch if normal else s234 / norm
        c234 = c_pitch if normal else c234 / norm
        # Step 3: the wrist centre in plane coordinates (radial r, height z), the reach miss.
        r_w = c1 * px + s1 * py - d5 * s234
        z_w = pz + d5 * c234
        dist = math.sqrt(r_w * r_w + z_w * z_w)
        miss = dist - (a2 + a3) if dist > a2 + a3 else 0.0
        miss = abs(a2 - a3) - dist if dist < abs(a2 - a3) else miss
        c3 = (r_w * r_w + z_w * z_w - a2 * a2 - a3 * a3) / (2.0 * a2 * a3)
        # Elbow stretched or folded: clamp, and snap within FOLD_SNAP (the last digits of c3
        # decide an elbow angle of up to 1.4e-7 rad there, which moves the tool < 1e-15 m)
        c3 = 1.0 if c3 > 1.0 - FOLD_SNAP_K else c3
        c3 = -1.0 if c3 < FOLD_SNAP_K - 1.0 else c3
        s3 = math.sqrt(1.0 - c3 * c3)
        q3_abs = atan2(s3, c3)
        beta = atan2(a3 * s3, a2 + a3 * c3)
        # Roll from n: q5 = atan2(n.y4, n.x4), x4 = (c1 c234, s1 c234, s234), y4 = (s1, -c1, 0).
        n_x4 = nx * c1 * c234 + ny * s1 * c234 + nz * s234
        n_y4 = nx * s1 - ny * c1
        q1_front = atan2(s1, c1)
        q234_front = atan2(s234, c234)
        phi_front = atan2(z_w, r_w)
        q5_front = s[_Q5_REF, i] if approach_only else atan2(n_y4, n_x4)
        # The status: 3 not finite, 1 out of reach (far away, or the wrist outside the
        # annulus), 2 not rigid, 0 solved (IkStatus), in this order of precedence.
        status = 0.0 if finite == 0.0 else 3.0
        status = 1.0 if (status == 0.0) & (far > FAR_AWAY_K) else status
        rigid = deviation <= RIGIDITY_REPAIR_TOLERANCE_K
        status = 2.0 if (status == 0.0) & (not rigid) else status
        admitted = status == 0.0
        status = 1.0 if admitted & (not miss <= WRIST_SNAP_TOLERANCE_K) else status
        solved = status == 0.0
        # Step 4: the four branches, wrapped into the limits, with their within-limit flags.
        # The back branch (plane direction reversed) follows from identities: q1 + pi,
        # q234 -> -q234, phi -> pi - phi, q5 + pi. q3 is -q3_abs or +q3_abs: two wraps.
        q3_neg, q3_neg_in = wrap_into_limits(-q3_abs, lo3, hi3, tol)
        q3_pos, q3_pos_in = wrap_into_limits(q3_abs, lo3, hi3, tol)
        q1_back = q1_front - math.pi if q1_front > 0.0 else q1_front + math.pi
        phi_back = math.pi - phi_front if phi_front >= 0.0 else -math.pi - phi_front
        q5_back = q5_front - math.pi if q5_front > 0.0 else q5_front + math.pi
        q1_b, q1_b_in = wrap_into_limits(q1_back, lo1, hi1, tol)
        q1_f, q1_f_in = wrap_into_limits(q1_front, lo1, hi1, tol)
        q5_b, q5_b_in = wrap_into_limits(q5_front if approach_only else q5_back, lo5, hi5, tol)
        q5_f, q5_f_in = wrap_into_limits(q5_front, lo5, hi5, tol)
        common = (beta, q3_abs, q3_neg, q3_neg_in, q3_pos, q3_pos_in, lo2, hi2, lo4, hi4, tol)
        front = (q1_f, q1_f_in, q5_f, q5_f_in, phi_front, q234_front)
        back = (q1_b, q1_b_in, q5_b, q5_b_in, phi_back, -q234_front)
        # branches 0, 1 ahead, 2, 3 behind; even: elbow up (q3 < 0 ahead). A loop, not four
        # calls: numba inlines _branch once (a quarter of its compile); LLVM unrolls it.
        for b in range(4):
            w = r_w if b < 2 else -r_w
            _branch(s, i, b, front if b < 2 else back, w >= 0.0 if b % 2 == 0 else w < 0.0,
                    common, solved)  # fmt: skip
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
            (
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
        )
        residual = approach_residual if approach_only else frame_residual
        s[_STATUS, i] = status
        s[_RESIDUAL, i] = residual if solved else np.nan
        # the miss: the wrist's once admitted, the distance beyond the reach when far away
        s[_MISS, i] = miss if admitted else (far - (a2 + a3 + d5) if status == 1.0 else 0.0)
        s[_DEVIATION, i] = deviation if (finite == 0.0) & (far <= FAR_AWAY_K) else 0.0


@numba.njit(cache=True, nogil=True, error_model="numpy")
def ik_kernel(T: np.ndarray, q_ref: np.ndarray, params: IkParams, out: IkOutputs) -> None:
    """IK of poses T (N, 4, 4) into ``out`` (see :class:`IkBatch`): admit the pose, find the arm
    plane, check the reach, write the four branches, measure the orientation residual.

    q_ref (M, 5) with M = 1 or N gives q1 on the base axis and q5 when the roll is free.
    Blocks of BLOCK poses: transposed into scratch rows, solved by one vectorised loop, the
    results transposed back; compiled with numpy's error model (a division by zero gives inf
    or NaN instead of a test per division).
    """
    # a constant width: the rows' distance is known at compile time, so the solving loop
    # needs no run-time aliasing checks between them (and vectorises)
    s = np.empty((_ROWS, BLOCK))
    for start in range(0, T.shape[0], BLOCK):
        m = min(BLOCK, T.shape[0] - start)
        for i in range(m):
            k = start + i
            r_k = k if q_ref.shape[0] > 1 else 0
            for r in range(4):
                for c in range(4):
                    s[4 * r + c, i] = T[k, r, c]
            s[_Q1_REF, i] = q_ref[r_k, 0]
            s[_PITCH_REF, i] = q_ref[r_k, 1] + q_ref[r_k, 2] + q_ref[r_k, 3]
            s[_Q5_REF, i] = q_ref[r_k, 4]
        _solve_block(m, params, s)
        for i in range(m):
            k = start + i
            out.status[k] = np.int8(s[_STATUS, i])
            out.miss[k] = s[_MISS, i]
            out.deviation[k] = s[_DEVIATION, i]
            out.residual[k] = s[_RESIDUAL, i]
            for b in range(4):
                out.within[k, b] = s[_WITHIN + b, i] != 0.0
                for j in range(5):
                    out.q[k, b, j] = s[_Q + 5 * b + j, i]
