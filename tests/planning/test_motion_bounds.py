"""The motion bounds behind every certificate: the lever-arm bounds of the planner's edge walk
and of the verifier's schedule never under-estimate how far a primitive really moves."""

from __future__ import annotations

import numpy as np
import pytest

from lynxplan.arm import Arm
from lynxplan.collision import BoxObstacle, CollisionWorld
from lynxplan.planning.bounds import primitive_poses
from lynxplan.planning.motion import lever_arms, reach_step, span_motion
from lynxplan.planning.validity import ValidityChecker

#: Dense samples of each tested interval.
SAMPLES = 60
#: Floating-point slack of the comparisons, in [m].
TOLERANCE = 1e-12
EDGES = 40


@pytest.fixture(scope="module")
def checker(arm: Arm) -> ValidityChecker:
    obstacles = [BoxObstacle("box", [0.2, 0.1, 0.05], [0.05, 0.3, 0.2])]
    world = CollisionWorld(arm, obstacles, self_collision=True)
    return ValidityChecker(world, 0.0)


def _corners(checker: ValidityChecker, poses: np.ndarray, g: int) -> np.ndarray:
    """Corners of primitive g's box at primitive poses (N, G, 4, 4) -> (N, 8, 3), in [m]."""
    half = checker.model.prim_half[g]
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    local = signs * half
    return np.einsum("nij,kj->nki", poses[:, g, :3, :3], local) + poses[:, g, None, :3, 3]


def _moving_corners(checker: ValidityChecker, p: int, q: np.ndarray) -> np.ndarray | None:
    """Corners of the moving primitive of pair p along q (N, nq), in the frame of the pair's
    other side (world for an obstacle); None for the pairs this test does not model (both
    sides moving, or a fixed primitive: its symmetry is tested elsewhere)."""
    a, b, is_self = checker.model.pairs[p]
    owners = checker.model.owners[p]
    poses = np.empty((len(q), len(checker.model.prim_joints), 4, 4))
    for n, config in enumerate(q):
        primitive_poses(config, checker.model, checker.scratch)
        poses[n] = checker.scratch.prim_poses
    corners = _corners(checker, poses, a)
    if not is_self:
        return corners
    if (owners == b).any() or checker.model.prim_joints[b] == 0:
        return None
    inverse = np.linalg.inv(poses[:, b])
    return np.einsum("nij,nkj->nki", inverse[:, :3, :3], corners) + inverse[:, None, :3, 3]


def _arms_at(checker: ValidityChecker, p: int, q: np.ndarray, side: int) -> None:
    primitive_poses(q, checker.model, checker.scratch)
    lever_arms(
        p,
        checker.scratch.joint_poses,
        checker.scratch.prim_poses,
        checker.model,
        checker.scratch.arms,
        side,
    )


def test_span_and_step_bounds_cover_the_real_motion(arm: Arm, checker: ValidityChecker) -> None:
    rng = np.random.default_rng(7)
    lower, upper = np.asarray(arm.limits.lower), np.asarray(arm.limits.upper)
    tested = tight = 0
    for _ in range(EDGES):
        q_a = rng.uniform(lower, upper)
        q_b = np.clip(q_a + rng.normal(scale=0.6, size=q_a.size), lower, upper)
        checker.scratch.dq[:] = np.abs(q_b - q_a)
        s = rng.uniform(0.0, 0.8)
        t = s + rng.uniform(0.02, 0.2)  # the walks' steps are short
        u = np.linspace(s, t, SAMPLES)
        q = q_a + u[:, None] * (q_b - q_a)
        for p in range(len(checker.pair_names)):
            corners = _moving_corners(checker, p, q)
            if corners is None:
                continue
            _arms_at(checker, p, q[0], 0)
            _arms_at(checker, p, q[-1], 1)
            bound = span_motion(p, t - s, checker.model, checker.scratch)
            # Straight-line displacements s -> u -> t are below the path's length over [s, t].
            there = np.linalg.norm(corners - corners[0], axis=2)
            back = np.linalg.norm(corners[-1] - corners, axis=2)
            assert (there + back).max() <= bound + TOLERANCE, (p, s, t)
            # One-sided: within reach_step(slack) of s, nothing moves more than slack.
            slack = 0.25 * max(bound, 1e-6)
            step = reach_step(slack, p, checker.scratch.arms, 0, checker.model, checker.scratch)
            inside = u - s <= step
            assert there[inside].max(initial=0.0) <= slack + TOLERANCE, (p, s, step)
            tested += 1
            static = float(checker.model.rates[p] @ checker.scratch.dq) * (t - s)
            tight += bound < 0.8 * static
    assert tested > 200
    assert tight > tested // 5  # the lever arms are tighter than the static reach


def test_a_pair_with_a_zero_rate_about_a_joint_keeps_its_exact_distance_when_it_turns(
    arm: Arm, checker: ValidityChecker
) -> None:
    """The edge walk certifies a pair without a walk when the edge differs from a certified one
    only in joints whose motion rate for the pair is zero (a partial shortcut's joint): the
    pair's exact distance (coal) must then not depend on those joints at all. And the rates
    that are not zero must belong to joints that do change some distance (the test can fail)."""
    obstacles = [BoxObstacle("box", [0.2, 0.1, 0.05], [0.05, 0.3, 0.2])]
    world = CollisionWorld(arm, obstacles, self_collision=True)
    world_rows = {
        (int(a), int(b), int(s)): k
        for k, (a, b, s) in enumerate(
            zip(world.pair_link, world.pair_other, world.pair_is_self, strict=True)
        )
    }
    rows = [world_rows[tuple(int(v) for v in row)] for row in checker.model.pairs]
    rates = checker.model.rates
    rng = np.random.default_rng(11)
    lower, upper = np.asarray(arm.limits.lower), np.asarray(arm.limits.upper)
    changed = np.zeros_like(rates, dtype=bool)
    for _ in range(30):
        q = rng.uniform(lower, upper)
        before = world.primitive_poses(q[None])[0]
        for j in range(len(q)):
            turned = q.copy()
            turned[j] = rng.uniform(lower[j], upper[j])
            after = world.primitive_poses(turned[None])[0]
            for p, k in enumerate(rows):
                d0, d1 = world.distance(before, k), world.distance(after, k)
                if rates[p, j] == 0.0:
                    assert abs(d1 - d0) <= 1e-6, (checker.pair_names[p], j, d0, d1)
                elif abs(d1 - d0) > 1e-6:
                    changed[p, j] = True
    # Rates are conservative (a primitive turning about its own axis of symmetry has one), but
    # most of them must show in the distances.
    assert changed[rates > 0.0].mean() > 0.8
