"""The HTML export of a meshed arm: each mesh sent once, decimated, the page a few MB; the mesh
reader and the decimation checked against independent computations."""

from __future__ import annotations

import base64
import json
import re
from pathlib import Path

import numpy as np
import pytest
import umsgpack

import lynxplan
from lynxplan._meshes import _binary_stl, decimate, mesh_arrays
from lynxplan.viz import _grid_step, export_html

#: The goal of issue 34: the SO-101's page was 28.8 MB and hung a headless browser.
SIZE_LIMIT = 5 * 1024**2


def _steps(html: str) -> list[object]:
    """The page's steps: meshcat commands (decoded) and the page's own steps (copies...)."""
    found = re.search(r"const STEPS = (\[.*?\]);\n", html, re.DOTALL)
    assert found is not None
    steps = json.loads(found.group(1))
    return [umsgpack.unpackb(base64.b64decode(s)) if isinstance(s, str) else s for s in steps]


@pytest.fixture(scope="module")
def so101():
    return lynxplan.load_robot("so101")


@pytest.fixture(scope="module")
def so101_page(so101, tmp_path_factory):
    q = np.linspace(so101.limits.lower * 0.3, so101.limits.upper * 0.3, 400)  # 20 s at 30 fps
    out = tmp_path_factory.mktemp("so101") / "so101.html"
    return export_html(so101, q, np.linspace(0.0, 20.0, 400), out)


def test_so101_page_is_a_few_mb(so101_page: Path) -> None:
    assert so101_page.stat().st_size <= SIZE_LIMIT


def test_each_mesh_file_is_sent_once_and_copied_for_its_other_uses(so101, so101_page) -> None:
    visuals = so101.visual_model.geometryObjects
    files = [g.meshPath for g in visuals]
    assert len(set(files)) < len(files)  # the servo's STL is used five times
    steps = _steps(so101_page.read_text())
    meshes = [
        s for s in steps
        if isinstance(s, dict) and s["type"] == "set_object"
        and s["object"]["object"]["type"] == "Mesh"
        and s["object"]["geometries"][0]["type"] == "BufferGeometry"
    ]  # fmt: skip
    assert len(meshes) == len(set(files))
    copies = [s for s in steps if isinstance(s, list) and s[0] == "copy"]
    assert len(copies) == len(files) - len(set(files))
    for mesh in meshes:  # decimated
        faces = mesh["object"]["geometries"][0]["data"]["index"]["array"]
        assert len(faces.data) // 12 <= 5_000


def test_binary_stl_reader_matches_pinocchios_mesh(so101) -> None:
    visual = so101.visual_model.geometryObjects[0]
    vertices, faces = _binary_stl(Path(visual.meshPath))
    shape = visual.geometry
    assert len(faces) == shape.num_tris
    loaded = np.asarray(shape.vertices())
    np.testing.assert_allclose(vertices.min(axis=0), loaded.min(axis=0), atol=1e-7)
    np.testing.assert_allclose(vertices.max(axis=0), loaded.max(axis=0), atol=1e-7)
    got_v, got_f = mesh_arrays(visual)
    np.testing.assert_array_equal(got_f, faces)
    np.testing.assert_allclose(got_v, vertices * np.asarray(visual.meshScale))


def _sphere(n: int) -> tuple[np.ndarray, np.ndarray]:
    """A UV sphere of radius 1 with about 2 n^2 triangles."""
    theta, phi = np.meshgrid(np.linspace(0, np.pi, n + 1), np.linspace(0, 2 * np.pi, 2 * n + 1))
    points = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])
    vertices = points.reshape(3, -1).T
    index = np.arange(vertices.shape[0]).reshape(2 * n + 1, n + 1)
    a, b = index[:-1, :-1].ravel(), index[1:, :-1].ravel()
    c, d = index[1:, 1:].ravel(), index[:-1, 1:].ravel()
    return vertices, np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])


def test_decimation_keeps_the_shape_within_a_cell() -> None:
    vertices, faces = _sphere(200)  # 160,000 triangles
    small_v, small_f = decimate(vertices, faces, 3_000)
    assert 500 < len(small_f) <= 3_000
    assert small_f.max() < len(small_v)
    radius = np.linalg.norm(small_v, axis=1)
    # Each vertex is the mean of a grid cell's vertices: inside the sphere, close to it.
    assert radius.max() <= 1.0 + 1e-12
    assert radius.min() > 0.9
    # Triangles keep their orientation (this UV sphere's all face inwards).
    original, area_before = _outward(vertices, faces)
    assert original.mean() < 0.01
    outward, area = _outward(small_v, small_f)
    assert outward.mean() < 0.05
    # The surface area stays close to the sphere's, 4 pi.
    assert area_before == pytest.approx(4.0 * np.pi, rel=1e-3)
    assert area == pytest.approx(4.0 * np.pi, rel=0.05)


def _outward(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, float]:
    """Whether each (non-degenerate) triangle of a sphere about the origin faces outwards; the
    total area."""
    corners = vertices[faces]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    area = np.linalg.norm(normals, axis=1)
    big = area > 1e-12
    outward = np.einsum("ij,ij->i", normals[big], corners[big].mean(axis=1)) > 0
    return outward, float(area.sum() / 2.0)


def test_small_mesh_is_kept() -> None:
    vertices, faces = _sphere(10)
    same_v, same_f = decimate(vertices, faces, 10_000)
    assert same_v is vertices
    np.testing.assert_array_equal(same_f, faces)


@pytest.mark.parametrize(("extent", "step"), [(0.3, 0.05), (0.75, 0.1), (2.0, 0.2), (0.01, 1e-3)])
def test_grid_step_is_round(extent: float, step: float) -> None:
    assert _grid_step(extent) == pytest.approx(step)
