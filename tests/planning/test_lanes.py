"""The vectorised bounds (:mod:`lynxplan.planning.lanes`) against the scalar kernels and coal."""

from __future__ import annotations

import numpy as np
import pytest
from test_validity import BOUND_TOLERANCE, OBSTACLES

from lynxplan.arm import Arm
from lynxplan.collision import CollisionWorld
from lynxplan.planning.bounds import primitive_poses
from lynxplan.planning.kernel_model import LANES
from lynxplan.planning.lanes import (
    OUT_ARMS,
    OUT_BOUND,
    OUT_S,
    OUT_SPHERE,
    pair_along,
    spheres_along,
)
from lynxplan.planning.pair_bound import EDGE_AXES_BELOW, all_pair_bounds, pair_bound
from lynxplan.planning.sphere_gaps import sphere_gap
from lynxplan.planning.validity import ValidityChecker
from lynxplan.planning.verify import ExactVerifier

#: The vectorised and scalar kernels round differently (fused multiply-adds), in [m].
ROUNDING = 1e-12
#: Random configurations (edges) compared.
SAMPLES = 150


@pytest.fixture(scope="module")
def world(arm: Arm) -> CollisionWorld:
    return CollisionWorld(arm, OBSTACLES, self_collision=True)


def _exact(verifier: ExactVerifier, checker: ValidityChecker, poses: np.ndarray) -> np.ndarray:
    """coal's distance of every checker pair at primitive poses (G, 4, 4), in [m]."""
    index = {verifier.world.pair_names(p)[1:]: p for p in range(len(verifier.pairs))}
    return np.array([verifier.exact(poses, index[name]) for name in checker.pair_names])


def test_all_pair_bounds_equal_the_scalar_bounds_and_stay_below_coal(
    arm: Arm, world: CollisionWorld
) -> None:
    checker = ValidityChecker(world, 0.0)
    verifier = ExactVerifier(world)
    model, scratch = checker.model, checker.scratch
    rng = np.random.default_rng(3)
    out = np.empty(len(checker.pair_names))
    near = 0
    for _ in range(SAMPLES):
        q = rng.uniform(arm.limits.lower, arm.limits.upper)
        primitive_poses(q, model, scratch)
        all_pair_bounds(model, scratch.prim_poses, out)
        scalar = np.array([pair_bound(p, model, scratch) for p in range(len(out))])
        # one definition: the same bound, where the scalar one tries every axis (it stops at
        # the sphere gap or the face axes when they are far enough)
        tight = scalar < EDGE_AXES_BELOW
        np.testing.assert_allclose(out[tight], scalar[tight], atol=ROUNDING)
        assert (out >= scalar - ROUNDING).all()
        exact = _exact(verifier, checker, scratch.prim_poses)
        apart = exact > 0
        assert (out[apart] <= exact[apart] + BOUND_TOLERANCE).all(), q.tolist()
        assert (out[~apart] <= 0.0).all(), q.tolist()
        near += int((apart & (exact < 0.01)).sum())
    assert near > 5  # close pairs were compared, not only far ones


def test_pair_and_spheres_along_match_single_steps_and_stay_below_coal(
    arm: Arm, world: CollisionWorld
) -> None:
    from lynxplan.planning.motion import pose_pair_at

    checker = ValidityChecker(world, 0.0)
    verifier = ExactVerifier(world)
    model, scratch = checker.model, checker.scratch
    rng = np.random.default_rng(4)
    pairs = len(checker.pair_names)
    nq = checker.nq
    out = np.empty((3 + nq, LANES))
    full = np.empty(pairs)
    near = 0
    for k in range(SAMPLES):
        q_a = rng.uniform(arm.limits.lower, arm.limits.upper)
        q_b = rng.uniform(arm.limits.lower, arm.limits.upper)
        p = k % pairs
        out[OUT_S] = np.sort(rng.uniform(0.0, 1.0, LANES))
        pair_along(q_a, q_b, p, model, out)
        bounds_arms = out[OUT_ARMS:].copy()
        spheres_along(q_a, q_b, p, model, out)
        np.testing.assert_array_equal(out[OUT_ARMS:], bounds_arms)
        for i in range(LANES):
            s = out[OUT_S, i]
            pose_pair_at(q_a, q_b, s, p, model, scratch, 1)
            np.testing.assert_allclose(out[OUT_ARMS:, i], scratch.arms[1], atol=ROUNDING)
            assert out[OUT_BOUND, i] >= pair_bound(p, model, scratch) - ROUNDING
            assert abs(out[OUT_SPHERE, i] - sphere_gap(p, model, scratch)) <= ROUNDING
            primitive_poses(q_a + s * (q_b - q_a), model, scratch)
            all_pair_bounds(model, scratch.prim_poses, full)
            assert abs(out[OUT_BOUND, i] - full[p]) <= ROUNDING
            exact = _exact(verifier, checker, scratch.prim_poses)[p]
            if exact > 0:
                assert out[OUT_BOUND, i] <= exact + BOUND_TOLERANCE
                assert out[OUT_SPHERE, i] <= exact + BOUND_TOLERANCE
                near += exact < 0.01
            else:
                assert out[OUT_BOUND, i] <= 0.0
                assert out[OUT_SPHERE, i] <= 0.0
    assert near > 5
