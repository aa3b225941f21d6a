"""The collision world: primitive poses, FCL distances against coal, lower bounds, obstacles."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest
from okq_reference import spec_obstacles

from lynxplan.collision import (
    BoxObstacle,
    CollisionWorld,
    CylinderObstacle,
    SphereObstacle,
    axis_aligned_box,
    rotation_from_axis,
)
from lynxplan.collision.world import signed_distance
from lynxplan.constants import COAL_GJK_TOLERANCE, FCL_DISTANCE_TOLERANCE
from lynxplan.exceptions import (
    CollisionModelError,
    InvalidObstacleError,
    NonFiniteInputError,
    ShapeError,
)

POSE_TOLERANCE = 1e-12
#: coal against closed forms, in [m] (its GJK stops at ~1e-10 m).
EXACT_DISTANCE_TOLERANCE = 1e-8


def _mixed_obstacles() -> list:
    tilted = rotation_from_axis([1.0, 1.0, 0.5])
    return [
        *spec_obstacles(),
        BoxObstacle("tilted_box", [0.15, -0.1, 0.1], [0.05, 0.08, 0.03], tilted),
        SphereObstacle("ball", [0.1, 0.15, 0.2], 0.04),
        CylinderObstacle("post", [-0.12, 0.05, 0.0], 0.02, 0.3, rotation_from_axis([0.2, 0, 1])),
    ]


@pytest.fixture(scope="module")
def world(arm):
    return CollisionWorld(arm, _mixed_obstacles(), self_collision=True)


@pytest.fixture(scope="module")
def configurations(arm):
    rng = np.random.default_rng(7)
    return rng.uniform(arm.limits.lower, arm.limits.upper, size=(40, 5))


def test_primitive_poses_match_pinocchio(arm, world, configurations):
    poses = world.primitive_poses(configurations)
    data = pin.GeometryData(arm.collision_model)
    for n, q in enumerate(configurations):
        pin.forwardKinematics(arm.model, arm.data, q)
        pin.updateGeometryPlacements(arm.model, arm.data, arm.collision_model, data)
        for g in range(len(world.links)):
            np.testing.assert_allclose(poses[n, g], data.oMg[g].homogeneous, atol=POSE_TOLERANCE)


def test_every_urdf_primitive_is_in_the_world(arm, world):
    assert [p.geometry for p in world.links] == [
        g.name for g in arm.collision_model.geometryObjects
    ]
    assert {p.link for p in world.links} == {
        "base_link",
        "turntable",
        "upper_arm",
        "forearm",
        "wrist",
        "gripper",
    }
    # Self pairs skip adjacent links: the pen is never paired with the wrist.
    names = [world.pair_names(p) for p in range(world.pair_count)]
    assert ("gripper", "gripper_1", "self:wrist_0") not in names
    assert ("forearm", "forearm_0", "self:gripper_1") in names


def _box_interval(pose, half_extents, kind):
    """World AABB of an axis-aligned primitive: (lo, hi)."""
    if kind == "cylinder":
        radius, half_length, _ = half_extents
        half_extents = np.array([radius, radius, half_length])
    extent = np.abs(pose[:3, :3]) @ half_extents
    return pose[:3, 3] - extent, pose[:3, 3] + extent


def _closed_form_distance(link, pose, box):
    """Exact distance of an axis-aligned primitive to an axis-aligned box obstacle."""
    lo, hi = _box_interval(pose, link.half_extents, link.kind)
    box_lo, box_hi = box.centre - box.size / 2, box.centre + box.size / 2
    gap = np.maximum(np.maximum(box_lo - hi, lo - box_hi), 0.0)
    if link.kind == "box":
        return float(np.linalg.norm(gap))
    axis = int(np.argmax(np.abs(pose[:3, 2])))
    radial = [i for i in range(3) if i != axis]
    # Disc centre to rectangle in the plane normal to the axis, minus the radius.
    centre_gap = np.maximum(
        np.maximum(box_lo[radial] - pose[radial, 3], pose[radial, 3] - box_hi[radial]), 0.0
    )
    planar = max(float(np.linalg.norm(centre_gap)) - link.half_extents[0], 0.0)
    return float(np.hypot(planar, gap[axis]))


def test_coal_distances_are_exact_for_axis_aligned_poses(arm):
    """Joint angles in multiples of 90 deg keep every primitive axis-aligned: closed forms."""
    rng = np.random.default_rng(3)
    boxes = [
        axis_aligned_box(f"b{i}", rng.uniform(-0.4, 0.3, 3), rng.uniform(0.01, 0.2, 3))
        for i in range(12)
    ]
    world = CollisionWorld(arm, boxes)
    angles = [
        (a, b, c, d, e)
        for a in (0, 90, 180)
        for b in (0, 90)
        for c in (0, -90)
        for d in (0, 90, 180)
        for e in (0, 90)
    ]
    grid = np.radians(np.array(angles, dtype=float))
    poses = world.primitive_poses(grid)
    distances = world.distances(grid)
    checked = 0
    for n in range(len(grid)):
        for pair in range(world.pair_count):
            g, o = int(world.pair_link[pair]), int(world.pair_other[pair])
            expected = _closed_form_distance(world.links[g], poses[n, g], boxes[o])
            if expected > 0:
                assert distances[n, pair] == pytest.approx(expected, abs=EXACT_DISTANCE_TOLERANCE)
                checked += 1
    assert checked > 2000


def test_fcl_box_box_distance_bug_is_why_coal_is_the_default():
    """FCL issue #508: two unit cubes 3 m apart along y are reported 3.162 m apart."""
    import fcl

    first = fcl.CollisionObject(fcl.Box(1.0, 1.0, 1.0), fcl.Transform(np.array([0.0, 4.0, 0.0])))
    second = fcl.CollisionObject(fcl.Box(1.0, 1.0, 1.0), fcl.Transform())
    reported = fcl.distance(first, second, fcl.DistanceRequest())
    assert abs(reported - 3.0) > 0.1
    exact = coal.distance(
        coal.Box(1.0, 1.0, 1.0),
        coal.Transform3s(np.eye(3), np.array([0.0, 4.0, 0.0])),
        coal.Box(1.0, 1.0, 1.0),
        coal.Transform3s(),
        coal.DistanceRequest(),
        coal.DistanceResult(),
    )
    assert exact == pytest.approx(3.0, abs=EXACT_DISTANCE_TOLERANCE)


def _coal_distance(arm, world, poses, pair):
    link = int(world.pair_link[pair])
    other = int(world.pair_other[pair])
    shapes = arm.collision_model.geometryObjects
    first = (shapes[link].geometry, poses[link])
    if world.pair_is_self[pair]:
        second = (shapes[other].geometry, poses[other])
    else:
        obstacle = world.obstacles[other]
        placement = np.eye(4)
        placement[:3, :3], placement[:3, 3] = obstacle.rotation, obstacle.centre
        second = (obstacle.coal_geometry(), placement)
    request = coal.DistanceRequest()
    request.gjk_tolerance = request.epa_tolerance = COAL_GJK_TOLERANCE
    return coal.distance(
        first[0],
        coal.Transform3s(first[1][:3, :3], first[1][:3, 3]),
        second[0],
        coal.Transform3s(second[1][:3, :3], second[1][:3, 3]),
        request,
        coal.DistanceResult(),
    )


def test_fcl_engine_over_estimates_some_distances(arm, world, configurations):
    fcl_world = CollisionWorld(arm, _mixed_obstacles(), self_collision=True, engine="fcl")
    exact = world.distances(configurations)
    approximate = fcl_world.distances(configurations)
    poses = world.primitive_poses(configurations)
    # The world's prebuilt queries equal plain coal.distance calls.
    for pair in range(world.pair_count):
        expected = _coal_distance(arm, world, poses[0], pair)
        assert exact[0, pair] == pytest.approx(expected, abs=1e-12)
    apart = exact > 0
    error = approximate[apart] - exact[apart]
    # Most FCL answers agree; the rest over-estimate (GJK stops early, the unsafe side), by
    # millimetres for box-box and box-cylinder pairs.
    assert np.quantile(np.abs(error), 0.95) <= FCL_DISTANCE_TOLERANCE
    assert error.min() >= -FCL_DISTANCE_TOLERANCE
    assert error.max() > 1e-3


def test_lower_bounds_never_exceed_the_distance(world, configurations):
    poses = world.primitive_poses(configurations)
    bounds = world.lower_bounds(poses)
    distances = world.distances(configurations)
    apart = distances > 0
    assert (bounds[apart] <= distances[apart] + EXACT_DISTANCE_TOLERANCE).all()
    # ... and are useful: within a few centimetres of the truth.
    assert np.median(distances[apart] - bounds[apart]) < 0.03


@pytest.mark.parametrize(
    ("obstacle", "point", "expected"),
    [
        (axis_aligned_box("b", [0, 0, 0], [1, 2, 3]), [2.0, 1.0, 1.0], 1.0),
        (axis_aligned_box("b", [0, 0, 0], [1, 2, 3]), [2.0, 3.0, 1.0], np.sqrt(2.0)),
        (axis_aligned_box("b", [0, 0, 0], [1, 2, 3]), [0.4, 1.0, 1.5], -0.4),
        (SphereObstacle("s", [1, 0, 0], 0.5), [1.0, 2.0, 0.0], 1.5),
        (CylinderObstacle("c", [0, 0, 0], 1.0, 2.0), [3.0, 0.0, 2.0], np.sqrt(5.0)),
        (CylinderObstacle("c", [0, 0, 0], 1.0, 2.0), [0.0, 0.5, 0.0], -0.5),
    ],
)
def test_point_signed_distance(obstacle, point, expected):
    assert signed_distance(obstacle, np.array(point)) == pytest.approx(expected, abs=1e-12)


def test_spec_walls_in_metres():
    letters, home = spec_obstacles()
    np.testing.assert_allclose(letters.centre, np.array([0.0, 13.0, -0.25]) * 0.0254, atol=1e-15)
    np.testing.assert_allclose(home.size, np.array([10.0, 1.0, 8.0]) * 0.0254, atol=1e-15)


def test_obstacle_errors(arm):
    with pytest.raises(InvalidObstacleError, match="'w': size along y must be positive"):
        axis_aligned_box("w", [0, 0, 0], [1, 0, 1])
    with pytest.raises(InvalidObstacleError, match="'s': radius must be positive"):
        SphereObstacle("s", [0, 0, 0], -1.0)
    with pytest.raises(InvalidObstacleError, match="'c': length must be positive"):
        CylinderObstacle("c", [0, 0, 0], 0.1, 0.0)
    with pytest.raises(InvalidObstacleError, match="not a proper rotation"):
        BoxObstacle("b", [0, 0, 0], [1, 1, 1], np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(ShapeError, match=r"b.centre must have shape \(3,\). Got: \(2,\)"):
        BoxObstacle("b", [0, 0], [1, 1, 1])
    with pytest.raises(ShapeError, match=r"b.rotation must have shape \(3, 3\)"):
        BoxObstacle("b", [0, 0, 0], [1, 1, 1], np.eye(2))
    with pytest.raises(NonFiniteInputError, match=r"b\.size contains NaN"):
        BoxObstacle("b", [0, 0, 0], [1, np.nan, 1])
    with pytest.raises(InvalidObstacleError, match="axis vector must not be zero"):
        rotation_from_axis([0, 0, 0])
    with pytest.raises(CollisionModelError, match="engine must be 'coal' or 'fcl'"):
        CollisionWorld(arm, [], engine="bullet")
    with pytest.raises(CollisionModelError, match="names must be unique"):
        CollisionWorld(
            arm, [SphereObstacle("s", [1, 0, 0], 0.1), SphereObstacle("s", [2, 0, 0], 0.1)]
        )


def test_unsupported_primitive_is_rejected(arm):
    class FakeArm:
        model = arm.model
        collision_model = pin.GeometryModel()

    FakeArm.collision_model.addGeometryObject(
        pin.GeometryObject("blob", 1, pin.SE3.Identity(), coal.Ellipsoid(0.1, 0.2, 0.3))
    )
    with pytest.raises(CollisionModelError, match="blob: shape Ellipsoid is not supported"):
        CollisionWorld(FakeArm(), [])


def test_configuration_shape_errors(world):
    with pytest.raises(ShapeError, match=r"q must have shape \(5,\) or \(N, 5\). Got: \(4,\)"):
        world.primitive_poses(np.zeros(4))
    with pytest.raises(NonFiniteInputError, match="q contains NaN"):
        world.primitive_poses(np.full(5, np.nan))
