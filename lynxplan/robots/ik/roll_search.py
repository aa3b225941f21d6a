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

from lynxplan.constants import (
    BOUNDARY_TOLERANCE,
    CLAMPED_ROOT_TOLERANCE,
    EXACT_BAND,
    NEAR_ROOT,
    ROOT_MERGE,
    TANGENT_TOLERANCE,
)
from lynxplan.robots import family as F  # noqa: N812
from lynxplan.robots.ik.exact_roll_equation import (
    ExactProblem,
    branch_reaches,
    exact_roll_equation,
)
from lynxplan.robots.ik.family_geometry import MODE_APPROACH, RollProblem, from_yaw_axis
from lynxplan.robots.ik.roll_equation import (
    lateral_miss,
    roll_equation,
    roll_mismatch,
    roll_terms,
)
from lynxplan.robots.ik.root_finding import equation, minimise, refine_root, simple_crossing

#: Uniform cells over the roll range on which the roots of the roll equation are bracketed.
ROOT_GRID = 48
#: Cells where the roll equation changes by more than FAST_CHANGE are split this many times.
SUBDIVISION = 16
FAST_CHANGE = 0.25
#: Samples between a grid point and a reach boundary of the yaw (quadratically spaced).
BOUNDARY_SAMPLES = 32
#: At most this many roll roots per side are kept (each gives two elbow branches).
MAX_ROOTS = 6
#: Grid samples of one side at most (uniform points, subdivisions, boundary samples).
GRID_SIZE = ROOT_GRID * (BOUNDARY_SAMPLES + SUBDIVISION) + 2


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
def sample_roll_grid(
    problem: RollProblem,
    lo: float,
    hi: float,
    xs: np.ndarray,
    fs: np.ndarray,
) -> int:
    """The roll equation sampled on [lo, hi] into xs, fs (GRID_SIZE,); returns the index m of
    the last sample (xs[: m + 1] increasing, xs[0] = lo, xs[m] = hi)."""
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
                    u = (j - 1) / BOUNDARY_SAMPLES
                    x = boundary + (x1 - boundary) * (u * u)
                else:  # reachable -> clamped: towards the boundary
                    u = (BOUNDARY_SAMPLES - j) / BOUNDARY_SAMPLES
                    x = boundary - (boundary - x0) * (u * u)
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
    return m


@numba.njit(cache=True, nogil=True)
def roll_candidates(
    problem: RollProblem,
    xs: np.ndarray,
    fs: np.ndarray,
    m: int,
    roots: np.ndarray,
) -> int:
    """Every root of the roll equation sampled at xs[: m + 1] (``sample_roll_grid``), at most
    MAX_ROOTS, into roots; returns their count (0 without a root: see ``nearest_roll``).

    Roots are bracketed by sign changes on the grid; a pair of roots inside one cell (a near
    double root) shows as a local minimum of |f| without a sign change: the extremum is located
    by Brent's minimisation and both halves bracketed.
    """
    near = problem[0][F.EXACT] == 0.0
    # int64 and np.bool_, not literals: numba compiles a callee once per literal value
    ends = (np.bool_(True), np.bool_(True))
    return _scan(problem, problem, (xs, fs, m), roots, np.int64(0), near, ends)


@numba.njit(cache=True, nogil=True)
def _scan(  # noqa: PLR0912 (numba kernel: one compiled scan)
    problem: RollProblem | ExactProblem,
    ideal: RollProblem,
    samples: tuple[np.ndarray, np.ndarray, int],
    roots: np.ndarray,
    count: int,
    near_roots: bool | np.bool_,
    ends: tuple[bool | np.bool_, bool | np.bool_],
) -> int:
    """The roots of problem's equation sampled at xs[: m + 1] (fs; NaN where undefined;
    ``samples``: (xs, fs, m)) added to roots[:count]; returns the new count. ``near_roots``: a
    near root of the ideal equation gives two tentative roots; ``ends``: whether xs[0], xs[m]
    are ends of the roll range (an extremum there hides roots)."""
    xs, fs, m = samples
    lo_end, hi_end = ends
    for i in range(m + 1):
        if count >= MAX_ROOTS:
            break
        if fs[i] == 0.0:
            count = _keep_root(ideal, xs[i], roots, count)
            continue
        if i == m:
            break
        f0, f1 = fs[i], fs[i + 1]
        if not (math.isfinite(f0) and math.isfinite(f1)):
            continue
        if f1 != 0.0 and (f0 < 0.0) != (f1 < 0.0):
            x = refine_root(problem, xs[i], f0, xs[i + 1], f1)
            count = _keep_root(ideal, x, roots, count)
        elif (
            i > 0
            and math.isfinite(fs[i - 1])
            and (fs[i - 1] < 0.0) == (f0 < 0.0)
            and abs(f0) < abs(fs[i - 1])
            and abs(f0) <= abs(f1)
        ):
            # local extremum of |f| at grid point i: two roots may hide in [x_{i-1}, x_{i+1}]
            sign = 1.0 if f0 > 0 else -1.0
            xm = minimise(problem, xs[i - 1], xs[i + 1], sign)
            fm = equation(problem, xm)
            if fm == 0.0:
                count = _keep_root(ideal, xm, roots, count)
            elif (fm < 0.0) == (f0 < 0.0) and abs(fm) <= TANGENT_TOLERANCE:
                # a double (tangent) root: f touches zero without crossing it
                count = _keep_root(ideal, xm, roots, count)
            elif near_roots and (fm < 0.0) == (f0 < 0.0) and abs(fm) < NEAR_ROOT:
                # the exact model may have a close pair of roots here that the nearly
                # identical ideal model lacks: tentative, kept only if Newton converges
                for shift in (-2e-3, 2e-3):
                    before = count
                    count = _keep_root(ideal, xm + shift, roots, count)
                    if count > before:
                        roots[MAX_ROOTS + count - 1] = 1.0
            elif (fm < 0.0) != (f0 < 0.0) and count + 2 <= MAX_ROOTS:
                x = refine_root(problem, xs[i - 1], fs[i - 1], xm, fm)
                count = _keep_root(ideal, x, roots, count)
                x = refine_root(problem, xm, fm, xs[i + 1], f1)
                count = _keep_root(ideal, x, roots, count)
    # an extremum at either end of the range hides roots the scan above cannot see
    if lo_end and m > 0:
        count = _end_roots(problem, ideal, xs, fs, np.int64(0), np.int64(1), roots, count)
    if hi_end and m > 0:
        count = _end_roots(problem, ideal, xs, fs, m, m - 1, roots, count)
    return count


@numba.njit(cache=True, nogil=True)
def _end_roots(
    problem: RollProblem | ExactProblem,
    ideal: RollProblem,
    xs: np.ndarray,
    fs: np.ndarray,
    end: int,
    inner: int,
    roots: np.ndarray,
    count: int,
) -> int:
    """The roots an extremum of |f| at the last sample before an end (of the range, or of
    where the equation is defined) hides between xs[inner] and xs[end]; returns the count."""
    a, b = min(end, inner), max(end, inner)
    if (
        count + 2 <= MAX_ROOTS
        and fs[end] != 0.0
        and math.isfinite(fs[end])
        and math.isfinite(fs[inner])
        and (fs[end] < 0.0) == (fs[inner] < 0.0)
        and abs(fs[end]) < abs(fs[inner])
    ):
        sign = 1.0 if fs[end] > 0 else -1.0
        xm = minimise(problem, xs[a], xs[b], sign)
        fm = equation(problem, xm)
        if fm != 0.0 and (fm < 0.0) != (fs[end] < 0.0):
            x = refine_root(problem, xs[a], fs[a], xm, fm)
            count = _keep_root(ideal, x, roots, count)
            x = refine_root(problem, xm, fm, xs[b], fs[b])
            count = _keep_root(ideal, x, roots, count)
        elif abs(fm) <= TANGENT_TOLERANCE:
            count = _keep_root(ideal, xm, roots, count)
    return count


@numba.njit(cache=True, nogil=True)
def _exact_samples(
    problem: ExactProblem,
    xs: np.ndarray,
    fs: np.ndarray,
    lo: int,
    hi: int,
    band: float,
    out: tuple[np.ndarray, np.ndarray, np.ndarray],
) -> int:
    """The exact equation at the samples xs[lo : hi + 1] where it is defined, into ys, es
    (``out``: ys, es, edges);
    returns the index of the last (-1 if none). edges[k] is the index of the defined neighbour
    of a sample at a reach boundary, else -1.

    Inside the band it is evaluated (one held polish); outside, the ideal value has its sign.
    Undefined samples are left out; where the branch stops or starts reaching the target, a
    sample at the reach boundary is added (``_reach_boundary``), so that a root between it and
    the nearest defined sample is bracketed.
    """
    ys, es, edges = out
    n = -1
    last = lo - 1  # the last defined sample
    for s in range(lo, hi + 1):
        f = fs[s]
        if abs(f) < band:
            f = exact_roll_equation(problem, xs[s])
        elif not branch_reaches(problem, xs[s]):
            f = np.nan
        if not math.isfinite(f):
            continue
        if last < s - 1:  # undefined before: the boundaries of the gap
            if last >= lo:
                x, fb = _reach_boundary(problem, xs[last], es[n], xs[last + 1])
                if x != xs[last]:
                    n += 1
                    ys[n], es[n], edges[n] = x, fb, n - 1
            x, fb = _reach_boundary(problem, xs[s], f, xs[s - 1])
            if x != xs[s]:
                n += 1
                ys[n], es[n], edges[n] = x, fb, n + 1
        last = s
        n += 1
        ys[n], es[n], edges[n] = xs[s], f, -1
    if lo <= last < hi:
        x, fb = _reach_boundary(problem, xs[last], es[n], xs[last + 1])
        if x != xs[last]:
            n += 1
            ys[n], es[n], edges[n] = x, fb, n - 1
    return n


@numba.njit(cache=True, nogil=True)
def _reach_boundary(
    problem: ExactProblem, inner: float, f_inner: float, outer: float
) -> tuple[float, float]:
    """The last roll from inner towards outer where the exact equation is defined (it is at
    inner, f_inner, not at outer), to BOUNDARY_TOLERANCE, and the equation there. The ideal
    branch's boundary first (bisection on its closed form), then the exact one between it and
    inner."""
    a, b = inner, outer
    for _ in range(60):
        if abs(b - a) < BOUNDARY_TOLERANCE:
            break
        mid = 0.5 * (a + b)
        if branch_reaches(problem, mid):
            a = mid
        else:
            b = mid
    f = exact_roll_equation(problem, a)
    if math.isfinite(f):
        return a, f
    outer = a
    for _ in range(60):
        if abs(outer - inner) < BOUNDARY_TOLERANCE:
            break
        mid = 0.5 * (inner + outer)
        f = exact_roll_equation(problem, mid)
        if math.isfinite(f):
            inner, f_inner = mid, f
        else:
            outer = mid
    return inner, f_inner


@numba.njit(cache=True, nogil=True)
def exact_candidates(  # noqa: PLR0912, PLR0915 (numba kernel: one compiled scan)
    problem: RollProblem,
    elbow0: ExactProblem,
    elbow1: ExactProblem,
    xs: np.ndarray,
    fs: np.ndarray,
    m: int,
    roots: np.ndarray,
    count: int,
) -> int:
    """A model only close to the family: the roots on the stretches where the ideal equation
    (sampled at xs[: m + 1], fs) is within EXACT_BAND deviations of zero are replaced by the
    exact chain's, searched the same way for each elbow on the same samples; the ideal roots
    there are kept after them. These roots are tentative (a branch only where Newton converges
    on the exact chain). Returns the count."""
    prm, target, g = problem[0], problem[1], problem[2]
    # the ideal and exact equations differ by up to ~6 deviations times d / rho (a position
    # error of the model turns the yaw by 1 / rho): measured on the SO-101
    d0, d1, d2 = from_yaw_axis(prm, target)
    d = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    band = EXACT_BAND * prm[F.DEVIATION] * (1.0 + d / max(g[3, 0], 1e-9))
    first = 0
    while first <= m and not abs(fs[first]) < band:
        first += 1
    if first > m:
        return count
    # the samples of a stretch, and at most two reach boundaries per gap between them
    ys, es = np.empty(2 * m + 4), np.empty(2 * m + 4)
    edges = np.empty(2 * m + 4, dtype=np.int64)
    aside = np.empty(MAX_ROOTS)
    i = first
    while i <= m:
        if not abs(fs[i]) < band:
            i += 1
            continue
        j = i
        while j < m and abs(fs[j + 1]) < band:
            j += 1
        lo, hi = max(i - 1, 0), min(j + 1, m)
        i = j + 1
        if simple_crossing(fs, lo, hi, m):
            continue  # one well-conditioned root: the ideal one, polished on the exact chain
        kept = dropped = np.int64(0)  # the ideal roots of the stretch: set aside, tried last
        for r in range(count):
            if not xs[lo] <= roots[r] <= xs[hi]:
                roots[kept], roots[MAX_ROOTS + kept] = roots[r], roots[MAX_ROOTS + r]
                kept += 1
            else:
                aside[dropped] = roots[r]
                dropped += 1
        count = kept
        start = count
        for exact in (elbow0, elbow1):
            n = _exact_samples(exact, xs, fs, lo, hi, band, (ys, es, edges))
            if n < 1:
                continue
            before = count
            ends = (ys[0] == xs[0], ys[n] == xs[m])
            count = _scan(exact, problem, (ys, es, n), roots, count, np.bool_(False), ends)
            for k in range(n + 1):
                if edges[k] >= 0:
                    count = _end_roots(exact, problem, ys, es, k, edges[k], roots, count)
            kept = before
            for r in range(before, count):  # the other elbow's roots already found
                seen = False
                for t in range(start, before):
                    seen = seen or abs(roots[r] - roots[t]) < ROOT_MERGE
                if not seen:
                    roots[kept], roots[MAX_ROOTS + kept] = roots[r], 1.0
                    kept += 1
            count = kept
        # the ideal roots stay candidates too (a root at a reach boundary, where the exact
        # equation is defined on one side only, may be bracketed by neither), tentative
        for r in range(dropped):
            before = count
            count = _keep_root(problem, aside[r], roots, count)
            if count > before:
                roots[MAX_ROOTS + count - 1] = 1.0
    return count


@numba.njit(cache=True, nogil=True)
def nearest_roll(
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
