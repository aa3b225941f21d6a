"""Numba kernel: the full-pose solver of ``pose_kernel`` over blocks of poses, vectorised.

The same solution as :func:`lynxplan.robots.ik.pose_kernel.solve_target` (read its docstring
for the geometry), laid out for SIMD: a block of :data:`BLOCK` poses is transposed into scratch
rows (one row per quantity, one column per pose) and each candidate branch (flip of the yaw,
elbow) is solved for the whole block by one loop without branches or calls, which LLVM turns
into vector instructions (the layout of :mod:`lynxplan.arm.ik_kernel`):

1. the closed form on the ideal model (yaw, pitch sum, roll, the side of the lateral offset
   whose yaw matches, the two-link shoulder and elbow); for a tool off the roll axis, of the
   flip of the yaw the position can match, the other flip only where it may (``_screen``);
2. on a model only close to the family, a fixed polish on the exact chain: two Gauss-Newton
   steps (pose and geometric Jacobian; where the pitch axes are parallel, as in the SO-101,
   solved by the family's structure, ``_newton_parallel``, else by an LDL^T factorisation of
   the normal equations): from ~1e-6 away the error falls to ~1e-12, then below rounding (a
   chord step in place of the second left ~6 % of the SO-101's candidates above
   VECTOR_EXACT); candidates that start farther away get a second polish, below;
3. the angles wrapped into the joint limits, and the pose of the exact chain at the final
   angles: the position and orientation errors that are reported. After a polish the sines
   and cosines of the final angles are carried from those of the start through each step and
   snap to the limits by their Taylor series (``_turn``: exact to rounding for steps up to
   TAYLOR_STEP, the only candidates taken there), not computed afresh.

A candidate is *taken* here only when its final errors are below :data:`VECTOR_EXACT` (far below
``POSE_EXACT``), and *rejected* (not an exact branch) when its error stopped falling far above
that. Any other candidate (still converging: next to a fold of the elbow Newton converges
linearly; or an ill-conditioned polish) that came within NOT_A_BRANCH of the pose is polished
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

import math

import numba
import numpy as np
from numba.np.unsafe.ndarray import to_fixed_tuple

from lynxplan import _fastmath
from lynxplan._fastmath import prefetch, prefetch_write, wide_vectors
from lynxplan.arm.ik_kernel import wrap_into_limits
from lynxplan.constants import (
    BRANCH_DUPLICATE_TOLERANCE,
    POSE_EXACT,
    VECTOR_EXACT,
)
from lynxplan.robots import family as F  # noqa: N812
from lynxplan.robots.ik.family_geometry import best_roll_terms, wrap
from lynxplan.robots.ik.family_polish import is_duplicate, rotation_angle, settle
from lynxplan.robots.ik.pose_kernel import (
    AXIAL_APPROACH,
    REACH_MISS,
    SLOT_COLUMNS,
    polish_pose,
    smallest_error,
    solve_target,
    write_slots,
    yaw_match,
)

_FAST = {"contract", "arcp"}  # fused multiply-adds, reciprocals: as in ``arm.ik_kernel``
#: Floats in registers: a pose (12, row-major 3 x 4), a Jacobian column (6), the parameters.
Floats = tuple[float, ...]
#: One flip (``_flip``): its geometry (12, where ``_branches`` finds the angles), candidate,
#: fallback, side, near a fold.
FlipBranches = tuple[Floats, bool, bool, float, bool]
#: One flip's branches (``_branches``): q of elbow up, q of elbow down, the sines and cosines of
#: elbow up's q, those of elbow down's (5 each).
Branches = tuple[Floats, Floats, Floats, Floats, Floats, Floats]
# The branch-free sine/cosine and arctangent, inlined by LLVM rather than by numba: numba's own
# inlining (``inline="always"``) of their ~40 call sites would multiply the compile time by 5.
sincos = numba.njit(nogil=True, fastmath=_FAST)(_fastmath.sincos.py_func)
atan2 = numba.njit(nogil=True, fastmath=_FAST)(_fastmath.atan2.py_func)
#: Poses per block (a constant width: the scratch rows never alias, see ``arm.ik_kernel``).
BLOCK = 32
#: A candidate whose final position [m] or orientation [rad] error is above NOT_A_BRANCH and has
#: stopped falling (at least STALLED times the error before the last step) is not an exact
#: branch: the orientation is out of reach on that flip, and the steps end at the residual of the
#: nearest orientation (~1e-4), as the scalar polish does, which rejects it too. A candidate
#: still falling there, or next to a fold of the elbow (where Newton's steps converge only
#: linearly: the roots are close), is finished by the scalar polish.
NOT_A_BRANCH, STALLED = 1e-6, 0.5
#: Next to a fold: |cos| of the elbow angle within this of 1 (an elbow ~0.045 rad from straight).
FOLD_BAND = 1e-3
#: A candidate whose step is this ill-conditioned (``_newton_ldl``: smallest over largest LDL^T
#: pivot of J^T J; ``_newton_parallel``: its two measures) is finished by the scalar polish.
ILL_CONDITIONED = 1e-8
#: Pitch axes parallel within this [rad] (and either sign) take ``_newton_parallel``'s steps:
#: the same Gauss-Newton step to ~1e-10 of its size, by the family's structure.
PARALLEL_PITCHES = 1e-10
_N_CHAIN = 12 + 4 * 6 + 12  # the base, four joint-to-joint links, the tool (``_chain_tuple``)
_N_PRM = F.N_PARAMS

# Pose scratch rows: the target (row-major 3 x 4), then per flip: its geometry (12: ``_flip``),
# candidate, fallback, side, near a fold (1/0); the pose's fallback.
_FLIP0 = 12
_F_CAND, _F_FALL, _F_SIDE, _F_FOLD = 12, 13, 14, 15
_PER_FLIP = 16
_POSE_FALL = _FLIP0 + 2 * _PER_FLIP
_POSE_OTHER = _POSE_FALL + 1  # 1 + the flip computed where the other is left (``_screen``)
_ROWS = _POSE_OTHER + 1
# Candidate scratch rows (up to 4 per pose): the target (12), q (5), near a fold, the error
# before the last step, then taken, fallback, within (1/0), position, orientation error,
# the closed-form q (5), and the sines and cosines of q (5 each) where the polish starts.
_C_Q, _C_FOLD, _C_PREV, _C_TAKE, _C_FALL, _C_IN, _C_PERR, _C_OERR = 12, 17, 18, 19, 20, 21, 22, 23
_C_START = 24  # the closed-form q (5), where a candidate that falls back starts
_C_SIN, _C_COS = 29, 34
_C_ROWS = 39
_CW = 4 * BLOCK  # the candidate rows' width
#: The candidate loops run on a multiple of this many lanes (AVX-512: 8 doubles).
LANES = 8
_ALL_TAKEN = np.ones(4, dtype=np.bool_)
#: The polish's steps [rad] up to which the sines and cosines of the new angles follow exactly
#: (to rounding) from those of the old by their Taylor series (``_turn``); a candidate with a
#: larger step is finished by the scalar polish.
TAYLOR_STEP = 1e-3
#: ... and up to which a candidate may be found not to be a branch: there the sines and cosines
#: are within FAR_STEP^6 / 720 (1.4e-9) of the exact ones, far below NOT_A_BRANCH.
FAR_STEP = 0.1
#: The margin [m per m of distance from the yaw axis] of the test that leaves a flip out
#: (``_screen``): ~1e5 times the rounding of the yaws it bounds.
OTHER_MARGIN = 1e-9
#: Both flips are computed where the approach's component along the yaw axis [1] or the
#: target's distance from it [m] is within this of 0 (the pitch sum or yaw may be degenerate).
OTHER_DEGENERATE = 1e-9


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _unit(y: float, x: float) -> tuple[float, float]:
    """(sin, cos) of the angle of the vector (x, y): the vector normalised, no trigonometry
    (NaN at the origin, where the callers leave the target to the scalar solver)."""
    inverse = 1.0 / math.sqrt(x * x + y * y)
    return y * inverse, x * inverse


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _pitch_sum(
    shape: Floats, a_h: float, a_p: float, a_k: float, s: float, c: float
) -> tuple[float, float, float, bool]:
    """Canonical pitch sum for the yaw of sine s and cosine c and the approach a (components
    along h, p, k): the angle, its sine and cosine, and whether it is degenerate (the approach
    along the pitch axis)."""
    x = c * a_h - s * a_p
    sx, cx = _unit(a_k, x)
    sg, cg = shape[4], shape[5]  # of gamma0: the pitch sum is atan2(a_k, x) - gamma0
    return (
        atan2(a_k, x) - shape[6],
        sx * cg - cx * sg,
        cx * cg + sx * sg,
        x * x + a_k * a_k <= 1e-24,
    )


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _roll_terms(
    pr: Floats, g: Floats, s_yaw: float, c_yaw: float, s_sum: float, c_sum: float
) -> tuple[float, float]:
    """(sin, cos) of the canonical roll nearest the target (``family_geometry.best_roll``) for
    the yaw and pitch sum of these sines and cosines; g: the 9 entries of G = Rt Rt0^T,
    row-major."""
    sine, cosine = best_roll_terms(pr, g, c_yaw, -s_yaw, c_sum, -s_sum)
    return _unit(sine, cosine)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _yaw(
    pr: Floats, rho: float, alpha: Floats, st: float, ct: float, side: int
) -> tuple[float, float, float, float, bool]:
    """Yaw of one side for the roll of sine st and cosine ct (``family_geometry.yaw``), its
    sine and cosine, the lateral miss [m], and whether the target is on the yaw axis (left to
    the scalar solver); alpha: the angle of the target about the yaw axis, its sine, cosine."""
    lat = pr[F.LAM4] + pr[F.W0 + 2] + ct * pr[F.E1 + 2] + st * pr[F.E2 + 2]
    on_axis = (rho <= 1e-12) & (abs(lat) <= 1e-12)
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


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _approach(pr: Floats, t: Floats) -> tuple[Floats, float, float, float, float, float, float]:
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


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _offset(pr: Floats, t: Floats) -> Floats:
    """The target t's (12) point less the yaw axis' point C1 [m] (3), its components along
    p, h and k, and rho, its distance from the yaw axis [m]."""
    d0, d1, d2 = t[3] - pr[F.C1], t[7] - pr[F.C1 + 1], t[11] - pr[F.C1 + 2]
    dp = d0 * pr[F.P] + d1 * pr[F.P + 1] + d2 * pr[F.P + 2]
    dh = d0 * pr[F.H] + d1 * pr[F.H + 1] + d2 * pr[F.H + 2]
    dk = d0 * pr[F.K] + d1 * pr[F.K + 1] + d2 * pr[F.K + 2]
    rho = math.sqrt(dp * dp + dh * dh)
    return d0, d1, d2, dp, dh, dk, rho


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _roll(pr: Floats, shape: Floats, t: Floats, flip: int) -> Floats:
    """(sin, cos) of the canonical roll nearest the target t (12) at flip ``flip``'s yaw (the
    orientation's, turned by flip pi: ``_roll_terms``). Flip 1 turns the yaw by pi and the
    pitch sum to its mirror: the same approach, the frame turned by pi about it, so its roll is
    flip 0's turned by pi (the same to rounding, as the tests check): the kernels compute
    flip 0's only."""
    g, _, _, _, a_h, a_p, a_k = _approach(pr, t)
    sign = 1.0 - 2.0 * flip
    s_phi, c_phi = _unit(-a_p, a_h)
    s_phi, c_phi = sign * s_phi, sign * c_phi
    _, s_big, c_big, _ = _pitch_sum(shape, a_h, a_p, a_k, s_phi, c_phi)
    return _roll_terms(pr, g, s_phi, c_phi, s_big, c_big)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _screen(pr: Floats, shape: Floats, t: Floats, roll: Floats) -> tuple[int, bool]:
    """For a tool off the roll axis: the flip whose yaw the target's position can match (of
    the smaller miss, below), and whether the other flip may be a candidate or send the pose
    to the scalar solver too (then ``_other_flip`` computes it; rare: the other flip's yaw
    misses by about twice the lateral offset over rho); roll: flip 0's (``_roll``).

    A side's yaw y = alpha +- beta matches flip f's yaw phi_f (the orientation's, turned by
    f pi) only where |y - phi_f| <= match_f (``yaw_match`` at flip f's lateral offset, the
    value ``_flip`` uses). cos is 1-Lipschitz and rho cos(y - alpha) = clamp(lateral_f, -rho,
    rho), so a match needs the miss |rho cos(phi_f - alpha) - clamp(lateral_f, -rho, rho)| <=
    rho match_f (rho: the target's distance from the yaw axis [m]; lateral_f [m]: the lateral
    offset at flip f's roll, flip 0's turned by pi), tested with a margin (OTHER_MARGIN) ~1e5
    times the rounding. A flip's own fallbacks need an approach square to the yaw axis (the
    pitch sum degenerate) or the target on the yaw axis (OTHER_DEGENERATE); the others are the
    same for both flips."""
    _, _, _, _, a_h, a_p, a_k = _approach(pr, t)
    axial = math.sqrt(a_h * a_h + a_p * a_p)
    _, _, _, dp, dh, _, rho = _offset(pr, t)
    s_phi, c_phi = _unit(-a_p, a_h)
    u = c_phi * dp + s_phi * dh  # rho cos(phi_0 - alpha)
    centre = pr[F.LAM4] + pr[F.W0 + 2]
    swing = roll[1] * pr[F.E1 + 2] + roll[0] * pr[F.E2 + 2]
    miss0 = abs(u - min(max(centre + swing, -rho), rho))
    miss1 = abs(-u - min(max(centre - swing, -rho), rho))
    one = 0 if miss0 <= miss1 else 1
    lateral = centre + swing if one else centre - swing  # the other flip's
    match = yaw_match(pr[F.DEVIATION], shape[0] + shape[1], axial, rho, lateral)
    tol = rho * match * (1.0 + 1e-6) + OTHER_MARGIN * max(1.0, rho)
    later = max(miss0, miss1) <= tol
    # a NaN anywhere: not <=, and flip 0's own tests (not finite) send the pose to the scalar
    return one, later | (abs(a_k) <= OTHER_DEGENERATE) | (rho <= OTHER_DEGENERATE)


@numba.njit(cache=True, nogil=True, fastmath=_FAST, error_model="numpy")
def _other_flip(pr: Floats, shape: Floats, x: np.ndarray, i: int) -> None:
    """The flip of pose i that ``_closed_forms`` left out (``_screen``; its row _POSE_OTHER:
    1 + the flip it computed) into the scratch rows x, and pose i's candidate lanes then from
    flip 0 where it is a candidate, else from flip 1 (as for a tool on the roll axis)."""
    t = _column_of(x, BLOCK, 0, i)
    computed = 0 if x[_POSE_OTHER * BLOCK + i] == 1.0 else 1
    missing = 1 - computed
    _put_flip(x, i, missing, _flip(pr, shape, t, missing, False, _roll(pr, shape, t, 0)))
    pick = 0 if x[(_FLIP0 + _F_CAND) * BLOCK + i] != 0.0 else 1
    if pick != computed:  # the lanes hold the computed flip's branches
        first = _FLIP0 + pick * _PER_FLIP
        fold = x[(first + _F_FOLD) * BLOCK + i] != 0.0
        up, down, s_up, c_up, s_down, c_down = _branches(pr, shape, _column_of(x, BLOCK, first, i))
        _put_candidate(x, i, t, up, s_up, c_up, fold)
        _put_candidate(x, BLOCK + i, t, down, s_down, c_down, fold)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _flip(
    pr: Floats, shape: Floats, t: Floats, flip: int, on_roll_axis: bool, roll: Floats
) -> FlipBranches:
    """One flip of the yaw (both elbows) of the target t (12: row-major 3 x 4) on the ideal
    model: (its geometry, where ``_branches`` finds the angles, candidate, fallback, side, near
    a fold of the elbow); on_roll_axis: the tool point on the roll axis (``F.OFF_AXIS`` 0: the
    roll is then the side's; a constant, so the roll of the other kind is not computed at all);
    roll: flip 0's (sin, cos) of the roll the orientation gives (``_roll``; flip 1's is it
    turned by pi); shape: (la, lb, b2, b3) of the two links
    (``family_geometry.two_link``), sin, cos and the angle gamma0, sin and cos of b2 and of
    b2 - b3.

    The angles enter the geometry through their sines and cosines, which come from the vectors
    that define them (normalised): arctangents only for the yaw (two of them shared by both
    flips), no sine or cosine; the other angles' arctangents are left to ``_branches``, for
    the flip that is taken."""
    g, a0, a1, a2, a_h, a_p, a_k = _approach(pr, t)
    axial_size = math.sqrt(a_h * a_h + a_p * a_p)
    axial = axial_size <= AXIAL_APPROACH
    d0, d1, d2, dp, dh, dk, rho = _offset(pr, t)
    # the yaw that puts the approach in the arm plane, flipped by pi: its sine and cosine flip
    sign = 1.0 - 2.0 * flip
    phi = atan2(-a_p, a_h) + flip * math.pi
    s_phi, c_phi = _unit(-a_p, a_h)
    s_phi, c_phi = sign * s_phi, sign * c_phi
    flat1 = _pitch_sum(shape, a_h, a_p, a_k, s_phi, c_phi)[3]
    st, ct = sign * roll[0], sign * roll[1]  # flip 1's roll is flip 0's turned by pi
    s_alpha, c_alpha = _unit(dh, dp)
    alpha = (atan2(dh, dp), s_alpha, c_alpha)
    lat = pr[F.LAM4] + pr[F.W0 + 2] + ct * pr[F.E1 + 2] + st * pr[F.E2 + 2]
    match = yaw_match(pr[F.DEVIATION], shape[0] + shape[1], axial_size, rho, lat)
    yaw0, s_yaw0, c_yaw0, lat_miss, on_axis = _yaw(pr, rho, alpha, st, ct, 0)
    yaw1, s_yaw1, c_yaw1, _, _ = _yaw(pr, rho, alpha, st, ct, 1)
    lat_ok = lat_miss <= REACH_MISS
    ok0 = lat_ok & (abs(wrap(yaw0 - phi)) <= match)
    ok1 = lat_ok & (abs(wrap(yaw1 - phi)) <= match)
    side = 1.0 if ok1 else 0.0
    phi2 = yaw1 if ok1 else yaw0
    s2, c2 = (s_yaw1, c_yaw1) if ok1 else (s_yaw0, c_yaw0)
    _, sp, cp, flat2 = _pitch_sum(shape, a_h, a_p, a_k, s2, c2)
    if on_roll_axis:  # a tool on the roll axis: the roll of the side's yaw
        st, ct = _roll_terms(pr, g, s2, c2, sp, cp)
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
    fold_start = (pr[F.EXACT] == 0.0) & (abs(cosd) > 1.0 - 1e-6)
    fold = abs(cosd) > 1.0 - FOLD_BAND
    miss = math.sqrt(reach * reach + lat_miss * lat_miss)
    candidate = (ok0 | ok1) & (miss <= REACH_MISS)
    finite = math.isfinite(d0 + d1 + d2 + a0 + a1 + a2 + g[0] + g[4] + g[8])
    fallback = axial | flat1 | flat2 | on_axis | (ok0 & ok1) | (candidate & fold_start)
    fallback |= not finite
    x_pitch = c2 * a_h - s2 * a_p  # the pitch sum is atan2(a_k, x_pitch) - gamma0
    geometry = (phi2, s2, c2, a_k, x_pitch, sp, cp, st, ct, rx, ry, cosd)
    return geometry, candidate, fallback, side, fold


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _branches(pr: Floats, shape: Floats, geometry: Floats) -> Branches:
    """The angles q (5) of elbow up and of elbow down of one flip, and their sines and
    cosines (5 each), from its geometry (``_flip``): the yaw, its sine and cosine, the
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
    s_to, c_to = _unit(ry, rx)
    s_be, c_be = _unit(lb * sd, la + lb * cd)
    sines_up, cosines_up = _elbow_terms(shape, sigma, s_to, c_to, s_be, c_be, -sd, cd, sp, cp)
    sines_down, cosines_down = _elbow_terms(shape, sigma, s_to, c_to, -s_be, c_be, sd, cd, sp, cp)
    s1, s5 = sigma[0] * s2, sigma[4] * st
    return (
        up,
        down,
        (s1, sines_up[0], sines_up[1], sines_up[2], s5),
        (c2, cosines_up[0], cosines_up[1], cosines_up[2], ct),
        (s1, sines_down[0], sines_down[1], sines_down[2], s5),
        (c2, cosines_down[0], cosines_down[1], cosines_down[2], ct),
    )


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _elbow_terms(
    shape: Floats,
    sigma: Floats,
    s_to: float,
    c_to: float,
    s_be: float,
    c_be: float,
    s_de: float,
    c_de: float,
    s_big: float,
    c_big: float,
) -> tuple[Floats, Floats]:
    """The sines and cosines of q2, q3, q4 of one elbow (``_flip``): q2 = toward + bend - b2,
    q3 = b2 - b3 + delta' and q4 = big - q2 - q3, each times its sign sigma (5, all joints),
    from the sines and cosines of toward, bend (its sign the elbow's), delta' (-delta for the
    elbow up) and the pitch sum big; shape[7:11]: those of b2 and b2 - b3."""
    s_b2, c_b2, s_23, c_23 = shape[7], shape[8], shape[9], shape[10]
    s_a, c_a = s_to * c_be + c_to * s_be, c_to * c_be - s_to * s_be  # toward + bend
    s_q2, c_q2 = s_a * c_b2 - c_a * s_b2, c_a * c_b2 + s_a * s_b2
    s_q3, c_q3 = s_23 * c_de + c_23 * s_de, c_23 * c_de - s_23 * s_de
    s_23q, c_23q = s_q2 * c_q3 + c_q2 * s_q3, c_q2 * c_q3 - s_q2 * s_q3  # q2 + q3
    s_q4, c_q4 = s_big * c_23q - c_big * s_23q, c_big * c_23q + s_big * s_23q
    return (sigma[1] * s_q2, sigma[2] * s_q3, sigma[3] * s_q4), (c_q2, c_q3, c_q4)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _joint_turned(ch: Floats, j: int, t: Floats, s: float, c: float) -> Floats:
    """The running pose t (12: row-major 3 x 4) times R(z, q_{j+1}) N_{j+2} (N_tool after the
    last joint); ch: the chain tuple (``_chain_tuple``). Between two joints, N = R(z, phi)
    R(x, beta) with a translation (px, py, 0) in the frame turned by q + phi, stored as (cos phi,
    sin phi, cos beta, sin beta, px, py): s and c are then the sine and cosine of q + phi
    (``_offsets``), and only beta and the translation are applied here; the tool's is a 3 x 4
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


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _axis_of(t: Floats) -> Floats:
    """A joint's origin and world axis (its z axis) from the running pose t before its
    rotation."""
    return t[3], t[7], t[11], t[2], t[6], t[10]


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _base(ch: Floats) -> Floats:
    """N_1 (``_chain_tuple``: 12, row-major 3 x 4), where every pose starts."""
    return ch[0], ch[1], ch[2], ch[3], ch[4], ch[5], ch[6], ch[7], ch[8], ch[9], ch[10], ch[11]


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _fk(ch: Floats, q0: float, q1: float, q2: float, q3: float, q4: float) -> Floats:
    """Tool pose (12: row-major 3 x 4) of the chain at q."""
    s0, c0 = sincos(q0)
    s1, c1 = sincos(q1)
    s2, c2 = sincos(q2)
    s3, c3 = sincos(q3)
    s4, c4 = sincos(q4)
    sn, cs = _offsets(ch, (s0, s1, s2, s3, s4), (c0, c1, c2, c3, c4))
    return _fk_turned(ch, sn, cs)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _offsets(ch: Floats, sn: Floats, cs: Floats) -> tuple[Floats, Floats]:
    """The sines and cosines of q + phi (``_chain_tuple``: phi of joint 1 and joint 5 is 0) from
    those of q (5 each), which ``_joint_turned`` takes."""
    s1, c1 = sn[1] * ch[18] + cs[1] * ch[19], cs[1] * ch[18] - sn[1] * ch[19]
    s2, c2 = sn[2] * ch[24] + cs[2] * ch[25], cs[2] * ch[24] - sn[2] * ch[25]
    s3, c3 = sn[3] * ch[30] + cs[3] * ch[31], cs[3] * ch[30] - sn[3] * ch[31]
    return (sn[0], s1, s2, s3, sn[4]), (cs[0], c1, c2, c3, cs[4])


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _column(o: Floats, p: Floats) -> Floats:
    """Geometric Jacobian column (6) of a joint with origin/axis o (6) for the tool point p."""
    dx, dy, dz = p[3] - o[0], p[7] - o[1], p[11] - o[2]
    wx, wy, wz = o[3], o[4], o[5]
    return (wy * dz - wz * dy, wz * dx - wx * dz, wx * dy - wy * dx, wx, wy, wz)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _error(p: Floats, t: Floats) -> Floats:
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


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _dot6(a: Floats, b: Floats) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5]


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _ldl(
    j0: Floats, j1: Floats, j2: Floats, j3: Floats, j4: Floats
) -> tuple[Floats, Floats, float]:
    """LDL^T factors of J^T J for the Jacobian columns j0..j4 (6 each): the strict lower
    triangle (10, row-major) and the inverse pivots (5)."""
    n00, n11, n22, n33, n44 = (
        _dot6(j0, j0),
        _dot6(j1, j1),
        _dot6(j2, j2),
        _dot6(j3, j3),
        _dot6(j4, j4),
    )
    n10, n20, n30, n40 = _dot6(j1, j0), _dot6(j2, j0), _dot6(j3, j0), _dot6(j4, j0)
    n21, n31, n41 = _dot6(j2, j1), _dot6(j3, j1), _dot6(j4, j1)
    n32, n42, n43 = _dot6(j3, j2), _dot6(j4, j2), _dot6(j4, j3)
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


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _step(
    lower: Floats,
    inverse: Floats,
    j0: Floats,
    j1: Floats,
    j2: Floats,
    j3: Floats,
    j4: Floats,
    e: Floats,
) -> Floats:
    """The Gauss-Newton step x = (J^T J)^-1 J^T e from the LDL^T factors (``_ldl``)."""
    l10, l20, l21, l30, l31, l32, l40, l41, l42, l43 = lower
    y0 = _dot6(j0, e)
    y1 = _dot6(j1, e) - l10 * y0
    y2 = _dot6(j2, e) - l20 * y0 - l21 * y1
    y3 = _dot6(j3, e) - l30 * y0 - l31 * y1 - l32 * y2
    y4 = _dot6(j4, e) - l40 * y0 - l41 * y1 - l42 * y2 - l43 * y3
    x4 = y4 * inverse[4]
    x3 = y3 * inverse[3] - l43 * x4
    x2 = y2 * inverse[2] - l32 * x3 - l42 * x4
    x1 = y1 * inverse[1] - l21 * x2 - l31 * x3 - l41 * x4
    x0 = y0 * inverse[0] - l10 * x1 - l20 * x2 - l30 * x3 - l40 * x4
    return x0, x1, x2, x3, x4


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _turn(s: float, c: float, x: float) -> tuple[float, float]:
    """(sin, cos) of the angle a - x from s = sin a and c = cos a: the angle difference, with
    sin x and cos x to fifth order (the remainder below x^6 / 720: rounding for |x| <=
    TAYLOR_STEP)."""
    xx = x * x
    sx = x * (1.0 - xx * (1.0 / 6.0) * (1.0 - xx * (1.0 / 20.0)))
    cx = 1.0 - xx * 0.5 * (1.0 - xx * (1.0 / 12.0))
    return s * cx - c * sx, c * cx + s * sx


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _stepped(q: Floats, sn: Floats, cs: Floats, x: Floats) -> tuple[Floats, Floats, Floats]:
    """The angles q - x (5) and their sines and cosines turned from sn, cs (:func:`_turn`)."""
    s0, c0 = _turn(sn[0], cs[0], x[0])
    s1, c1 = _turn(sn[1], cs[1], x[1])
    s2, c2 = _turn(sn[2], cs[2], x[2])
    s3, c3 = _turn(sn[3], cs[3], x[3])
    s4, c4 = _turn(sn[4], cs[4], x[4])
    return (
        (q[0] - x[0], q[1] - x[1], q[2] - x[2], q[3] - x[3], q[4] - x[4]),
        (s0, s1, s2, s3, s4),
        (c0, c1, c2, c3, c4),
    )


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _fk_axes(
    ch: Floats, sn: Floats, cs: Floats
) -> tuple[Floats, Floats, Floats, Floats, Floats, Floats]:
    """The origin and world axis of each joint (6 each, ``_axis_of``) and the tool pose (12)
    of the chain at the angles of sines sn and cosines cs."""
    p = _base(ch)
    o0 = _axis_of(p)
    p = _joint_turned(ch, 0, p, sn[0], cs[0])
    o1 = _axis_of(p)
    p = _joint_turned(ch, 1, p, sn[1], cs[1])
    o2 = _axis_of(p)
    p = _joint_turned(ch, 2, p, sn[2], cs[2])
    o3 = _axis_of(p)
    p = _joint_turned(ch, 3, p, sn[3], cs[3])
    o4 = _axis_of(p)
    return o0, o1, o2, o3, o4, _joint_turned(ch, 4, p, sn[4], cs[4])


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _newton_ldl(ch: Floats, t: Floats, q: Floats, sn: Floats, cs: Floats) -> Floats:
    """One Gauss-Newton step on the exact chain from q (5), sn and cs the sines and cosines of
    q + phi (``_offsets``): the step x (5; the new angles are q - x), the smallest over the
    largest LDL^T pivot of J^T J (its conditioning), and the largest component of the pose
    error at q."""
    o0, o1, o2, o3, o4, p = _fk_axes(ch, sn, cs)
    j0, j1, j2 = _column(o0, p), _column(o1, p), _column(o2, p)
    j3, j4 = _column(o3, p), _column(o4, p)
    lower, inverse, ratio = _ldl(j0, j1, j2, j3, j4)
    e = _error(p, t)
    size = max(abs(e[0]), abs(e[1]), abs(e[2]), abs(e[3]), abs(e[4]), abs(e[5]))
    x = _step(lower, inverse, j0, j1, j2, j3, j4, e)
    return x[0], x[1], x[2], x[3], x[4], ratio, size


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _cross(a0: float, a1: float, a2: float, b0: float, b1: float, b2: float) -> Floats:
    """The cross product of (a0, a1, a2) and (b0, b1, b2)."""
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _newton_parallel(ch: Floats, t: Floats, q: Floats, sn: Floats, cs: Floats) -> Floats:
    """``_newton_ldl``'s Gauss-Newton step (the same x = J^+ e, the same outputs; its
    conditioning here: the smaller of two, below) for a chain whose pitch axes are parallel
    (``_parallel_pitches``: each pitch column's axis is +-h, joint 3's), solved by the family's
    structure instead of the 5 x 5 normal equations.

    With the pitch angles' effects on the orientation summed (xs = s2 x2 + x3 + s4 x4 in the
    signs s of the axes against h), the position across h is met exactly by the first two
    pitch steps for any yaw, pitch-sum and roll steps (the pitch joints' origins span the plane
    across h: a 2 x 2 system, singular at a fold of the elbow); so x0, xs, x4 are the least
    squares solution of the four rows left, the orientation's and the position along h (3 x 3
    normal equations, by cofactors), then the pitch steps follow from the 2 x 2. Conditioning:
    the smaller of det N / (N00 N11 N22) of those normal equations and the squared sine of the
    elbow's triangle of pitch origins."""
    o0, o1, o2, o3, o4, p = _fk_axes(ch, sn, cs)
    e = _error(p, t)
    size = max(abs(e[0]), abs(e[1]), abs(e[2]), abs(e[3]), abs(e[4]), abs(e[5]))
    s1, s3 = _pitch_signs(ch)
    k0, k1, k2 = o0[3], o0[4], o0[5]
    h0, h1, h2 = o2[3], o2[4], o2[5]
    a0, a1, a2 = o4[3], o4[4], o4[5]
    px, py, pz = p[3], p[7], p[11]
    v0 = _cross(k0, k1, k2, px - o0[0], py - o0[1], pz - o0[2])
    v4 = _cross(a0, a1, a2, px - o4[0], py - o4[1], pz - o4[2])
    v3 = _cross(h0, h1, h2, px - o3[0], py - o3[1], pz - o3[2])
    x0, xs, x4, cond3 = _sum_steps(o0[3:], o2[3:], o4[3:], v0, v4, e)
    # across h: h x (A y1 + B y2) = w, A and B from the pitch origins (y: the signed steps)
    w0 = e[0] - v0[0] * x0 - v4[0] * x4 - v3[0] * xs
    w1 = e[1] - v0[1] * x0 - v4[1] * x4 - v3[1] * xs
    w2 = e[2] - v0[2] * x0 - v4[2] * x4 - v3[2] * xs
    y = _cross(w0, w1, w2, h0, h1, h2)
    b0, b1, b2 = o3[0] - o1[0], o3[1] - o1[1], o3[2] - o1[2]
    d0, d1, d2 = o3[0] - o2[0], o3[1] - o2[1], o3[2] - o2[2]
    bd = _cross(b0, b1, b2, d0, d1, d2)
    det2 = bd[0] * h0 + bd[1] * h1 + bd[2] * h2
    inv2 = 1.0 / det2
    yd = _cross(y[0], y[1], y[2], d0, d1, d2)
    by = _cross(b0, b1, b2, y[0], y[1], y[2])
    y1 = (yd[0] * h0 + yd[1] * h1 + yd[2] * h2) * inv2
    y2 = (by[0] * h0 + by[1] * h1 + by[2] * h2) * inv2
    lengths = (b0 * b0 + b1 * b1 + b2 * b2) * (d0 * d0 + d1 * d1 + d2 * d2)
    ratio = min(cond3, det2 * det2 / lengths)
    return x0, s1 * y1, y2, s3 * (xs - y1 - y2), x4, ratio, size


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _sum_steps(k: Floats, h: Floats, a: Floats, v0: Floats, v4: Floats, e: Floats) -> Floats:
    """(``_newton_parallel``) The yaw, pitch-sum and roll steps x0, xs, x4: the least squares
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


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _pitch_signs(ch: Floats) -> tuple[float, float]:
    """The signs of joints 2 and 4's axes against joint 3's (the cosines of beta of the links
    2-3 and 3-4 in ``_chain_tuple``; +-1 where the pitch axes are parallel)."""
    return math.copysign(1.0, ch[20]), math.copysign(1.0, ch[26])


@numba.njit(cache=True, nogil=True)
def _parallel_pitches(ch: Floats) -> bool:
    """Whether the pitch axes are parallel within PARALLEL_PITCHES (the sines of beta of the
    links 2-3 and 3-4 in ``_chain_tuple``): then ``_newton_parallel`` takes the steps."""
    return (abs(ch[21]) <= PARALLEL_PITCHES) & (abs(ch[27]) <= PARALLEL_PITCHES)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _newton(ch: Floats, t: Floats, q: Floats, sn: Floats, cs: Floats, parallel: bool) -> Floats:
    """One Gauss-Newton step (``_newton_ldl``; ``_newton_parallel`` where the pitch axes are
    parallel: parallel must be a constant)."""
    if parallel:
        return _newton_parallel(ch, t, q, sn, cs)
    return _newton_ldl(ch, t, q, sn, cs)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _polish(
    ch: Floats, t: Floats, q: Floats, sn: Floats, cs: Floats, parallel: bool
) -> tuple[Floats, Floats, Floats, float, float, float]:
    """Two Gauss-Newton steps on the exact chain from q (5), sn and cs the sines and cosines of
    q + phi (``_offsets``): the final q, those sines and cosines, the smaller of the two
    conditionings (``_newton``; parallel: a constant), the largest component of the pose error
    before the last step, and the largest step [rad] of either.

    The sines and cosines after each step follow from the ones before it (``_turn``): exact to
    rounding where the steps are within TAYLOR_STEP, and still good enough for the second
    step's direction where they are not."""
    x0, x1, x2, x3, x4, first, _ = _newton(ch, t, q, sn, cs, parallel)
    big = max(abs(x0), abs(x1), abs(x2), abs(x3), abs(x4))
    q, sn, cs = _stepped(q, sn, cs, (x0, x1, x2, x3, x4))
    x0, x1, x2, x3, x4, second, size = _newton(ch, t, q, sn, cs, parallel)
    big = max(big, abs(x0), abs(x1), abs(x2), abs(x3), abs(x4))
    q, sn, cs = _stepped(q, sn, cs, (x0, x1, x2, x3, x4))
    return q, sn, cs, min(first, second), size, big


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _fk_turned(ch: Floats, sn: Floats, cs: Floats) -> Floats:
    """Tool pose (12: row-major 3 x 4) of the chain at the angles of sines sn and cosines cs."""
    t = _base(ch)
    t = _joint_turned(ch, 0, t, sn[0], cs[0])
    t = _joint_turned(ch, 1, t, sn[1], cs[1])
    t = _joint_turned(ch, 2, t, sn[2], cs[2])
    t = _joint_turned(ch, 3, t, sn[3], cs[3])
    return _joint_turned(ch, 4, t, sn[4], cs[4])


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _rotation_angle(p: Floats, t: Floats) -> float:
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


@numba.njit(cache=True, nogil=True, fastmath=_FAST, error_model="numpy")
def _closed_forms(pr: Floats, shape: Floats, x: np.ndarray) -> None:
    """``_closed_forms_of`` for a tool point off the roll axis (``F.OFF_AXIS`` not 0)."""
    wide_vectors()
    _closed_forms_of(pr, shape, x, False)


@numba.njit(cache=True, nogil=True, fastmath=_FAST, error_model="numpy")
def _closed_forms_on_roll_axis(pr: Floats, shape: Floats, x: np.ndarray) -> None:
    """``_closed_forms_of`` for a tool point on the roll axis (``F.OFF_AXIS`` 0)."""
    wide_vectors()
    _closed_forms_of(pr, shape, x, True)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _closed_forms_of(pr: Floats, shape: Floats, x: np.ndarray, on_roll_axis: bool) -> None:
    """Both flips (a tool off the roll axis: the flip ``_screen`` picks, the other left out:
    no candidate, no fallback, unless ``_screen`` marks it for ``_other_flip``) and elbows of
    the block's poses in the scratch rows (x[: _ROWS * BLOCK], row k at x[k * BLOCK:]), and
    pose i's first candidate flip (flip 0 where it is a candidate, else
    flip 1) in the candidate rows (x[_ROWS * BLOCK:], row k at x[_ROWS * BLOCK + k * _CW:]):
    lane i its elbow up, lane BLOCK + i its elbow down (the target, q and its copy, the sines and
    cosines, near a fold, the flags cleared). One loop, no branch and no call (see the module
    docstring); one array at distances LLVM sees, so it needs no aliasing checks. The loop runs
    over the whole block (in a last block of fewer poses, the rows past them hold earlier poses
    or zeros, their results unused): with a constant count LLVM sees that no store reaches a
    target. on_roll_axis: a constant (``_flip``), one compiled loop for each kind of tool."""
    for i in range(BLOCK):
        t = _column_of(x, BLOCK, 0, i)
        roll = _roll(pr, shape, t, 0)
        if on_roll_axis:  # both flips are often branches: both computed
            first = _flip(pr, shape, t, 0, on_roll_axis, roll)
            other = _flip(pr, shape, t, 1, on_roll_axis, roll)
            one, later = 0, False
        else:  # the flip whose yaw the position can match; the other where it may (_screen)
            one, later = _screen(pr, shape, t, roll)
            chosen = _flip(pr, shape, t, one, on_roll_axis, roll)
            none = (chosen[0], False, False, 0.0, False)
            first = chosen if one == 0 else none
            other = chosen if one == 1 else none
        _put_flip(x, i, 0, first)
        _put_flip(x, i, 1, other)
        x[_POSE_OTHER * BLOCK + i] = (1.0 + one) if later else 0.0
        pick = first[1]  # flip 0 where it is a candidate (selects, scalar by scalar)
        g0, g1 = first[0], other[0]
        geometry = (
            g0[0] if pick else g1[0], g0[1] if pick else g1[1], g0[2] if pick else g1[2],
            g0[3] if pick else g1[3], g0[4] if pick else g1[4], g0[5] if pick else g1[5],
            g0[6] if pick else g1[6], g0[7] if pick else g1[7], g0[8] if pick else g1[8],
            g0[9] if pick else g1[9], g0[10] if pick else g1[10], g0[11] if pick else g1[11],
        )  # fmt: skip
        fold = first[4] if pick else other[4]
        up, down, sines_up, cosines_up, sines_down, cosines_down = _branches(pr, shape, geometry)
        _put_candidate(x, i, t, up, sines_up, cosines_up, fold)
        _put_candidate(x, BLOCK + i, t, down, sines_down, cosines_down, fold)


@numba.njit(cache=True, nogil=True, inline="always")
def _put_flip(x: np.ndarray, i: int, flip: int, branches: FlipBranches) -> None:
    """One flip of pose i (``_flip``) into the scratch rows x (``_closed_forms``)."""
    geometry, cand, fall, side, fold = branches
    base = (_FLIP0 + flip * _PER_FLIP) * BLOCK + i
    x[base], x[base + BLOCK], x[base + 2 * BLOCK] = geometry[0], geometry[1], geometry[2]
    x[base + 3 * BLOCK], x[base + 4 * BLOCK] = geometry[3], geometry[4]
    x[base + 5 * BLOCK], x[base + 6 * BLOCK] = geometry[5], geometry[6]
    x[base + 7 * BLOCK], x[base + 8 * BLOCK] = geometry[7], geometry[8]
    x[base + 9 * BLOCK], x[base + 10 * BLOCK] = geometry[9], geometry[10]
    x[base + 11 * BLOCK] = geometry[11]
    x[base + _F_CAND * BLOCK] = 1.0 if cand else 0.0
    x[base + _F_FALL * BLOCK] = 1.0 if fall else 0.0
    x[base + _F_SIDE * BLOCK] = side
    x[base + _F_FOLD * BLOCK] = 1.0 if fold else 0.0


@numba.njit(cache=True, nogil=True, inline="always")
def _put_candidate(
    x: np.ndarray, lane: int, t: Floats, q: Floats, sines: Floats, cosines: Floats, fold: bool
) -> None:
    """A candidate of target t (12) at angles q (5) of these sines and cosines into lane
    ``lane`` of the candidate rows of x (``_closed_forms``), its flags cleared (written out:
    a loop here would keep the caller's loop from vectorising)."""
    b = _ROWS * BLOCK + lane
    x[b], x[b + _CW], x[b + 2 * _CW], x[b + 3 * _CW] = t[0], t[1], t[2], t[3]
    x[b + 4 * _CW], x[b + 5 * _CW], x[b + 6 * _CW], x[b + 7 * _CW] = t[4], t[5], t[6], t[7]
    x[b + 8 * _CW], x[b + 9 * _CW], x[b + 10 * _CW], x[b + 11 * _CW] = t[8], t[9], t[10], t[11]
    _put5(x, b + _C_Q * _CW, q)
    _put5(x, b + _C_START * _CW, q)
    _put5(x, b + _C_SIN * _CW, sines)
    _put5(x, b + _C_COS * _CW, cosines)
    x[b + _C_FOLD * _CW] = 1.0 if fold else 0.0
    x[b + _C_FALL * _CW] = 0.0
    x[b + _C_PREV * _CW] = 0.0


@numba.njit(cache=True, nogil=True, inline="always")
def _put5(x: np.ndarray, b: int, v: Floats) -> None:
    """v (5) into x[b + k * _CW], k = 0..4 (five candidate rows)."""
    x[b], x[b + _CW], x[b + 2 * _CW], x[b + 3 * _CW], x[b + 4 * _CW] = v[0], v[1], v[2], v[3], v[4]


@numba.njit(cache=True, nogil=True, inline="always")
def _column_of(rows: np.ndarray, width: int, first: int, i: int) -> Floats:
    """The 12 values rows[(first + k) * width + i], k = 0..11 (a target, row-major 3 x 4)."""
    b = first * width + i
    return (
        rows[b], rows[b + width], rows[b + 2 * width], rows[b + 3 * width],
        rows[b + 4 * width], rows[b + 5 * width], rows[b + 6 * width], rows[b + 7 * width],
        rows[b + 8 * width], rows[b + 9 * width], rows[b + 10 * width], rows[b + 11 * width],
    )  # fmt: skip


@numba.njit(cache=True, nogil=True, inline="always")
def _column_of5(c: np.ndarray, first: int, i: int) -> Floats:
    """The 5 values c[(first + k) * _CW + i], k = 0..4, of the candidate rows c."""
    b = first * _CW + i
    return c[b], c[b + _CW], c[b + 2 * _CW], c[b + 3 * _CW], c[b + 4 * _CW]


@numba.njit(cache=True, nogil=True, inline="always")
def _angles_of(c: np.ndarray, i: int) -> Floats:
    """Candidate i's five angles from the candidate rows c."""
    b = _C_Q * _CW + i
    return c[b], c[b + _CW], c[b + 2 * _CW], c[b + 3 * _CW], c[b + 4 * _CW]


@numba.njit(cache=True, nogil=True, inline="always")
def _put_angles(
    c: np.ndarray, i: int, q0: float, q1: float, q2: float, q3: float, q4: float
) -> None:
    """Candidate i's five angles into the candidate rows c."""
    b = _C_Q * _CW + i
    c[b], c[b + _CW], c[b + 2 * _CW], c[b + 3 * _CW], c[b + 4 * _CW] = q0, q1, q2, q3, q4


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _wrapped(pr: Floats, q: Floats) -> Floats:
    """The angles q (5) wrapped into the limits (``wrap_into_limits``), and whether all are
    within them (1/0)."""
    tol = pr[F.LIMIT_TOL]
    lo = (pr[F.LOWER], pr[F.LOWER + 1], pr[F.LOWER + 2], pr[F.LOWER + 3], pr[F.LOWER + 4])
    hi = (pr[F.UPPER], pr[F.UPPER + 1], pr[F.UPPER + 2], pr[F.UPPER + 3], pr[F.UPPER + 4])
    q0, in0 = wrap_into_limits(q[0], lo[0], hi[0], tol)
    q1, in1 = wrap_into_limits(q[1], lo[1], hi[1], tol)
    q2, in2 = wrap_into_limits(q[2], lo[2], hi[2], tol)
    q3, in3 = wrap_into_limits(q[3], lo[3], hi[3], tol)
    q4, in4 = wrap_into_limits(q[4], lo[4], hi[4], tol)
    return q0, q1, q2, q3, q4, 1.0 if in0 & in1 & in2 & in3 & in4 else 0.0


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _snap(q: float, w: float) -> float:
    """The angle [rad] between q and its wrapped w, less whole turns: what the limits snapped."""
    d = q - w
    return d - math.floor(d * (0.5 / math.pi) + 0.5) * (2.0 * math.pi)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _verdict(t: Floats, p: Floats, prev: float, fold: float) -> Floats:
    """A candidate's position and orientation errors from its pose p on the exact chain at its
    final angles, taken (1/0), and whether it is not a branch (1/0: its error is above
    NOT_A_BRANCH and stopped falling, from prev before the last step, away from a fold (fold
    0); see the module docstring)."""
    dx, dy, dz = p[3] - t[3], p[7] - t[7], p[11] - t[11]
    err = math.sqrt(dx * dx + dy * dy + dz * dz)
    angle = _rotation_angle(p, t)
    good = (err <= VECTOR_EXACT) & (angle <= VECTOR_EXACT)
    final = max(err, angle)
    far = (final > NOT_A_BRANCH) & (final >= STALLED * prev) & (fold == 0.0)
    return err, angle, 1.0 if good else 0.0, 1.0 if far else 0.0


@numba.njit(cache=True, nogil=True, fastmath=_FAST, error_model="numpy")
def _settle_all(m: int, pr: Floats, ch: Floats, c: np.ndarray) -> None:
    """The m candidates in the rows c (flat: row k is c[k * _CW:]) as they are (an exact model
    of the family: no polish), wrapped into the limits, and the verdict (``_verdict``) at the
    final angles: taken, fallback (see the module docstring), or neither (not a branch)."""
    wide_vectors()
    for i in range(m):
        t = _column_of(c, _CW, 0, i)
        q0, q1, q2, q3, q4, inside = _wrapped(pr, _angles_of(c, i))
        p = _fk(ch, q0, q1, q2, q3, q4)
        prev, fold = c[_C_PREV * _CW + i], c[_C_FOLD * _CW + i]
        err, angle, good, far = _verdict(t, p, prev, fold)
        _put_angles(c, i, q0, q1, q2, q3, q4)
        c[_C_TAKE * _CW + i] = good
        c[_C_FALL * _CW + i] = 1.0 if (good == 0.0) & (far == 0.0) else 0.0
        c[_C_IN * _CW + i] = inside
        c[_C_PERR * _CW + i] = err
        c[_C_OERR * _CW + i] = angle


@numba.njit(cache=True, nogil=True, fastmath=_FAST, error_model="numpy")
def _polish_settle_all(m: int, pr: Floats, ch: Floats, c: np.ndarray) -> None:
    """``_polish_settle_all_of`` with the normal equations' steps (``_newton_ldl``)."""
    wide_vectors()
    _polish_settle_all_of(m, pr, ch, c, False)


@numba.njit(cache=True, nogil=True, fastmath=_FAST, error_model="numpy")
def _polish_settle_all_parallel(m: int, pr: Floats, ch: Floats, c: np.ndarray) -> None:
    """``_polish_settle_all_of`` with the steps of parallel pitch axes (``_newton_parallel``)."""
    wide_vectors()
    _polish_settle_all_of(m, pr, ch, c, True)


@numba.njit(cache=True, nogil=True)
def _polish_settle(m: int, pr: Floats, ch: Floats, c: np.ndarray, parallel: bool) -> None:
    """``_polish_settle_all_parallel`` where the pitch axes are parallel, else
    ``_polish_settle_all`` (one compiled loop each)."""
    if parallel:
        _polish_settle_all_parallel(m, pr, ch, c)
    else:
        _polish_settle_all(m, pr, ch, c)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=_FAST)
def _polish_settle_all_of(m: int, pr: Floats, ch: Floats, c: np.ndarray, parallel: bool) -> None:
    """The polish (``_polish``) of the m candidates in the rows c (flat: row k is c[k * _CW:];
    a model only close to the family), the error before its last step, the angles wrapped into
    the limits, and the verdict (``_verdict``) at the final angles, whose sines and cosines
    follow from the polish's by what the limits snapped (``_turn``): only where every step
    and snap is within TAYLOR_STEP is a candidate taken, within FAR_STEP found not to be a
    branch; the others, and an ill-conditioned polish, are left to the second polish.
    parallel: a constant (``_newton``)."""
    for i in range(m):
        t = _column_of(c, _CW, 0, i)
        sines, cosines = _offsets(ch, _column_of5(c, _C_SIN, i), _column_of5(c, _C_COS, i))
        q, sn, cs, ratio, size, big = _polish(ch, t, _angles_of(c, i), sines, cosines, parallel)
        w0, w1, w2, w3, w4, inside = _wrapped(pr, q)
        r0, r1, r2 = _snap(q[0], w0), _snap(q[1], w1), _snap(q[2], w2)
        r3, r4 = _snap(q[3], w3), _snap(q[4], w4)
        s0, c0 = _turn(sn[0], cs[0], r0)
        s1, c1 = _turn(sn[1], cs[1], r1)
        s2, c2 = _turn(sn[2], cs[2], r2)
        s3, c3 = _turn(sn[3], cs[3], r3)
        s4, c4 = _turn(sn[4], cs[4], r4)
        p = _fk_turned(ch, (s0, s1, s2, s3, s4), (c0, c1, c2, c3, c4))
        big = max(big, abs(r0), abs(r1), abs(r2), abs(r3), abs(r4))
        err, angle, good, far = _verdict(t, p, size, c[_C_FOLD * _CW + i])
        good = good if big <= TAYLOR_STEP else 0.0
        far = far if big <= FAR_STEP else 0.0
        _put_angles(c, i, w0, w1, w2, w3, w4)
        c[_C_PREV * _CW + i] = size
        c[_C_TAKE * _CW + i] = good
        fall = (ratio < ILL_CONDITIONED) | ((good == 0.0) & (far == 0.0))
        c[_C_FALL * _CW + i] = 1.0 if fall else 0.0
        c[_C_IN * _CW + i] = inside
        c[_C_PERR * _CW + i] = err
        c[_C_OERR * _CW + i] = angle


@numba.njit(cache=True, nogil=True)
def _repolish(
    m: int,
    pr: Floats,
    ch: Floats,
    c_flat: np.ndarray,
    c2_flat: np.ndarray,
    index: np.ndarray,
    parallel: bool,
) -> None:
    """The m candidates in the rows c_flat that the polish left unfinished next to a branch
    (final errors below NOT_A_BRANCH: next to a fold of the elbow the steps converge
    slowly) polished once more from where they stopped, gathered into the rows c2_flat (whole
    vectors): those that reach VECTOR_EXACT are taken, the others stay with the scalar polish
    (from their closed-form start)."""
    c, c2 = c_flat.reshape((_C_ROWS, _CW)), c2_flat.reshape((_C_ROWS, _CW))
    count = 0
    for k in range(m):
        if (c[_C_FALL, k] != 0.0) & (max(c[_C_PERR, k], c[_C_OERR, k]) <= NOT_A_BRANCH):
            index[count] = k
            count += 1
    if count == 0:
        return
    lanes = min((count + LANES - 1) // LANES * LANES, _CW)
    for j in range(lanes):
        k = index[min(j, count - 1)]
        for row in range(_C_ROWS):
            c2[row, j] = c[row, k]
        for row in range(5):  # the sines and cosines where the first polish stopped
            c2[_C_SIN + row, j], c2[_C_COS + row, j] = sincos(c2[_C_Q + row, j])
    _polish_settle(lanes, pr, ch, c2_flat, parallel)
    for j in range(count):
        if c2[_C_TAKE, j] == 0.0:
            continue
        k = index[j]
        for row in (_C_Q, _C_Q + 1, _C_Q + 2, _C_Q + 3, _C_Q + 4, _C_IN, _C_PERR, _C_OERR):
            c[row, k] = c2[row, j]
        c[_C_TAKE, k], c[_C_FALL, k] = 1.0, 0.0


@numba.njit(cache=True, nogil=True)
def _clear_slots(
    first: int,
    last: int,
    q: np.ndarray,
    valid: np.ndarray,
    within: np.ndarray,
    position_error: np.ndarray,
    orientation_error: np.ndarray,
) -> None:
    """Slots first..last - 1 of the flat outputs (q: 5 values a slot) empty: NaN / False (one
    contiguous run each, in whole vectors: unsigned indices, which numba does not wrap around,
    so LLVM sees consecutive addresses rather than scattering the stores)."""
    wide_vectors()
    begin, end = np.uint64(first), np.uint64(last)
    for k in range(np.uint64(5) * begin, np.uint64(5) * end):
        q[k] = np.nan
    for k in range(begin, end):
        valid[k] = False
    for k in range(begin, end):
        within[k] = False
    for k in range(begin, end):
        position_error[k] = np.nan
    for k in range(begin, end):
        orientation_error[k] = np.nan


@numba.njit(cache=True, nogil=True)
def _chain_tuple(placements: np.ndarray, axes: np.ndarray) -> Floats:
    """The chain in frames that make each link between two joints sparse, as one tuple: the
    base block N_1 (3 x 4, row-major, below), four links (6 each, ``_joint_turned``), the tool block
    (3 x 4); placements (6, 4, 4), axes (5, 3).

    T(q) = M_1 R(u_1, q_1) M_2 ... R(u_5, q_5) M_tool with G_i = [A_i | lambda_i u_i] a frame on
    joint i's axis (A_i takes z to u_i) and R(u_i, q) = G_i R(z, q) G_i^-1:
    T(q) = N_1 R(z, q_1) N_2 ... R(z, q_5) N_tool, N_1 = M_1 G_1, N_i = G_{i-1}^-1 M_i G_i,
    N_tool = G_5^-1 M_tool. Frame i's x axis is normal to both joint axes i - 1 and i (any
    normal to u_i where they are parallel) and frame 1's is frame 2's, so N_i's rotation is
    R(z, phi_i) R(x, beta_i) (phi_2 = 0); lambda_i puts frame i's origin where N_{i+1} has no
    translation along z (back from the tool). The same poses to rounding: the fourth entries
    (N_i's z-x rotation entry and z translation) are rounding, left out.
    """
    frames = np.zeros((5, 4, 4))
    xs = np.zeros((5, 3))
    for k in range(4, -1, -1):
        u = axes[k].copy()
        w = np.zeros(3)
        if k >= 1:  # normal to u and to the axis before it (in joint k's frame)
            v = np.ascontiguousarray(placements[k, :3, :3]).T @ axes[k - 1]
            w = v - (v @ u) * u
        if k >= 1 and w @ w > 1e-300:
            x = np.cross(u, w)
        elif k == 0:  # frame 2's x axis in joint 1's frame: phi_2 = 0
            x = np.ascontiguousarray(placements[1, :3, :3]) @ xs[1]
        else:  # parallel: any normal
            a = np.array([1.0, 0.0, 0.0]) if abs(u[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
            x = a - (a @ u) * u
        x = x - (x @ u) * u
        x /= math.sqrt(x @ x)
        xs[k] = x
        frames[k, :3, 0], frames[k, :3, 1], frames[k, :3, 2] = x, np.cross(u, x), u
        frames[k, 3, 3] = 1.0
    # lambda: back from the tool, each frame's origin where the next link has no z translation
    lam = np.zeros(5)
    lam[4] = axes[4] @ np.ascontiguousarray(placements[5, :3, 3])
    for k in range(3, -1, -1):
        m = placements[k + 1]
        lam[k] = axes[k] @ (np.ascontiguousarray(m[:3, :3]) @ (lam[k + 1] * axes[k + 1]) + m[:3, 3])
    for k in range(5):
        frames[k, :3, 3] = lam[k] * axes[k]
    inverse = np.zeros((5, 4, 4))
    for k in range(5):
        r = frames[k, :3, :3].T.copy()
        inverse[k, :3, :3] = r
        inverse[k, :3, 3] = -(r @ np.ascontiguousarray(frames[k, :3, 3]))
        inverse[k, 3, 3] = 1.0
    flat = np.empty(_N_CHAIN)
    base = np.ascontiguousarray(placements[0]) @ frames[0]
    tool = inverse[4] @ np.ascontiguousarray(placements[5])
    for r in range(3):
        for col in range(4):
            flat[4 * r + col] = base[r, col]
            flat[36 + 4 * r + col] = tool[r, col]
    for k in range(1, 5):
        link = inverse[k - 1] @ np.ascontiguousarray(placements[k]) @ frames[k]
        cf, sf = link[0, 0], link[1, 0]
        b = 12 + 6 * (k - 1)
        flat[b], flat[b + 1] = cf, sf
        flat[b + 2], flat[b + 3] = link[2, 2], link[2, 1]
        # the translation in the frame turned by phi: R(z, -phi) (tx, ty)
        tx, ty = link[0, 3], link[1, 3]
        flat[b + 4], flat[b + 5] = cf * tx + sf * ty, cf * ty - sf * tx
    chain: Floats = to_fixed_tuple(flat, _N_CHAIN)  # type: ignore[call-arg]
    return chain


@numba.njit(cache=True, nogil=True)
def _shape(prm: np.ndarray) -> Floats:
    """The two links' shape (``_flip``) from the packed parameters: their lengths la, lb [m],
    their angles b2, b3 [rad], sin, cos of gamma0 and gamma0, sin and cos of b2 and of
    b2 - b3."""
    l20, l21 = prm[F.O3] - prm[F.O2], prm[F.O3 + 1] - prm[F.O2 + 1]
    l30, l31 = prm[F.O4] - prm[F.O3], prm[F.O4 + 1] - prm[F.O3 + 1]
    gamma0 = prm[F.GAMMA0]
    b2, b3 = math.atan2(l21, l20), math.atan2(l31, l30)
    return (
        math.hypot(l20, l21),
        math.hypot(l30, l31),
        b2,
        b3,
        math.sin(gamma0),
        math.cos(gamma0),
        gamma0,
        math.sin(b2),
        math.cos(b2),
        math.sin(b2 - b3),
        math.cos(b2 - b3),
    )


@numba.njit(cache=True, nogil=True)
def pose_block_kernel(  # noqa: PLR0912, PLR0915 (numba: one compiled pass)
    prm: np.ndarray,
    placements: np.ndarray,
    axes: np.ndarray,
    targets: np.ndarray,
    reference: np.ndarray,
    q_out: np.ndarray,
    valid: np.ndarray,
    within: np.ndarray,
    position_error: np.ndarray,
    orientation_error: np.ndarray,
    solved: np.ndarray,
    distance: np.ndarray,
) -> int:
    """``pose_kernel`` (same arguments and outputs), by blocks of BLOCK vectorised poses with
    the scalar ``solve_target`` for the poses that need it and the scalar polish for the
    candidates that need it. Returns how many poses needed either.

    targets: (N, 4, 4) rigid poses; reference (N, 5) or (1, 5) [rad]; outputs (N, B, ...), every
    slot written; solved (N,): an exact branch was found; distance (N,): the smallest position
    error over the slots [m].
    """
    wide_vectors()
    nb = q_out.shape[1]
    per_side = nb // 2
    ch = _chain_tuple(placements, axes)
    parallel = _parallel_pitches(ch)
    pr: Floats = to_fixed_tuple(prm, _N_PRM)  # type: ignore[call-arg]
    exact = prm[F.EXACT] != 0.0
    on_roll_axis = prm[F.OFF_AXIS] == 0.0
    lower, upper, tol = prm[F.LOWER : F.LOWER + 5], prm[F.UPPER : F.UPPER + 5], prm[F.LIMIT_TOL]
    shape = _shape(prm)
    # the scratch rows and the candidate rows in one array (constant distances: ``_closed_forms``)
    x_flat = np.zeros(_ROWS * BLOCK + _C_ROWS * _CW)
    s_flat, c_flat = x_flat[: _ROWS * BLOCK], x_flat[_ROWS * BLOCK :]
    c2_flat, slot_index = np.empty(_C_ROWS * _CW), np.empty(_CW, dtype=np.int64)
    s, c = s_flat.reshape((_ROWS, BLOCK)), c_flat.reshape((_C_ROWS, _CW))
    owned = np.empty(BLOCK, dtype=np.int64)  # the candidates of pose i: its owned[i] lanes
    lane_of = np.empty(4 * BLOCK, dtype=np.int64)  # lane_of[4 * i : 4 * i + owned[i]]
    slot_of = np.empty(_CW, dtype=np.int64)
    out = np.empty((nb, SLOT_COLUMNS))
    g, pose, work = np.empty((3, 4)), np.empty((4, 4)), np.empty((4, 4))
    qs, jac, origins = np.empty(5), np.empty((6, 5)), np.empty((5, 6))
    normal, vectors = np.empty((7, 5)), np.empty((3, 6))
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
        if on_roll_axis:
            _closed_forms_on_roll_axis(pr, shape, x_flat)
        else:
            _closed_forms(pr, shape, x_flat)
            for i in range(m):  # the other flip where it may matter (rare: see _screen)
                if s[_POSE_OTHER, i] != 0.0:
                    _other_flip(pr, shape, x_flat, i)
        # the candidates of the poses that need no fallback, in the scalar solver's order: lane
        # i the elbow up and lane BLOCK + i the elbow down of pose i's first candidate flip
        # (written by _closed_forms), then the other flip where it is a candidate too (rare:
        # its yaw misses by twice the lateral offset), gathered one by one
        mc = np.int64(2 * BLOCK)  # not a literal: one compile of _repolish
        second_flips = False
        for i in range(m):  # by selects: the first flip's lanes and slots
            fall = (s[_FLIP0 + _F_FALL, i] != 0.0) | (s[_FLIP0 + _PER_FLIP + _F_FALL, i] != 0.0)
            cand0 = s[_FLIP0 + _F_CAND, i] != 0.0
            cand1 = s[_FLIP0 + _PER_FLIP + _F_CAND, i] != 0.0
            s[_POSE_FALL, i] = 1.0 if fall else 0.0
            owned[i] = 2 if (not fall) and (cand0 or cand1) else 0
            second_flips = second_flips or ((not fall) and cand0 and cand1)
            base = _FLIP0 + (0 if cand0 else _PER_FLIP)
            side = s[base + _F_SIDE, i]
            slot = int(side) * per_side + (0 if cand0 or per_side <= 2 else 2)
            lane_of[4 * i], lane_of[4 * i + 1] = i, BLOCK + i
            slot_of[i], slot_of[BLOCK + i] = slot, slot + 1
        for i in range(m if second_flips else 0):  # the second candidate flips: gathered
            fall = s[_POSE_FALL, i] != 0.0
            if fall or s[_FLIP0 + _F_CAND, i] == 0.0 or s[_FLIP0 + _PER_FLIP + _F_CAND, i] == 0.0:
                continue
            owned[i] = 0
            for flip in range(2):
                base = _FLIP0 + flip * _PER_FLIP
                if s[base + _F_CAND, i] == 0.0:
                    continue
                side = int(s[base + _F_SIDE, i])
                for elbow in range(2):
                    lane = elbow * BLOCK + i if owned[i] < 2 else mc
                    if owned[i] >= 2:  # the second flip: gathered
                        for k in range(12):
                            c[k, mc] = s[k, i]
                        geometry = (s[base, i], s[base + 1, i], s[base + 2, i], s[base + 3, i],
                                    s[base + 4, i], s[base + 5, i], s[base + 6, i], s[base + 7, i],
                                    s[base + 8, i], s[base + 9, i], s[base + 10, i],
                                    s[base + 11, i])  # fmt: skip
                        up, down, s_up, c_up, s_down, c_down = _branches(pr, shape, geometry)
                        for k in range(5):
                            c[_C_Q + k, mc] = down[k] if elbow else up[k]
                            c[_C_SIN + k, mc] = s_down[k] if elbow else s_up[k]
                            c[_C_COS + k, mc] = c_down[k] if elbow else c_up[k]
                        c[_C_FOLD, mc] = s[base + _F_FOLD, i]
                        mc += 1
                    lane_of[4 * i + owned[i]] = lane
                    slot_of[lane] = side * per_side + (flip * 2 if per_side > 2 else 0) + elbow
                    owned[i] += 1
        for lane in range(2 * BLOCK, mc):
            for k in range(5):
                c[_C_START + k, lane] = c[_C_Q + k, lane]
            c[_C_FALL, lane] = 0.0
            c[_C_PREV, lane] = 0.0
        # whole vectors: the lanes past the last candidate repeat the first (a remainder
        # would run through the loops' scalar epilogue, ~8 times the cost per candidate)
        lanes = min((mc + LANES - 1) // LANES * LANES, _CW)
        for lane in range(mc, lanes):
            for k in range(_C_ROWS):
                c[k, lane] = c[k, 0]
        if exact:
            _settle_all(lanes, pr, ch, c_flat)
        else:
            _polish_settle(lanes, pr, ch, c_flat, parallel)
        for i in range(BLOCK):  # the lanes of no candidate (no flip, past m): nothing to finish
            if i >= m or owned[i] == 0:
                c[_C_FALL, i] = c[_C_FALL, BLOCK + i] = 0.0
        if not exact:
            _repolish(mc, pr, ch, c_flat, c2_flat, slot_index, parallel)
        _clear_slots(start * nb, (start + m) * nb, q_flat, valid_flat, within_flat, p_flat, o_flat)
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
            if s[_POSE_FALL, i] != 0.0:  # solved after the blocks (below)
                if deferred_count == deferred.shape[0]:
                    grown = np.empty(2 * deferred.shape[0], dtype=np.int64)
                    grown[:deferred_count] = deferred
                    deferred = grown
                deferred[deferred_count] = n
                deferred_count += 1
                continue
            if owned[i] == 2:  # the common case: both elbows of one flip, both taken
                ka, kb = lane_of[4 * i], lane_of[4 * i + 1]
                both = (c[_C_TAKE, ka] != 0.0) & (c[_C_TAKE, kb] != 0.0)
                if both & (c[_C_FALL, ka] == 0.0) & (c[_C_FALL, kb] == 0.0):
                    gap = 0.0
                    for j in range(5):
                        gap = max(gap, abs(c[_C_Q + j, ka] - c[_C_Q + j, kb]))
                    pair = gap >= BRANCH_DUPLICATE_TOLERANCE  # else kb is a duplicate
                    for h in range(2 if pair else 1):
                        k = kb if h else ka
                        b = slot_of[k]
                        for j in range(5):
                            q_out[n, b, j] = c[_C_Q + j, k]
                        valid[n, b] = True
                        within[n, b] = c[_C_IN, k] != 0.0
                        position_error[n, b] = c[_C_PERR, k]
                        orientation_error[n, b] = c[_C_OERR, k]
                    solved[n] = True
                    # the smallest error over the slots (``smallest_error``: the others empty)
                    nearest = c[_C_PERR, ka]
                    distance[n] = min(nearest, c[_C_PERR, kb]) if pair else nearest
                    continue
            count = np.int64(0)  # not a literal 0: one compile of is_duplicate
            scalar = False
            for h in range(owned[i]):
                k = lane_of[4 * i + h]
                b = slot_of[k]
                if valid[n, b]:
                    continue
                if c[_C_FALL, k] != 0.0:  # the scalar solver's polish of this candidate
                    scalar = True
                    for j in range(5):
                        qs[j] = c[_C_START + j, k]
                    current = False
                    if not exact:
                        current = polish_pose(
                            placements, axes, targets[n], qs, pose, work, jac, origins, normal,
                            vectors,
                        )  # fmt: skip
                    inside, err = settle(
                        placements, axes, lower, upper, tol, targets[n], qs, pose, work, current
                    )
                    angle = rotation_angle(targets[n], pose)
                    if not (err <= POSE_EXACT and angle <= POSE_EXACT):
                        continue
                else:
                    if c[_C_TAKE, k] == 0.0:
                        continue
                    for j in range(5):
                        qs[j] = c[_C_Q + j, k]
                    inside, err, angle = c[_C_IN, k] != 0.0, c[_C_PERR, k], c[_C_OERR, k]
                if is_duplicate(taken, _ALL_TAKEN, count, qs, BRANCH_DUPLICATE_TOLERANCE):
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
        solved[n] = solve_target(
            prm, placements, axes, targets[n], ref, out,
            g, pose, work, qs, jac, origins, normal, vectors,
        )  # fmt: skip
        write_slots(out, n, q_out, valid, within, position_error, orientation_error, distance)
    return fallbacks + deferred_count
