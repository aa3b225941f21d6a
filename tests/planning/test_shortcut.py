"""Shortcutting: every pass keeps the path certified, never lengthens it, and is deterministic."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from conftest import SUITE, dense_min_distance, load_problem

from lynxplan.planning import Planner
from lynxplan.planning.problem import goal_configurations
from lynxplan.planning.rrt_connect import rrt_connect
from lynxplan.planning.shortcut import shortcut, shortcut_to_goals

#: Exact distances are accurate to ~1e-9 m.
CLEARANCE_TOLERANCE = 1e-7
PROBLEMS = [p for p in SUITE if p.stem.startswith(("p02", "p08"))]


@pytest.mark.parametrize("path", PROBLEMS, ids=[p.stem for p in PROBLEMS])
@pytest.mark.parametrize(("greedy", "partial"), [(True, 0.0), (False, 0.0), (True, 0.5)])
def test_shortcut_keeps_the_path_certified_and_shorter(
    path: object, greedy: bool, partial: float
) -> None:
    """With and without the first greedy pass, and with random partial (one-joint) cuts."""
    problem = load_problem(path)
    planner = Planner(problem.robot, problem.obstacles, problem.options)
    goals = goal_configurations(problem.robot, planner.space, problem.goal).configurations
    goals = np.array([g for g in goals if planner.checker.is_valid(g)])
    space, checker = planner.space, planner.checker
    for seed in (0, 1):
        raw = rrt_connect(
            checker, space.lower, space.upper, problem.start, goals, seed=seed, time_limit=5.0
        ).path
        short = shortcut(checker, raw, seed=seed, greedy=greedy, partial=partial)
        again = shortcut(checker, raw, seed=seed, greedy=greedy, partial=partial)
        assert np.array_equal(short, again)
        np.testing.assert_array_equal(short[0], raw[0])
        np.testing.assert_array_equal(short[-1], raw[-1])
        assert space.path_length(short) <= space.path_length(raw) + 1e-12
        for a, b in itertools.pairwise(short):
            assert checker.edge_fraction(a, b) == 1.0
        distance, _where = dense_min_distance(planner.world, short)
        assert distance >= problem.options.clearance - CLEARANCE_TOLERANCE


def _raw_paths(problem: object, planner: Planner, seeds: range) -> tuple[np.ndarray, list]:
    goals = goal_configurations(problem.robot, planner.space, problem.goal).configurations
    goals = np.array([g for g in goals if planner.checker.is_valid(g)])
    space = planner.space
    found = [
        rrt_connect(
            planner.checker, space.lower, space.upper, problem.start, goals, seed=s, time_limit=5.0
        )
        for s in seeds
    ]
    return goals, found


def test_the_goal_switch_ends_on_a_goal_configuration_and_is_taken() -> None:
    """An approach goal has one goal configuration per roll and IK branch: the shortcut may
    end the path on another one when that is shorter, the path staying certified."""
    problem = load_problem(next(p for p in SUITE if p.stem.startswith("p08")))
    planner = Planner(problem.robot, problem.obstacles, problem.options)
    space, checker = planner.space, planner.checker
    goals, found = _raw_paths(problem, planner, range(6))
    assert len(goals) > 1
    switched = 0
    for seed, raw in enumerate(found):
        result = shortcut_to_goals(
            checker, raw.path, goals, raw.goal_index, space.lower, space.upper, seed=seed
        )
        again = shortcut_to_goals(
            checker, raw.path, goals, raw.goal_index, space.lower, space.upper, seed=seed
        )
        assert np.array_equal(result.path, again.path) and result.goal_index == again.goal_index
        np.testing.assert_array_equal(result.path[0], raw.path[0])
        np.testing.assert_array_equal(result.path[-1], goals[result.goal_index])
        assert space.path_length(result.path) <= space.path_length(raw.path) + 1e-12
        assert (result.path >= space.lower).all() and (result.path <= space.upper).all()
        for a, b in itertools.pairwise(result.path):
            assert checker.edge_fraction(a, b) == 1.0
        switched += result.goal_index != raw.goal_index
    assert switched > 0


def test_one_joint_straightening_removes_wander() -> None:
    """Partial (one-joint) cuts: the joints' excess motion (total variation beyond the net
    displacement) after shortcutting is well below what full cuts alone leave."""
    problem = load_problem(next(p for p in SUITE if p.stem.startswith("p02")))
    planner = Planner(problem.robot, problem.obstacles, problem.options)
    _goals, found = _raw_paths(problem, planner, range(6))

    def excess(path: np.ndarray) -> float:
        variation = np.abs(np.diff(path, axis=0)).sum(axis=0)
        return float((variation - np.abs(path[-1] - path[0])).sum())

    full_only = partial = 0.0
    for seed, raw in enumerate(found):
        full_only += excess(shortcut(planner.checker, raw.path, seed=seed, partial=0.0, levels=0))
        partial += excess(shortcut(planner.checker, raw.path, seed=seed))
    assert partial < 0.5 * full_only


def test_paths_of_one_or_two_waypoints_come_back_unchanged() -> None:
    """Nothing to cut: a single configuration stays one row, a straight edge two."""
    problem = load_problem(PROBLEMS[0])
    planner = Planner(problem.robot, problem.obstacles, problem.options)
    q = np.asarray(problem.start, dtype=float)
    for path in (q[None], np.vstack([q, q]), np.vstack([q, q + 0.01])):
        np.testing.assert_array_equal(shortcut(planner.checker, path, seed=0), path)
