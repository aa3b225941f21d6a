"""Shortcutting: every pass keeps the path certified, never lengthens it, and is deterministic."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from conftest import SUITE, dense_min_distance, load_problem

from lynxplan.planning import Planner
from lynxplan.planning.problem import goal_configurations
from lynxplan.planning.rrt_connect import rrt_connect
from lynxplan.planning.shortcut import shortcut

#: Exact distances are accurate to ~1e-9 m.
CLEARANCE_TOLERANCE = 1e-7
PROBLEMS = [p for p in SUITE if p.stem.startswith(("p02", "p08"))]


@pytest.mark.parametrize("path", PROBLEMS, ids=[p.stem for p in PROBLEMS])
@pytest.mark.parametrize("greedy", [True, False])
def test_shortcut_keeps_the_path_certified_and_shorter(path: object, greedy: bool) -> None:
    problem = load_problem(path)
    planner = Planner(problem.robot, problem.obstacles, problem.options)
    goals = goal_configurations(problem.robot, planner.space, problem.goal).configurations
    goals = np.array([g for g in goals if planner.checker.is_valid(g)])
    space, checker = planner.space, planner.checker
    for seed in (0, 1):
        raw = rrt_connect(
            checker, space.lower, space.upper, problem.start, goals, seed=seed, time_limit=5.0
        ).path
        short = shortcut(checker, raw, seed=seed, greedy=greedy)
        again = shortcut(checker, raw, seed=seed, greedy=greedy)
        assert np.array_equal(short, again)
        np.testing.assert_array_equal(short[0], raw[0])
        np.testing.assert_array_equal(short[-1], raw[-1])
        assert space.path_length(short) <= space.path_length(raw) + 1e-12
        for a, b in itertools.pairwise(short):
            assert checker.edge_fraction(a, b) == 1.0
        distance, _where = dense_min_distance(planner.world, short)
        assert distance >= problem.options.clearance - CLEARANCE_TOLERANCE
