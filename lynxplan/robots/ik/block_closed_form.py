"""The vectorised closed form of the yaw-pitch-pitch-pitch-roll family on the ideal model
(``pose_block``, step 1): for a block of poses, each flip of the yaw and each elbow, with sines
and cosines from the vectors that define the angles (few arctangents, no sine or cosine). The
same geometry as :func:`lynxplan.robots.ik.pose_kernel.solve_target`.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from lynxplan._fastmath import wide_vectors
from lynxplan.constants import (
    AXIAL_APPROACH,
    BLOCK_FOLD_BAND,
    BLOCK_OTHER_DEGENERATE,
    BLOCK_OTHER_MARGIN,
    FOLD_START_BAND,
    REACH_MISS,
    ROLL_DEGENERATE,
)
from lynxplan.robots import family as F  # noqa: N812
from lynxplan.robots.ik.block_layout import (
    BLOCK,
    FAST,
    FLIP,
    POSE,
    Branches,
    FlipBranches,
    Floats,
    SinCos,
    atan2,
    column_of,
    put_candidate,
    put_flip,
)
from lynxplan.robots.ik.family_geometry import best_roll_terms, wrap
from lynxplan.robots.ik.pose_kernel import yaw_match


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def unit_terms(y: float, x: float) -> tuple[float, float]:
    """(sin, cos) of the angle of the vector (x, y): the vector normalised, no trigonometry
    (NaN at the origin, where the callers leave the target to the scalar solver)."""
    inverse = 1.0 / math.sqrt(x * x + y * y)
    return y * inverse, x * inverse


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def pitch_sum(
    shape: Floats, a_h: float, a_p: float, a_k: float, s: float, c: float
) -> tuple[float, float, float, bool]:
    """Canonical pitch sum for the yaw of sine s and cosine c and the approach a (components
    along h, p, k): the angle, its sine and cosine, and whether it is degenerate (the approach
    along the pitch axis)."""
    x = c * a_h - s * a_p
    sx, cx = unit_terms(a_k, x)
    sg, cg = shape[4], shape[5]  # of gamma0: the pitch sum is atan2(a_k, x) - gamma0
    return (
        atan2(a_k, x) - shape[6],
        sx * cg - cx * sg,
        cx * cg + sx * sg,
        x * x + a_k * a_k <= ROLL_DEGENERATE * ROLL_DEGENERATE,
    )


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def roll_terms(
    pr: Floats, g: Floats, s_yaw: float, c_yaw: float, s_sum: float, c_sum: float
) -> tuple[float, float]:
    """(sin, cos) of the canonical roll nearest the target (``family_geometry.best_roll``) for
    the yaw and pitch sum of these sines and cosines; g: the 9 entries of G = Rt Rt0^T,
    row-major."""
    sine, cosine = best_roll_terms(pr, g, c_yaw, -s_yaw, c_sum, -s_sum)
    return unit_terms(sine, cosine)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def side_yaw(
    pr: Floats, rho: float, alpha: Floats, st: float, ct: float, side: int
) -> tuple[float, float, float, float, bool]:
    """Yaw of one side for the roll of sine st and cosine ct (``family_geometry.yaw``), its
    sine and cosine, the lateral miss [m], and whether the target is on the yaw axis (left to
    the scalar solver); alpha: the angle of the target about the yaw axis, its sine, cosine."""
    lat = pr[F.LAM4] + pr[F.W0 + 2] + ct * pr[F.E1 + 2] + st * pr[F.E2 + 2]
    on_axis = (rho <= ROLL_DEGENERATE) & (abs(lat) <= ROLL_DEGENERATE)
    ratio = lat / rho if rho > 0.0 else math.copysign(1.0, lat)
    miss = lat - rho if ratio > 1.0 else 0.0
    miss = -lat - rho if ratio < -1.0 else miss
    cb = min(max(ratio, -1.0), 1.0)
    sb = math.sqrt((1.0 - cb) * (1.0 + cb))  # beta = arccos(ratio) in [0, pi]
    beta = atan2(sb, cb)
    a, sa, ca = alpha
    if side == 1:  # alpha + beta
        return a + beta, sa * cb + ca * sb, ca * cb - sa * sb, miss, on_axis
    return a - beta, sa * cb - ca * sb, ca * cb + sa * sb, miss, on_axis


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def approach_in_family(
    pr: Floats, t: Floats
) -> tuple[Floats, float, float, float, float, float, float]:
    """The target t's (12) rotation in the family frame, G = Rt Rt0^T (9, row-major), its
    approach a (the roll axis R turned by G, 3) and a's components along h, p and k."""
    rt = (pr[F.RT0], pr[F.RT0 + 1], pr[F.RT0 + 2], pr[F.RT0 + 3], pr[F.RT0 + 4],
          pr[F.RT0 + 5], pr[F.RT0 + 6], pr[F.RT0 + 7], pr[F.RT0 + 8])  # fmt: skip
    g0 = t[0] * rt[0] + t[1] * rt[1] + t[2] * rt[2]
    g1 = t[0] * rt[3] + t[1] * rt[4] + t[2] * rt[5]
    g2 = t[0] * rt[6] + t[1] * rt[7] + t[2] * rt[8]
    g3 = t[4] * rt[0] + t[5] * rt[1] + t[6] * rt[2]
    g4 = t[4] * rt[3] + t[5] * rt[4] + t[6] * rt[5]
    g5 = t[4] * rt[6] + t[5] * rt[7] + t[6] * rt[8]
    g6 = t[8] * rt[0] + t[9] * rt[1] + t[10] * rt[2]
    g7 = t[8] * rt[3] + t[9] * rt[4] + t[10] * rt[5]
    g8 = t[8] * rt[6] + t[9] * rt[7] + t[10] * rt[8]
    g = (g0, g1, g2, g3, g4, g5, g6, g7, g8)
    a0 = g0 * pr[F.R] + g1 * pr[F.R + 1] + g2 * pr[F.R + 2]
    a1 = g3 * pr[F.R] + g4 * pr[F.R + 1] + g5 * pr[F.R + 2]
    a2 = g6 * pr[F.R] + g7 * pr[F.R + 1] + g8 * pr[F.R + 2]
    a_h = a0 * pr[F.H] + a1 * pr[F.H + 1] + a2 * pr[F.H + 2]
    a_p = a0 * pr[F.P] + a1 * pr[F.P + 1] + a2 * pr[F.P + 2]
    a_k = a0 * pr[F.K] + a1 * pr[F.K + 1] + a2 * pr[F.K + 2]
    return g, a0, a1, a2, a_h, a_p, a_k


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def offset_from_yaw_axis(pr: Floats, t: Floats) -> Floats:
    """The target t's (12) point less the yaw axis' point C1 [m] (3), its components along
    p, h and k, and rho, its distance from the yaw axis [m]."""
    d0, d1, d2 = t[3] - pr[F.C1], t[7] - pr[F.C1 + 1], t[11] - pr[F.C1 + 2]
    dp = d0 * pr[F.P] + d1 * pr[F.P + 1] + d2 * pr[F.P + 2]
    dh = d0 * pr[F.H] + d1 * pr[F.H + 1] + d2 * pr[F.H + 2]
    dk = d0 * pr[F.K] + d1 * pr[F.K + 1] + d2 * pr[F.K + 2]
    rho = math.sqrt(dp * dp + dh * dh)
    return d0, d1, d2, dp, dh, dk, rho


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def orientation_roll(pr: Floats, shape: Floats, t: Floats, flip: int) -> Floats:
    """(sin, cos) of the canonical roll nearest the target t (12) at flip ``flip``'s yaw (the
    orientation's, turned by flip pi: ``roll_terms``). Flip 1 turns the yaw by pi and the
    pitch sum to its mirror: the same approach, the frame turned by pi about it, so its roll is
    flip 0's turned by pi (the same to rounding, as the tests check): the kernels compute
    flip 0's only."""
    g, _, _, _, a_h, a_p, a_k = approach_in_family(pr, t)
    sign = 1.0 - 2.0 * flip
    s_phi, c_phi = unit_terms(-a_p, a_h)
    s_phi, c_phi = sign * s_phi, sign * c_phi
    _, s_big, c_big, _ = pitch_sum(shape, a_h, a_p, a_k, s_phi, c_phi)
    return roll_terms(pr, g, s_phi, c_phi, s_big, c_big)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def screen_flips(pr: Floats, shape: Floats, t: Floats, roll: Floats) -> tuple[int, bool]:
    """For a tool off the roll axis: the flip whose yaw the target's position can match (of
    the smaller miss, below), and whether the other flip may be a candidate or send the pose
    to the scalar solver too (then ``other_flip`` computes it; rare: the other flip's yaw
    misses by about twice the lateral offset over rho); roll: flip 0's (``orientation_roll``).

    A side's yaw y = alpha +- beta matches flip f's yaw phi_f (the orientation's, turned by
    f pi) only where |y - phi_f| <= match_f (``yaw_match`` at flip f's lateral offset, the
    value ``flip_geometry`` uses). cos is 1-Lipschitz and rho cos(y - alpha) = clamp(lateral_f,
    -rho,
    rho), so a match needs the miss |rho cos(phi_f - alpha) - clamp(lateral_f, -rho, rho)| <=
    rho match_f (rho: the target's distance from the yaw axis [m]; lateral_f [m]: the lateral
    offset at flip f's roll, flip 0's turned by pi), tested with a margin (BLOCK_OTHER_MARGIN) ~1e5
    times the rounding. A flip's own fallbacks need an approach square to the yaw axis (the
    pitch sum degenerate) or the target on the yaw axis (BLOCK_OTHER_DEGENERATE); the others are the
    same for both flips."""
    _, _, _, _, a_h, a_p, a_k = approach_in_family(pr, t)
    axial = math.sqrt(a_h * a_h + a_p * a_p)
    _, _, _, dp, dh, _, rho = offset_from_yaw_axis(pr, t)
    s_phi, c_phi = unit_terms(-a_p, a_h)
    u = c_phi * dp + s_phi * dh  # rho cos(phi_0 - alpha)
    centre = pr[F.LAM4] + pr[F.W0 + 2]
    swing = roll[1] * pr[F.E1 + 2] + roll[0] * pr[F.E2 + 2]
    miss0 = abs(u - min(max(centre + swing, -rho), rho))
    miss1 = abs(-u - min(max(centre - swing, -rho), rho))
    one = 0 if miss0 <= miss1 else 1
    lateral = centre + swing if one else centre - swing  # the other flip's
    match = yaw_match(pr[F.DEVIATION], shape[0] + shape[1], axial, rho, lateral)
    tol = rho * match * (1.0 + 1e-6) + BLOCK_OTHER_MARGIN * max(1.0, rho)
    later = max(miss0, miss1) <= tol
    # a NaN anywhere: not <=, and flip 0's own tests (not finite) send the pose to the scalar
    return one, later | (abs(a_k) <= BLOCK_OTHER_DEGENERATE) | (rho <= BLOCK_OTHER_DEGENERATE)


@numba.njit(cache=True, nogil=True, fastmath=FAST, error_model="numpy")
def other_flip(pr: Floats, shape: Floats, x: np.ndarray, i: int) -> None:
    """The flip of pose i that ``closed_forms`` left out (``screen_flips``; its row POSE.other:
    1 + the flip it computed) into the scratch rows x, and pose i's candidate lanes then from
    flip 0 where it is a candidate, else from flip 1 (as for a tool on the roll axis)."""
    t = column_of(x, BLOCK, 0, i)
    computed = 0 if x[POSE.other * BLOCK + i] == 1.0 else 1
    missing = 1 - computed
    put_flip(
        x,
        i,
        missing,
        flip_geometry(pr, shape, t, missing, False, orientation_roll(pr, shape, t, 0)),
    )
    pick = 0 if x[(POSE.flips + FLIP.candidate) * BLOCK + i] != 0.0 else 1
    if pick != computed:  # the lanes hold the computed flip's branches
        first = POSE.flips + pick * FLIP.rows
        fold = x[(first + FLIP.fold) * BLOCK + i] != 0.0
        up, down, s_up, c_up, s_down, c_down = flip_branches(
            pr, shape, column_of(x, BLOCK, first, i)
        )
        put_candidate(x, i, t, up, s_up, c_up, fold)
        put_candidate(x, BLOCK + i, t, down, s_down, c_down, fold)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def flip_geometry(
    pr: Floats, shape: Floats, t: Floats, flip: int, on_roll_axis: bool, roll: Floats
) -> FlipBranches:
    """One flip of the yaw (both elbows) of the target t (12: row-major 3 x 4) on the ideal
    model: (its geometry, where ``flip_branches`` finds the angles, candidate, fallback, side, near
    a fold of the elbow); on_roll_axis: the tool point on the roll axis (``F.OFF_AXIS`` 0: the
    roll is then the side's; a constant, so the roll of the other kind is not computed at all);
    roll: flip 0's (sin, cos) of the roll the orientation gives (``orientation_roll``; flip 1's is
    it
    turned by pi); shape: (la, lb, b2, b3) of the two links
    (``family_geometry.two_link``), sin, cos and the angle gamma0, sin and cos of b2 and of
    b2 - b3.

    The angles enter the geometry through their sines and cosines, which come from the vectors
    that define them (normalised): arctangents only for the yaw (two of them shared by both
    flips), no sine or cosine; the other angles' arctangents are left to ``flip_branches``, for
    the flip that is taken."""
    g, a0, a1, a2, a_h, a_p, a_k = approach_in_family(pr, t)
    axial_size = math.sqrt(a_h * a_h + a_p * a_p)
    axial = axial_size <= AXIAL_APPROACH
    d0, d1, d2, dp, dh, dk, rho = offset_from_yaw_axis(pr, t)
    # the yaw that puts the approach in the arm plane, flipped by pi: its sine and cosine flip
    sign = 1.0 - 2.0 * flip
    phi = atan2(-a_p, a_h) + flip * math.pi
    s_phi, c_phi = unit_terms(-a_p, a_h)
    s_phi, c_phi = sign * s_phi, sign * c_phi
    flat1 = pitch_sum(shape, a_h, a_p, a_k, s_phi, c_phi)[3]
    st, ct = sign * roll[0], sign * roll[1]  # flip 1's roll is flip 0's turned by pi
    s_alpha, c_alpha = unit_terms(dh, dp)
    alpha = (atan2(dh, dp), s_alpha, c_alpha)
    lat = pr[F.LAM4] + pr[F.W0 + 2] + ct * pr[F.E1 + 2] + st * pr[F.E2 + 2]
    match = yaw_match(pr[F.DEVIATION], shape[0] + shape[1], axial_size, rho, lat)
    yaw0, s_yaw0, c_yaw0, lat_miss, on_axis = side_yaw(pr, rho, alpha, st, ct, 0)
    yaw1, s_yaw1, c_yaw1, _, _ = side_yaw(pr, rho, alpha, st, ct, 1)
    lat_ok = lat_miss <= REACH_MISS
    ok0 = lat_ok & (abs(wrap(yaw0 - phi)) <= match)
    ok1 = lat_ok & (abs(wrap(yaw1 - phi)) <= match)
    side = 1.0 if ok1 else 0.0
    phi2 = yaw1 if ok1 else yaw0
    s2, c2 = (s_yaw1, c_yaw1) if ok1 else (s_yaw0, c_yaw0)
    _, sp, cp, flat2 = pitch_sum(shape, a_h, a_p, a_k, s2, c2)
    if on_roll_axis:  # a tool on the roll axis: the roll of the side's yaw
        st, ct = roll_terms(pr, g, s2, c2, sp, cp)
    x, y = c2 * dh - s2 * dp, dk
    wh = pr[F.W0] + ct * pr[F.E1] + st * pr[F.E2]
    wk = pr[F.W0 + 1] + ct * pr[F.E1 + 1] + st * pr[F.E2 + 1]
    la, lb = shape[0], shape[1]
    rx = x - (cp * wh - sp * wk) - pr[F.O2]
    ry = y - (sp * wh + cp * wk) - pr[F.O2 + 1]
    dist = math.sqrt(rx * rx + ry * ry)
    cosd = (dist * dist - la * la - lb * lb) / (2.0 * la * lb)
    reach = dist - (la + lb) if cosd > 1.0 else 0.0
    reach = abs(la - lb) - dist if cosd < -1.0 else reach
    cosd = min(max(cosd, -1.0), 1.0)
    # where the scalar solver starts the two elbows apart (a near-family model): its result
    fold_start = (pr[F.EXACT] == 0.0) & (abs(cosd) > 1.0 - FOLD_START_BAND)
    fold = abs(cosd) > 1.0 - BLOCK_FOLD_BAND
    miss = math.sqrt(reach * reach + lat_miss * lat_miss)
    candidate = (ok0 | ok1) & (miss <= REACH_MISS)
    finite = math.isfinite(d0 + d1 + d2 + a0 + a1 + a2 + g[0] + g[4] + g[8])
    fallback = axial | flat1 | flat2 | on_axis | (ok0 & ok1) | (candidate & fold_start)
    fallback |= not finite
    x_pitch = c2 * a_h - s2 * a_p  # the pitch sum is atan2(a_k, x_pitch) - gamma0
    geometry = (phi2, s2, c2, a_k, x_pitch, sp, cp, st, ct, rx, ry, cosd)
    return geometry, candidate, fallback, side, fold


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def flip_branches(pr: Floats, shape: Floats, geometry: Floats) -> Branches:
    """The angles q (5) of elbow up and of elbow down of one flip, and their sines and
    cosines (5 each), from its geometry (``flip_geometry``): the yaw, its sine and cosine, the
    approach's components along k and in the arm plane, the pitch sum's sine and cosine, the
    roll's, the shoulder-to-wrist vector and the elbow's cosine."""
    phi2, s2, c2, a_k, x_pitch, sp, cp, st, ct, rx, ry, cd = geometry
    la, lb, b2, b3 = shape[0], shape[1], shape[2], shape[3]
    big2 = atan2(a_k, x_pitch) - shape[6]
    theta = atan2(st, ct)
    sd = math.sqrt((1.0 - cd) * (1.0 + cd))  # delta = arccos(cd) in [0, pi]
    delta = atan2(sd, cd)
    toward = atan2(ry, rx)
    bend = atan2(lb * sd, la + lb * cd)
    # elbow up (0): the elbow above the shoulder-wrist line, the elbow angle -delta
    up2, down2 = toward + bend - b2, toward - bend - b2
    up3, down3 = b2 - b3 - delta, b2 - b3 + delta
    sigma = (pr[F.SIGMA], pr[F.SIGMA + 1], pr[F.SIGMA + 2], pr[F.SIGMA + 3], pr[F.SIGMA + 4])
    q1, q5 = sigma[0] * phi2, sigma[4] * theta
    up = (q1, sigma[1] * up2, sigma[2] * up3, sigma[3] * (big2 - up2 - up3), q5)
    down = (q1, sigma[1] * down2, sigma[2] * down3, sigma[3] * (big2 - down2 - down3), q5)
    # the sines and cosines of the angles, from those of toward, bend, delta and the constants
    s_to, c_to = unit_terms(ry, rx)
    s_be, c_be = unit_terms(lb * sd, la + lb * cd)
    sines_up, cosines_up = elbow_terms(
        shape, sigma, (s_to, c_to), (s_be, c_be), (-sd, cd), (sp, cp)
    )
    sines_down, cosines_down = elbow_terms(
        shape, sigma, (s_to, c_to), (-s_be, c_be), (sd, cd), (sp, cp)
    )
    s1, s5 = sigma[0] * s2, sigma[4] * st
    return (
        up,
        down,
        (s1, sines_up[0], sines_up[1], sines_up[2], s5),
        (c2, cosines_up[0], cosines_up[1], cosines_up[2], ct),
        (s1, sines_down[0], sines_down[1], sines_down[2], s5),
        (c2, cosines_down[0], cosines_down[1], cosines_down[2], ct),
    )


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def elbow_terms(
    shape: Floats,
    sigma: Floats,
    toward: SinCos,
    bend: SinCos,
    delta: SinCos,
    big: SinCos,
) -> tuple[Floats, Floats]:
    """The sines and cosines of q2, q3, q4 of one elbow (``flip_geometry``): q2 = toward +
    bend - b2, q3 = b2 - b3 + delta' and q4 = big - q2 - q3, each times its sign sigma (5, all
    joints), from the (sin, cos) of toward, bend (its sign the elbow's), delta' (-delta for the
    elbow up) and the pitch sum big; shape[7:11]: those of b2 and b2 - b3."""
    s_to, c_to = toward
    s_be, c_be = bend
    s_de, c_de = delta
    s_big, c_big = big
    s_b2, c_b2, s_23, c_23 = shape[7], shape[8], shape[9], shape[10]
    s_a, c_a = s_to * c_be + c_to * s_be, c_to * c_be - s_to * s_be  # toward + bend
    s_q2, c_q2 = s_a * c_b2 - c_a * s_b2, c_a * c_b2 + s_a * s_b2
    s_q3, c_q3 = s_23 * c_de + c_23 * s_de, c_23 * c_de - s_23 * s_de
    s_23q, c_23q = s_q2 * c_q3 + c_q2 * s_q3, c_q2 * c_q3 - s_q2 * s_q3  # q2 + q3
    s_q4, c_q4 = s_big * c_23q - c_big * s_23q, c_big * c_23q + s_big * s_23q
    return (sigma[1] * s_q2, sigma[2] * s_q3, sigma[3] * s_q4), (c_q2, c_q3, c_q4)


@numba.njit(cache=True, nogil=True)
def solve_closed_forms(
    pr: Floats, shape: Floats, x: np.ndarray, m: int, off_axis: bool | None
) -> None:
    """The block's closed forms (the first m poses' count): ``closed_forms_on_roll_axis`` where
    the tool point is on the roll axis (``off_axis`` None), else ``closed_forms`` and, for the
    poses it marks, ``other_flip``. numba prunes the ``is None`` branch when it compiles: only
    the one an arm needs is compiled."""
    if off_axis is None:
        closed_forms_on_roll_axis(pr, shape, x)
    else:
        closed_forms(pr, shape, x)
        for i in range(m):  # the other flip where it may matter (rare: see screen_flips)
            if x[POSE.other * BLOCK + i] != 0.0:
                other_flip(pr, shape, x, i)


@numba.njit(cache=True, nogil=True, fastmath=FAST, error_model="numpy")
def closed_forms(pr: Floats, shape: Floats, x: np.ndarray) -> None:
    """``closed_forms_of`` for a tool point off the roll axis (``F.OFF_AXIS`` not 0)."""
    wide_vectors()
    closed_forms_of(pr, shape, x, False)


@numba.njit(cache=True, nogil=True, fastmath=FAST, error_model="numpy")
def closed_forms_on_roll_axis(pr: Floats, shape: Floats, x: np.ndarray) -> None:
    """``closed_forms_of`` for a tool point on the roll axis (``F.OFF_AXIS`` 0)."""
    wide_vectors()
    closed_forms_of(pr, shape, x, True)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def closed_forms_of(pr: Floats, shape: Floats, x: np.ndarray, on_roll_axis: bool) -> None:
    """Both flips (a tool off the roll axis: the flip ``screen_flips`` picks, the other left out:
    no candidate, no fallback, unless ``screen_flips`` marks it for ``other_flip``) and elbows of
    the block's poses in the scratch rows (x[: POSE.rows * BLOCK], row k at x[k * BLOCK:]), and
    pose i's first candidate flip (flip 0 where it is a candidate, else
    flip 1) in the candidate rows (x[POSE.rows * BLOCK:], row k at x[POSE.rows * BLOCK + k *
    CANDIDATE_WIDTH:]):
    lane i its elbow up, lane BLOCK + i its elbow down (the target, q and its copy, the sines and
    cosines, near a fold, the flags cleared). One loop, no branch and no call (see the module
    docstring); one array at distances LLVM sees, so it needs no aliasing checks. The loop runs
    over the whole block (in a last block of fewer poses, the rows past them hold earlier poses
    or zeros, their results unused): with a constant count LLVM sees that no store reaches a
    target. on_roll_axis: a constant (``flip_geometry``), one compiled loop for each kind of
    tool."""
    for i in range(BLOCK):
        t = column_of(x, BLOCK, 0, i)
        roll = orientation_roll(pr, shape, t, 0)
        if on_roll_axis:  # both flips are often branches: both computed
            first = flip_geometry(pr, shape, t, 0, on_roll_axis, roll)
            other = flip_geometry(pr, shape, t, 1, on_roll_axis, roll)
            one, later = 0, False
        else:  # the flip whose yaw the position can match; the other where it may (screen_flips)
            one, later = screen_flips(pr, shape, t, roll)
            chosen = flip_geometry(pr, shape, t, one, on_roll_axis, roll)
            none = (chosen[0], False, False, 0.0, False)
            first = chosen if one == 0 else none
            other = chosen if one == 1 else none
        put_flip(x, i, 0, first)
        put_flip(x, i, 1, other)
        x[POSE.other * BLOCK + i] = (1.0 + one) if later else 0.0
        pick = first[1]  # flip 0 where it is a candidate (selects, scalar by scalar)
        g0, g1 = first[0], other[0]
        geometry = (
            g0[0] if pick else g1[0], g0[1] if pick else g1[1], g0[2] if pick else g1[2],
            g0[3] if pick else g1[3], g0[4] if pick else g1[4], g0[5] if pick else g1[5],
            g0[6] if pick else g1[6], g0[7] if pick else g1[7], g0[8] if pick else g1[8],
            g0[9] if pick else g1[9], g0[10] if pick else g1[10], g0[11] if pick else g1[11],
        )  # fmt: skip
        fold = first[4] if pick else other[4]
        up, down, sines_up, cosines_up, sines_down, cosines_down = flip_branches(
            pr, shape, geometry
        )
        put_candidate(x, i, t, up, sines_up, cosines_up, fold)
        put_candidate(x, BLOCK + i, t, down, sines_down, cosines_down, fold)
