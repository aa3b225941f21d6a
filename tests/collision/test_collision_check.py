"""Trajectory check: contacts, minimum clearances, the between-sample guarantee, assertions."""

from __future__ import annotations

import numpy as np
import pytest
from okq_reference import joint_space_task, spec_obstacles

from lynxplan.collision import (
    BoxObstacle,
    CollisionWorld,
    axis_aligned_box,
    check_trajectory,
    clearance_profile,
)
from lynxplan.exceptions import NonFiniteInputError, ShapeError, TrajectoryCheckError
from lynxplan.testing import assert_collision_free, assert_within_limits

#: Exact engine (coal) against closed forms, in [m].
DISTANCE_TOLERANCE = 1e-8
HOME = np.zeros(5)


def _below_pen(gap: float) -> BoxObstacle:
    """A 40 mm block under the pen tip at home (tip at x = 0.3334, z = -0.0857, pointing down),
    its top face ``gap`` below the tip (negative: the pen is pushed in)."""
    tip_x, tip_z = 0.333375, -0.085725
    return axis_aligned_box("block", [tip_x - 0.02, -0.02, tip_z - gap - 0.05], [0.04, 0.04, 0.05])


def test_clearance_of_pen_above_a_block(arm):
    world = CollisionWorld(arm, [_below_pen(0.01)])
    report = check_trajectory(world, np.stack([HOME, HOME]), [0.0, 1.0])
    record = report.min_clearance
    assert record.clearance == pytest.approx(0.01, abs=DISTANCE_TOLERANCE)
    assert (record.link, record.geometry, record.obstacle) == ("gripper", "gripper_1", "block")
    assert report.collision_free
    assert report.contacts == ()


def test_contact_with_penetration_depth(arm):
    world = CollisionWorld(arm, [_below_pen(-0.002)])
    q = np.stack([HOME, HOME, HOME])
    report = check_trajectory(world, q, [0.0, 0.5, 1.0])
    assert not report.collision_free
    (contact,) = report.contacts
    assert (contact.link, contact.geometry, contact.obstacle) == ("gripper", "gripper_1", "block")
    assert contact.penetration_depth == pytest.approx(0.002, abs=DISTANCE_TOLERANCE)
    assert (contact.t_start, contact.t_end, contact.between_samples) == (0.0, 1.0, False)
    assert report.min_clearance.clearance == pytest.approx(-0.002, abs=DISTANCE_TOLERANCE)
    with pytest.raises(AssertionError, match=r"gripper \(gripper_1\) hits block at t = 0.0000 s"):
        assert_collision_free(q, [0.0, 0.5, 1.0], world)


def _thin_wall(angle_deg: float) -> BoxObstacle:
    """A 2 mm thick radial wall at azimuth ``angle_deg``, 0.12-0.28 m from the base axis."""
    angle = np.radians(angle_deg)
    c, s = np.cos(angle), np.sin(angle)
    rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return BoxObstacle("thin_wall", [0.2 * c, 0.2 * s, 0.0], [0.16, 0.002, 0.1], rotation)


def test_fast_motion_through_a_thin_wall_is_caught_between_samples(arm):
    """q1 sweeps 0 -> 90 deg in one 1 ms interval through a wall at 45 deg: both samples are
    clear, the between-sample check finds the contact."""
    world = CollisionWorld(arm, [_thin_wall(45.0)])
    q = np.stack([HOME, np.radians([90.0, 0, 0, 0, 0])])
    t = np.array([0.0, 0.001])
    assert (world.distances(q) > 0.05).all()  # the samples alone see nothing
    report = check_trajectory(world, q, t)
    assert not report.collision_free
    assert report.refined_intervals >= 1
    contact = report.contacts[0]
    assert contact.between_samples
    assert contact.obstacle == "thin_wall"
    assert 0.0 < contact.time < 0.001
    assert report.min_clearance.clearance <= 0.0
    assert report.min_clearance.sample == -1
    with pytest.raises(AssertionError, match=r"hits thin_wall .*\(between samples\)"):
        assert_collision_free(q, t, world)


def test_fast_motion_past_a_wall_is_certified(arm):
    world = CollisionWorld(arm, [_thin_wall(-45.0)])
    q = np.stack([HOME, np.radians([90.0, 0, 0, 0, 0])])
    report = check_trajectory(world, q, [0.0, 0.001])
    assert report.refined_intervals >= 1  # the bound alone could not decide
    assert report.collision_free
    assert report.certified
    assert report.min_clearance.clearance > 0.05


def test_acceleration_margin_makes_the_test_stricter(arm):
    world = CollisionWorld(arm, [_thin_wall(-45.0)])
    q = np.stack([HOME, np.radians([10.0, 0, 0, 0, 0])])
    plain = check_trajectory(world, q, [0.0, 0.01])
    assert plain.refined_intervals == 0
    # m = sum_j R_j * 1e3 * 0.01**2 / 8 ~ 1.6 cm: still provable.
    assert check_trajectory(world, q, [0.0, 0.01], acceleration_bound=1e3).collision_free
    # A margin larger than the clearance cannot be certified by bisecting the linear motion.
    hopeless = check_trajectory(world, q, [0.0, 0.01], acceleration_bound=1e6)
    assert not hopeless.certified
    assert not hopeless.collision_free
    assert hopeless.contacts == ()


@pytest.fixture(scope="module")
def spec_world(arm):
    return CollisionWorld(arm, spec_obstacles())


def test_segment_minima_equal_brute_force(spec_world):
    q, t, segment = joint_space_task(rate=25.0)
    report = check_trajectory(spec_world, q, t, segment)
    distances = spec_world.distances(q)  # every pair at every sample
    assert report.segment_ids == tuple(range(13))
    for s, record in zip(report.segment_ids, report.segments, strict=True):
        rows = np.flatnonzero(segment == s)
        block = distances[rows]
        row, pair = np.unravel_index(np.argmin(block), block.shape)
        assert record.clearance == pytest.approx(block[row, pair], abs=1e-12)
        assert record.time == t[rows[row]]
        assert record.geometry == spec_world.pair_names(int(pair))[1]
    assert report.min_clearance.clearance == pytest.approx(distances.min(), abs=1e-12)
    profile = clearance_profile(spec_world, q)
    np.testing.assert_allclose(profile[:, 0], distances[:, :8].min(axis=1), atol=1e-12)
    np.testing.assert_allclose(profile[:, 1], distances[:, 8:].min(axis=1), atol=1e-12)


def test_spec_task_in_joint_space_is_collision_free_at_1khz(spec_world, arm):
    q, t, segment = joint_space_task(rate=1000.0)
    report = assert_collision_free(q, t, spec_world, clearance=0.005, segment=segment)
    assert report.certified
    assert len(report.segments) == 13
    assert report.min_clearance.obstacle == "wall_letters"
    assert_within_limits(q, arm)


def test_self_collision_of_a_folded_arm(arm):
    world = CollisionWorld(arm, [], self_collision=True)
    folded = np.radians([0.0, 0.0, -150.0, 180.0, 0.0])  # forearm folded down onto the base
    report = check_trajectory(world, np.stack([HOME, folded]), [0.0, 1.0])
    assert [(c.geometry, c.obstacle) for c in report.contacts if not c.between_samples] == [
        ("base_link_0", "self:forearm_0")
    ]
    assert check_trajectory(world, np.stack([HOME, HOME]), [0.0, 1.0]).collision_free


def test_check_input_errors(spec_world):
    q = np.zeros((3, 5))
    with pytest.raises(ShapeError, match=r"t must have shape \(3,\). Got: \(2,\)"):
        check_trajectory(spec_world, q, [0.0, 1.0])
    with pytest.raises(
        TrajectoryCheckError, match=r"strictly increasing: t\[1\] = 1 s, t\[2\] = 1 s"
    ):
        check_trajectory(spec_world, q, [0.0, 1.0, 1.0])
    with pytest.raises(NonFiniteInputError, match="t contains NaN"):
        check_trajectory(spec_world, q, [0.0, np.nan, 1.0])
    with pytest.raises(ShapeError, match=r"segment must have shape \(3,\)"):
        check_trajectory(spec_world, q, [0.0, 1.0, 2.0], [0, 1])
    with pytest.raises(TrajectoryCheckError, match="segment indices must be integers"):
        check_trajectory(spec_world, q, [0.0, 1.0, 2.0], [0.0, 0.5, 1.0])
    with pytest.raises(TrajectoryCheckError, match="acceleration_bound must be finite and >= 0"):
        check_trajectory(spec_world, q, [0.0, 1.0, 2.0], acceleration_bound=-1.0)
    with pytest.raises(ShapeError, match=r"q must have shape"):
        check_trajectory(spec_world, np.zeros((3, 4)), [0.0, 1.0, 2.0])


def test_assert_within_limits(arm):
    q = np.radians([[10.0, 10, -10, 10, 10], [10.0, 10, 5, 10, 10]])
    with pytest.raises(AssertionError, match=r"sample 1, joint q3 = 5 deg outside \[-150, 0\] deg"):
        assert_within_limits(q, arm)
    assert_within_limits(q[0], arm)
    assert_within_limits(q, arm, tolerance=np.radians(5.0))
    with pytest.raises(ShapeError, match=r"q must have shape"):
        assert_within_limits(np.zeros(4), arm)


def test_assert_collision_free_clearance_message(spec_world):
    q, t, _ = joint_space_task(rate=10.0)
    with pytest.raises(AssertionError, match=r"clearance .* mm < required 50.0000 mm: .* wall_"):
        assert_collision_free(q, t, spec_world, clearance=0.05)
