"""Roots and minima of the scalar roll equation (``roll_search``): the equation at a roll on
the ideal model or the exact chain (one name for both in compiled code), the Illinois method on
a bracket, Brent's minimisation, and the test for one simple crossing. Angles in [rad].
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np
from numba.extending import overload

from lynxplan.constants import (
    BRENT_ABSOLUTE,
    BRENT_RELATIVE,
    EXACT_ROOT_STEP,
    ROOT_BRACKET,
    ROOT_BRACKET_RELATIVE,
)
from lynxplan.robots.ik.exact_roll_equation import ExactProblem, exact_roll_equation
from lynxplan.robots.ik.family_geometry import RollProblem
from lynxplan.robots.ik.roll_equation import roll_equation


def equation(problem: RollProblem | ExactProblem, theta: float) -> float:
    """The roll equation at theta: the ideal one (``RollProblem``) or the exact chain's
    (``ExactProblem``). Compiled code calls the overload below."""
    if len(problem) == 7:
        return float(roll_equation(problem, theta))
    return float(exact_roll_equation(problem, theta))


@overload(equation)
def _equation_overload(problem: Any, theta: Any) -> Any:
    # the implementations repeat the overload's signature, annotations included (numba checks)
    if len(problem.types) == 7:

        def ideal(problem: Any, theta: Any) -> Any:
            return roll_equation(problem, theta)

        return ideal

    def exact(problem: Any, theta: Any) -> Any:
        return exact_roll_equation(problem, theta)

    return exact


@numba.njit(cache=True, nogil=True)
def refine_root(
    problem: RollProblem | ExactProblem,
    a: float,
    fa: float,
    b: float,
    fb: float,
) -> float:
    """Illinois regula falsi on a bracket [a, b] with fa * fb < 0: to the last bit on the
    ideal equation, to EXACT_ROOT_STEP on the exact one (Newton's method on the exact chain
    finishes its roots)."""
    xtol = 0.0 if len(problem) == 7 else EXACT_ROOT_STEP
    side_kept = 0
    previous = np.inf
    for _ in range(80):
        c = (a * fb - b * fa) / (fb - fa)
        if not (min(a, b) <= c <= max(a, b)):
            c = 0.5 * (a + b)
        fc = equation(problem, c)
        if fc == 0.0 or abs(b - a) < ROOT_BRACKET or abs(c - previous) < xtol:
            return c
        previous = c
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
        if abs(b - a) < ROOT_BRACKET_RELATIVE * (1.0 + abs(c)):
            return c
    return (a * fb - b * fa) / (fb - fa)


@numba.njit(cache=True, nogil=True)
def minimise(  # noqa: PLR0912 (Brent's method as published, one compiled loop)
    problem: RollProblem | ExactProblem,
    a: float,
    b: float,
    sign: float,
) -> float:
    """Minimiser of sign * f on [a, b] (Brent's method: parabolic steps, golden-section
    fallback), or the first point found where sign * f < 0 (then f changes sign in [a, b])."""
    golden = 0.5 * (3.0 - math.sqrt(5.0))
    x = w = v = a + golden * (b - a)
    fx = sign * equation(problem, x)
    if fx < 0.0:
        return x
    fw = fv = fx
    d = e = 0.0
    for _ in range(100):
        xm = 0.5 * (a + b)
        tol1 = BRENT_RELATIVE * abs(x) + BRENT_ABSOLUTE
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
        fu = sign * equation(problem, u)
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
def simple_crossing(fs: np.ndarray, lo: int, hi: int, m: int) -> bool:
    """Whether the samples fs[lo : hi + 1] are strictly monotone with one sign change, away from
    the ends of the range [0, m]: then the exact equation, within the band of the ideal one,
    has the one root the ideal equation has, next to it."""
    if lo == 0 or hi == m:
        return False
    rising = fs[hi] > fs[lo]
    for k in range(lo, hi):
        if not ((fs[k + 1] > fs[k]) == rising and fs[k + 1] != fs[k]):
            return False
    return bool((fs[lo] < 0.0) != (fs[hi] < 0.0))
