"""The on-disk convex hulls of collision meshes: the same collision geometry, loaded faster."""

from __future__ import annotations

import os
import re
import types
from pathlib import Path

import numpy as np
import pytest

from lynxplan.collision import CollisionWorld
from lynxplan.collision.obstacles import axis_aligned_box
from lynxplan.robots import hull_cache, load_robot


@pytest.fixture
def private_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv(hull_cache.CACHE_ENV, str(tmp_path / "cache"))
    return tmp_path / "cache" / "hulls"


def test_collision_meshes_become_cached_hull_files(private_cache: Path) -> None:
    robot = load_robot("so101")
    xml = hull_cache.hull_urdf(robot._urdf_xml, robot.urdf_path.parent, robot._mesh_dirs())
    hulls = sorted(private_cache.glob("*.stl"))
    assert len(hulls) == len(
        set(re.findall(r'<collision>.*?filename="([^"]+)"', robot._urdf_xml, re.S))
    )
    assert xml.count(str(private_cache)) == 17  # every collision mesh, no visual one
    meshes = {g.meshPath for g in robot.collision_mesh_model.geometryObjects}
    assert sum(map(os.path.getsize, hulls)) < 0.3 * sum(map(os.path.getsize, meshes))
    # a second call reuses the files
    stamps = [h.stat().st_mtime_ns for h in hulls]
    assert hull_cache.hull_urdf(robot._urdf_xml, robot.urdf_path.parent, robot._mesh_dirs()) == xml
    assert [h.stat().st_mtime_ns for h in hulls] == stamps


def test_the_hull_of_the_hull_file_is_the_hull_of_the_mesh(private_cache: Path) -> None:
    import coal
    from scipy.spatial import ConvexHull

    robot = load_robot("so101")
    for geometry in list(robot.collision_mesh_model.geometryObjects)[:5]:
        mesh = Path(geometry.meshPath)
        points = np.array(coal.MeshLoader().load(str(mesh), np.ones(3)).vertices())
        hull_path = hull_cache.hull_file(mesh, private_cache.parent / "x")
        assert hull_path is None  # the folder must exist: nothing made
        private_cache.mkdir(parents=True, exist_ok=True)
        hull_path = hull_cache.hull_file(mesh, private_cache)
        assert hull_path is not None
        hull_points = np.array(coal.MeshLoader().load(str(hull_path), np.ones(3)).vertices())
        expected = {tuple(p) for p in points[ConvexHull(points).vertices]}
        got = {tuple(p) for p in hull_points[ConvexHull(hull_points).vertices]}
        assert got == expected  # bit for bit: mesh vertices, float32 in both files


def test_world_distances_equal_with_hulls_and_with_meshes(private_cache: Path) -> None:
    robot = load_robot("so101")
    boxes = [axis_aligned_box("wall", np.array([0.29, -0.12, 0.0]), np.array([0.02, 0.24, 0.12]))]
    with_hulls = CollisionWorld(robot, boxes, self_collision=True)
    meshes = types.SimpleNamespace(model=robot.model, collision_model=robot.collision_mesh_model)
    with_meshes = CollisionWorld(meshes, boxes, self_collision=True)
    q = robot.random_configurations(20, seed=4)
    # the same polytopes; their vertices in another order move coal's GJK within its tolerance
    np.testing.assert_allclose(with_hulls.distances(q), with_meshes.distances(q), rtol=0, atol=1e-8)


def test_no_writable_cache_keeps_the_original(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    monkeypatch.setenv(hull_cache.CACHE_ENV, str(blocker))
    robot = load_robot("so101")
    assert hull_cache.cache_dir() is None
    xml = robot._urdf_xml
    assert hull_cache.hull_urdf(xml, robot.urdf_path.parent, robot._mesh_dirs()) is xml


def test_a_changed_mesh_gets_a_new_hull(tmp_path: Path, private_cache: Path) -> None:
    robot = load_robot("so101")
    source = Path(robot.collision_mesh_model.geometryObjects[0].meshPath)
    mesh = tmp_path / "part.stl"
    mesh.write_bytes(source.read_bytes())
    private_cache.mkdir(parents=True)
    first = hull_cache.hull_file(mesh, private_cache)
    os.utime(mesh, ns=(1, 1))
    second = hull_cache.hull_file(mesh, private_cache)
    assert first is not None and second is not None and first != second
    assert hull_cache.resolve_mesh("part.stl", tmp_path, ()) == mesh
    assert hull_cache.resolve_mesh("package://x/part.stl", None, (str(tmp_path.parent),)) is None
    assert hull_cache.resolve_mesh(f"file://{mesh}", None, ()) == mesh
