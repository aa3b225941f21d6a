"""The vectorised Gauss-Newton polish of the full-pose block solver (``pose_block``, step 2):
the pose and geometric Jacobian of the exact chain in its sparse frames (``chain_tuple``), and
one step solved by the family's structure where the pitch axes are parallel
(``newton_parallel``) or else by an LDL^T factorisation of the normal equations
(``newton_ldl``). Sines and cosines are carried through the steps (``turn``).
"""

from __future__ import annotations

import math

import numba

from lynxplan.constants import BLOCK_PARALLEL_PITCHES
from lynxplan.robots.ik.block_layout import FAST, Floats, atan2, sincos


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def joint_turned(ch: Floats, j: int, t: Floats, s: float, c: float) -> Floats:
    """The running pose t (12: row-major 3 x 4) times R(z, q_{j+1}) N_{j+2} (N_tool after the
    last joint); ch: the chain tuple (``chain_tuple``). Between two joints, N = R(z, phi)
    R(x, beta) with a translation (px, py, 0) in the frame turned by q + phi, stored as (cos phi,
    sin phi, cos beta, sin beta, px, py): s and c are then the sine and cosine of q + phi
    (``offsets``), and only beta and the translation are applied here; the tool's is a 3 x 4
    block. j must be a literal (a constant index into ch)."""
    if j < 4:
        b = 12 + 6 * j
        cb, sb, px, py = ch[b + 2], ch[b + 3], ch[b + 4], ch[b + 5]
        w00, w01 = c * t[0] + s * t[1], c * t[1] - s * t[0]
        w10, w11 = c * t[4] + s * t[5], c * t[5] - s * t[4]
        w20, w21 = c * t[8] + s * t[9], c * t[9] - s * t[8]
        w02, w12, w22 = t[2], t[6], t[10]
        return (
            w00,
            cb * w01 + sb * w02,
            cb * w02 - sb * w01,
            w00 * px + w01 * py + t[3],
            w10,
            cb * w11 + sb * w12,
            cb * w12 - sb * w11,
            w10 * px + w11 * py + t[7],
            w20,
            cb * w21 + sb * w22,
            cb * w22 - sb * w21,
            w20 * px + w21 * py + t[11],
        )
    w00, w01 = c * t[0] + s * t[1], c * t[1] - s * t[0]
    w10, w11 = c * t[4] + s * t[5], c * t[5] - s * t[4]
    w20, w21 = c * t[8] + s * t[9], c * t[9] - s * t[8]
    w02, w12, w22 = t[2], t[6], t[10]
    b = 36
    m00, m01, m02, m03 = ch[b], ch[b + 1], ch[b + 2], ch[b + 3]
    m10, m11, m12, m13 = ch[b + 4], ch[b + 5], ch[b + 6], ch[b + 7]
    m20, m21, m22, m23 = ch[b + 8], ch[b + 9], ch[b + 10], ch[b + 11]
    return (
        w00 * m00 + w01 * m10 + w02 * m20,
        w00 * m01 + w01 * m11 + w02 * m21,
        w00 * m02 + w01 * m12 + w02 * m22,
        w00 * m03 + w01 * m13 + w02 * m23 + t[3],
        w10 * m00 + w11 * m10 + w12 * m20,
        w10 * m01 + w11 * m11 + w12 * m21,
        w10 * m02 + w11 * m12 + w12 * m22,
        w10 * m03 + w11 * m13 + w12 * m23 + t[7],
        w20 * m00 + w21 * m10 + w22 * m20,
        w20 * m01 + w21 * m11 + w22 * m21,
        w20 * m02 + w21 * m12 + w22 * m22,
        w20 * m03 + w21 * m13 + w22 * m23 + t[11],
    )


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def axis_of(t: Floats) -> Floats:
    """A joint's origin and world axis (its z axis) from the running pose t before its
    rotation."""
    return t[3], t[7], t[11], t[2], t[6], t[10]


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def base_block(ch: Floats) -> Floats:
    """N_1 (``chain_tuple``: 12, row-major 3 x 4), where every pose starts."""
    return ch[0], ch[1], ch[2], ch[3], ch[4], ch[5], ch[6], ch[7], ch[8], ch[9], ch[10], ch[11]


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def chain_pose(ch: Floats, q0: float, q1: float, q2: float, q3: float, q4: float) -> Floats:
    """Tool pose (12: row-major 3 x 4) of the chain at q."""
    s0, c0 = sincos(q0)
    s1, c1 = sincos(q1)
    s2, c2 = sincos(q2)
    s3, c3 = sincos(q3)
    s4, c4 = sincos(q4)
    sn, cs = offsets(ch, (s0, s1, s2, s3, s4), (c0, c1, c2, c3, c4))
    return fk_turned(ch, sn, cs)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def offsets(ch: Floats, sn: Floats, cs: Floats) -> tuple[Floats, Floats]:
    """The sines and cosines of q + phi (``chain_tuple``: phi of joint 1 and joint 5 is 0) from
    those of q (5 each), which ``joint_turned`` takes."""
    s1, c1 = sn[1] * ch[18] + cs[1] * ch[19], cs[1] * ch[18] - sn[1] * ch[19]
    s2, c2 = sn[2] * ch[24] + cs[2] * ch[25], cs[2] * ch[24] - sn[2] * ch[25]
    s3, c3 = sn[3] * ch[30] + cs[3] * ch[31], cs[3] * ch[30] - sn[3] * ch[31]
    return (sn[0], s1, s2, s3, sn[4]), (cs[0], c1, c2, c3, cs[4])


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def jacobian_column(o: Floats, p: Floats) -> Floats:
    """Geometric Jacobian column (6) of a joint with origin/axis o (6) for the tool point p."""
    dx, dy, dz = p[3] - o[0], p[7] - o[1], p[11] - o[2]
    wx, wy, wz = o[3], o[4], o[5]
    return (wy * dz - wz * dy, wz * dx - wx * dz, wx * dy - wy * dx, wx, wy, wz)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def pose_error(p: Floats, t: Floats) -> Floats:
    """Pose error (6) of p against the target t (both 12, row-major 3 x 4): the position
    difference [m] and vee(R Rt^T - Rt R^T) / 2 [rad]."""
    m01 = p[0] * t[4] + p[1] * t[5] + p[2] * t[6]
    m10 = p[4] * t[0] + p[5] * t[1] + p[6] * t[2]
    m02 = p[0] * t[8] + p[1] * t[9] + p[2] * t[10]
    m20 = p[8] * t[0] + p[9] * t[1] + p[10] * t[2]
    m12 = p[4] * t[8] + p[5] * t[9] + p[6] * t[10]
    m21 = p[8] * t[4] + p[9] * t[5] + p[10] * t[6]
    return (
        p[3] - t[3],
        p[7] - t[7],
        p[11] - t[11],
        0.5 * (m21 - m12),
        0.5 * (m02 - m20),
        0.5 * (m10 - m01),
    )


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def dot6(a: Floats, b: Floats) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5]


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def ldl_solve(
    j0: Floats, j1: Floats, j2: Floats, j3: Floats, j4: Floats
) -> tuple[Floats, Floats, float]:
    """LDL^T factors of J^T J for the Jacobian columns j0..j4 (6 each): the strict lower
    triangle (10, row-major) and the inverse pivots (5)."""
    n00, n11, n22, n33, n44 = (
        dot6(j0, j0),
        dot6(j1, j1),
        dot6(j2, j2),
        dot6(j3, j3),
        dot6(j4, j4),
    )
    n10, n20, n30, n40 = dot6(j1, j0), dot6(j2, j0), dot6(j3, j0), dot6(j4, j0)
    n21, n31, n41 = dot6(j2, j1), dot6(j3, j1), dot6(j4, j1)
    n32, n42, n43 = dot6(j3, j2), dot6(j4, j2), dot6(j4, j3)
    d0 = n00
    i0 = 1.0 / d0
    l10, l20, l30, l40 = n10 * i0, n20 * i0, n30 * i0, n40 * i0
    d1 = n11 - l10 * l10 * d0
    i1 = 1.0 / d1
    l21 = (n21 - l20 * l10 * d0) * i1
    l31 = (n31 - l30 * l10 * d0) * i1
    l41 = (n41 - l40 * l10 * d0) * i1
    d2 = n22 - l20 * l20 * d0 - l21 * l21 * d1
    i2 = 1.0 / d2
    l32 = (n32 - l30 * l20 * d0 - l31 * l21 * d1) * i2
    l42 = (n42 - l40 * l20 * d0 - l41 * l21 * d1) * i2
    d3 = n33 - l30 * l30 * d0 - l31 * l31 * d1 - l32 * l32 * d2
    i3 = 1.0 / d3
    l43 = (n43 - l40 * l30 * d0 - l41 * l31 * d1 - l42 * l32 * d2) * i3
    d4 = n44 - l40 * l40 * d0 - l41 * l41 * d1 - l42 * l42 * d2 - l43 * l43 * d3
    i4 = 1.0 / d4
    ratio = min(d0, d1, d2, d3, d4) / max(d0, d1, d2, d3, d4)
    return (l10, l20, l21, l30, l31, l32, l40, l41, l42, l43), (i0, i1, i2, i3, i4), ratio


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def normal_step(
    lower: Floats,
    inverse: Floats,
    j0: Floats,
    j1: Floats,
    j2: Floats,
    j3: Floats,
    j4: Floats,
    e: Floats,
) -> Floats:
    """The Gauss-Newton step x = (J^T J)^-1 J^T e from the LDL^T factors (``ldl_solve``)."""
    l10, l20, l21, l30, l31, l32, l40, l41, l42, l43 = lower
    y0 = dot6(j0, e)
    y1 = dot6(j1, e) - l10 * y0
    y2 = dot6(j2, e) - l20 * y0 - l21 * y1
    y3 = dot6(j3, e) - l30 * y0 - l31 * y1 - l32 * y2
    y4 = dot6(j4, e) - l40 * y0 - l41 * y1 - l42 * y2 - l43 * y3
    x4 = y4 * inverse[4]
    x3 = y3 * inverse[3] - l43 * x4
    x2 = y2 * inverse[2] - l32 * x3 - l42 * x4
    x1 = y1 * inverse[1] - l21 * x2 - l31 * x3 - l41 * x4
    x0 = y0 * inverse[0] - l10 * x1 - l20 * x2 - l30 * x3 - l40 * x4
    return x0, x1, x2, x3, x4


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def turn(s: float, c: float, x: float) -> tuple[float, float]:
    """(sin, cos) of the angle a - x from s = sin a and c = cos a: the angle difference, with
    sin x and cos x to fifth order (the remainder below x^6 / 720: rounding for |x| <=
    BLOCK_TAYLOR_STEP)."""
    xx = x * x
    sx = x * (1.0 - xx * (1.0 / 6.0) * (1.0 - xx * (1.0 / 20.0)))
    cx = 1.0 - xx * 0.5 * (1.0 - xx * (1.0 / 12.0))
    return s * cx - c * sx, c * cx + s * sx


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def stepped(q: Floats, sn: Floats, cs: Floats, x: Floats) -> tuple[Floats, Floats, Floats]:
    """The angles q - x (5) and their sines and cosines turned from sn, cs (:func:`turn`)."""
    s0, c0 = turn(sn[0], cs[0], x[0])
    s1, c1 = turn(sn[1], cs[1], x[1])
    s2, c2 = turn(sn[2], cs[2], x[2])
    s3, c3 = turn(sn[3], cs[3], x[3])
    s4, c4 = turn(sn[4], cs[4], x[4])
    return (
        (q[0] - x[0], q[1] - x[1], q[2] - x[2], q[3] - x[3], q[4] - x[4]),
        (s0, s1, s2, s3, s4),
        (c0, c1, c2, c3, c4),
    )


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def fk_axes(
    ch: Floats, sn: Floats, cs: Floats
) -> tuple[Floats, Floats, Floats, Floats, Floats, Floats]:
    """The origin and world axis of each joint (6 each, ``axis_of``) and the tool pose (12)
    of the chain at the angles of sines sn and cosines cs."""
    p = base_block(ch)
    o0 = axis_of(p)
    p = joint_turned(ch, 0, p, sn[0], cs[0])
    o1 = axis_of(p)
    p = joint_turned(ch, 1, p, sn[1], cs[1])
    o2 = axis_of(p)
    p = joint_turned(ch, 2, p, sn[2], cs[2])
    o3 = axis_of(p)
    p = joint_turned(ch, 3, p, sn[3], cs[3])
    o4 = axis_of(p)
    return o0, o1, o2, o3, o4, joint_turned(ch, 4, p, sn[4], cs[4])


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def newton_ldl(ch: Floats, t: Floats, q: Floats, sn: Floats, cs: Floats) -> Floats:
    """One Gauss-Newton step on the exact chain from q (5), sn and cs the sines and cosines of
    q + phi (``offsets``): the step x (5; the new angles are q - x), the smallest over the
    largest LDL^T pivot of J^T J (its conditioning), and the largest component of the pose
    error at q."""
    o0, o1, o2, o3, o4, p = fk_axes(ch, sn, cs)
    j0, j1, j2 = jacobian_column(o0, p), jacobian_column(o1, p), jacobian_column(o2, p)
    j3, j4 = jacobian_column(o3, p), jacobian_column(o4, p)
    lower, inverse, ratio = ldl_solve(j0, j1, j2, j3, j4)
    e = pose_error(p, t)
    size = max(abs(e[0]), abs(e[1]), abs(e[2]), abs(e[3]), abs(e[4]), abs(e[5]))
    x = normal_step(lower, inverse, j0, j1, j2, j3, j4, e)
    return x[0], x[1], x[2], x[3], x[4], ratio, size


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def cross(a0: float, a1: float, a2: float, b0: float, b1: float, b2: float) -> Floats:
    """The cross product of (a0, a1, a2) and (b0, b1, b2)."""
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def newton_parallel(ch: Floats, t: Floats, q: Floats, sn: Floats, cs: Floats) -> Floats:
    """``newton_ldl``'s Gauss-Newton step (the same x = J^+ e, the same outputs; its
    conditioning here: the smaller of two, below) for a chain whose pitch axes are parallel
    (``parallel_pitches``: each pitch column's axis is +-h, joint 3's), solved by the family's
    structure instead of the 5 x 5 normal equations.

    With the pitch angles' effects on the orientation summed (xs = s2 x2 + x3 + s4 x4 in the
    signs s of the axes against h), the position across h is met exactly by the first two
    pitch steps for any yaw, pitch-sum and roll steps (the pitch joints' origins span the plane
    across h: a 2 x 2 system, singular at a fold of the elbow); so x0, xs, x4 are the least
    squares solution of the four rows left, the orientation's and the position along h (3 x 3
    normal equations, by cofactors), then the pitch steps follow from the 2 x 2. Conditioning:
    the smaller of det N / (N00 N11 N22) of those normal equations and the squared sine of the
    elbow's triangle of pitch origins."""
    o0, o1, o2, o3, o4, p = fk_axes(ch, sn, cs)
    e = pose_error(p, t)
    size = max(abs(e[0]), abs(e[1]), abs(e[2]), abs(e[3]), abs(e[4]), abs(e[5]))
    s1, s3 = pitch_signs(ch)
    k0, k1, k2 = o0[3], o0[4], o0[5]
    h0, h1, h2 = o2[3], o2[4], o2[5]
    a0, a1, a2 = o4[3], o4[4], o4[5]
    px, py, pz = p[3], p[7], p[11]
    v0 = cross(k0, k1, k2, px - o0[0], py - o0[1], pz - o0[2])
    v4 = cross(a0, a1, a2, px - o4[0], py - o4[1], pz - o4[2])
    v3 = cross(h0, h1, h2, px - o3[0], py - o3[1], pz - o3[2])
    x0, xs, x4, cond3 = sum_steps(o0[3:], o2[3:], o4[3:], v0, v4, e)
    # across h: h x (A y1 + B y2) = w, A and B from the pitch origins (y: the signed steps)
    w0 = e[0] - v0[0] * x0 - v4[0] * x4 - v3[0] * xs
    w1 = e[1] - v0[1] * x0 - v4[1] * x4 - v3[1] * xs
    w2 = e[2] - v0[2] * x0 - v4[2] * x4 - v3[2] * xs
    y = cross(w0, w1, w2, h0, h1, h2)
    b0, b1, b2 = o3[0] - o1[0], o3[1] - o1[1], o3[2] - o1[2]
    d0, d1, d2 = o3[0] - o2[0], o3[1] - o2[1], o3[2] - o2[2]
    bd = cross(b0, b1, b2, d0, d1, d2)
    det2 = bd[0] * h0 + bd[1] * h1 + bd[2] * h2
    inv2 = 1.0 / det2
    yd = cross(y[0], y[1], y[2], d0, d1, d2)
    by = cross(b0, b1, b2, y[0], y[1], y[2])
    y1 = (yd[0] * h0 + yd[1] * h1 + yd[2] * h2) * inv2
    y2 = (by[0] * h0 + by[1] * h1 + by[2] * h2) * inv2
    lengths = (b0 * b0 + b1 * b1 + b2 * b2) * (d0 * d0 + d1 * d1 + d2 * d2)
    ratio = min(cond3, det2 * det2 / lengths)
    return x0, s1 * y1, y2, s3 * (xs - y1 - y2), x4, ratio, size


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def sum_steps(k: Floats, h: Floats, a: Floats, v0: Floats, v4: Floats, e: Floats) -> Floats:
    """(``newton_parallel``) The yaw, pitch-sum and roll steps x0, xs, x4: the least squares
    solution of the orientation's rows (axes k, h, a: 3 each) and the position's along h
    (v0, v4: the yaw and roll columns' position parts; e: the pose error, 6), by the
    cofactors of the 3 x 3 normal equations N; and det N / (N00 N11 N22)."""
    k0, k1, k2, h0, h1, h2, a0, a1, a2 = k[0], k[1], k[2], h[0], h[1], h[2], a[0], a[1], a[2]
    g0, g2 = h0 * v0[0] + h1 * v0[1] + h2 * v0[2], h0 * v4[0] + h1 * v4[1] + h2 * v4[2]
    eh = h0 * e[0] + h1 * e[1] + h2 * e[2]
    n00, n11, n22 = 1.0 + g0 * g0, 1.0, 1.0 + g2 * g2
    n01 = k0 * h0 + k1 * h1 + k2 * h2
    n02 = k0 * a0 + k1 * a1 + k2 * a2 + g0 * g2
    n12 = h0 * a0 + h1 * a1 + h2 * a2
    r0 = k0 * e[3] + k1 * e[4] + k2 * e[5] + g0 * eh
    r1 = h0 * e[3] + h1 * e[4] + h2 * e[5]
    r2 = a0 * e[3] + a1 * e[4] + a2 * e[5] + g2 * eh
    c00, c11, c22 = n11 * n22 - n12 * n12, n00 * n22 - n02 * n02, n00 * n11 - n01 * n01
    c01, c02, c12 = n02 * n12 - n01 * n22, n01 * n12 - n02 * n11, n01 * n02 - n00 * n12
    det = n00 * c00 + n01 * c01 + n02 * c02
    inverse = 1.0 / det
    x0 = (c00 * r0 + c01 * r1 + c02 * r2) * inverse
    xs = (c01 * r0 + c11 * r1 + c12 * r2) * inverse
    x4 = (c02 * r0 + c12 * r1 + c22 * r2) * inverse
    return x0, xs, x4, det / (n00 * n11 * n22)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def pitch_signs(ch: Floats) -> tuple[float, float]:
    """The signs of joints 2 and 4's axes against joint 3's (the cosines of beta of the links
    2-3 and 3-4 in ``chain_tuple``; +-1 where the pitch axes are parallel)."""
    return math.copysign(1.0, ch[20]), math.copysign(1.0, ch[26])


@numba.njit(cache=True, nogil=True)
def parallel_pitches(ch: Floats) -> bool:
    """Whether the pitch axes are parallel within BLOCK_PARALLEL_PITCHES (the sines of beta of the
    links 2-3 and 3-4 in ``chain_tuple``): then ``newton_parallel`` takes the steps."""
    return (abs(ch[21]) <= BLOCK_PARALLEL_PITCHES) & (abs(ch[27]) <= BLOCK_PARALLEL_PITCHES)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def newton_step(ch: Floats, t: Floats, q: Floats, sn: Floats, cs: Floats, parallel: bool) -> Floats:
    """One Gauss-Newton step (``newton_ldl``; ``newton_parallel`` where the pitch axes are
    parallel: parallel must be a constant)."""
    if parallel:
        return newton_parallel(ch, t, q, sn, cs)
    return newton_ldl(ch, t, q, sn, cs)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def polish_twice(
    ch: Floats, t: Floats, q: Floats, sn: Floats, cs: Floats, parallel: bool
) -> tuple[Floats, Floats, Floats, float, float, float]:
    """Two Gauss-Newton steps on the exact chain from q (5), sn and cs the sines and cosines of
    q + phi (``offsets``): the final q, those sines and cosines, the smaller of the two
    conditionings (``newton_step``; parallel: a constant), the largest component of the pose error
    before the last step, and the largest step [rad] of either.

    The sines and cosines after each step follow from the ones before it (``turn``): exact to
    rounding where the steps are within BLOCK_TAYLOR_STEP, and still good enough for the second
    step's direction where they are not."""
    x0, x1, x2, x3, x4, first, _ = newton_step(ch, t, q, sn, cs, parallel)
    big = max(abs(x0), abs(x1), abs(x2), abs(x3), abs(x4))
    q, sn, cs = stepped(q, sn, cs, (x0, x1, x2, x3, x4))
    x0, x1, x2, x3, x4, second, size = newton_step(ch, t, q, sn, cs, parallel)
    big = max(big, abs(x0), abs(x1), abs(x2), abs(x3), abs(x4))
    q, sn, cs = stepped(q, sn, cs, (x0, x1, x2, x3, x4))
    return q, sn, cs, min(first, second), size, big


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def fk_turned(ch: Floats, sn: Floats, cs: Floats) -> Floats:
    """Tool pose (12: row-major 3 x 4) of the chain at the angles of sines sn and cosines cs."""
    t = base_block(ch)
    t = joint_turned(ch, 0, t, sn[0], cs[0])
    t = joint_turned(ch, 1, t, sn[1], cs[1])
    t = joint_turned(ch, 2, t, sn[2], cs[2])
    t = joint_turned(ch, 3, t, sn[3], cs[3])
    return joint_turned(ch, 4, t, sn[4], cs[4])


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def pose_rotation_angle(p: Floats, t: Floats) -> float:
    """Angle of the rotation from t's to p's rotation block [rad] (``rotation_angle``)."""
    tr = t[0] * p[0] + t[4] * p[4] + t[8] * p[8] + t[1] * p[1] + t[5] * p[5] + t[9] * p[9]
    tr += t[2] * p[2] + t[6] * p[6] + t[10] * p[10]
    m01 = t[0] * p[1] + t[4] * p[5] + t[8] * p[9]
    m10 = t[1] * p[0] + t[5] * p[4] + t[9] * p[8]
    m02 = t[0] * p[2] + t[4] * p[6] + t[8] * p[10]
    m20 = t[2] * p[0] + t[6] * p[4] + t[10] * p[8]
    m12 = t[1] * p[2] + t[5] * p[6] + t[9] * p[10]
    m21 = t[2] * p[1] + t[6] * p[5] + t[10] * p[9]
    s0, s1, s2 = m21 - m12, m02 - m20, m10 - m01
    return atan2(0.5 * math.sqrt(s0 * s0 + s1 * s1 + s2 * s2), 0.5 * (tr - 1.0))
