"""The one exact verifier: a task's trajectory and a planned path are decided by the same
conservative advancement (:mod:`lynxplan.collision.verify`) and answered with the same report."""

from __future__ import annotations

import numpy as np
import pytest

from lynxplan.arm import Arm
from lynxplan.collision import (
    BoxObstacle,
    CollisionReport,
    CollisionWorld,
    MotionReport,
    SphereObstacle,
    check_trajectory,
)
from lynxplan.collision.verify import Certification, separated, smallest_exact
from lynxplan.constants import COAL_GJK_TOLERANCE
from lynxplan.exceptions import PathVerificationError
from lynxplan.planning import VerificationReport
from lynxplan.planning.verify import verify_path

#: How deep (or how far) the probe sphere is placed from the moving pen, in [m].
GRAZE = 1e-4
Q_A = np.radians([40.0, 40.0, -60.0, 60.0, 0.0])
Q_B = np.radians([100.0, 40.0, -60.0, 60.0, 0.0])


def _graze_world(arm: Arm, gap: float) -> CollisionWorld:
    """A sphere ``gap`` [m] from the pen at the middle of Q_A -> Q_B (negative: penetrating),
    far from it at both ends."""
    middle = 0.5 * (Q_A + Q_B)
    tool = arm.fk(middle)
    centre = tool[:3, 3] + 0.03 * tool[:3, 0]
    probe = CollisionWorld(arm, [SphereObstacle("probe", centre, 0.005)], self_collision=True)
    distance = probe.distances(middle)[0][~probe.pair_is_self].min()
    radius = 0.005 + distance - gap
    return CollisionWorld(arm, [SphereObstacle("probe", centre, radius)], self_collision=True)


def test_one_report_type_under_its_former_names() -> None:
    assert CollisionReport is MotionReport
    assert VerificationReport is MotionReport


@pytest.mark.parametrize("gap", [-GRAZE, GRAZE])
def test_trajectory_and_path_get_the_same_verdict_between_samples(arm: Arm, gap: float) -> None:
    """The two straight-line samples of a grazing motion, checked as a task trajectory and
    verified as a planned path: one verdict, one report type, the same closest obstacle, and a
    smallest clearance below the gap (found between the samples by the same bisection)."""
    world = _graze_world(arm, gap)
    path = np.vstack([Q_A, Q_B])
    trajectory = check_trajectory(world, path, [0.0, 1.0])
    assert isinstance(trajectory, MotionReport)
    assert trajectory.self_collision_pairs == int(world.pair_is_self.sum()) > 0
    assert trajectory.obstacle_pairs == world.pair_count - trajectory.self_collision_pairs
    assert trajectory.collision_free == (gap > 0)
    assert trajectory.min_clearance.obstacle == "probe"
    assert trajectory.min_clearance.sample == -1  # between the samples
    assert trajectory.min_clearance.clearance <= gap + 1e-6
    if gap < 0:
        (contact,) = trajectory.contacts
        assert contact.between_samples and contact.obstacle == "probe"
        assert 0.4 <= contact.time <= 0.6
        with pytest.raises(PathVerificationError, match=r"touches probe at path parameter 0\.[45]"):
            verify_path(world, path, 0.0)
        return
    report = verify_path(world, path, 0.002)
    assert isinstance(report, MotionReport)
    assert report.collision_free and report.certified and report.contacts == ()
    assert report.required_clearance == 0.002
    assert (report.self_collision_pairs, report.obstacle_pairs) == (
        trajectory.self_collision_pairs,
        trajectory.obstacle_pairs,
    )
    assert report.min_clearance.obstacle == "probe"
    assert 0.0 < report.min_clearance.clearance <= gap + 1e-6
    assert report.segments == (report.min_clearance,) and report.segment_ids == (0,)


def test_reports_read_back_from_their_fields(arm: Arm) -> None:
    """as_dict / from_dict (the service's answers) give back the equal report, contacts and
    per-segment records included."""
    world = _graze_world(arm, -GRAZE)
    path = np.vstack([Q_A, Q_B, Q_A])
    report = check_trajectory(world, path, [0.0, 1.0, 2.0], [0, 0, 1])
    assert report.contacts and len(report.segments) == 2
    assert MotionReport.from_dict(report.as_dict()) == report
    clear = verify_path(_graze_world(arm, GRAZE), path[:2], 0.0)
    assert MotionReport.from_dict(clear.as_dict()) == clear


def test_separated_is_the_advancement_inequality() -> None:
    """d0 + d1 > D + 2 m, on scalars and arrays alike (strict: equality proves nothing)."""
    assert separated(0.02, 0.02, 0.03)
    assert not separated(0.02, 0.01, 0.03)
    assert not separated(0.02, 0.02, 0.03, 0.005)
    got = separated(np.array([0.02, 0.01]), np.array([0.02, 0.02]), np.array([0.03, 0.03]))
    np.testing.assert_array_equal(got, [True, False])


@pytest.mark.parametrize("hit", [False, True])
def test_bisection_matches_a_dense_exact_check(arm: Arm, hit: bool) -> None:
    """The certification's bisection on a segment that passes near a box (or through one at the
    pen's middle position): its lowest midpoint is an exact distance on the segment, no lower
    than the dense minimum (to coal's tolerance), and the segment is certified clear exactly
    when the dense check finds no contact."""
    if hit:
        centre = arm.fk(0.5 * (Q_A + Q_B))[:3, 3]
        box = BoxObstacle("box", centre, [0.02, 0.02, 0.02])
    else:
        box = BoxObstacle("box", [0.05, 0.25, 0.0], [0.04, 0.04, 0.3])
    world = CollisionWorld(arm, [box])
    pair = next(p for p in range(world.pair_count) if world.pair_names(p)[1] == "gripper_1")
    q = np.vstack([Q_A, Q_B])

    def exact_at(k: int, s: float, p: int) -> float:
        return world.distance(world.primitive_poses(q[k] + s * (q[k + 1] - q[k]))[0], p)

    certification = Certification(world, np.array([0.0, 1.0]), exact_at)
    d0, d1 = exact_at(0, 0.0, pair), exact_at(0, 1.0, pair)
    motion = float(world.motion_bounds(q)[0, pair])
    lowest = certification.bisect(0, pair, (0.0, 1.0, d0, d1), motion)
    dense = [exact_at(0, s, pair) for s in np.linspace(0.0, 1.0, 401)]
    assert certification.certified and lowest is not None  # bisected
    assert certification.collision_free == (min(dense) > 0) == (not hit)
    assert len(certification.contacts) == hit
    if not hit:
        assert lowest.clearance >= min(dense) - COAL_GJK_TOLERANCE
        assert lowest.clearance == pytest.approx(exact_at(0, lowest.time, pair), abs=1e-12)


def test_branch_and_bound_finds_the_smallest_exact_distance(arm: Arm) -> None:
    """smallest_exact on the world's sphere bounds gives the smallest distance of all pairs
    (and its pair), in contact and apart, querying fewer pairs than there are."""
    world = CollisionWorld(
        arm,
        [BoxObstacle("post", [0.12, 0.18, 0.05], [0.04, 0.04, 0.3])],
        self_collision=True,
    )
    rng = np.random.default_rng(3)
    lower, upper = np.asarray(arm.limits.lower), np.asarray(arm.limits.upper)
    q = rng.uniform(lower, upper, size=(30, lower.size))
    poses, every = world.primitive_poses(q), world.distances(q)
    bounds = world.lower_bounds(poses)
    queried = 0
    for n in range(len(q)):
        asked: list[int] = []

        def exact(pair: int, n: int = n, asked: list[int] = asked) -> float:
            asked.append(pair)
            return world.distance(poses[n], pair)

        best, pair = smallest_exact(bounds[n], exact)
        assert best == pytest.approx(every[n].min(), abs=COAL_GJK_TOLERANCE)
        assert every[n, pair] == pytest.approx(best, abs=COAL_GJK_TOLERANCE)
        queried += len(asked)
    assert (every.min(axis=1) < 0).any() and (every.min(axis=1) > 0).any()
    assert queried < every.size / 2
    assert smallest_exact(np.empty(0), lambda pair: 0.0) == (np.inf, -1)
