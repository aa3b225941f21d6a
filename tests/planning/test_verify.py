"""Exact path verification (conservative advancement on coal distances) against a dense exact
check, and against paths that graze an obstacle between their waypoints."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import dense_min_distance

from lynxplan.arm import Arm
from lynxplan.collision import BoxObstacle, CollisionWorld, SphereObstacle
from lynxplan.constants import COAL_GJK_TOLERANCE
from lynxplan.exceptions import PathVerificationError
from lynxplan.planning.verify import verifier_of, verify_path

TABLE = BoxObstacle("table", [0.0, 0.1, -0.105], [0.9, 0.7, 0.03])
POST = BoxObstacle("post", [0.12, 0.18, 0.05], [0.04, 0.04, 0.3])
#: How deep (or how far) the probe sphere is placed from the moving gripper, in [m].
GRAZE = 1e-4
#: Random paths of the comparison and their waypoints.
RANDOM_PATHS, RANDOM_WAYPOINTS = 16, 3


@pytest.fixture(scope="module")
def world(arm: Arm) -> CollisionWorld:
    return CollisionWorld(arm, [TABLE, POST], self_collision=True)


def _random_path(arm: Arm, rng: np.random.Generator) -> np.ndarray:
    lower, upper = np.asarray(arm.limits.lower), np.asarray(arm.limits.upper)
    centre = lower + (upper - lower) * rng.uniform(0.3, 0.7, size=lower.size)
    steps = rng.normal(scale=0.35, size=(RANDOM_WAYPOINTS, lower.size))
    return np.clip(centre + np.cumsum(steps, axis=0), lower, upper)


def test_verdict_agrees_with_a_dense_exact_check(arm: Arm, world: CollisionWorld) -> None:
    """A certified path has no contact at >= 10 exact checks per segment and every 0.002 rad;
    a path the dense check finds in contact is rejected."""
    rng = np.random.default_rng(14)
    verdicts = []
    for _ in range(RANDOM_PATHS):
        path = _random_path(arm, rng)
        distance, where = dense_min_distance(world, path)
        try:
            report = verify_path(world, path, 0.0)
        except PathVerificationError:
            verdicts.append(False)
            continue
        verdicts.append(True)
        assert report.collision_free
        assert distance > 0.0, (path, where)
        # The reported minimum is an exact distance at a point of the path.
        assert report.min_clearance.clearance >= distance - 1e-9
    assert any(verdicts) and not all(verdicts), verdicts


def _graze_world(arm: Arm, q_a: np.ndarray, q_b: np.ndarray, gap: float) -> CollisionWorld:
    """A small sphere placed ``gap`` [m] from the pen at the middle of the segment (negative:
    penetrating), far from it at both ends."""
    middle = 0.5 * (q_a + q_b)
    tool = arm.fk(middle)
    centre = tool[:3, 3] + 0.03 * tool[:3, 0]
    probe = CollisionWorld(arm, [SphereObstacle("probe", centre, 0.005)], self_collision=True)
    obstacle_pairs = ~probe.pair_is_self
    distance = probe.distances(middle)[0][obstacle_pairs].min()
    radius = 0.005 + distance - gap
    return CollisionWorld(arm, [SphereObstacle("probe", centre, radius)], self_collision=True)


@pytest.mark.parametrize("gap", [-GRAZE, GRAZE])
def test_a_path_grazing_an_obstacle_between_waypoints(arm: Arm, gap: float) -> None:
    q_a = np.radians([40.0, 40.0, -60.0, 60.0, 0.0])
    q_b = np.radians([100.0, 40.0, -60.0, 60.0, 0.0])
    world = _graze_world(arm, q_a, q_b, gap)
    ends = world.distances(np.vstack([q_a, q_b]))[:, ~world.pair_is_self]
    assert ends.min() > 0.02  # both waypoints far from the probe
    path = np.vstack([q_a, q_b])
    if gap < 0:
        contact = r"gripper_1\) touches probe at path parameter 0\.[45]"
        with pytest.raises(PathVerificationError, match=contact):
            verify_path(world, path, 0.0)
    else:
        report = verify_path(world, path, 0.0)
        assert report.collision_free
        assert report.min_clearance.obstacle == "probe"
        assert 0.0 < report.min_clearance.clearance <= gap + 1e-6


def test_a_single_configuration_and_the_verifier_is_kept_per_world(
    arm: Arm, world: CollisionWorld
) -> None:
    q = np.radians([90.0, 60.0, -60.0, 60.0, 0.0])
    report = verify_path(world, q[None, :], 0.0)
    exact = world.distances(q)[0].min()
    assert report.min_clearance.clearance == pytest.approx(exact, abs=1e-9)
    assert verifier_of(world) is verifier_of(world)


def test_closest_contact_and_sample_clearances_are_the_exact_minimum(
    arm: Arm, world: CollisionWorld
) -> None:
    """The start/goal check's closest contact and the samples' branch and bound on the lower
    bounds give the smallest distance (and pair) of all pairs, in contact and apart, on the AL5
    and on the SO-101's meshes."""
    from lynxplan.planning.verify import closest_contact, sample_clearances
    from lynxplan.robots import load_robot

    so101 = load_robot("so101")
    block = BoxObstacle("block", [0.2, 0.0, 0.05], [0.06, 0.06, 0.1])
    rng = np.random.default_rng(31)
    for robot, collision_world in (
        (arm, world),
        (so101, CollisionWorld(so101, [block], self_collision=True)),
    ):
        lower = np.asarray(robot.limits.lower)
        upper = np.asarray(robot.limits.upper)
        q = rng.uniform(lower, upper, size=(40, lower.size))
        every = collision_world.distances(q)
        assert (every.min(axis=1) < 0).any() and (every.min(axis=1) > 0).any()
        np.testing.assert_allclose(
            sample_clearances(collision_world, q), every.min(axis=1), atol=COAL_GJK_TOLERANCE
        )
        for n in range(len(q)):
            distance, link, other = closest_contact(collision_world, q[n])
            pair = int(np.argmin(every[n]))
            # coal's GJK/EPA answers depend on its warm start (the previous query): equal to
            # its tolerance
            assert distance == pytest.approx(every[n, pair], abs=COAL_GJK_TOLERANCE)
            names = collision_world.pair_names(pair)
            if np.sort(every[n])[1] - every[n, pair] > 2 * COAL_GJK_TOLERANCE:  # one nearest
                assert (link, other) == (names[0], names[2])


def test_exact_rows_are_the_worlds_exact_distances(arm: Arm, world: CollisionWorld) -> None:
    """The verifier's batched exact queries (poses of only the pair's joints from one compiled
    call, :func:`lynxplan.planning.certify.row_transforms`) equal the collision world's own
    exact distances at the same configurations (posed by the world, every pair, self pairs
    included), in contact and apart."""
    verifier = verifier_of(world)
    rng = np.random.default_rng(5)
    path = _random_path(arm, rng)
    rows = 60
    segment = rng.integers(0, len(path) - 1, size=rows)
    parameter = rng.uniform(0.0, 1.0, size=rows)
    pair = rng.integers(0, world.pair_count, size=rows)
    pair[:2] = np.flatnonzero(world.pair_is_self)[:2]  # self pairs set both transforms
    got = verifier.exact_rows(path, segment, parameter, pair)
    q = path[segment] + parameter[:, None] * (path[segment + 1] - path[segment])
    every = world.distances(q)
    expected = every[np.arange(rows), pair]
    np.testing.assert_allclose(got, expected, atol=COAL_GJK_TOLERANCE)
    # The sample reaches contacts and clear pairs alike.
    assert (every.min(axis=1) < 0).any() and (got > 0).any()


def test_every_scheduled_row_has_its_exact_distance(arm: Arm, world: CollisionWorld) -> None:
    """A row the schedule does not query (a chain starting at a waypoint where the pair's
    previous segment left a row, a pair static on consecutive segments) gets the distance of
    the row it points to: every row's distance equals the world's exact distance at its own
    configuration, and some rows are such copies."""
    verifier = verifier_of(world)
    rng = np.random.default_rng(21)
    copies = 0
    for _ in range(RANDOM_PATHS):
        path = np.ascontiguousarray(_random_path(arm, rng))
        planned = verifier.schedule(path)
        exact = verifier.exact_posed(planned.query_pair, planned.rotation, planned.translation)
        got = exact[planned.lookup]
        q = path[planned.segment] + planned.parameter[:, None] * (
            path[planned.segment + 1] - path[planned.segment]
        )
        expected = world.distances(q)[np.arange(len(q)), planned.pair]
        np.testing.assert_allclose(got, expected, atol=COAL_GJK_TOLERANCE)
        copies += len(planned.pair) - len(planned.query_pair)
    assert copies > 0


def test_covering_sphere_gaps_are_lower_bounds_of_the_exact_distances(arm: Arm) -> None:
    """The verification's own bound (:func:`lynxplan.planning.sphere_gaps.sphere_gap`: one
    primitive's covering spheres against the other's box) stays below coal's distance for
    every pair, self pairs and a sphere obstacle included, at random configurations; it is far
    tighter than one circumscribed sphere per primitive on the long links, which is what spares
    most exact queries."""
    from lynxplan.planning.bounds import primitive_poses
    from lynxplan.planning.certify import sphere_gap

    ball = SphereObstacle("ball", [0.15, 0.0, 0.12], 0.03)
    world = CollisionWorld(arm, [TABLE, POST, ball], self_collision=True)
    verifier = verifier_of(world)
    model, scratch = verifier.model, verifier.scratch
    rng = np.random.default_rng(11)
    lower, upper = np.asarray(arm.limits.lower), np.asarray(arm.limits.upper)
    tight = near = apart = 0
    for _ in range(200):
        q = rng.uniform(lower, upper)
        primitive_poses(q, model, scratch)
        poses = scratch.prim_poses.copy()
        for p in range(len(verifier.pairs)):
            gap = sphere_gap(p, model, scratch)
            exact = verifier.exact(poses, p)
            if exact <= 0:  # in contact: the spheres touch too
                assert gap <= 0.0, (q.tolist(), p)
                continue
            assert gap <= exact + COAL_GJK_TOLERANCE, (q.tolist(), p)
            apart += 1
            near += exact < 0.03
            tight += exact - gap < 0.02
    # within 2 cm: 94 % of the pairs apart (one circumscribed sphere per primitive: 42 %)
    assert near > 50 and tight > 0.9 * apart
