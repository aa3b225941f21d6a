"""The roll equation evaluated on the exact chain (numba; see ``roll_search.py``).

A URDF only close to the family (SO-101: angles written to 5 digits, 3.7e-6 rad off) has a roll
equation that differs from the ideal one (``roll_equation.py``) by about that deviation. Where
the ideal equation is itself that small (a flat stretch, a near double root), its roots say
nothing about the exact chain's: the exact chain may have two roots 0.3 rad apart where the
ideal equation has none. There the equation is evaluated on the exact chain instead: the roll
held at theta, the other four joints by Newton's method from the closed-form branch
(``family_polish.polish``), and the value is the roll condition e4 of
``family_polish.conditions`` (zero at a solution). One evaluation costs one held polish.
Angles in [rad].
"""

from __future__ import annotations

import numba
import numpy as np

from lynxplan.constants import HELD_TOLERANCE, REACH_MARGIN
from lynxplan.robots.ik.family_geometry import ChainProblem, RollProblem, branch
from lynxplan.robots.ik.family_polish import conditions, polish

#: One side and elbow of one target on the exact chain: (the ideal problem, the chain problem,
#: elbow, then scratch: q (5,), (6, 5), (2, 4, 4), (6, 5), e (5,)).
ExactProblem = tuple[
    RollProblem, ChainProblem, int, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray
]


@numba.njit(cache=True, nogil=True)
def branch_reaches(problem: ExactProblem, theta: float) -> bool:
    """Whether the ideal branch of this elbow reaches the target at roll theta (to REACH_MARGIN)."""
    return bool(branch(problem[0], problem[1][6], theta, problem[2], problem[3]) <= REACH_MARGIN)


@numba.njit(cache=True, nogil=True)
def exact_roll_equation(problem: ExactProblem, theta: float) -> float:
    """The roll condition of the exact chain at roll theta (canonical sign), NaN where the
    branch does not reach the target with that roll."""
    ideal, chain, elbow, q, scratch, scratch4, scratch5, e = problem
    if branch(ideal, chain[6], theta, elbow, q) > REACH_MARGIN:
        return np.nan
    if not polish(chain, q[4], q, scratch, scratch4, scratch5) < HELD_TOLERANCE:
        return np.nan
    conditions(chain, np.nan, q, scratch4[0], scratch4[1], e)
    return float(e[4])
