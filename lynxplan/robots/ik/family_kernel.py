"""Numba kernels: every IK branch of a yaw-pitch-pitch-pitch-roll arm (see ``family.py``).

For a fixed roll angle the tool point is fixed in the wrist link, and the problem is closed-form:
the yaw angle from the lateral offset (two sides: front and back), the pitch sum from the
approach direction projected into the arm plane (or from a given pitch), the shoulder and elbow
from a two-link triangle (elbow up and down). When the tool point is on the roll axis the roll
does not move it, so the roll is taken from the target (best roll about the approach axis) or
given. When the tool point is off the roll axis and the roll is not given, the roll is the root
of one scalar function on the roll joint's range (the approach must lie in the arm plane, or the
roll must equal the best roll of the target): every root is bracketed on a uniform grid of
:data:`ROOT_GRID` cells and refined by the Illinois method. Without a root, the roll that comes
nearest is used and the residual reported.

When the model is only close to the family (URDF angles written to 5 digits), each closed-form
answer is polished by Newton's method on the exact chain, on the same five conditions.
Angles are in [rad], lengths in [m].
"""

from __future__ import annotations

import math

import numba
import numpy as np

from lynxplan.robots import family as F  # noqa: N812
from lynxplan.robots.chain import chain_fk

MODE_POSE, MODE_APPROACH, MODE_PITCH = 0, 1, 2
#: Uniform cells over the roll range on which the roots of the roll equation are bracketed.
ROOT_GRID = 48
#: Cells where the roll equation changes by more than FAST_CHANGE are split this many times.
SUBDIVISION = 16
#: Samples between a grid point and a reach boundary of the yaw (quadratically spaced).
BOUNDARY_SAMPLES = 32
#: Two branches closer than this in every joint are one [rad].
DUPLICATE_TOLERANCE = 1e-9
#: Near-roots of the ideal model (|f| below this at a local extremum) are tried on the exact one.
NEAR_ROOT = 5e-3
#: A local extremum of the roll equation this close to zero is a double root (f is the sine of
#: a roll mismatch or an axis component: 1e-10 means 1e-10 rad).
TANGENT_TOLERANCE = 1e-10
FAST_CHANGE = 0.25
#: Roots where the tool point misses the yaw circle by more than this [m] are not solutions
#: (more than the ~1e-7 m the exact model differs from the ideal one by).
CLAMPED_ROOT_TOLERANCE = 1e-6
#: At most this many roll roots per side are kept (each gives two elbow branches).
MAX_ROOTS = 6
TWO_PI = 2.0 * math.pi
_NEWTON_STEPS = 40
_NEWTON_TOLERANCE = 1e-14


@numba.njit(cache=True, nogil=True, inline="always")
def _rotate(
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
def _wrap(x: float) -> float:
    return x - TWO_PI * math.floor((x + math.pi) / TWO_PI)


@numba.njit(cache=True, nogil=True, inline="always")
def _wrap_into_limits(x: float, lo: float, hi: float, tol: float) -> tuple[float, bool]:
    """x moved by whole turns into [lo, hi] (snapped within tol), or the nearest copy outside."""
    if lo <= x <= hi:
        return x, True
    y = x - math.floor((x - lo) / TWO_PI) * TWO_PI
    if y <= hi:
        return y, True
    if y <= hi + tol:
        return hi, True
    if y >= lo + TWO_PI - tol:
        return lo, True
    return (y, False) if y - hi <= lo + TWO_PI - y else (y - TWO_PI, False)


@numba.njit(cache=True, nogil=True)
def _yaw(
    prm: np.ndarray, d0: float, d1: float, d2: float, theta: float, side: int, phi_ref: float
) -> tuple[float, float]:
    """Canonical yaw angle phi of one side for roll theta, and the lateral miss [m]."""
    dp = d0 * prm[F.P] + d1 * prm[F.P + 1] + d2 * prm[F.P + 2]
    dh = d0 * prm[F.H] + d1 * prm[F.H + 1] + d2 * prm[F.H + 2]
    lat = (
        prm[F.LAM4]
        + prm[F.W0 + 2]
        + math.cos(theta) * prm[F.E1 + 2]
        + math.sin(theta) * prm[F.E2 + 2]
    )
    rho = math.hypot(dp, dh)
    if rho <= 1e-12 and abs(lat) <= 1e-12:  # on the yaw axis: any yaw; keep the reference
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
def _plane_target(
    prm: np.ndarray, d0: float, d1: float, d2: float, phi: float
) -> tuple[float, float]:
    """Target point in the arm plane (outward, up) for yaw phi."""
    c, s = math.cos(phi), math.sin(phi)
    dp = d0 * prm[F.P] + d1 * prm[F.P + 1] + d2 * prm[F.P + 2]
    dh = d0 * prm[F.H] + d1 * prm[F.H + 1] + d2 * prm[F.H + 2]
    dk = d0 * prm[F.K] + d1 * prm[F.K + 1] + d2 * prm[F.K + 2]
    return c * dh - s * dp, dk


@numba.njit(cache=True, nogil=True)
def _approach_in_plane(
    prm: np.ndarray, a0: float, a1: float, a2: float, phi: float
) -> tuple[float, float, float]:
    """Components of the approach a along h(phi), k and p(phi)."""
    c, s = math.cos(phi), math.sin(phi)
    ap = a0 * prm[F.P] + a1 * prm[F.P + 1] + a2 * prm[F.P + 2]
    ah = a0 * prm[F.H] + a1 * prm[F.H + 1] + a2 * prm[F.H + 2]
    ak = a0 * prm[F.K] + a1 * prm[F.K + 1] + a2 * prm[F.K + 2]
    return c * ah - s * ap, ak, c * ap + s * ah


@numba.njit(cache=True, nogil=True)
def _best_roll(prm: np.ndarray, g: np.ndarray, phi: float, pitch_sum: float) -> float:
    """Canonical roll theta nearest the target: argmax tr(R(r, theta)^T M), M = Q^T G."""
    k0, k1, k2 = prm[F.K], prm[F.K + 1], prm[F.K + 2]
    p0, p1, p2 = prm[F.P], prm[F.P + 1], prm[F.P + 2]
    r0, r1, r2 = prm[F.R], prm[F.R + 1], prm[F.R + 2]
    cy, sy = math.cos(-phi), math.sin(-phi)
    cp, sp = math.cos(-pitch_sum), math.sin(-pitch_sum)
    x0, x1, x2 = _rotate(k0, k1, k2, cy, sy, g[0, 0], g[1, 0], g[2, 0])
    m00, m10, m20 = _rotate(p0, p1, p2, cp, sp, x0, x1, x2)
    x0, x1, x2 = _rotate(k0, k1, k2, cy, sy, g[0, 1], g[1, 1], g[2, 1])
    m01, m11, m21 = _rotate(p0, p1, p2, cp, sp, x0, x1, x2)
    x0, x1, x2 = _rotate(k0, k1, k2, cy, sy, g[0, 2], g[1, 2], g[2, 2])
    m02, m12, m22 = _rotate(p0, p1, p2, cp, sp, x0, x1, x2)
    sine = r0 * (m21 - m12) + r1 * (m02 - m20) + r2 * (m10 - m01)
    rmr = (
        r0 * (m00 * r0 + m01 * r1 + m02 * r2)
        + r1 * (m10 * r0 + m11 * r1 + m12 * r2)
        + r2 * (m20 * r0 + m21 * r1 + m22 * r2)
    )
    return math.atan2(sine, m00 + m11 + m22 - rmr)


@numba.njit(cache=True, nogil=True)
def _pitch_sum(
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
    ah, ak, out = _approach_in_plane(prm, a0, a1, a2, phi)
    if math.hypot(ah, ak) <= 1e-12:  # approach along the pitch axis: any pitch is as good
        return ref_sum, out
    return math.atan2(ak, ah) - prm[F.GAMMA0], out


@numba.njit(cache=True, nogil=True)
def _roll_equation(
    prm: np.ndarray,
    target: np.ndarray,
    g: np.ndarray,
    mode: int,
    theta: float,
    side: int,
    phi_ref: float,
    sum_ref: float,
) -> float:
    # g[:, 3] holds the target approach axis (column 3 of the (3, 4) scratch)
    """The scalar whose roots are the rolls of an off-axis tool (one side)."""
    d0, d1, d2 = (
        target[0, 3] - prm[F.C1],
        target[1, 3] - prm[F.C1 + 1],
        target[2, 3] - prm[F.C1 + 2],
    )
    phi, _ = _yaw(prm, d0, d1, d2, theta, side, phi_ref)
    big_phi, out = _pitch_sum(prm, mode, g[0, 3], g[1, 3], g[2, 3], 0.0, phi, sum_ref)
    if mode == MODE_APPROACH:
        return out
    # sin, not the wrapped difference: continuous through +-pi; roots at pi are rejected later
    return math.sin(_best_roll(prm, g, phi, big_phi) - theta)


@numba.njit(cache=True, nogil=True)
def _roll_mismatch(
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
    if mode == MODE_APPROACH:
        return abs(_roll_equation(prm, target, g, mode, theta, side, phi_ref, sum_ref))
    d0, d1, d2 = (
        target[0, 3] - prm[F.C1],
        target[1, 3] - prm[F.C1 + 1],
        target[2, 3] - prm[F.C1 + 2],
    )
    phi, _ = _yaw(prm, d0, d1, d2, theta, side, phi_ref)
    big_phi, _ = _pitch_sum(prm, mode, g[0, 3], g[1, 3], g[2, 3], 0.0, phi, sum_ref)
    return abs(_wrap(_best_roll(prm, g, phi, big_phi) - theta))


@numba.njit(cache=True, nogil=True)
def _refine_root(
    prm: np.ndarray,
    target: np.ndarray,
    g: np.ndarray,
    mode: int,
    side: int,
    phi_ref: float,
    sum_ref: float,
    a: float,
    fa: float,
    b: float,
    fb: float,
) -> float:
    """Illinois regula falsi on a bracket [a, b] with fa * fb < 0."""
    side_kept = 0
    for _ in range(80):
        c = (a * fb - b * fa) / (fb - fa)
        if not (min(a, b) <= c <= max(a, b)):
            c = 0.5 * (a + b)
        fc = _roll_equation(prm, target, g, mode, c, side, phi_ref, sum_ref)
        if fc == 0.0 or abs(b - a) < 1e-15:
            return c
        if (fc > 0) == (fb > 0):
            b, fb = c, fc
            if side_kept == -1:
                fa *= 0.5
            side_kept = -1
        else:
            a, fa = c, fc
            if side_kept == 1:
                fb *= 0.5
            side_kept = 1
        if abs(b - a) < 4e-16 * (1.0 + abs(c)):
            return c
    return (a * fb - b * fa) / (fb - fa)


@numba.njit(cache=True, nogil=True)
def _golden(
    prm: np.ndarray,
    target: np.ndarray,
    g: np.ndarray,
    mode: int,
    side: int,
    phi_ref: float,
    sum_ref: float,
    a: float,
    b: float,
    sign: float,
) -> float:
    """Minimiser of sign * f on [a, b] (golden-section search)."""
    inv = 0.5 * (math.sqrt(5.0) - 1.0)
    for _ in range(60):
        c, d = b - inv * (b - a), a + inv * (b - a)
        fc = sign * _roll_equation(prm, target, g, mode, c, side, phi_ref, sum_ref)
        fd = sign * _roll_equation(prm, target, g, mode, d, side, phi_ref, sum_ref)
        if fc < fd:
            b = d
        else:
            a = c
        if b - a < 1e-15:
            break
    return 0.5 * (a + b)


@numba.njit(cache=True, nogil=True)
def _lateral_miss(
    prm: np.ndarray, target: np.ndarray, theta: float, side: int, phi_ref: float
) -> float:
    d0, d1, d2 = (
        target[0, 3] - prm[F.C1],
        target[1, 3] - prm[F.C1 + 1],
        target[2, 3] - prm[F.C1 + 2],
    )
    return _yaw(prm, d0, d1, d2, theta, side, phi_ref)[1]


@numba.njit(cache=True, nogil=True)
def _keep_root(
    prm: np.ndarray,
    target: np.ndarray,
    g: np.ndarray,
    mode: int,
    side: int,
    phi_ref: float,
    sum_ref: float,
    x: float,
    roots: np.ndarray,
    count: int,
) -> int:
    """Store root x unless it is a spurious one (best roll opposite, sin = 0 at pi)."""
    if mode != MODE_APPROACH and (
        _roll_mismatch(prm, target, g, mode, x, side, phi_ref, sum_ref) > 0.5 * math.pi
    ):
        return count
    d0, d1, d2 = (
        target[0, 3] - prm[F.C1],
        target[1, 3] - prm[F.C1 + 1],
        target[2, 3] - prm[F.C1 + 2],
    )
    _, lateral_miss = _yaw(prm, d0, d1, d2, x, side, phi_ref)
    if lateral_miss > CLAMPED_ROOT_TOLERANCE:  # the yaw is clamped there: not a solution
        return count
    if count < MAX_ROOTS:
        roots[count] = x
        roots[MAX_ROOTS + count] = 0.0  # second half: 1 marks a tentative root
        count += 1
    return count


@numba.njit(cache=True, nogil=True)
def _roll_candidates(  # noqa: PLR0912, PLR0915 (numba kernel: one compiled scan)
    prm: np.ndarray,
    target: np.ndarray,
    g: np.ndarray,
    mode: int,
    side: int,
    phi_ref: float,
    sum_ref: float,
    lo: float,
    hi: float,
    roots: np.ndarray,
    xs: np.ndarray,
    fs: np.ndarray,
) -> int:
    """Every root of the roll equation in [lo, hi] (at most MAX_ROOTS); returns their count.

    Roots are bracketed by sign changes on the grid; a pair of roots inside one cell (a near
    double root) shows as a local minimum of |f| without a sign change: the extremum is located
    by golden section and both halves bracketed. Without any root, writes the minimiser of |f|
    and returns -1.
    """
    # uniform grid; cells where f changes fast are split SUBDIVISION times, and cells where
    # the yaw circle starts or stops being reachable are sampled towards that boundary with a
    # quadratic spacing (f behaves like the square root of the distance to it there)
    step = (hi - lo) / ROOT_GRID
    m = 0
    xs[0] = lo
    fs[0] = _roll_equation(prm, target, g, mode, lo, side, phi_ref, sum_ref)
    c0 = _lateral_miss(prm, target, lo, side, phi_ref) > 0.0
    for i in range(1, ROOT_GRID + 1):
        x0 = xs[m]
        x1 = lo + step * i if i < ROOT_GRID else hi
        f1 = _roll_equation(prm, target, g, mode, x1, side, phi_ref, sum_ref)
        c1 = _lateral_miss(prm, target, x1, side, phi_ref) > 0.0
        if c0 != c1:
            a, b = x0, x1  # a keeps the state of x0
            for _ in range(60):
                mid = 0.5 * (a + b)
                if (_lateral_miss(prm, target, mid, side, phi_ref) > 0.0) == c0:
                    a = mid
                else:
                    b = mid
            boundary = b if c0 else a  # on the reachable side
            for j in range(1, BOUNDARY_SAMPLES + 1):
                if c0:  # clamped -> reachable: from the boundary outwards
                    x = boundary + (x1 - boundary) * ((j - 1) / BOUNDARY_SAMPLES) ** 2
                else:  # reachable -> clamped: towards the boundary
                    x = (
                        boundary
                        - (boundary - x0) * ((BOUNDARY_SAMPLES - j) / BOUNDARY_SAMPLES) ** 2
                    )
                if x <= xs[m] or x >= x1:
                    continue
                m += 1
                xs[m] = x
                fs[m] = _roll_equation(prm, target, g, mode, x, side, phi_ref, sum_ref)
        elif abs(f1 - fs[m]) > FAST_CHANGE:
            for j in range(1, SUBDIVISION):
                m += 1
                xs[m] = x0 + (x1 - x0) * j / SUBDIVISION
                fs[m] = _roll_equation(prm, target, g, mode, xs[m], side, phi_ref, sum_ref)
        m += 1
        xs[m], fs[m] = x1, f1
        c0 = c1
    count = 0
    for i in range(m + 1):
        if count >= MAX_ROOTS:
            break
        if fs[i] == 0.0:
            count = _keep_root(prm, target, g, mode, side, phi_ref, sum_ref, xs[i], roots, count)
            continue
        if i == m:
            break
        f0, f1 = fs[i], fs[i + 1]
        if f1 != 0.0 and (f0 < 0.0) != (f1 < 0.0):
            x = _refine_root(prm, target, g, mode, side, phi_ref, sum_ref, xs[i], f0, xs[i + 1], f1)
            count = _keep_root(prm, target, g, mode, side, phi_ref, sum_ref, x, roots, count)
        elif (
            i > 0
            and (fs[i - 1] < 0.0) == (f0 < 0.0)
            and abs(f0) < abs(fs[i - 1])
            and abs(f0) <= abs(f1)
        ):
            # local extremum of |f| at grid point i: two roots may hide in [x_{i-1}, x_{i+1}]
            sign = 1.0 if f0 > 0 else -1.0
            xm = _golden(prm, target, g, mode, side, phi_ref, sum_ref, xs[i - 1], xs[i + 1], sign)
            fm = _roll_equation(prm, target, g, mode, xm, side, phi_ref, sum_ref)
            if fm == 0.0:
                count = _keep_root(prm, target, g, mode, side, phi_ref, sum_ref, xm, roots, count)
            elif (fm < 0.0) == (f0 < 0.0) and abs(fm) <= TANGENT_TOLERANCE:
                # a double (tangent) root: f touches zero without crossing it
                count = _keep_root(prm, target, g, mode, side, phi_ref, sum_ref, xm, roots, count)
            elif prm[F.EXACT] == 0.0 and (fm < 0.0) == (f0 < 0.0) and abs(fm) < NEAR_ROOT:
                # the exact model may have a close pair of roots here that the nearly
                # identical ideal model lacks: tentative, kept only if Newton converges
                for shift in (-2e-3, 2e-3):
                    before = count
                    count = _keep_root(
                        prm,
                        target,
                        g,
                        mode,
                        side,
                        phi_ref,
                        sum_ref,
                        xm + shift,
                        roots,
                        count,
                    )
                    if count > before:
                        roots[MAX_ROOTS + count - 1] = 1.0
            elif (fm < 0.0) != (f0 < 0.0) and count + 2 <= MAX_ROOTS:
                x = _refine_root(
                    prm, target, g, mode, side, phi_ref, sum_ref, xs[i - 1], fs[i - 1], xm, fm
                )
                count = _keep_root(prm, target, g, mode, side, phi_ref, sum_ref, x, roots, count)
                x = _refine_root(
                    prm, target, g, mode, side, phi_ref, sum_ref, xm, fm, xs[i + 1], f1
                )
                count = _keep_root(prm, target, g, mode, side, phi_ref, sum_ref, x, roots, count)
    # an extremum at either end of the range hides roots the scan above cannot see
    for lo_i, hi_i, end in ((0, 1, 0), (m - 1, m, m)):
        inner = 1 if end == 0 else m - 1
        if (
            count + 2 <= MAX_ROOTS
            and m > 0
            and fs[end] != 0.0
            and (fs[end] < 0.0) == (fs[inner] < 0.0)
            and abs(fs[end]) < abs(fs[inner])
        ):
            sign = 1.0 if fs[end] > 0 else -1.0
            xm = _golden(prm, target, g, mode, side, phi_ref, sum_ref, xs[lo_i], xs[hi_i], sign)
            fm = _roll_equation(prm, target, g, mode, xm, side, phi_ref, sum_ref)
            if abs(fm) <= TANGENT_TOLERANCE:
                count = _keep_root(prm, target, g, mode, side, phi_ref, sum_ref, xm, roots, count)
            elif (fm < 0.0) != (fs[end] < 0.0):
                x = _refine_root(
                    prm, target, g, mode, side, phi_ref, sum_ref, xs[lo_i], fs[lo_i], xm, fm
                )
                count = _keep_root(prm, target, g, mode, side, phi_ref, sum_ref, x, roots, count)
                x = _refine_root(
                    prm, target, g, mode, side, phi_ref, sum_ref, xm, fm, xs[hi_i], fs[hi_i]
                )
                count = _keep_root(prm, target, g, mode, side, phi_ref, sum_ref, x, roots, count)
    best = 0
    for i in range(m + 1):
        fs[i] = _roll_mismatch(prm, target, g, mode, xs[i], side, phi_ref, sum_ref)
        if fs[i] < fs[best]:
            best = i
    if count > 0:
        return count
    a, b = xs[max(best - 1, 0)], xs[min(best + 1, m)]
    inv = 0.5 * (math.sqrt(5.0) - 1.0)
    for _ in range(60):
        c, d = b - inv * (b - a), a + inv * (b - a)
        if _roll_mismatch(prm, target, g, mode, c, side, phi_ref, sum_ref) < _roll_mismatch(
            prm, target, g, mode, d, side, phi_ref, sum_ref
        ):
            b = d
        else:
            a = c
    xm = 0.5 * (a + b)
    better = _roll_mismatch(prm, target, g, mode, xm, side, phi_ref, sum_ref) < fs[best]
    roots[0] = xm if better else xs[best]
    return -1


@numba.njit(cache=True, nogil=True)
def _two_link(prm: np.ndarray, x: float, y: float, elbow: int) -> tuple[float, float, float]:
    """Canonical shoulder and elbow angles reaching the wrist point (x, y); and the miss [m]."""
    l20, l21 = prm[F.O3] - prm[F.O2], prm[F.O3 + 1] - prm[F.O2 + 1]
    l30, l31 = prm[F.O4] - prm[F.O3], prm[F.O4 + 1] - prm[F.O3 + 1]
    la, lb = math.hypot(l20, l21), math.hypot(l30, l31)
    b2, b3 = math.atan2(l21, l20), math.atan2(l31, l30)
    rx, ry = x - prm[F.O2], y - prm[F.O2 + 1]
    dist = math.hypot(rx, ry)
    cosd = (dist * dist - la * la - lb * lb) / (2.0 * la * lb)
    miss = 0.0
    if cosd > 1.0:
        miss, cosd = dist - (la + lb), 1.0
    elif cosd < -1.0:
        miss, cosd = abs(la - lb) - dist, -1.0
    delta = math.acos(cosd)
    if prm[F.EXACT] == 0.0 and abs(cosd) > 1.0 - 1e-6:
        # near a fold of a model that is only close to the family: start the two elbows apart,
        # Newton then finds each exact root (they are ~sqrt(deviation) apart)
        delta = max(delta, 2e-3) if cosd > 0 else min(delta, math.pi - 2e-3)
    if elbow == 0:  # elbow up: the elbow lies above the shoulder-wrist line
        delta = -delta
    t2 = math.atan2(ry, rx) - math.atan2(lb * math.sin(delta), la + lb * math.cos(delta))
    psi2 = t2 - b2
    psi3 = delta + b2 - b3
    return psi2, psi3, miss


@numba.njit(cache=True, nogil=True)
def _branch(
    prm: np.ndarray,
    target: np.ndarray,
    g: np.ndarray,
    mode: int,
    pitch: float,
    theta: float,
    side: int,
    elbow: int,
    phi_ref: float,
    sum_ref: float,
    out: np.ndarray,
) -> float:
    """Joint angles of one branch for roll theta into out (5,); returns the reach miss [m]."""
    d0, d1, d2 = (
        target[0, 3] - prm[F.C1],
        target[1, 3] - prm[F.C1 + 1],
        target[2, 3] - prm[F.C1 + 2],
    )
    phi, lat_miss = _yaw(prm, d0, d1, d2, theta, side, phi_ref)
    big_phi, _ = _pitch_sum(prm, mode, g[0, 3], g[1, 3], g[2, 3], pitch, phi, sum_ref)
    if mode == MODE_POSE and prm[F.OFF_AXIS] == 0.0:
        theta = _best_roll(prm, g, phi, big_phi)
    x, y = _plane_target(prm, d0, d1, d2, phi)
    ct, st = math.cos(theta), math.sin(theta)
    wh = prm[F.W0] + ct * prm[F.E1] + st * prm[F.E2]
    wk = prm[F.W0 + 1] + ct * prm[F.E1 + 1] + st * prm[F.E2 + 1]
    cp, sp = math.cos(big_phi), math.sin(big_phi)
    psi2, psi3, miss = _two_link(prm, x - (cp * wh - sp * wk), y - (sp * wh + cp * wk), elbow)
    out[0] = prm[F.SIGMA] * phi
    out[1] = prm[F.SIGMA + 1] * psi2
    out[2] = prm[F.SIGMA + 2] * psi3
    out[3] = prm[F.SIGMA + 3] * (big_phi - psi2 - psi3)
    out[4] = prm[F.SIGMA + 4] * theta
    return math.hypot(miss, lat_miss)


@numba.njit(cache=True, nogil=True)
def _conditions(
    prm: np.ndarray,
    placements: np.ndarray,
    axes: np.ndarray,
    target: np.ndarray,
    g: np.ndarray,
    mode: int,
    pitch: float,
    roll_given: float,
    q: np.ndarray,
    pose: np.ndarray,
    work: np.ndarray,
    e: np.ndarray,
) -> None:
    """The five conditions the branch satisfies, evaluated on the exact chain."""
    chain_fk(placements, axes, q, pose, work)
    for i in range(3):
        e[i] = pose[i, 3] - target[i, 3]
    # approach axis and pitch axis of the reached configuration
    rt = prm[F.RT0 : F.RT0 + 9]
    r0, r1, r2 = prm[F.R], prm[F.R + 1], prm[F.R + 2]
    # approach in the tool frame: Rt0^T r
    u0 = rt[0] * r0 + rt[3] * r1 + rt[6] * r2
    u1 = rt[1] * r0 + rt[4] * r1 + rt[7] * r2
    u2 = rt[2] * r0 + rt[5] * r1 + rt[8] * r2
    a0 = pose[0, 0] * u0 + pose[0, 1] * u1 + pose[0, 2] * u2
    a1 = pose[1, 0] * u0 + pose[1, 1] * u1 + pose[1, 2] * u2
    a2 = pose[2, 0] * u0 + pose[2, 1] * u1 + pose[2, 2] * u2
    cy, sy = math.cos(prm[F.SIGMA] * q[0]), math.sin(prm[F.SIGMA] * q[0])
    k0, k1, k2 = prm[F.K], prm[F.K + 1], prm[F.K + 2]
    pp0, pp1, pp2 = _rotate(k0, k1, k2, cy, sy, prm[F.P], prm[F.P + 1], prm[F.P + 2])
    if mode == MODE_PITCH:
        h0, h1, h2 = _rotate(k0, k1, k2, cy, sy, prm[F.H], prm[F.H + 1], prm[F.H + 2])
        sp, cp = math.sin(pitch), math.cos(pitch)
        t0, t1, t2 = sp * h0 - cp * k0, sp * h1 - cp * k1, sp * h2 - cp * k2
    else:
        t0, t1, t2 = g[0, 3], g[1, 3], g[2, 3]
    # in-plane approach angle matches: (a x at) . p = 0
    c0 = a1 * t2 - a2 * t1
    c1 = a2 * t0 - a0 * t2
    c2 = a0 * t1 - a1 * t0
    e[3] = c0 * pp0 + c1 * pp1 + c2 * pp2
    if (
        not math.isnan(roll_given)
        or mode == MODE_PITCH
        or (mode == MODE_APPROACH and prm[F.OFF_AXIS] == 0.0)
    ):
        e[4] = q[4] - roll_given
    elif mode == MODE_APPROACH:  # the approach exactly: (a x at) . (a x p) = 0 as well
        w0 = a1 * pp2 - a2 * pp1
        w1 = a2 * pp0 - a0 * pp2
        w2 = a0 * pp1 - a1 * pp0
        e[4] = c0 * w0 + c1 * w1 + c2 * w2
    else:  # best roll about the approach axis: a . vee(Rt R^T - R Rt^T) = 0
        v0 = v1 = v2 = 0.0
        for m in range(3):
            v0 += target[2, m] * pose[1, m] - pose[2, m] * target[1, m]
            v1 += target[0, m] * pose[2, m] - pose[0, m] * target[2, m]
            v2 += target[1, m] * pose[0, m] - pose[1, m] * target[0, m]
        e[4] = a0 * v0 + a1 * v1 + a2 * v2


@numba.njit(cache=True, nogil=True)
def _polish(
    prm: np.ndarray,
    placements: np.ndarray,
    axes: np.ndarray,
    target: np.ndarray,
    g: np.ndarray,
    mode: int,
    pitch: float,
    roll_given: float,
    q: np.ndarray,
    scratch: np.ndarray,
    scratch4: np.ndarray,
    scratch5: np.ndarray,
) -> float:
    """Newton's method on the five conditions, on the exact chain (finite-difference Jacobian).

    Keeps the closed-form answer when Newton does not reduce the conditions (unreachable).
    """
    # scratch (7, 5): rows e, e2, qh, start, qt; (pose, work) in scratch4, jac in scratch5
    pose, work = scratch4[0], scratch4[1]
    e, e2, qh, start, qt = scratch[0], scratch[1], scratch[2], scratch[3], scratch[4]
    jac = scratch5
    start[:] = q
    _conditions(prm, placements, axes, target, g, mode, pitch, roll_given, q, pose, work, e)
    first = max(abs(e[0]), abs(e[1]), abs(e[2]), abs(e[3]), abs(e[4]))
    norm = first
    for _ in range(_NEWTON_STEPS):
        if norm < _NEWTON_TOLERANCE or not math.isfinite(norm):
            break
        for j in range(5):
            qh[:] = q
            qh[j] += 1e-7
            _conditions(
                prm, placements, axes, target, g, mode, pitch, roll_given, qh, pose, work, e2
            )
            for i in range(5):
                jac[i, j] = (e2[i] - e[i]) / 1e-7
        if abs(np.linalg.det(jac)) < 1e-300:
            break
        step = np.linalg.solve(jac, e)
        # backtracking: the full step unless it increases the conditions
        t = 1.0
        accepted = False
        for _ in range(12):
            for j in range(5):
                qt[j] = q[j] - t * step[j]
            _conditions(
                prm, placements, axes, target, g, mode, pitch, roll_given, qt, pose, work, e2
            )
            trial = max(abs(e2[0]), abs(e2[1]), abs(e2[2]), abs(e2[3]), abs(e2[4]))
            if trial < norm:
                q[:] = qt
                e[:] = e2
                norm = trial
                accepted = True
                break
            t *= 0.5
        if not accepted:
            break
    if not (norm <= first):
        q[:] = start
        return float(first)
    return float(norm)


@numba.njit(cache=True, nogil=True)
def _orientation_error(
    prm: np.ndarray,
    target: np.ndarray,
    g: np.ndarray,
    mode: int,
    pitch: float,
    q: np.ndarray,
    pose: np.ndarray,
) -> float:
    """Angle between target and reached orientation (pose) or approach axes (approach, pitch)."""
    if mode == MODE_POSE:
        s0 = s1 = s2 = 0.0
        tr = 0.0
        for i in range(3):
            tr += target[0, i] * pose[0, i] + target[1, i] * pose[1, i] + target[2, i] * pose[2, i]
        # vee of (Rt^T R - R^T Rt): rows of Rt^T R are columns of Rt dotted with columns of R
        m01 = m10 = m02 = m20 = m12 = m21 = 0.0
        for r in range(3):
            m01 += target[r, 0] * pose[r, 1]
            m10 += target[r, 1] * pose[r, 0]
            m02 += target[r, 0] * pose[r, 2]
            m20 += target[r, 2] * pose[r, 0]
            m12 += target[r, 1] * pose[r, 2]
            m21 += target[r, 2] * pose[r, 1]
        s0, s1, s2 = m21 - m12, m02 - m20, m10 - m01
        return math.atan2(0.5 * math.sqrt(s0 * s0 + s1 * s1 + s2 * s2), 0.5 * (tr - 1.0))
    rt = prm[F.RT0 : F.RT0 + 9]
    r0, r1, r2 = prm[F.R], prm[F.R + 1], prm[F.R + 2]
    u0 = rt[0] * r0 + rt[3] * r1 + rt[6] * r2
    u1 = rt[1] * r0 + rt[4] * r1 + rt[7] * r2
    u2 = rt[2] * r0 + rt[5] * r1 + rt[8] * r2
    a0 = pose[0, 0] * u0 + pose[0, 1] * u1 + pose[0, 2] * u2
    a1 = pose[1, 0] * u0 + pose[1, 1] * u1 + pose[1, 2] * u2
    a2 = pose[2, 0] * u0 + pose[2, 1] * u1 + pose[2, 2] * u2
    if mode == MODE_PITCH:
        k0, k1, k2 = prm[F.K], prm[F.K + 1], prm[F.K + 2]
        cy, sy = math.cos(prm[F.SIGMA] * q[0]), math.sin(prm[F.SIGMA] * q[0])
        h0, h1, h2 = _rotate(k0, k1, k2, cy, sy, prm[F.H], prm[F.H + 1], prm[F.H + 2])
        sp, cp = math.sin(pitch), math.cos(pitch)
        t0, t1, t2 = sp * h0 - cp * k0, sp * h1 - cp * k1, sp * h2 - cp * k2
    else:
        t0, t1, t2 = g[0, 3], g[1, 3], g[2, 3]
    c0, c1, c2 = a1 * t2 - a2 * t1, a2 * t0 - a0 * t2, a0 * t1 - a1 * t0
    return math.atan2(math.sqrt(c0 * c0 + c1 * c1 + c2 * c2), a0 * t0 + a1 * t1 + a2 * t2)


@numba.njit(cache=True, nogil=True)
def family_ik_kernel(  # noqa: PLR0912, PLR0915 (numba kernel: one compiled loop per pose)
    prm: np.ndarray,
    placements: np.ndarray,
    axes: np.ndarray,
    targets: np.ndarray,
    mode: int,
    pitch: np.ndarray,
    roll: np.ndarray,
    reference: np.ndarray,
    q_out: np.ndarray,
    valid: np.ndarray,
    within: np.ndarray,
    position_error: np.ndarray,
    orientation_error: np.ndarray,
    miss_out: np.ndarray,
) -> None:
    """Every branch of N targets.

    Args:
        prm: Packed family parameters (``family.py``).
        placements, axes: The exact chain (``chain.py``).
        targets: (N, 4, 4) poses; for approach targets only column 2 (approach) and 3 count.
        mode: MODE_POSE, MODE_APPROACH or MODE_PITCH.
        pitch: (N,) approach pitch for MODE_PITCH [rad] (from straight down towards outward).
        roll: (N,) roll joint angle [rad], NaN where free.
        reference: (N, 5) or (1, 5) joint angles [rad]: yaw on the base axis, the pitch sum when
            the approach is along the pitch axis, the roll where free and not determined.
        q_out: (N, B, 5) output angles; B = 4 (closed form) or 4 * MAX_ROOTS (root search).
        valid, within: (N, B) output flags (branch exists; within joint limits).
        position_error, orientation_error: (N, B) output, [m] and [rad] on the exact chain.
        miss_out: (N, B) output: by how much the closed form missed the reach, [m].
    """
    nb = q_out.shape[1]
    per_side = nb // 2
    lower, upper = prm[F.LOWER : F.LOWER + 5], prm[F.UPPER : F.UPPER + 5]
    tol = prm[F.LIMIT_TOL]
    sig5 = prm[F.SIGMA + 4]
    lo5, hi5 = sig5 * lower[4], sig5 * upper[4]
    if lo5 > hi5:
        lo5, hi5 = hi5, lo5
    if hi5 - lo5 > TWO_PI:
        hi5 = lo5 + TWO_PI
    rt0 = prm[F.RT0 : F.RT0 + 9]
    g = np.empty((3, 4))  # G = Rt Rt0^T, then the target approach axis
    pose, work = np.empty((4, 4)), np.empty((4, 4))
    roots = np.empty(2 * MAX_ROOTS)
    q = np.empty(5)
    trial = np.empty(5)
    scratch = np.empty((5, 5))
    scratch4 = np.empty((2, 4, 4))
    scratch5 = np.empty((5, 5))
    size = ROOT_GRID * (BOUNDARY_SAMPLES + SUBDIVISION) + 2
    grid_x, grid_f = np.empty(size), np.empty(size)
    nearest = 0.0
    exact = prm[F.EXACT] != 0.0
    off_axis = prm[F.OFF_AXIS] != 0.0
    for n in range(targets.shape[0]):
        target = targets[n]
        ref = reference[n if reference.shape[0] > 1 else 0]
        phi_ref = prm[F.SIGMA] * ref[0]
        sum_ref = prm[F.SIGMA + 1] * ref[1] + prm[F.SIGMA + 2] * ref[2] + prm[F.SIGMA + 3] * ref[3]
        if mode == MODE_POSE:
            for i in range(3):  # G = Rt Rt0^T
                for j in range(3):
                    g[i, j] = (
                        target[i, 0] * rt0[3 * j]
                        + target[i, 1] * rt0[3 * j + 1]
                        + target[i, 2] * rt0[3 * j + 2]
                    )
        if mode == MODE_POSE:  # approach = Rt (Rt0^T r)
            for i in range(3):
                g[i, 3] = g[i, 0] * prm[F.R] + g[i, 1] * prm[F.R + 1] + g[i, 2] * prm[F.R + 2]
        else:
            for i in range(3):
                g[i, 3] = target[i, 2]
        roll_given = roll[n]
        need_roots = off_axis and math.isnan(roll_given) and mode != MODE_PITCH
        theta_fixed = sig5 * (ref[4] if math.isnan(roll_given) else roll_given)
        for b in range(nb):
            valid[n, b] = False
            within[n, b] = False
            position_error[n, b] = np.nan
            orientation_error[n, b] = np.nan
            miss_out[n, b] = np.nan
            for j in range(5):
                q_out[n, b, j] = np.nan
        for side in range(2):
            count = 1
            roots[0] = theta_fixed
            rooted = True
            if need_roots:
                count = _roll_candidates(
                    prm, target, g, mode, side, phi_ref, sum_ref, lo5, hi5, roots, grid_x, grid_f
                )
                if count < 0:  # no root: the nearest roll, held during the polish
                    count, rooted = 1, False
                    nearest = roots[0]
                    if not exact and MAX_ROOTS >= 2:
                        # the exact model may still have a close pair of roots the nearly
                        # identical ideal model lacks: try Newton from either side first
                        count = 2
                        roots[0], roots[1] = nearest - 2e-3, nearest + 2e-3
            for ri in range(count):
                for elbow in range(2):
                    b = side * per_side + ri * 2 + elbow
                    miss = _branch(
                        prm, target, g, mode, pitch[n], roots[ri], side, elbow, phi_ref, sum_ref, q
                    )
                    polished = False
                    hold = False
                    if need_roots and rooted and roots[MAX_ROOTS + ri] == 1.0:
                        # a tentative root: a branch only if Newton converges on the exact model
                        if (
                            _polish(
                                prm,
                                placements,
                                axes,
                                target,
                                g,
                                mode,
                                pitch[n],
                                np.nan,
                                q,
                                scratch,
                                scratch4,
                                scratch5,
                            )
                            >= _NEWTON_TOLERANCE
                        ):
                            firm = 0
                            for j in range(count):
                                firm += roots[MAX_ROOTS + j] == 0.0
                            if firm > 0:
                                continue
                            # only tentative roots on this side: keep the nearest, roll held
                            miss = _branch(
                                prm,
                                target,
                                g,
                                mode,
                                pitch[n],
                                roots[ri],
                                side,
                                elbow,
                                phi_ref,
                                sum_ref,
                                q,
                            )
                            hold = True
                        else:
                            polished = True
                    elif not exact and not rooted:
                        trial[:] = q
                        if (
                            _polish(
                                prm,
                                placements,
                                axes,
                                target,
                                g,
                                mode,
                                pitch[n],
                                np.nan,
                                trial,
                                scratch,
                                scratch4,
                                scratch5,
                            )
                            < _NEWTON_TOLERANCE
                        ):
                            q[:] = trial
                            polished = True
                        else:
                            miss = _branch(
                                prm,
                                target,
                                g,
                                mode,
                                pitch[n],
                                nearest,
                                side,
                                elbow,
                                phi_ref,
                                sum_ref,
                                q,
                            )
                    if not exact and not polished:
                        rg = roll_given
                        if math.isnan(rg) and (
                            mode == MODE_PITCH
                            or (mode == MODE_APPROACH and not off_axis)
                            or not rooted
                            or hold
                        ):
                            rg = q[4]
                        _polish(
                            prm,
                            placements,
                            axes,
                            target,
                            g,
                            mode,
                            pitch[n],
                            rg,
                            q,
                            scratch,
                            scratch4,
                            scratch5,
                        )
                    inside = True
                    for j in range(5):
                        x, ok = _wrap_into_limits(q[j], lower[j], upper[j], tol)
                        q_out[n, b, j] = x
                        q[j] = x
                        inside = inside and ok
                    chain_fk(placements, axes, q, pose, work)
                    err = 0.0
                    for i in range(3):
                        d = pose[i, 3] - target[i, 3]
                        err += d * d
                    duplicate = False
                    for b2 in range(b):
                        if valid[n, b2]:
                            gap = 0.0
                            for j in range(5):
                                gap = max(gap, abs(q_out[n, b2, j] - q[j]))
                            duplicate = duplicate or gap < DUPLICATE_TOLERANCE
                    if duplicate:  # the same branch reached twice (merged roots, a fold)
                        for j in range(5):
                            q_out[n, b, j] = np.nan
                        continue
                    valid[n, b] = True
                    within[n, b] = inside
                    position_error[n, b] = math.sqrt(err)
                    orientation_error[n, b] = _orientation_error(
                        prm, target, g, mode, pitch[n], q, pose
                    )
                    miss_out[n, b] = miss
