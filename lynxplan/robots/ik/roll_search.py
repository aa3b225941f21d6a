"""The roll root search of an off-axis tool point (numba; see ``family_kernel.py``).

When the tool point is off the roll axis and the roll is not given, the roll is a root of one
scalar function of the roll on the roll joint's range (``roll_equation.py``). Every root is
bracketed on a uniform grid of :data:`ROOT_GRID` cells (cells where the function changes fast
subdivided, the reach boundary of the yaw sampled densely) and refined by the Illinois method;
a local minimum of |f| without a sign change is located by Brent's minimisation (two roots may
hide in its cells). Without a root, the roll that comes nearest is used. Angles in [rad].
"""

from __future__ import annotations

import math

import numba
import numpy as np

from lynxplan.robots import family as F  # noqa: N812
from lynxplan.robots.ik.family_geometry import MODE_APPROACH, RollProblem
from lynxplan.robots.ik.roll_equation import (
    lateral_miss,
    roll_equation,
    roll_mismatch,
    roll_terms,
)

#: Uniform cells over the roll range on which the roots of the roll equation are bracketed.
ROOT_GRID = 48
#: Cells where the roll equation changes by more than FAST_CHANGE are split this many times.
SUBDIVISION = 16
FAST_CHANGE = 0.25
#: Samples between a grid point and a reach boundary of the yaw (quadratically spaced).
BOUNDARY_SAMPLES = 32
#: Near-roots of the ideal model (|f| below this at a local extremum) are tried on the exact one.
NEAR_ROOT = 5e-3
#: A local extremum of the roll equation this close to zero is a double root (f is the sine of
#: a roll mismatch or an axis component: 1e-10 means 1e-10 rad).
TANGENT_TOLERANCE = 1e-10
#: Roots where the tool point misses the yaw circle by more than this [m] are not solutions
#: (more than the ~1e-7 m the exact model differs from the ideal one by).
CLAMPED_ROOT_TOLERANCE = 1e-6
#: At most this many roll roots per side are kept (each gives two elbow branches).
MAX_ROOTS = 6
#: Grid samples of one side at most (uniform points, subdivisions, boundary samples).
GRID_SIZE = ROOT_GRID * (BOUNDARY_SAMPLES + SUBDIVISION) + 2
#: Brent's minimisation: relative and absolute tolerance on the minimiser [rad].
_BRENT_RELATIVE, _BRENT_ABSOLUTE = 1.5e-8, 1e-11


@numba.njit(cache=True, nogil=True)
def _refine_root(
    problem: RollProblem,
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
        fc = roll_equation(problem, c)
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
def _minimise(  # noqa: PLR0912 (Brent's method as published, one compiled loop)
    problem: RollProblem,
    a: float,
    b: float,
    sign: float,
) -> float:
    """Minimiser of sign * f on [a, b] (Brent's method: parabolic steps, golden-section
    fallback), or the first point found where sign * f < 0 (then f changes sign in [a, b])."""
    golden = 0.5 * (3.0 - math.sqrt(5.0))
    x = w = v = a + golden * (b - a)
    fx = sign * roll_equation(problem, x)
    if fx < 0.0:
        return x
    fw = fv = fx
    d = e = 0.0
    for _ in range(100):
        xm = 0.5 * (a + b)
        tol1 = _BRENT_RELATIVE * abs(x) + _BRENT_ABSOLUTE
        tol2 = 2.0 * tol1
        if abs(x - xm) <= tol2 - 0.5 * (b - a):
            break
        parabolic = False
        if abs(e) > tol1:
            r = (x - w) * (fx - fv)
            q = (x - v) * (fx - fw)
            p = (x - v) * q - (x - w) * r
            q = 2.0 * (q - r)
            if q > 0.0:
                p = -p
            q = abs(q)
            previous = e
            e = d
            if abs(p) < abs(0.5 * q * previous) and q * (a - x) < p < q * (b - x):
                d = p / q
                u = x + d
                if u - a < tol2 or b - u < tol2:
                    d = tol1 if xm >= x else -tol1
                parabolic = True
        if not parabolic:
            e = (a - x) if x >= xm else (b - x)
            d = golden * e
        u = x + d if abs(d) >= tol1 else x + (tol1 if d > 0 else -tol1)
        fu = sign * roll_equation(problem, u)
        if fu < 0.0:
            return u
        if fu <= fx:
            if u >= x:
                a = x
            else:
                b = x
            v, fv, w, fw, x, fx = w, fw, x, fx, u, fu
        else:
            if u < x:
                a = u
            else:
                b = u
            if fu <= fw or w == x:
                v, fv, w, fw = w, fw, u, fu
            elif fu <= fv or (v - x) * (v - w) == 0.0:  # v is x or w
                v, fv = u, fu
    return x


@numba.njit(cache=True, nogil=True)
def _keep_root(
    problem: RollProblem,
    x: float,
    roots: np.ndarray,
    count: int,
) -> int:
    """Store root x unless it is a spurious one (best roll opposite, sin = 0 at pi)."""
    f, c, miss = roll_terms(problem, x)
    if problem[3] != MODE_APPROACH and abs(math.atan2(f, c)) > 0.5 * math.pi:
        return count
    if miss > CLAMPED_ROOT_TOLERANCE:  # the yaw is clamped there: not a solution
        return count
    if count < MAX_ROOTS:
        roots[count] = x
        roots[MAX_ROOTS + count] = 0.0  # second half: 1 marks a tentative root
        count += 1
    return count


@numba.njit(cache=True, nogil=True)
def roll_candidates(  # noqa: PLR0912, PLR0915 (numba kernel: one compiled scan)
    problem: RollProblem,
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
    f0, _, miss0 = roll_terms(problem, lo)
    fs[0] = f0
    c0 = miss0 > 0.0
    for i in range(1, ROOT_GRID + 1):
        x0 = xs[m]
        x1 = lo + step * i if i < ROOT_GRID else hi
        f1, _, miss1 = roll_terms(problem, x1)
        c1 = miss1 > 0.0
        if c0 != c1:
            a, b = x0, x1  # a keeps the state of x0
            for _ in range(60):
                mid = 0.5 * (a + b)
                if (lateral_miss(problem, mid) > 0.0) == c0:
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
                fs[m] = roll_equation(problem, x)
        elif abs(f1 - fs[m]) > FAST_CHANGE:
            for j in range(1, SUBDIVISION):
                m += 1
                xs[m] = x0 + (x1 - x0) * j / SUBDIVISION
                fs[m] = roll_equation(problem, xs[m])
        m += 1
        xs[m], fs[m] = x1, f1
        c0 = c1
    count = 0
    for i in range(m + 1):
        if count >= MAX_ROOTS:
            break
        if fs[i] == 0.0:
            count = _keep_root(problem, xs[i], roots, count)
            continue
        if i == m:
            break
        f0, f1 = fs[i], fs[i + 1]
        if f1 != 0.0 and (f0 < 0.0) != (f1 < 0.0):
            x = _refine_root(problem, xs[i], f0, xs[i + 1], f1)
            count = _keep_root(problem, x, roots, count)
        elif (
            i > 0
            and (fs[i - 1] < 0.0) == (f0 < 0.0)
            and abs(f0) < abs(fs[i - 1])
            and abs(f0) <= abs(f1)
        ):
            # local extremum of |f| at grid point i: two roots may hide in [x_{i-1}, x_{i+1}]
            sign = 1.0 if f0 > 0 else -1.0
            xm = _minimise(problem, xs[i - 1], xs[i + 1], sign)
            fm = roll_equation(problem, xm)
            if fm == 0.0:
                count = _keep_root(problem, xm, roots, count)
            elif (fm < 0.0) == (f0 < 0.0) and abs(fm) <= TANGENT_TOLERANCE:
                # a double (tangent) root: f touches zero without crossing it
                count = _keep_root(problem, xm, roots, count)
            elif problem[0][F.EXACT] == 0.0 and (fm < 0.0) == (f0 < 0.0) and abs(fm) < NEAR_ROOT:
                # the exact model may have a close pair of roots here that the nearly
                # identical ideal model lacks: tentative, kept only if Newton converges
                for shift in (-2e-3, 2e-3):
                    before = count
                    count = _keep_root(problem, xm + shift, roots, count)
                    if count > before:
                        roots[MAX_ROOTS + count - 1] = 1.0
            elif (fm < 0.0) != (f0 < 0.0) and count + 2 <= MAX_ROOTS:
                x = _refine_root(problem, xs[i - 1], fs[i - 1], xm, fm)
                count = _keep_root(problem, x, roots, count)
                x = _refine_root(problem, xm, fm, xs[i + 1], f1)
                count = _keep_root(problem, x, roots, count)
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
            xm = _minimise(problem, xs[lo_i], xs[hi_i], sign)
            fm = roll_equation(problem, xm)
            if abs(fm) <= TANGENT_TOLERANCE:
                count = _keep_root(problem, xm, roots, count)
            elif (fm < 0.0) != (fs[end] < 0.0):
                x = _refine_root(problem, xs[lo_i], fs[lo_i], xm, fm)
                count = _keep_root(problem, x, roots, count)
                x = _refine_root(problem, xm, fm, xs[hi_i], fs[hi_i])
                count = _keep_root(problem, x, roots, count)
    if count > 0:
        return count
    roots[0] = _nearest_roll(problem, xs, fs, m)
    return -1


@numba.njit(cache=True, nogil=True)
def _nearest_roll(
    problem: RollProblem,
    xs: np.ndarray,
    fs: np.ndarray,
    m: int,
) -> float:
    """Without a root: the roll of least mismatch, from the grid xs[: m + 1] refined by golden
    section (fs is overwritten with the mismatch)."""
    best = 0
    for i in range(m + 1):
        fs[i] = roll_mismatch(problem, xs[i])
        if fs[i] < fs[best]:
            best = i
    a, b = xs[max(best - 1, 0)], xs[min(best + 1, m)]
    inv = 0.5 * (math.sqrt(5.0) - 1.0)
    for _ in range(60):
        c, d = b - inv * (b - a), a + inv * (b - a)
        if roll_mismatch(problem, c) < roll_mismatch(problem, d):
            b = d
        else:
            a = c
    xm = 0.5 * (a + b)
    better = roll_mismatch(problem, xm) < fs[best]
    return xm if better else float(xs[best])
