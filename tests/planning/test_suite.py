"""The AL5 problem suite: every problem solved (or reported unsolvable) for several seeds, every
returned trajectory re-verified independently and within the joint limits at every sample."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import (
    CLEARANCE_TOLERANCE,
    LIMIT_RELATIVE_TOLERANCE,
    POSITION_TOLERANCE,
    SLOW,
    SUITE,
    dense_min_distance,
    load_problem,
)

from lynxplan.exceptions import PlanningFailed
from lynxplan.planning import Planner

CI_SEEDS = (0, 1, 2)
ALL_SEEDS = tuple(range(20))
#: An unsolvable problem must stop within its time limit plus one chunk of iterations, in [s].
TIME_LIMIT_SLACK = 0.25


def test_the_suite_has_ten_solvable_and_two_unsolvable_problems() -> None:
    solvable = [load_problem(path).solvable for path in SUITE]
    assert len(solvable) >= 12
    assert sum(solvable) >= 10 and solvable.count(False) >= 2


def _check_problem(path: Path, seeds: tuple[int, ...]) -> None:
    problem = load_problem(path)
    planner = Planner(problem.robot, problem.obstacles, problem.options)
    paths = []
    for seed in seeds:
        if not problem.solvable:
            with pytest.raises(PlanningFailed, match=r"after \d+ nodes") as failure:
                planner.solve(problem.start, problem.goal, seed=seed, time_limit=problem.time_limit)
            assert failure.value.nodes > 10
            assert failure.value.elapsed < problem.time_limit + TIME_LIMIT_SLACK
            continue
        trajectory = planner.solve(
            problem.start, problem.goal, seed=seed, time_limit=problem.time_limit
        )
        _check_trajectory(planner, problem, trajectory)
        paths.append(trajectory.waypoints)
    if len(paths) > 1 and not all(len(p) == 2 for p in paths):
        # Different seeds explore differently: not every path may be the same.
        assert any(not np.array_equal(paths[0], other) for other in paths[1:])


def _check_trajectory(planner: Planner, problem: object, trajectory: object) -> None:
    t, q, qd, qdd = trajectory.t, trajectory.q, trajectory.qd, trajectory.qdd
    assert trajectory.verification.collision_free
    np.testing.assert_allclose(q[0], problem.start, atol=1e-12, rtol=0)
    assert (np.diff(t) > 0).all()
    # Independent dense exact check: no contact, the required clearance everywhere.
    distance, where = dense_min_distance(planner.world, q)
    assert distance >= problem.options.clearance - CLEARANCE_TOLERANCE, (distance, where)
    assert trajectory.min_clearance >= problem.options.clearance - CLEARANCE_TOLERANCE
    # Joint limits at every sample.
    space = planner.space
    assert (q >= space.lower - POSITION_TOLERANCE).all()
    assert (q <= space.upper + POSITION_TOLERANCE).all()
    assert (np.abs(qd) <= planner.velocity * (1 + LIMIT_RELATIVE_TOLERANCE)).all()
    assert (np.abs(qdd) <= planner.acceleration * (1 + LIMIT_RELATIVE_TOLERANCE)).all()
    # The samples follow the waypoints' straight segments and end on the goal.
    np.testing.assert_allclose(q[-1], trajectory.waypoints[-1], atol=1e-12, rtol=0)


@pytest.mark.parametrize("path", SUITE, ids=[p.stem for p in SUITE])
def test_suite_problem_for_ci_seeds(path: Path) -> None:
    _check_problem(path, CI_SEEDS)


@SLOW
@pytest.mark.parametrize("path", SUITE, ids=[p.stem for p in SUITE])
def test_suite_problem_for_twenty_seeds(path: Path) -> None:
    _check_problem(path, ALL_SEEDS)
