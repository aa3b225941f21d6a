"""The roll equation of an off-axis tool point (numba; see ``roll_search.py``).

For a roll theta the tool point is fixed in the wrist link; the yaw puts it on the target's
lateral offset and the pitch sum follows from the approach. The roll is a solution when the
approach lies in the arm plane (approach targets) or equals the best roll of the target (full
poses): the roots of one scalar function f(theta). It is evaluated with one cosine and one sine
of the roll: the yaw and pitch-sum angles enter only through their cosines and sines, which
follow from the target by square roots (``reference_terms`` is the same function written
with the angles, kept for the degenerate targets and the tests). Lengths [m], angles [rad].
"""

from __future__ import annotations

import math

import numba
import numpy as np

from lynxplan.constants import ROLL_DEGENERATE
from lynxplan.robots import family as F  # noqa: N812
from lynxplan.robots.ik.family_geometry import (
    MODE_APPROACH,
    RollProblem,
    across_yaw_axis,
    best_roll,
    from_yaw_axis,
    pitch_sum,
    tool_lateral,
    yaw,
)


@numba.njit(cache=True, nogil=True)
def reference_terms(problem: RollProblem, theta: float) -> tuple[float, float, float]:
    """``roll_terms`` written with the angles (yaw, pitch sum, best roll): the degenerate
    targets, and the reference the tests hold the angle-free form to.

    ``g[:3, :3]`` is G = Rt Rt0^T, ``g[:3, 3]`` the target approach axis.
    """
    prm, target, g, mode, side, phi_ref, sum_ref = problem
    d0, d1, d2 = from_yaw_axis(prm, target)
    phi, miss = yaw(prm, d0, d1, d2, theta, side, phi_ref)
    big_phi, out = pitch_sum(prm, mode, g[0, 3], g[1, 3], g[2, 3], 0.0, phi, sum_ref)
    if mode == MODE_APPROACH:
        return out, 1.0, miss
    # sin, not the wrapped difference: continuous through +-pi; roots at pi are rejected later
    delta = best_roll(prm, g, phi, big_phi) - theta
    return math.sin(delta), math.cos(delta), miss


#: Rows of the kernel's scratch ``g`` (shape (SCRATCH_ROWS, 4)): 0-2 hold G = Rt Rt0^T and the
#: approach axis; 3-8 the per-target constants of the roll equation (``prepare_roll_terms``):
#: row 3 (rho, cos alpha, sin alpha, a.p), row 4 (a.h, a.k, cos gamma0, sin gamma0), row 5 the
#: roll axis in (h, k, p), rows 6-8 G in the canonical basis (h, k, p).
SCRATCH_ROWS = 9


@numba.njit(cache=True, nogil=True)
def prepare_roll_terms(prm: np.ndarray, target: np.ndarray, g: np.ndarray) -> None:
    """Store the roll-independent parts of the roll equation of one target in g[3:9]."""
    d0, d1, d2 = from_yaw_axis(prm, target)
    dp, dh, rho = across_yaw_axis(prm, d0, d1, d2)
    g[3, 0] = rho
    g[3, 1] = dp / rho if rho > 0.0 else 1.0
    g[3, 2] = dh / rho if rho > 0.0 else 0.0
    g[3, 3] = g[0, 3] * prm[F.P] + g[1, 3] * prm[F.P + 1] + g[2, 3] * prm[F.P + 2]
    g[4, 0] = g[0, 3] * prm[F.H] + g[1, 3] * prm[F.H + 1] + g[2, 3] * prm[F.H + 2]
    g[4, 1] = g[0, 3] * prm[F.K] + g[1, 3] * prm[F.K + 1] + g[2, 3] * prm[F.K + 2]
    g[4, 2], g[4, 3] = math.cos(prm[F.GAMMA0]), math.sin(prm[F.GAMMA0])
    for i, base in enumerate((F.H, F.K, F.P)):
        g[5, i] = prm[F.R] * prm[base] + prm[F.R + 1] * prm[base + 1] + prm[F.R + 2] * prm[base + 2]
    # Gc = B^T G B with B = [h k p] (a rotation: h x k = p)
    for i, bi in enumerate((F.H, F.K, F.P)):
        for j, bj in enumerate((F.H, F.K, F.P)):
            total = 0.0
            for a in range(3):
                row = g[a, 0] * prm[bj] + g[a, 1] * prm[bj + 1] + g[a, 2] * prm[bj + 2]
                total += prm[bi + a] * row
            g[6 + i, j] = total


@numba.njit(cache=True, nogil=True, inline="always")
def _turn(
    x: float, y: float, z: float, cphi: float, sphi: float, cbig: float, sbig: float
) -> tuple[float, float, float]:
    """R(p, -Phi) R(k, -phi) (x, y, z) in the canonical basis (x = h, y = k, z = p)."""
    x1 = x * cphi - z * sphi
    return x1 * cbig + y * sbig, y * cbig - x1 * sbig, x * sphi + z * cphi


@numba.njit(cache=True, nogil=True)
def roll_terms(problem: RollProblem, theta: float) -> tuple[float, float, float]:
    """(f, c, lateral miss) at roll theta: f the roll equation; for full poses f and c are the
    sine and cosine of the best-roll mismatch (c = 1 for approach targets); the lateral miss
    [m] > 0 where the yaw circle is out of reach (the yaw is clamped there).

    ``g`` holds the target's constants (``prepare_roll_terms``).
    """
    prm, _, g, mode, side, _, _ = problem
    rho = g[3, 0]
    if rho <= ROLL_DEGENERATE:
        return reference_terms(problem, theta)
    ct, st = math.cos(theta), math.sin(theta)
    lat = prm[F.LAM4] + prm[F.W0 + 2] + ct * prm[F.E1 + 2] + st * prm[F.E2 + 2]
    # yaw phi = alpha -+ beta, alpha = atan2(dh, dp), beta = acos(lat / rho) (see ``yaw``)
    cb, miss = lat / rho, 0.0
    if cb > 1.0:
        miss, cb = lat - rho, 1.0
    elif cb < -1.0:
        miss, cb = -lat - rho, -1.0
    sb = math.sqrt(max(0.0, 1.0 - cb * cb))
    ca, sa = g[3, 1], g[3, 2]
    if side == 0:
        cphi, sphi = ca * cb + sa * sb, sa * cb - ca * sb
    else:
        cphi, sphi = ca * cb - sa * sb, sa * cb + ca * sb
    ap, ah, ak = g[3, 3], g[4, 0], g[4, 1]
    if mode == MODE_APPROACH:  # the out-of-plane approach component (see ``approach_in_plane``)
        return cphi * ap + sphi * ah, 1.0, miss
    in_h = cphi * ah - sphi * ap
    norm = math.sqrt(in_h * in_h + ak * ak)
    if norm <= ROLL_DEGENERATE:  # approach along the pitch axis: the reference pitch sum
        return reference_terms(problem, theta)
    # pitch sum Phi = atan2(ak, in_h) - gamma0
    cg, sg = g[4, 2], g[4, 3]
    cbig, sbig = (in_h * cg + ak * sg) / norm, (ak * cg - in_h * sg) / norm
    # M = R(p, -Phi) R(k, -phi) Gc in the canonical basis (x = h, y = k, z = p)
    m00, m10, m20 = _turn(g[6, 0], g[7, 0], g[8, 0], cphi, sphi, cbig, sbig)
    m01, m11, m21 = _turn(g[6, 1], g[7, 1], g[8, 1], cphi, sphi, cbig, sbig)
    m02, m12, m22 = _turn(g[6, 2], g[7, 2], g[8, 2], cphi, sphi, cbig, sbig)
    r0, r1, r2 = g[5, 0], g[5, 1], g[5, 2]
    sine = r0 * (m21 - m12) + r1 * (m02 - m20) + r2 * (m10 - m01)
    rmr = (
        r0 * (m00 * r0 + m01 * r1 + m02 * r2)
        + r1 * (m10 * r0 + m11 * r1 + m12 * r2)
        + r2 * (m20 * r0 + m21 * r1 + m22 * r2)
    )
    cosine = m00 + m11 + m22 - rmr
    size = math.sqrt(sine * sine + cosine * cosine)
    if size == 0.0:  # atan2(0, 0) = 0: the best roll is 0
        return -st, ct, miss
    # sin and cos of (best roll - theta)
    return (sine * ct - cosine * st) / size, (cosine * ct + sine * st) / size, miss


@numba.njit(cache=True, nogil=True, inline="always")
def roll_equation(problem: RollProblem, theta: float) -> float:
    """The scalar whose roots are the rolls of an off-axis tool (one side)."""
    return roll_terms(problem, theta)[0]


@numba.njit(cache=True, nogil=True)
def roll_mismatch(problem: RollProblem, theta: float) -> float:
    """|wrapped best-roll difference| (pose) or |out-of-plane approach| (approach)."""
    mode = problem[3]
    f, c, _ = roll_terms(problem, theta)
    if mode == MODE_APPROACH:
        return abs(f)
    return abs(math.atan2(f, c))


@numba.njit(cache=True, nogil=True)
def lateral_miss(problem: RollProblem, theta: float) -> float:
    """By how much the tool point misses the yaw circle at roll theta [m] (0 within reach)."""
    prm, target, _, _, side, phi_ref, _ = problem
    d0, d1, d2 = from_yaw_axis(prm, target)
    rho = across_yaw_axis(prm, d0, d1, d2)[2]
    if rho <= ROLL_DEGENERATE:
        return yaw(prm, d0, d1, d2, theta, side, phi_ref)[1]
    lat = tool_lateral(prm, theta)
    if lat > rho:
        return lat - rho
    if -lat > rho:
        return -lat - rho
    return 0.0
