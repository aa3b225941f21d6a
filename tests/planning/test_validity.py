"""The planner's conservative checker: its bounds never exceed coal's exact distances."""

from __future__ import annotations

import numpy as np
import pytest

from lynxplan.arm import Arm
from lynxplan.collision import BoxObstacle, CollisionWorld, CylinderObstacle, SphereObstacle
from lynxplan.planning.validity import ValidityChecker

#: Exact distances from coal are accurate to ~1e-9 m; the bound may not exceed them by more.
BOUND_TOLERANCE = 1e-8
OBSTACLES = (
    BoxObstacle("box", [0.2, 0.05, 0.05], [0.05, 0.3, 0.2]),
    BoxObstacle(
        "tilted",
        [-0.15, 0.2, 0.1],
        [0.1, 0.05, 0.2],
        rotation=[
            [np.cos(0.5), -np.sin(0.5), 0.0],
            [np.sin(0.5), np.cos(0.5), 0.0],
            [0.0, 0.0, 1.0],
        ],
    ),
    SphereObstacle("ball", [0.0, 0.25, 0.15], 0.05),
    CylinderObstacle("post", [-0.1, 0.15, 0.0], 0.03, 0.3),
)


@pytest.fixture(scope="module")
def world(arm: Arm) -> CollisionWorld:
    return CollisionWorld(arm, OBSTACLES, self_collision=True)


def test_bounds_are_lower_bounds_of_exact_distances(arm: Arm, world: CollisionWorld) -> None:
    checker = ValidityChecker(world, 0.0)
    index = {world.pair_names(p)[1:]: p for p in range(world.pair_count)}
    assert set(checker.pair_names) <= set(index)
    rng = np.random.default_rng(1)
    near = 0
    for _ in range(120):
        q = rng.uniform(arm.limits.lower, arm.limits.upper)
        bounds = checker.pair_bounds(q)
        exact = world.distances(q)[0]
        for p, name in enumerate(checker.pair_names):
            distance = exact[index[name]]
            if distance > 0:
                assert bounds[p] <= distance + BOUND_TOLERANCE, (name, q.tolist())
                near += distance < 0.01
            else:
                assert bounds[p] <= 0.0, (name, q.tolist())
    assert near > 5  # the comparison covered close pairs, not only far ones


def test_edge_fraction_certifies_only_free_edges(arm: Arm, world: CollisionWorld) -> None:
    """Every certified edge is free at a dense set of exact checks; blocked edges stop early."""
    checker = ValidityChecker(world, 0.002)
    rng = np.random.default_rng(2)
    certified = blocked = 0
    for _ in range(60):
        q_a = rng.uniform(arm.limits.lower, arm.limits.upper)
        if not checker.is_valid(q_a):
            continue
        q_b = np.clip(q_a + rng.normal(scale=0.4, size=5), arm.limits.lower, arm.limits.upper)
        fraction = checker.edge_fraction(q_a, q_b)
        assert 0.0 < fraction <= 1.0
        s = np.linspace(0.0, fraction, 80)
        distances = world.distances(q_a + s[:, None] * (q_b - q_a))
        assert distances.min() >= 0.002 - BOUND_TOLERANCE
        certified += fraction == 1.0
        blocked += fraction < 1.0
    assert certified > 5 and blocked > 2


def test_turning_the_base_joint_near_the_base_takes_few_steps(arm: Arm) -> None:
    """The base cylinder is coaxial with q1: turning q1 cannot change any distance to it, so an
    edge that only turns q1 with the upper arm 5 mm above the base is certified in one step of
    the (upper arm, base) pair instead of hundreds."""
    world = CollisionWorld(arm, [], self_collision=True)
    checker = ValidityChecker(world, 0.002)
    q_a = np.array([0.0, 0.0, -1.0, 1.5, 0.0])  # upper arm horizontal, 5 mm above the base
    q_b = q_a + np.array([3.0, 0.0, 0.0, 0.0, 0.0])
    assert min(world.distances(q_a)[0]) < 0.006
    counters = checker.scratch.counters
    counters[:] = 0
    assert checker.edge_fraction(q_a, q_b) == 1.0
    assert counters[1] < 40
    s = np.linspace(0.0, 1.0, 50)
    assert world.distances(q_a + s[:, None] * (q_b - q_a)).min() >= 0.002


def test_whole_edges_certified_from_the_probes_grid_are_free(
    arm: Arm, world: CollisionWorld
) -> None:
    """An edge that passes the quarter probes and is then walked with their bounds as a grid
    (pairs certified interval by interval, walks that start and stop at grid points) is free at
    a dense set of exact checks."""
    from lynxplan.planning.bounds import probes_are_clear
    from lynxplan.planning.edge_walk import edge_is_free_after_probes

    checker = ValidityChecker(world, 0.002)
    model, scratch = checker.model, checker.scratch
    rng = np.random.default_rng(3)
    certified = rejected = 0
    for _ in range(300):
        q_a = rng.uniform(arm.limits.lower, arm.limits.upper)
        q_b = np.clip(q_a + rng.normal(scale=0.8, size=5), arm.limits.lower, arm.limits.upper)
        if not (checker.is_valid(q_a) and checker.is_valid(q_b)):
            continue
        free = probes_are_clear(q_a, q_b, model, scratch, 0.002) and edge_is_free_after_probes(
            q_a, q_b, model, scratch, 0.002
        )
        if not free:
            rejected += 1
            continue
        certified += 1
        s = np.linspace(0.0, 1.0, 200)
        distances = world.distances(q_a + s[:, None] * (q_b - q_a))
        assert distances.min() >= 0.002 - BOUND_TOLERANCE, (q_a.tolist(), q_b.tolist())
    assert certified > 10 and rejected > 10
