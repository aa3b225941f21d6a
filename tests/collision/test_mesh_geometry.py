"""Mesh collision geometry (the SO-101's STL parts): convex hulls in the collision world, checked
against coal's distance to the original meshes, and the sphere bound below the exact distance."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest

import lynxplan
from lynxplan.collision import CollisionWorld
from lynxplan.collision.obstacles import axis_aligned_box

#: coal distance agreement [m].
DISTANCE_TOL = 1e-7


@pytest.fixture(scope="module")
def world():
    robot = lynxplan.load_robot("so101")
    boxes = [
        axis_aligned_box("wall", np.array([0.29, -0.12, 0.0]), np.array([0.02, 0.24, 0.12])),
        axis_aligned_box("holder", np.array([0.13, -0.15, 0.0]), np.array([0.06, 0.04, 0.06])),
    ]
    return robot, CollisionWorld(robot, boxes, self_collision=True)


def _mesh_distance(robot, q: np.ndarray, geometry: int, box) -> float:
    """coal's distance from the original (non-convex) mesh to a box obstacle."""
    data = robot.model.createData()
    collision = robot.collision_mesh_model
    geometry_data = pin.GeometryData(collision)
    pin.forwardKinematics(robot.model, data, q)
    pin.updateGeometryPlacements(robot.model, data, collision, geometry_data)
    mesh_pose = geometry_data.oMg[geometry]
    request, result = coal.DistanceRequest(), coal.DistanceResult()
    box_pose = coal.Transform3s(np.eye(3), box.centre)
    return float(
        coal.distance(
            collision.geometryObjects[geometry].geometry,
            coal.Transform3s(mesh_pose.rotation, mesh_pose.translation),
            coal.Box(*box.size),
            box_pose,
            request,
            result,
        )
    )


def test_every_mesh_becomes_a_hull_primitive(world) -> None:
    robot, w = world
    assert len(w.links) == robot.collision_model.ngeoms == 17
    assert {p.kind for p in w.links} == {"mesh"}
    assert any(w.pair_is_self)


def test_hull_distance_is_never_more_than_the_mesh_distance(world) -> None:
    robot, w = world
    q = robot.random_configurations(12, seed=7)
    distances = w.distances(q)
    checked = 0
    for k in range(len(q)):
        for pair in range(w.pair_count):
            if w.pair_is_self[pair]:
                continue
            link = int(w.pair_link[pair])
            box = w.obstacles[int(w.pair_other[pair])]
            mesh = _mesh_distance(robot, q[k], link, box)
            hull = distances[k, pair]
            if mesh > 0:
                assert hull <= mesh + DISTANCE_TOL  # the hull contains the mesh: safe side
                checked += 1
    assert checked > 100


def test_sphere_bound_is_below_the_exact_distance(world) -> None:
    robot, w = world
    q = robot.random_configurations(50, seed=8)
    exact = w.distances(q)
    bound = w.lower_bounds(w.primitive_poses(q))
    apart = (exact > 0) | (bound > 0)  # in contact, a bound <= 0 proves nothing (see world.py)
    assert (bound[apart] <= exact[apart] + 1e-12).all()
    assert (bound > 0).any()  # the bound proves something, not only <= 0


def test_a_second_world_reuses_the_hulls_and_answers_the_same(world):
    """Worlds of the same robot share each mesh's centred hull (built once per process), and a
    second world's distances equal the first's (within coal's agreement: GJK warm starts)."""
    robot, first = world
    second = CollisionWorld(robot, first.obstacles, self_collision=True)
    meshes = [k for k, link in enumerate(first.links) if link.kind == "mesh"]
    assert meshes
    for k in meshes:
        assert second.links[k].shape is first.links[k].shape
        np.testing.assert_array_equal(second.links[k].placement, first.links[k].placement)
    rng = np.random.default_rng(7)
    bounds = np.asarray(robot.limits.position)  # (n, 2) [rad]
    for q in rng.uniform(bounds[:, 0], bounds[:, 1], size=(5, len(bounds))):
        again = second.distances(q)
        np.testing.assert_allclose(again, first.distances(q), rtol=0, atol=DISTANCE_TOL)
