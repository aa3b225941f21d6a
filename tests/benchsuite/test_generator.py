"""SmallArmBench generator: reproducible from its seed, and what it keeps is what it claims."""

from __future__ import annotations

import numpy as np
import pytest

from lynxplan.benchsuite import generator
from lynxplan.benchsuite.families import ROBOT_FRAMES
from lynxplan.benchsuite.problem import suite_robot
from lynxplan.benchsuite.runner import dense_check
from lynxplan.benchsuite.storage import load_shipped, suite_bytes
from lynxplan.collision import CollisionWorld
from lynxplan.exceptions import InputError

#: The issue's size: at least 100 problems per robot, at least 5 families.
MIN_PROBLEMS, MIN_FAMILIES = 100, 5


def test_same_seed_same_problems_bit_for_bit() -> None:
    first = generator.generate_family("al5", "bin", 3, seed=7)
    again = generator.generate_family("al5", "bin", 3, seed=7)
    other = generator.generate_family("al5", "bin", 3, seed=8)
    assert all(a.same_as(b) for a, b in zip(first, again, strict=True))
    assert suite_bytes(first, {"seed": 7}) == suite_bytes(again, {"seed": 7})
    assert not first[0].same_as(other[0])


@pytest.mark.parametrize("robot", sorted(ROBOT_FRAMES))
def test_shipped_suite_is_its_generator_output(robot: str) -> None:
    """The shipped file's first problem of a family is what its attempt gives from the seed."""
    problems = load_shipped(robot)
    family = {"al5": "shelf", "so101": "window", "ur5": "cage"}[robot]
    stored = next(p for p in problems if p.family == family)
    assert stored.same_as(generator.regenerate(stored))


@pytest.mark.parametrize("robot", sorted(ROBOT_FRAMES))
def test_shipped_suite_size_and_problem_claims(robot: str) -> None:
    problems = load_shipped(robot)
    assert len(problems) >= MIN_PROBLEMS
    assert len({p.family for p in problems}) >= MIN_FAMILIES
    arm = suite_robot(robot)
    for problem in problems[:: len(problems) // 6]:  # one of each family
        for q in (problem.start, problem.goal):
            assert np.all(q >= arm.limits.lower) and np.all(q <= arm.limits.upper)
        # start and goal clear (independent check: Pinocchio + coal), the straight motion not
        assert dense_check(arm, problem, problem.start[None]) > 0.0
        assert dense_check(arm, problem, problem.goal[None]) > 0.0
        assert dense_check(arm, problem, np.stack([problem.start, problem.goal])) <= 0.0
        world = CollisionWorld(arm, problem.obstacles(), self_collision=True)
        assert generator.straight_motion_collides(world, problem.start, problem.goal)


def test_tool_reaches_the_goal_target_region() -> None:
    """A goal's tool point lies within the robot's reach (the targets are scaled to it)."""
    arm = suite_robot("so101")
    problem = load_shipped("so101")[0]
    tool = arm.fk(problem.goal)[:3, 3]
    assert np.linalg.norm(tool[:2]) <= 1.2 * ROBOT_FRAMES["so101"].reach


def test_unknown_family_and_robot_are_refused() -> None:
    with pytest.raises(InputError, match="unknown SmallArmBench family 'desk'; families: "):
        generator.generate_family("al5", "desk", 1)
    with pytest.raises(InputError, match="robot 'panda' has no SmallArmBench frame"):
        generator.generate_family("panda", "bin", 1)
