"""Choosing among IK branches: the one nearest a reference for one target (along a track:
:mod:`lynxplan.robots.tracking`), or a robot's own rule (:data:`REPORT`, the AL5's)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from lynxplan.constants import REACH_TOLERANCE
from lynxplan.robots.results import RobotIkBatch, RobotIkResult, RobotIkSolution

#: The selection rules: the branch nearest the reference (every robot), and the report's rule
#: (SPEC Part 1, the AL5's): the first branch, in slot order, with q2 >= 0 and q3 <= 0.
NEAREST, REPORT = "nearest", "report"


def by_report_rule(result: RobotIkResult) -> RobotIkResult:
    """``result`` with the branch the report's rule selects: the first, in slot order, within
    the limits with q2 >= 0 [rad] and q3 <= 0 [rad] among those that reach the target (or, out
    of reach, come nearest); None when no branch qualifies (the orientation residual is then
    the best branch's). On the shipped AL5's limits (q2 in [0, 150] deg, q3 in [-150, 0] deg)
    the sign test always holds and at most one branch of a pose lies within the limits: the
    rule then selects what "nearest" selects."""
    limit = result.distance + REACH_TOLERANCE
    chosen = next(
        (
            i
            for i, s in enumerate(result.solutions)
            if s.within_limits and s.position_error <= limit and s.q[1] >= 0.0 and s.q[2] <= 0.0
        ),
        None,
    )
    errors = [s.orientation_error for s in result.solutions]
    ranked = chosen if chosen is not None else (int(np.argmin(errors)) if errors else None)
    residual = float(errors[ranked]) if ranked is not None else np.nan
    return dataclasses.replace(result, selected=chosen, orientation_residual=residual)


def select_one(batch: RobotIkBatch, reference: np.ndarray, solver: str) -> RobotIkResult:
    """The branches of the single target of ``batch``, the one nearest ``reference`` (n,) [rad]
    selected among those within the limits that reach the target (or come nearest)."""
    slots = np.flatnonzero(batch.valid[0])
    names = batch.branch_names
    return assemble_result(
        batch.q[0, slots],
        [names[b] for b in slots.tolist()],
        batch.within_limits[0, slots].tolist(),
        batch.position_error[0, slots].tolist(),
        batch.orientation_error[0, slots].tolist(),
        bool(batch.reachable[0]),
        float(batch.distance[0]),
        reference,
        solver,
    )


def assemble_result(
    q: np.ndarray,
    names: list[str],
    within: list[bool],
    position_error: list[float],
    orientation_error: list[float],
    reachable: bool,
    distance: float,
    reference: np.ndarray,
    solver: str,
) -> RobotIkResult:
    """One target's result from its branches q (k, n) [rad] (a fresh array; made read-only)
    and per-branch lists: the one nearest ``reference`` (n,) [rad] selected among those within
    the limits that reach the target (or come nearest)."""
    q.setflags(write=False)
    solutions = [
        RobotIkSolution(q[i], names[i], within[i], position_error[i], orientation_error[i])
        for i in range(len(names))
    ]
    return finish_result(solutions, q.tolist(), reachable, distance, reference, solver)


def finish_result(
    solutions: list[RobotIkSolution],
    rows: list[list[float]],
    reachable: bool,
    distance: float,
    reference: np.ndarray,
    solver: str,
) -> RobotIkResult:
    """The result of one target's branches (``rows``: their q as lists): the one nearest
    ``reference`` (n,) [rad] selected among those within the limits that reach the target (or
    come nearest). ``solver``: the solver's name, for the result."""
    limit = distance + REACH_TOLERANCE
    ref = reference.tolist()
    # plain Python on the few branches: cheaper than numpy calls on arrays this small
    best, best_cost = None, math.inf
    for i, s in enumerate(solutions):
        if not s.within_limits or s.position_error > limit:
            continue
        cost = sum((a - r) ** 2 for a, r in zip(rows[i], ref, strict=True))
        if cost < best_cost:
            best, best_cost = i, cost
    ranked = (
        best
        if best is not None
        else (int(np.argmin([s.orientation_error for s in solutions])) if solutions else None)
    )
    residual = float(solutions[ranked].orientation_error) if ranked is not None else np.nan
    return RobotIkResult(tuple(solutions), best, reachable, distance, residual, solver)
