"""The roll equation of an off-axis tool point (numba; see ``roll_search.py``).

For a roll theta the tool point is fixed in the wrist link; the yaw puts it on the target's
lateral offset and the pitch sum follows from the approach. The roll is a solution when the
approach lies in the arm plane (approach targets) or equals the best roll of the target (full
poses): the roots of one scalar function f(theta). It is evaluated with one cosine and one sine
of the roll: the yaw and pitch-sum angles enter only through their cosines and sines, which
follow from the target by square roots (``roll_equation_reference`` is the same function written
with the angles, kept for the degenerate targets and the tests). Lengths [m], angles [rad].
"""

from __future__ import annotations

import math

import numba
import numpy as np

from lynxplan.robots import family as F  # noqa: N812
from lynxplan.robots.ik.family_geometry import (
    MODE_APPROACH,
    best_roll,
    best_roll_terms,
    pitch_sum,
    yaw,
)

#: Below this the target is on the yaw axis, or the approach along the pitch axis [m], [1]:
#: there the angle form (with its reference angles) is used.
_DEGENERATE = 1e-12


@numba.njit(cache=True, nogil=True)
def roll_equation_reference(
    prm: np.ndarray,
    target: np.ndarray,
    g: np.ndarray,
    mode: int,
    theta: float,
    side: int,
    phi_ref: float,
    sum_ref: float,
) -> float:
    """The scalar whose roots are the rolls of an off-axis tool (one side), with angles.

    ``g[:, :3]`` is G = Rt Rt0^T, ``g[:, 3]`` the target approach axis.
    """
    d0, d1, d2 = (
        target[0, 3] - prm[F.C1],
        target[1, 3] - prm[F.C1 + 1],
        target[2, 3] - prm[F.C1 + 2],
    )
    phi, _ = yaw(prm, d0, d1, d2, theta, side, phi_ref)
    big_phi, out = pitch_sum(prm, mode, g[0, 3], g[1, 3], g[2, 3], 0.0, phi, sum_ref)
    if mode == MODE_APPROACH:
        return out
    # sin, not the wrapped difference: continuous through +-pi; roots at pi are rejected later
    return math.sin(best_roll(prm, g, phi, big_phi) - theta)


@numba.njit(cache=True, nogil=True)
def _reference_terms(
    prm: np.ndarray,
    target: np.ndarray,
    g: np.ndarray,
    mode: int,
    theta: float,
    side: int,
    phi_ref: float,
    sum_ref: float,
) -> tuple[float, float, float]:
    """``roll_terms`` with angles (the degenerate targets)."""
    d0, d1, d2 = (
        target[0, 3] - prm[F.C1],
        target[1, 3] - prm[F.C1 + 1],
        target[2, 3] - prm[F.C1 + 2],
    )
    phi, miss = yaw(prm, d0, d1, d2, theta, side, phi_ref)
    big_phi, out = pitch_sum(prm, mode, g[0, 3], g[1, 3], g[2, 3], 0.0, phi, sum_ref)
    if mode == MODE_APPROACH:
        return out, 1.0, miss
    delta = best_roll(prm, g, phi, big_phi) - theta
    return math.sin(delta), math.cos(delta), miss


@numba.njit(cache=True, nogil=True)
def roll_terms(
    prm: np.ndarray,
    target: np.ndarray,
    g: np.ndarray,
    mode: int,
    theta: float,
    side: int,
    phi_ref: float,
    sum_ref: float,
) -> tuple[float, float, float]:
    """(f, c, lateral miss) at roll theta: f the roll equation; for full poses f and c are the
    sine and cosine of the best-roll mismatch (c = 1 for approach targets); the lateral miss
    [m] > 0 where the yaw circle is out of reach (the yaw is clamped there)."""
    d0 = target[0, 3] - prm[F.C1]
    d1 = target[1, 3] - prm[F.C1 + 1]
    d2 = target[2, 3] - prm[F.C1 + 2]
    dp = d0 * prm[F.P] + d1 * prm[F.P + 1] + d2 * prm[F.P + 2]
    dh = d0 * prm[F.H] + d1 * prm[F.H + 1] + d2 * prm[F.H + 2]
    rho = math.hypot(dp, dh)
    if rho <= _DEGENERATE:
        return _reference_terms(prm, target, g, mode, theta, side, phi_ref, sum_ref)
    ct, st = math.cos(theta), math.sin(theta)
    lat = prm[F.LAM4] + prm[F.W0 + 2] + ct * prm[F.E1 + 2] + st * prm[F.E2 + 2]
    # yaw phi = alpha -+ beta, alpha = atan2(dh, dp), beta = acos(lat / rho) (see ``yaw``)
    cb, miss = lat / rho, 0.0
    if cb > 1.0:
        miss, cb = lat - rho, 1.0
    elif cb < -1.0:
        miss, cb = -lat - rho, -1.0
    sb = math.sqrt(max(0.0, 1.0 - cb * cb))
    ca, sa = dp / rho, dh / rho
    if side == 0:
        cphi, sphi = ca * cb + sa * sb, sa * cb - ca * sb
    else:
        cphi, sphi = ca * cb - sa * sb, sa * cb + ca * sb
    a0, a1, a2 = g[0, 3], g[1, 3], g[2, 3]
    ap = a0 * prm[F.P] + a1 * prm[F.P + 1] + a2 * prm[F.P + 2]
    ah = a0 * prm[F.H] + a1 * prm[F.H + 1] + a2 * prm[F.H + 2]
    ak = a0 * prm[F.K] + a1 * prm[F.K + 1] + a2 * prm[F.K + 2]
    if mode == MODE_APPROACH:  # the out-of-plane approach component (see ``approach_in_plane``)
        return cphi * ap + sphi * ah, 1.0, miss
    in_h = cphi * ah - sphi * ap
    norm = math.hypot(in_h, ak)
    if norm <= _DEGENERATE:  # approach along the pitch axis: the reference pitch sum
        return _reference_terms(prm, target, g, mode, theta, side, phi_ref, sum_ref)
    # pitch sum Phi = atan2(ak, in_h) - gamma0
    cg, sg = math.cos(prm[F.GAMMA0]), math.sin(prm[F.GAMMA0])
    cbig, sbig = (in_h * cg + ak * sg) / norm, (ak * cg - in_h * sg) / norm
    sine, cosine = best_roll_terms(prm, g, cphi, -sphi, cbig, -sbig)
    size = math.hypot(sine, cosine)
    if size == 0.0:  # atan2(0, 0) = 0: the best roll is 0
        return -st, ct, miss
    # sin and cos of (best roll - theta)
    return (sine * ct - cosine * st) / size, (cosine * ct + sine * st) / size, miss


@numba.njit(cache=True, nogil=True, inline="always")
def roll_equation(
    prm: np.ndarray,
    target: np.ndarray,
    g: np.ndarray,
    mode: int,
    theta: float,
    side: int,
    phi_ref: float,
    sum_ref: float,
) -> float:
    """The scalar whose roots are the rolls of an off-axis tool (one side)."""
    return roll_terms(prm, target, g, mode, theta, side, phi_ref, sum_ref)[0]


@numba.njit(cache=True, nogil=True)
def roll_mismatch(
    prm: np.ndarray,
    target: np.ndarray,
    g: np.ndarray,
    mode: int,
    theta: float,
    side: int,
    phi_ref: float,
    sum_ref: float,
) -> float:
    """|wrapped best-roll difference| (pose) or |out-of-plane approach| (approach)."""
    f, c, _ = roll_terms(prm, target, g, mode, theta, side, phi_ref, sum_ref)
    if mode == MODE_APPROACH:
        return abs(f)
    return abs(math.atan2(f, c))


@numba.njit(cache=True, nogil=True)
def lateral_miss(
    prm: np.ndarray, target: np.ndarray, theta: float, side: int, phi_ref: float
) -> float:
    """By how much the tool point misses the yaw circle at roll theta [m] (0 within reach)."""
    d0 = target[0, 3] - prm[F.C1]
    d1 = target[1, 3] - prm[F.C1 + 1]
    d2 = target[2, 3] - prm[F.C1 + 2]
    dp = d0 * prm[F.P] + d1 * prm[F.P + 1] + d2 * prm[F.P + 2]
    dh = d0 * prm[F.H] + d1 * prm[F.H + 1] + d2 * prm[F.H + 2]
    rho = math.hypot(dp, dh)
    if rho <= _DEGENERATE:
        return yaw(prm, d0, d1, d2, theta, side, phi_ref)[1]
    lat: float = (
        prm[F.LAM4]
        + prm[F.W0 + 2]
        + math.cos(theta) * prm[F.E1 + 2]
        + math.sin(theta) * prm[F.E2 + 2]
    )
    if lat > rho:
        return lat - rho
    if -lat > rho:
        return -lat - rho
    return 0.0
