"""Closed-form pieces of the yaw-pitch-pitch-pitch-roll IK (numba; see ``family_kernel.py``).

For a fixed roll angle the tool point is fixed in the wrist link, and one branch follows in
closed form: the yaw from the lateral offset (two sides: front and back), the pitch sum from the
approach projected into the arm plane (or from a given pitch), the shoulder and elbow from a
two-link triangle (elbow up and down). Angles are in [rad], lengths in [m]; ``prm`` is the
packed parameter vector of ``family.py``.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import math
from collections.abc import Callable
from typing import cast

import numba
import numpy as np

from lynxplan._jit import kernels_run_as_python
from lynxplan.constants import FOLD_START_BAND, FOLD_START_GAP, ROLL_DEGENERATE
from lynxplan.robots import family as F  # noqa: N812

MODE_POSE, MODE_APPROACH, MODE_PITCH = 0, 1, 2
#: One target and one side: (prm, target (4, 4), g (SCRATCH_ROWS, 4) the kernel's per-target
#: scratch, mode, side 0/1, reference yaw phi_ref, reference pitch sum sum_ref), see
#: ``family_kernel``.
RollProblem = tuple[np.ndarray, np.ndarray, np.ndarray, int, int, float, float]
#: One target on the exact chain: (prm, placements, axes, target, g, mode, pitch).
ChainProblem = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, int, float]
TWO_PI = 2.0 * math.pi


def _libm_hypot() -> Callable[[float, float], float]:
    """The C library's ``hypot``: what numba's compiled ``math.hypot`` calls (CPython's own
    ``math.hypot`` rounds differently in the last bit)."""
    libm = ctypes.CDLL(ctypes.util.find_library("m") or "libm.so.6")
    function = libm.hypot
    function.restype = ctypes.c_double
    function.argtypes = (ctypes.c_double, ctypes.c_double)
    return cast(Callable[[float, float], float], function)


#: sqrt(x^2 + y^2) without overflow, the same bits compiled and interpreted: compiled kernels
#: call the C library's ``hypot`` for ``math.hypot``; under numba's ``NUMBA_DISABLE_JIT`` (the
#: command line's single-target ``ik``) the kernels are Python and call it through ctypes.
hypot: Callable[[float, float], float] = _libm_hypot() if kernels_run_as_python() else math.hypot


@numba.njit(cache=True, nogil=True, inline="always")
def rotate(
    u0: float, u1: float, u2: float, c: float, s: float, v0: float, v1: float, v2: float
) -> tuple[float, float, float]:
    """Rodrigues: v rotated by the angle with cosine c and sine s about the unit axis u."""
    d = (u0 * v0 + u1 * v1 + u2 * v2) * (1.0 - c)
    return (
        v0 * c + (u1 * v2 - u2 * v1) * s + u0 * d,
        v1 * c + (u2 * v0 - u0 * v2) * s + u1 * d,
        v2 * c + (u0 * v1 - u1 * v0) * s + u2 * d,
    )


@numba.njit(cache=True, nogil=True, inline="always")
def wrap(x: float) -> float:
    return x - TWO_PI * math.floor((x + math.pi) / TWO_PI)


@numba.njit(cache=True, nogil=True, inline="always")
def wrap_into_limits(x: float, lo: float, hi: float, tol: float) -> tuple[float, bool]:
    """Angle x moved by whole turns into [lo, hi] (snapping within tol), or nearest outside.

    By selects, no branch: array loops over it vectorise (branches outside the limits are
    common and unpredictable in scalar loops too)."""
    inside = (lo <= x) & (x <= hi)
    y = x - math.floor((x - lo) / TWO_PI) * TWO_PI  # y in [lo, lo + 2 pi) up to rounding
    snap_hi = y <= hi + tol
    snap_lo = y >= lo + TWO_PI - tol
    nearest = y if y - hi <= lo + TWO_PI - y else y - TWO_PI
    out = lo if snap_lo else nearest
    out = hi if snap_hi else out
    out = y if y <= hi else out
    return (x if inside else out), inside | snap_hi | snap_lo


@numba.njit(cache=True, nogil=True, inline="always")
def from_yaw_axis(prm: np.ndarray, target: np.ndarray) -> tuple[float, float, float]:
    """The target's (4, 4) tool point from the yaw axis's point C1 (3) [m]."""
    return target[0, 3] - prm[F.C1], target[1, 3] - prm[F.C1 + 1], target[2, 3] - prm[F.C1 + 2]


@numba.njit(cache=True, nogil=True, inline="always")
def across_yaw_axis(prm: np.ndarray, d0: float, d1: float, d2: float) -> tuple[float, float, float]:
    """(dp, dh, rho): the components of d (from ``from_yaw_axis``) along p and h, and its
    distance from the yaw axis [m]."""
    dp = d0 * prm[F.P] + d1 * prm[F.P + 1] + d2 * prm[F.P + 2]
    dh = d0 * prm[F.H] + d1 * prm[F.H + 1] + d2 * prm[F.H + 2]
    return dp, dh, hypot(dp, dh)


@numba.njit(cache=True, nogil=True, inline="always")
def tool_lateral(prm: np.ndarray, theta: float) -> float:
    """The tool point's offset along the pitch axis from the yaw axis at roll theta [m]: the
    distance from the yaw axis the yaw must give the target."""
    lat: float = (
        prm[F.LAM4]
        + prm[F.W0 + 2]
        + math.cos(theta) * prm[F.E1 + 2]
        + math.sin(theta) * prm[F.E2 + 2]
    )
    return lat


@numba.njit(cache=True, nogil=True)
def yaw(
    prm: np.ndarray, d0: float, d1: float, d2: float, theta: float, side: int, phi_ref: float
) -> tuple[float, float]:
    """Canonical yaw angle phi of one side for roll theta, and the lateral miss [m]."""
    dp, dh, rho = across_yaw_axis(prm, d0, d1, d2)
    lat = tool_lateral(prm, theta)
    # on the yaw axis: any yaw; keep the reference
    if rho <= ROLL_DEGENERATE and abs(lat) <= ROLL_DEGENERATE:
        return phi_ref + side * math.pi, 0.0
    ratio, miss = lat / rho if rho > 0 else math.copysign(1.0, lat), 0.0
    if ratio > 1.0:
        miss, ratio = lat - rho, 1.0
    elif ratio < -1.0:
        miss, ratio = -lat - rho, -1.0
    beta = math.acos(ratio)
    alpha = math.atan2(dh, dp)
    return (alpha - beta if side == 0 else alpha + beta), miss


@numba.njit(cache=True, nogil=True)
def plane_target(
    prm: np.ndarray, d0: float, d1: float, d2: float, phi: float
) -> tuple[float, float]:
    """Target point in the arm plane (outward, up) for yaw phi."""
    c, s = math.cos(phi), math.sin(phi)
    dp = d0 * prm[F.P] + d1 * prm[F.P + 1] + d2 * prm[F.P + 2]
    dh = d0 * prm[F.H] + d1 * prm[F.H + 1] + d2 * prm[F.H + 2]
    dk = d0 * prm[F.K] + d1 * prm[F.K + 1] + d2 * prm[F.K + 2]
    return c * dh - s * dp, dk


@numba.njit(cache=True, nogil=True)
def approach_in_plane(
    prm: np.ndarray, a0: float, a1: float, a2: float, phi: float
) -> tuple[float, float, float]:
    """Components of the approach a along h(phi), k and p(phi)."""
    c, s = math.cos(phi), math.sin(phi)
    ap = a0 * prm[F.P] + a1 * prm[F.P + 1] + a2 * prm[F.P + 2]
    ah = a0 * prm[F.H] + a1 * prm[F.H + 1] + a2 * prm[F.H + 2]
    ak = a0 * prm[F.K] + a1 * prm[F.K + 1] + a2 * prm[F.K + 2]
    return c * ah - s * ap, ak, c * ap + s * ah


@numba.njit(cache=True, nogil=True, inline="always")
def best_roll_terms(
    prm: np.ndarray | tuple[float, ...],
    g: tuple[float, ...],
    cy: float,
    sy: float,
    cp: float,
    sp: float,
) -> tuple[float, float]:
    """(sine, cosine) terms of the best roll for M = Q^T G, Q = R(k, -yaw) R(p, -pitch sum)
    given by the cosines and sines (cy, sy) of -yaw and (cp, sp) of -pitch sum; g: the 9
    entries of G's rotation block, row-major; prm: the packed parameters (array or tuple)."""
    k0, k1, k2 = prm[F.K], prm[F.K + 1], prm[F.K + 2]
    p0, p1, p2 = prm[F.P], prm[F.P + 1], prm[F.P + 2]
    r0, r1, r2 = prm[F.R], prm[F.R + 1], prm[F.R + 2]
    x0, x1, x2 = rotate(k0, k1, k2, cy, sy, g[0], g[3], g[6])
    m00, m10, m20 = rotate(p0, p1, p2, cp, sp, x0, x1, x2)
    x0, x1, x2 = rotate(k0, k1, k2, cy, sy, g[1], g[4], g[7])
    m01, m11, m21 = rotate(p0, p1, p2, cp, sp, x0, x1, x2)
    x0, x1, x2 = rotate(k0, k1, k2, cy, sy, g[2], g[5], g[8])
    m02, m12, m22 = rotate(p0, p1, p2, cp, sp, x0, x1, x2)
    sine = r0 * (m21 - m12) + r1 * (m02 - m20) + r2 * (m10 - m01)
    rmr = (
        r0 * (m00 * r0 + m01 * r1 + m02 * r2)
        + r1 * (m10 * r0 + m11 * r1 + m12 * r2)
        + r2 * (m20 * r0 + m21 * r1 + m22 * r2)
    )
    return sine, m00 + m11 + m22 - rmr


@numba.njit(cache=True, nogil=True)
def best_roll(prm: np.ndarray, g: np.ndarray, phi: float, big_phi: float) -> float:
    """Canonical roll theta nearest the target: argmax tr(R(r, theta)^T M), M = Q^T G."""
    g9 = (g[0, 0], g[0, 1], g[0, 2], g[1, 0], g[1, 1], g[1, 2], g[2, 0], g[2, 1], g[2, 2])
    sine, cosine = best_roll_terms(
        prm, g9, math.cos(-phi), math.sin(-phi), math.cos(-big_phi), math.sin(-big_phi)
    )
    return math.atan2(sine, cosine)


@numba.njit(cache=True, nogil=True)
def pitch_sum(
    prm: np.ndarray,
    mode: int,
    a0: float,
    a1: float,
    a2: float,
    pitch: float,
    phi: float,
    ref_sum: float,
) -> tuple[float, float]:
    """Canonical pitch sum Phi for yaw phi, and the out-of-plane approach component."""
    if mode == MODE_PITCH:
        return pitch - 0.5 * math.pi - prm[F.GAMMA0], 0.0
    ah, ak, out = approach_in_plane(prm, a0, a1, a2, phi)
    if hypot(ah, ak) <= ROLL_DEGENERATE:  # approach along the pitch axis: any pitch is as good
        return ref_sum, out
    return math.atan2(ak, ah) - prm[F.GAMMA0], out


#: The two-link triangle of an arm (``two_link_shape``): the link lengths la, lb [m] and the
#: angles b2, b3 [rad] of the shoulder-elbow and elbow-wrist links at zero joint angles.
TwoLink = tuple[float, float, float, float]


@numba.njit(cache=True, nogil=True, inline="always")
def two_link_shape(prm: np.ndarray) -> TwoLink:
    """The shoulder-elbow and elbow-wrist links in the canonical arm plane: lengths [m] and
    angles at zero joint angles [rad]."""
    l20, l21 = prm[F.O3] - prm[F.O2], prm[F.O3 + 1] - prm[F.O2 + 1]
    l30, l31 = prm[F.O4] - prm[F.O3], prm[F.O4 + 1] - prm[F.O3 + 1]
    return hypot(l20, l21), hypot(l30, l31), math.atan2(l21, l20), math.atan2(l31, l30)


@numba.njit(cache=True, nogil=True)
def two_link(prm: np.ndarray, x: float, y: float, elbow: int) -> tuple[float, float, float]:
    """Canonical shoulder and elbow angles reaching the wrist point (x, y); and the miss [m]."""
    la, lb, b2, b3 = two_link_shape(prm)
    rx, ry = x - prm[F.O2], y - prm[F.O2 + 1]
    dist = hypot(rx, ry)
    cosd = (dist * dist - la * la - lb * lb) / (2.0 * la * lb)
    miss = 0.0
    if cosd > 1.0:
        miss, cosd = dist - (la + lb), 1.0
    elif cosd < -1.0:
        miss, cosd = abs(la - lb) - dist, -1.0
    delta = math.acos(cosd)
    if prm[F.EXACT] == 0.0 and abs(cosd) > 1.0 - FOLD_START_BAND:
        # near a fold of a model that is only close to the family: start the two elbows apart
        delta = max(delta, FOLD_START_GAP) if cosd > 0 else min(delta, math.pi - FOLD_START_GAP)
    if elbow == 0:  # elbow up: the elbow lies above the shoulder-wrist line
        delta = -delta
    t2 = math.atan2(ry, rx) - math.atan2(lb * math.sin(delta), la + lb * math.cos(delta))
    psi2 = t2 - b2
    psi3 = delta + b2 - b3
    return psi2, psi3, miss


@numba.njit(cache=True, nogil=True)
def branch(problem: RollProblem, pitch: float, theta: float, elbow: int, out: np.ndarray) -> float:
    """Joint angles of one branch (one side of ``problem``) for roll theta into out (5,);
    pitch [rad] for pitch targets. Returns the reach miss [m]."""
    prm, target, g, mode, side, phi_ref, sum_ref = problem
    d0, d1, d2 = from_yaw_axis(prm, target)
    phi, lat_miss = yaw(prm, d0, d1, d2, theta, side, phi_ref)
    big_phi, _ = pitch_sum(prm, mode, g[0, 3], g[1, 3], g[2, 3], pitch, phi, sum_ref)
    if mode == MODE_POSE and prm[F.OFF_AXIS] == 0.0:
        theta = best_roll(prm, g, phi, big_phi)
    x, y = plane_target(prm, d0, d1, d2, phi)
    ct, st = math.cos(theta), math.sin(theta)
    wh = prm[F.W0] + ct * prm[F.E1] + st * prm[F.E2]
    wk = prm[F.W0 + 1] + ct * prm[F.E1 + 1] + st * prm[F.E2 + 1]
    cp, sp = math.cos(big_phi), math.sin(big_phi)
    psi2, psi3, miss = two_link(prm, x - (cp * wh - sp * wk), y - (sp * wh + cp * wk), elbow)
    out[0] = prm[F.SIGMA] * phi
    out[1] = prm[F.SIGMA + 1] * psi2
    out[2] = prm[F.SIGMA + 2] * psi3
    out[3] = prm[F.SIGMA + 3] * (big_phi - psi2 - psi3)
    out[4] = prm[F.SIGMA + 4] * theta
    return hypot(miss, lat_miss)
